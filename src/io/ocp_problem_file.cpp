// src/io/ocp_problem_file.cpp: optimal control problem files (TOML with an [ocp] table) ->
// OcpProblem. The format is documented in docs/problem-files.md ("Optimal control problems");
// every check here has a line there. [model], [discretization], [homotopy] and [ipopt] are read
// exactly as for simulation files (problem_file_reader.hpp).
//
// Reading order: syntax, top-level keys, [model] names and expressions, [ocp] keys and
// expressions (which decide, with the model's, whether a clock state is needed), [model] x0 and the
// Pss, the [ocp] bounds and guesses, [ocp] scalar options, [discretization] (N_finite_elements may
// be a list, one per control interval), [homotopy], [ipopt], and finally the ranges of
// validate(OcpOptions) and of the OCP's own rules, all reported together.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "fesd/error.hpp"
#include "fesd/problem_file.hpp"
#include "io/ocp_expression_functions.hpp"
#include "io/problem_file_reader.hpp"
#include "ocp/ocp_checks.hpp"

namespace fesd {
namespace {

using namespace io_detail;

constexpr double kInf = std::numeric_limits<double>::infinity();

constexpr std::array<std::string_view, 7> kTopKeys{"name",           "description", "model", "ocp",
                                                   "discretization", "homotopy",    "ipopt"};
// [ocp] keys that are not scalar options (kOcpOptions below): expressions, bounds, guesses.
constexpr std::array<std::string_view, 15> kOcpVectorKeys{
    "f_q", "f_q_T", "g_path", "lbg_path", "ubg_path", "g_terminal", "lbg_terminal", "ubg_terminal",
    "lbx", "ubx",   "lbu",    "ubu",      "u_guess",  "lbx0",       "ubx0"};

using Op = OcpProblem;
using Ov = OptionValue;

constexpr std::array<OptionSpec<Op>, 6> kOcpOptions{{
    {"ocp", "T", Kind::Double, [](Op& q, const Ov& v) { q.ocp.T = v.d; }},
    {"ocp", "N_stages", Kind::Int, [](Op& q, const Ov& v) { q.ocp.N_stages = v.i; }},
    {"ocp", "relax_terminal_constraint", Kind::TerminalMode,
     [](Op& q, const Ov& v) {
       q.ocp.terminal_constraint =
           v.name == "ell_1" ? TerminalConstraint::L1 : TerminalConstraint::Hard;
     }},
    {"ocp", "rho_terminal", Kind::Double, [](Op& q, const Ov& v) { q.ocp.rho_terminal = v.d; }},
    {"ocp", "initialization", Kind::InitMode,
     [](Op& q, const Ov& v) {
       q.options.initialization =
           v.name == "simulation" ? OcpInitialization::Simulation : OcpInitialization::Constant;
     }},
    {"ocp", "constraints_at_stages", Kind::Bool,
     [](Op& q, const Ov& v) { q.options.constraints_at_stages = v.b; }},
}};
constexpr auto kOptions = concat(kOcpOptions, solver_option_specs<Op>());
constexpr std::array<std::string_view, 4> kTables{"ocp", "discretization", "homotopy", "ipopt"};

std::vector<std::string_view> keys_of(std::string_view table) {
  if (table != "ocp") return keys_of_table(kOptions, table);
  // T and N_stages first, as in the documentation's table.
  std::vector<std::string_view> keys{"T", "N_stages"};
  keys.insert(keys.end(), kOcpVectorKeys.begin(), kOcpVectorKeys.end());
  for (std::string_view k : keys_of_table(kOptions, "ocp"))
    if (std::find(keys.begin(), keys.end(), k) == keys.end()) keys.push_back(k);
  return keys;
}

std::string list_of_ints(const std::vector<int>& v) {
  std::string s;
  for (int i : v) s += fmt::format("{}{}", s.empty() ? "" : ", ", i);
  return "[" + s + "]";
}

/// Rules of an OcpProblem that validate(OcpOptions) does not cover. Messages start with the
/// "table.key = value" they are about, so that file errors can point at its line.
std::vector<std::string> validate_ocp(const OcpProblem& q) {
  std::vector<std::string> e;
  const Ocp& o = q.ocp;
  if (!(std::isfinite(o.T) && o.T > 0)) e.push_back(fmt::format("ocp.T = {}: must be > 0", o.T));
  if (o.N_stages < 1) e.push_back(fmt::format("ocp.N_stages = {}: must be >= 1", o.N_stages));
  if (std::string s = ocp_detail::step_length_error(o); !s.empty()) e.push_back(std::move(s));
  if (!o.N_FE.empty()) {
    if (static_cast<int>(o.N_FE.size()) != o.N_stages)
      e.push_back(fmt::format(
          "discretization.N_finite_elements = {}: wrong length (expected {} {}, one per control "
          "interval (N_stages = {}), or one integer for all intervals)",
          list_of_ints(o.N_FE), o.N_stages, o.N_stages == 1 ? "entry" : "entries", o.N_stages));
    const bool fesd = q.options.discretization.use_fesd;
    for (std::size_t k = 0; k < o.N_FE.size(); ++k) {
      const int n = o.N_FE[k];
      if (n < 1 || n > 1000)
        e.push_back(
            fmt::format("discretization.N_finite_elements[{}] = {}: must be in 1..1000", k, n));
      else if (fesd && n < 2)
        e.push_back(fmt::format(
            "discretization.N_finite_elements[{}] = {}: FESD needs >= 2 finite elements (with one "
            "there is no step size to move); use 2 or use_fesd = false",
            k, n));
    }
  }
  if (!(std::isfinite(o.rho_terminal) && o.rho_terminal > 0))
    e.push_back(fmt::format("ocp.rho_terminal = {}: must be > 0", o.rho_terminal));
  if (o.terminal_constraint == TerminalConstraint::L1 && o.n_g_terminal == 0)
    e.push_back(
        "ocp.relax_terminal_constraint = ell_1: there are no terminal constraints to relax "
        "(expected g_terminal, or relax_terminal_constraint = \"none\")");
  return e;
}

std::vector<std::string> validate_all(const OcpProblem& q) {
  std::vector<std::string> e = validate_ocp(q);
  for (std::string& s : validate(q.options)) e.push_back(std::move(s));
  if (e.empty())  // the limits of the NLP's blocks, docs/problem-files.md "Limits"
    for (std::string& s : ocp_detail::block_size_errors(q.ocp, q.options))
      e.push_back(std::move(s));
  return e;
}

/// A list of expressions (g_path, g_terminal).
std::vector<expr::Expression> read_expressions(const Reader& r, const toml::node& n,
                                               std::string_view path, const Symbols& sym,
                                               bool controls_allowed, std::string_view what) {
  const toml::array& a = r.array(n, path, "an array of expressions");
  std::vector<expr::Expression> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    out.push_back(r.expression(a[i], index(path, i), sym.all));
    if (!controls_allowed) check_no_controls(r, out.back(), a[i], index(path, i), sym, what);
  }
  return out;
}

/// Lower and upper bounds of one kind (lbx/ubx, lbg_path/ubg_path, ...), each optional.
struct Bounds {
  Eigen::VectorXd lb, ub;
  const toml::node* lb_node = nullptr;
  const toml::node* ub_node = nullptr;
};

/// Reads lb_key/ub_key of [ocp]. `list_key`: the constraint list the bounds belong to (g_path,
/// g_terminal), or empty for variable bounds; bounds without their list are a mistake.
Bounds read_bounds(const Reader& r, const toml::table& t, std::string_view lb_key,
                   std::string_view ub_key, int n, std::string_view what,
                   std::string_view list_key = {}) {
  Bounds b;
  b.lb_node = t.get(lb_key);
  b.ub_node = t.get(ub_key);
  if (!list_key.empty() && t.get(list_key) == nullptr)
    for (const auto& [node, key] : {std::pair{b.lb_node, lb_key}, std::pair{b.ub_node, ub_key}})
      if (node != nullptr)
        r.fail(node->source(), join("ocp", key),
               fmt::format("bounds without constraints (expected {} = [...] in [ocp], the "
                           "expressions these bounds apply to)",
                           list_key));
  if (b.lb_node != nullptr) b.lb = r.vector(*b.lb_node, join("ocp", lb_key), n, what, true);
  if (b.ub_node != nullptr) b.ub = r.vector(*b.ub_node, join("ocp", ub_key), n, what, true);
  return b;
}

/// Fills an absent side: `lb_default` / `ub_default` if neither is given, else unbounded. Then
/// checks lb <= ub entry by entry.
void complete_bounds(const Reader& r, Bounds& b, std::string_view lb_key, std::string_view ub_key,
                     int n, double lb_default, double ub_default) {
  const bool none = b.lb_node == nullptr && b.ub_node == nullptr;
  if (b.lb_node == nullptr) b.lb = Eigen::VectorXd::Constant(n, none ? lb_default : -kInf);
  if (b.ub_node == nullptr) b.ub = Eigen::VectorXd::Constant(n, none ? ub_default : kInf);
  for (int i = 0; i < n; ++i)
    if (b.lb[i] > b.ub[i]) {
      const toml::node* at = b.lb_node != nullptr ? b.lb_node : b.ub_node;
      r.fail(at->source(), "",
             fmt::format("ocp.{}[{}] = {} > ocp.{}[{}] = {}: empty bounds (expected {} <= {})",
                         lb_key, i, format_number(b.lb[i]), ub_key, i, format_number(b.ub[i]),
                         lb_key, ub_key));
    }
}

/// [discretization] N_finite_elements: one integer for all control intervals, or a list.
void read_N_FE(const Reader& r, const toml::node& n, OcpProblem& problem) {
  const std::string path = "discretization.N_finite_elements";
  if (n.is_integer()) {
    problem.options.discretization.N_FE = r.integer(n, path);
    return;
  }
  const toml::array* a = n.as_array();
  if (a == nullptr)
    r.wrong_type(n, path, "an integer, or an array of integers, one per control interval");
  if (a->empty())
    r.fail(n.source(), path,
           "empty (expected one number of finite elements per control interval, or one integer)");
  for (std::size_t i = 0; i < a->size(); ++i)
    problem.ocp.N_FE.push_back(r.integer((*a)[i], index(path, i)));
}

void read_options(const Reader& r, const toml::table& root, OcpProblem& problem) {
  for (std::string_view table_name : kTables) {
    const toml::node* tn = root.get(table_name);
    if (tn == nullptr) continue;  // [ocp] is checked before
    const toml::table& t = r.table(*tn, table_name);
    const std::vector<std::string_view> keys = keys_of(table_name);
    if (table_name != "ipopt") r.check_keys(t, keys, table_name);
    for (const OptionSpec<Op>& o : kOptions) {
      if (o.table != table_name) continue;
      const toml::node* n = t.get(o.key);
      if (n == nullptr) continue;
      if (o.key == "N_finite_elements")
        read_N_FE(r, *n, problem);
      else
        o.set(problem, read_option(r, o.table, o.key, o.kind, *n));
    }
    if (table_name == "ipopt") read_ipopt_extra(r, t, keys, problem.options.nlp.extra);
  }
  const std::vector<std::string> errors = validate_all(problem);
  if (!errors.empty()) throw_validation_errors(r, root, errors);
}

/// v with `value` appended (the clock's entry).
Eigen::VectorXd append(const Eigen::VectorXd& v, double value) {
  Eigen::VectorXd out(v.size() + 1);
  out << v, value;
  return out;
}

}  // namespace

OcpProblem parse_ocp_problem(std::string_view toml_text, std::string_view source_name) {
  const Reader r{std::string(source_name)};
  const toml::table root = parse_toml(toml_text, source_name);
  const toml::node* ocp_node = root.get("ocp");
  if (const toml::node* sim = root.get("simulation"))
    r.fail(sim->source(), "simulation",
           ocp_node != nullptr
               ? "both [simulation] and [ocp] given (expected exactly one: [simulation] for a "
                 "simulation, [ocp] for an optimal control problem)"
               : "this is a simulation file (a [simulation] table, expected [ocp]): run it with "
                 "`fesd simulate` or fesd::load_simulation_problem");
  r.check_keys(root, kTopKeys, "");
  if (ocp_node == nullptr)
    r.fail(toml::source_region{}, "ocp",
           "missing table [ocp] (expected at least T, the length of the horizon)");

  OcpProblem problem;
  problem.source = std::string(source_name);
  problem.name = std::filesystem::path(std::string(source_name)).stem().string();
  if (const toml::node* n = root.get("name")) {
    problem.name = r.string(*n, "name");
    if (problem.name.empty()) r.fail(n->source(), "name", "empty (expected a non-empty name)");
  }
  if (const toml::node* n = root.get("description"))
    problem.description = r.string(*n, "description");

  ModelSpec spec = read_model_spec(r, root);
  const Symbols sym = spec.sym;
  const int n_x_user = static_cast<int>(sym.x.size());
  const int n_u = static_cast<int>(sym.u.size());

  // [ocp]: keys, then the expressions (they may read t, which decides the clock).
  const toml::table& t = r.table(*ocp_node, "ocp");
  if (const toml::node* x0 = t.get("x0"))
    r.fail(x0->source(), "ocp.x0",
           "x0 belongs in [model] (the initial state; with lbx0/ubx0 in [ocp] it is the guess of "
           "a free initial state)");
  r.check_keys(t, keys_of("ocp"), "ocp");
  if (t.get("T") == nullptr)
    r.fail(t.source(), "ocp", "missing key 'T' (expected the length of the horizon, a number > 0)");
  OcpExpressions e;
  if (const toml::node* n = t.get("f_q")) e.f_q = r.expression(*n, "ocp.f_q", sym.all);
  if (const toml::node* n = t.get("f_q_T")) {
    e.f_q_T = r.expression(*n, "ocp.f_q_T", sym.all);
    check_no_controls(r, *e.f_q_T, *n, "ocp.f_q_T", sym, "the Mayer term f_q_T(x, p)");
  }
  const toml::node* g_path = t.get("g_path");
  const toml::node* g_terminal = t.get("g_terminal");
  if (g_path != nullptr)
    e.g_path = read_expressions(r, *g_path, "ocp.g_path", sym, true, "a path constraint");
  if (g_terminal != nullptr)
    e.g_terminal = read_expressions(r, *g_terminal, "ocp.g_terminal", sym, false,
                                    "a terminal constraint g_terminal(x, p)");

  const auto reads_time = [&](const expr::Expression& x) {
    return sym.time_index >= 0 && x.depends_on(sym.time_index);
  };
  bool has_clock = spec.uses_time();
  if (e.f_q) has_clock = has_clock || reads_time(*e.f_q);
  if (e.f_q_T) has_clock = has_clock || reads_time(*e.f_q_T);
  for (const auto* list : {&e.g_path, &e.g_terminal})
    has_clock = has_clock || std::any_of(list->begin(), list->end(), reads_time);

  // [model] x0 and the Pss; the OCP starts at t = 0.
  const toml::node* x0_node = spec.table->get("x0");
  BuiltModel built = build_model(r, std::move(spec), has_clock, 0.0);
  Ocp& ocp = problem.ocp;
  ocp.model = std::move(built.model);
  ocp.x0 = std::move(built.x0);
  ocp.p = std::move(built.p);
  problem.has_clock = has_clock;
  ExpressionLayout layout;
  layout.n_x = ocp.model.n_x();
  layout.n_x_slots = n_x_user + (sym.time_index >= 0 ? 1 : 0);
  layout.n_u = n_u;
  layout.n_p = ocp.model.n_p();
  ocp.n_g_path = static_cast<int>(e.g_path.size());
  ocp.n_g_terminal = static_cast<int>(e.g_terminal.size());
  try {
    ocp.functions = std::make_shared<const ExpressionOcpFunctions>(layout, std::move(e));
  } catch (const InvalidModel& err) {
    throw InvalidModel(fmt::format("{}: {}", r.at(t.source()), err.what()));
  }

  // Bounds and guesses. The clock (if any) is unbounded and starts at 0.
  const std::string per_state = "one per state in model.x";
  const std::string per_control = "one per control in model.u";
  Bounds x = read_bounds(r, t, "lbx", "ubx", n_x_user, per_state);
  if (x.lb_node != nullptr || x.ub_node != nullptr) {
    complete_bounds(r, x, "lbx", "ubx", n_x_user, -kInf, kInf);
    ocp.lbx = has_clock ? append(x.lb, -kInf) : x.lb;
    ocp.ubx = has_clock ? append(x.ub, kInf) : x.ub;
  }
  Bounds u = read_bounds(r, t, "lbu", "ubu", n_u, per_control);
  if (u.lb_node != nullptr || u.ub_node != nullptr) {
    complete_bounds(r, u, "lbu", "ubu", n_u, -kInf, kInf);
    ocp.lbu = u.lb;
    ocp.ubu = u.ub;
  }
  if (const toml::node* n = t.get("u_guess")) {
    ocp.u_guess = r.vector(*n, "ocp.u_guess", n_u, per_control);
    for (int i = 0; i < n_u && ocp.lbu.size() > 0; ++i)
      if (ocp.u_guess[i] < ocp.lbu[i] || ocp.u_guess[i] > ocp.ubu[i])
        r.fail(n->source(), index("ocp.u_guess", static_cast<std::size_t>(i)),
               fmt::format("{} is outside [lbu, ubu] = [{}, {}] (expected a guess within the "
                           "control bounds)",
                           format_number(ocp.u_guess[i]), format_number(ocp.lbu[i]),
                           format_number(ocp.ubu[i])));
  }
  Bounds x0 = read_bounds(r, t, "lbx0", "ubx0", n_x_user, per_state);
  if (x0.lb_node != nullptr || x0.ub_node != nullptr) {
    complete_bounds(r, x0, "lbx0", "ubx0", n_x_user, -kInf, kInf);
    for (int i = 0; i < n_x_user; ++i)
      if (ocp.x0[i] < x0.lb[i] || ocp.x0[i] > x0.ub[i])
        r.fail(x0_node->source(), index("model.x0", static_cast<std::size_t>(i)),
               fmt::format("{} is outside [lbx0, ubx0] = [{}, {}] (with lbx0/ubx0, model.x0 is "
                           "the guess of the free initial state and must satisfy its bounds)",
                           format_number(ocp.x0[i]), format_number(x0.lb[i]),
                           format_number(x0.ub[i])));
    ocp.lbx0 = has_clock ? append(x0.lb, 0.0) : x0.lb;
    ocp.ubx0 = has_clock ? append(x0.ub, 0.0) : x0.ub;
  }
  // Path constraints: g_path <= 0 unless bounds are given; terminal constraints: g_terminal = 0
  // (nosnoc's convention) unless bounds are given. One bound alone leaves the other side open.
  Bounds gp = read_bounds(r, t, "lbg_path", "ubg_path", ocp.n_g_path,
                          "one per path constraint in g_path", "g_path");
  complete_bounds(r, gp, "lbg_path", "ubg_path", ocp.n_g_path, -kInf, 0.0);
  ocp.lbg_path = gp.lb;
  ocp.ubg_path = gp.ub;
  Bounds gt = read_bounds(r, t, "lbg_terminal", "ubg_terminal", ocp.n_g_terminal,
                          "one per terminal constraint in g_terminal", "g_terminal");
  complete_bounds(r, gt, "lbg_terminal", "ubg_terminal", ocp.n_g_terminal, 0.0, 0.0);
  ocp.lbg_terminal = gt.lb;
  ocp.ubg_terminal = gt.ub;

  read_options(r, root, problem);
  return problem;
}

OcpProblem load_ocp_problem(const std::string& path) {
  return parse_ocp_problem(read_problem_text(path), path);
}

ProblemKind problem_file_kind(const std::string& path) {
  const toml::table root = parse_toml(read_problem_text(path), path);
  return root.get("ocp") != nullptr ? ProblemKind::Ocp : ProblemKind::Simulation;
}

void apply_override(OcpProblem& problem, std::string_view key_in, std::string_view value_in) {
  const OverrideArg arg = parse_override_arg(key_in, value_in, kTables);
  const std::string_view table = arg.table, key = arg.key;
  const std::string& value = arg.value;
  const std::string& head = arg.head;

  OcpProblem updated = problem;
  const OptionSpec<Op>* spec = find_option(kOptions, table, key);

  if (spec != nullptr) {
    spec->set(updated, override_value(spec->kind, value, head));
    // One number for every control interval replaces a per-interval list.
    if (spec->key == "N_finite_elements") updated.ocp.N_FE.clear();
  } else if (table == "ipopt" && !key.empty()) {
    set_ipopt_option(updated.options.nlp.extra, key, value);
  } else {
    std::vector<std::string_view> valid;
    for (const OptionSpec<Op>& o : kOptions)
      if (table.empty() || o.table == table) valid.push_back(o.key);
    if (table.empty() || table == "discretization") valid.push_back("N_FE");
    std::string hint = key_hint(key, valid);
    if (std::find(kOcpVectorKeys.begin(), kOcpVectorKeys.end(), key) != kOcpVectorKeys.end())
      hint = "(expressions, bounds and guesses can only be set in the file)";
    override_error(head, fmt::format("unknown option '{}' {}", key, hint));
  }

  const std::vector<std::string> errors = validate_all(updated);
  if (!errors.empty())
    throw_override_errors(
        head, spec != nullptr ? fmt::format("{}.{}", spec->table, spec->key) : std::string{},
        errors);
  problem = std::move(updated);
}

}  // namespace fesd
