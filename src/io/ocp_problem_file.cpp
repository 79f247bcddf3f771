// src/io/ocp_problem_file.cpp: optimal control problem files (TOML with an [ocp] table) ->
// OcpProblem. The format is documented in docs/problem-files.md ("Optimal control problems");
// every check here has a line there. [model], [discretization], [homotopy] and [ipopt] are read
// exactly as for simulation files (problem_file_reader.hpp).
//
// Reading order: syntax, top-level keys, [model] names and expressions, [ocp] keys and
// expressions (which decide, with the model's, whether a clock state is needed), [model] x0 and the
// Pss, the [ocp] bounds and guesses, [ocp] scalar options, [discretization] (N_finite_elements may
// be a list, one per control interval), [homotopy], [ipopt], and finally the OCP's input rules
// (src/ocp/ocp_input.cpp, shared with fesd::solve): the data's first, then every option rule.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "fesd/error.hpp"
#include "fesd/pds_problem_file.hpp"
#include "fesd/problem_file.hpp"
#include "io/ocp_expression_functions.hpp"
#include "io/option_target.hpp"
#include "io/pds_model_reader.hpp"
#include "io/problem_file_reader.hpp"
#include "ocp/ocp_input.hpp"

namespace fesd {
namespace {

using namespace io_detail;

constexpr double kInf = std::numeric_limits<double>::infinity();

constexpr std::array<std::string_view, 7> kTopKeys{"name",           "description", "model", "ocp",
                                                   "discretization", "homotopy",    "ipopt"};
constexpr registry::Use kKind = registry::Use::Ocp;

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

/// Fills an absent side: `lb_default` / `ub_default` if neither is given, else unbounded. lb <= ub
/// is an input rule of the OCP (src/ocp/ocp_input.cpp).
void complete_bounds(Bounds& b, int n, double lb_default, double ub_default) {
  const bool none = b.lb_node == nullptr && b.ub_node == nullptr;
  if (b.lb_node == nullptr) b.lb = Eigen::VectorXd::Constant(n, none ? lb_default : -kInf);
  if (b.ub_node == nullptr) b.ub = Eigen::VectorXd::Constant(n, none ? ub_default : kInf);
}

/// [discretization] N_finite_elements: one integer for all control intervals, or a list.
template <class Problem>
void read_N_FE(const Reader& r, const toml::node& n, Problem& problem) {
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

/// The options of [ocp], [discretization], [homotopy] and [ipopt], then every input rule of the
/// OCP (src/ocp/ocp_input.cpp): the problem's data first (ProblemFileError), then the options
/// (InvalidOption), each message at the line of the key it names.
/// `read_stage_data` runs after the option tables (it needs T and N_stages), before the rules.
template <class Problem>
void read_options(const Reader& r, const toml::table& root, Problem& problem,
                  const std::function<void()>& read_stage_data) {
  const registry::OptionTarget target = target_of(problem);
  static constexpr std::array<std::string_view, 1> kPerInterval{"N_finite_elements"};
  for (registry::Table table : registry::tables(kKind)) {
    const toml::node* tn = root.get(registry::to_string(table));
    if (tn == nullptr) continue;  // [ocp] is checked before
    const toml::table& t = r.table(*tn, registry::to_string(table));
    check_table_keys(r, t, table, kKind);
    read_option_table(r, t, table, kKind, target, problem.options.nlp.extra, kPerInterval);
    if (table == registry::Table::Discretization)
      if (const toml::node* n = t.get(kPerInterval[0])) read_N_FE(r, *n, problem);
  }
  read_stage_data();
  const ocp_detail::OcpInputErrors errors = ocp_detail::check_input(problem.ocp, problem.options);
  if (!errors.data.empty()) throw ProblemFileError(located(r, root, errors.data));
  if (!errors.options.empty()) throw_validation_errors(r, root, errors.options);
}

/// `u_guess`, `x_guess`: an array of `n_rows` vectors of `length` numbers.
std::vector<Eigen::VectorXd> read_rows(const Reader& r, const toml::node& n, std::string_view path,
                                       int n_rows, std::string_view rows_what, int length,
                                       std::string_view what) {
  const toml::array& a = r.array(n, path, "an array of arrays of numbers");
  if (static_cast<int>(a.size()) != n_rows)
    r.fail(n.source(), path, fmt::format("{} rows, expected {} ({})", a.size(), n_rows, rows_what));
  std::vector<Eigen::VectorXd> rows;
  for (std::size_t k = 0; k < a.size(); ++k)
    rows.push_back(r.vector(a[k], index(path, k), length, what));
  return rows;
}

Eigen::VectorXd append(const Eigen::VectorXd& v, double value);

/// The guesses and parameters per control interval of [ocp] (once T and N_stages are known):
/// u_guess (one vector, or one row per interval), x_guess (the states at the control grid points;
/// a clock state gets t_k; it makes initialization = external unless the file sets it) and
/// p_time_var ({name = [one value per interval]}, names of [model] p); v_global ({name = {guess,
/// lb, ub}}, names of [model] p, read first: a guess sets the parameter's value).
void read_stage_data(const Reader& r, const toml::table& t, const std::vector<std::string>& p_names,
                     int n_x_user, int n_u, bool has_clock, OcpData& ocp, OcpOptions& options) {
  const std::string per_state = "one per state in model.x";
  const std::string per_control = "one per control in model.u";
  if (const toml::node* n = t.get("u_guess")) {
    const toml::array* a = n->as_array();
    if (a != nullptr && !a->empty() && (*a)[0].is_array())  // one row per control interval
      ocp.u_guess_stage = read_rows(r, *n, "ocp.u_guess", ocp.N_stages,
                                    "one per control interval, N_stages", n_u, per_control);
    else
      ocp.u_guess = r.vector(*n, "ocp.u_guess", n_u, per_control);
  }
  if (const toml::node* n = t.get("x_guess")) {
    ocp.x_guess = read_rows(r, *n, "ocp.x_guess", ocp.N_stages + 1,
                            "one per control grid point t_k = k T / N_stages, k = 0..N_stages",
                            n_x_user, per_state);
    if (has_clock)
      for (std::size_t k = 0; k < ocp.x_guess.size(); ++k)
        ocp.x_guess[k] = append(ocp.x_guess[k], static_cast<double>(k) * ocp.T / ocp.N_stages);
    if (t.get("initialization") == nullptr) options.initialization = OcpInitialization::External;
  }
  if (const toml::node* n = t.get("v_global")) {  // {name = {guess, lb, ub}}
    const toml::table& vt = r.table(*n, "ocp.v_global");
    static constexpr std::array<std::string_view, 3> kKeys{"guess", "lb", "ub"};
    for (const auto& [key, value] : vt) {
      const std::string name(key.str());
      const std::string path = "ocp.v_global." + name;
      const auto it = std::find(p_names.begin(), p_names.end(), name);
      if (it == p_names.end())
        r.fail(value.source(), path,
               fmt::format("unknown parameter '{}' (expected a name of [model] p)", name));
      const toml::table& spec = r.table(value, path);
      r.check_keys(spec, kKeys, path);
      GlobalVariable v;
      v.index = static_cast<int>(it - p_names.begin());
      if (const toml::node* lb = spec.get("lb")) v.lb = r.number(*lb, path + ".lb", true);
      if (const toml::node* ub = spec.get("ub")) v.ub = r.number(*ub, path + ".ub", true);
      if (v.lb > v.ub)
        r.fail(value.source(), path,
               fmt::format("lb = {} > ub = {}: empty bounds (expected lb <= ub)", v.lb, v.ub));
      if (const toml::node* g = spec.get("guess")) ocp.p[v.index] = r.number(*g, path + ".guess");
      if (ocp.p[v.index] < v.lb || ocp.p[v.index] > v.ub)
        r.fail(value.source(), path,
               fmt::format("the guess {} is outside [lb, ub] = [{}, {}] (the guess is `guess`, or "
                           "the parameter's [model] p value)",
                           ocp.p[v.index], v.lb, v.ub));
      ocp.v_global.push_back(v);
    }
  }
  if (const toml::node* n = t.get("p_time_var")) {
    const toml::table& pt = r.table(*n, "ocp.p_time_var");
    ocp.p_stage.assign(static_cast<std::size_t>(ocp.N_stages), ocp.p);
    for (const auto& [key, value] : pt) {
      const std::string name(key.str());
      const std::string path = "ocp.p_time_var." + name;
      const auto it = std::find(p_names.begin(), p_names.end(), name);
      if (it == p_names.end())
        r.fail(value.source(), path,
               fmt::format("unknown parameter '{}' (expected a name of [model] p)", name));
      const Eigen::VectorXd v =
          r.vector(value, path, ocp.N_stages, "one value per control interval, N_stages");
      const auto i = static_cast<Eigen::Index>(it - p_names.begin());
      for (const GlobalVariable& global : ocp.v_global)
        if (global.index == i)
          r.fail(value.source(), path,
                 fmt::format("'{}' is a global variable (ocp.v_global): one value for the whole "
                             "horizon, not one per control interval",
                             name));
      for (int k = 0; k < ocp.N_stages; ++k) ocp.p_stage[static_cast<std::size_t>(k)][i] = v[k];
    }
  }
}

/// clock_state (a name of model.x: its index), T_final_min, T_final_max (+-inf allowed).
void read_time_keys(const Reader& r, const toml::table& t, Ocp& ocp) {
  if (const toml::node* n = t.get("clock_state")) {
    const std::string name = r.string(*n, "ocp.clock_state");
    const std::vector<std::string>& names = ocp.model.state_names;
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end())
      r.fail(n->source(), "ocp.clock_state",
             fmt::format("unknown state '{}' (expected a name of [model] x)", name));
    ocp.clock_state = static_cast<int>(it - names.begin());
  }
  if (const toml::node* n = t.get("T_final_min"))
    ocp.T_final_min = r.number(*n, "ocp.T_final_min", true);
  if (const toml::node* n = t.get("T_final_max"))
    ocp.T_final_max = r.number(*n, "ocp.T_final_max", true);
}

/// v with `value` appended (the clock's entry).
Eigen::VectorXd append(const Eigen::VectorXd& v, double value) {
  Eigen::VectorXd out(v.size() + 1);
  out << v, value;
  return out;
}

/// The DCS algebraic variables of an RK stage that g_path_comp may read (RkAlgebraic), or none
/// (`projected`: a projected model has no theta).
struct StageSymbols {
  RkAlgebraic layout;
  bool projected = false;
};

/// The entry of the RkAlgebraic layout named by `name` (theta_i, lambda_i, alpha_j, lambda_n_j,
/// lambda_p_j with a number >= 1; -1: not such a name); `range` gets the number of names of its
/// kind (n_theta or n_c) and `kind` the kind's name.
int stage_entry(std::string_view name, const RkAlgebraic& layout, int& range, std::string& kind) {
  static constexpr std::array<std::string_view, 5> kKinds{"lambda_n", "lambda_p", "theta", "lambda",
                                                          "alpha"};
  for (std::string_view k : kKinds) {
    if (name.size() <= k.size() + 1 || name.substr(0, k.size()) != k || name[k.size()] != '_')
      continue;
    const std::string_view digits = name.substr(k.size() + 1);
    if (digits.size() > 6 || digits[0] == '0' ||
        !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
      return -1;
    const int j = std::stoi(std::string(digits));
    kind = std::string(k);
    const bool per_region = k == "theta" || k == "lambda";
    range = per_region ? layout.n_theta : layout.n_c;
    if (j > range) return layout.size();  // out of range
    const int offset = k == "theta"      ? 0
                       : k == "lambda"   ? layout.n_theta
                       : k == "alpha"    ? 2 * layout.n_theta
                       : k == "lambda_n" ? 2 * layout.n_theta + layout.n_c
                                         : 2 * layout.n_theta + 2 * layout.n_c;
    return offset + j - 1;
  }
  return -1;
}

/// Fails on a name of a stage variable (stage_entry) in the expression `n` that is no model
/// symbol, where stage variables cannot be read: outside g_path_comp (`in_comp` false), in a
/// projected file, or beyond the model's regions / switching functions.
void check_stage_names(const Reader& r, const toml::node& n, std::string_view path,
                       const Symbols& sym, const StageSymbols& stage, bool in_comp) {
  const auto* str = n.as_string();
  if (str == nullptr) return;
  const std::string& text = str->get();
  const auto ident = [](char c, bool first) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' ||
           (!first && c >= '0' && c <= '9');
  };
  for (std::size_t i = 0; i < text.size();) {
    if (!ident(text[i], true) || (i > 0 && ident(text[i - 1], false))) {
      ++i;
      continue;
    }
    std::size_t e = i;
    while (e < text.size() && ident(text[e], false)) ++e;
    const std::string name = text.substr(i, e - i);
    i = e;
    int range = 0;
    std::string kind;
    const int entry = stage_entry(name, stage.layout, range, kind);
    if (entry < 0 || std::find(sym.all.begin(), sym.all.end(), name) != sym.all.end()) continue;
    if (stage.projected)
      r.fail(n.source(), path,
             fmt::format("'{}': a projected model has no DCS algebraic variables (theta, lambda, "
                         "alpha exist for piecewise smooth models only)",
                         name));
    if (!in_comp)
      r.fail(n.source(), path,
             fmt::format("'{}' is a DCS algebraic variable of the RK stages: only g_path_comp may "
                         "read it",
                         name));
    if (entry >= stage.layout.size())
      r.fail(n.source(), path,
             fmt::format("'{}': out of range (the model has {} {}: {}_1 .. {}_{})", name,
                         kind == "theta" || kind == "lambda" ? "n_theta =" : "n_c =",
                         kind == "theta" || kind == "lambda"
                             ? count(static_cast<std::size_t>(range), "region")
                             : count(static_cast<std::size_t>(range), "switching function"),
                         kind, kind, range));
  }
}

/// The expressions of [ocp]: f_q, f_q_T, g_path, g_terminal (f_q_T and g_terminal without
/// controls), g_path_comp (its pairs that read stage variables become g_rk_comp).
OcpExpressions read_ocp_expressions(const Reader& r, const toml::table& t, const Symbols& sym,
                                    const StageSymbols& stage) {
  OcpExpressions e;
  for (std::string_view key : {"f_q", "f_q_T"})
    if (const toml::node* n = t.get(key))
      check_stage_names(r, *n, join("ocp", key), sym, stage, false);
  for (std::string_view key : {"g_path", "g_terminal"})
    if (const toml::node* n = t.get(key); n != nullptr && n->as_array() != nullptr)
      for (std::size_t i = 0; i < n->as_array()->size(); ++i)
        check_stage_names(r, (*n->as_array())[i], index(join("ocp", key), i), sym, stage, false);
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
  if (const toml::node* n = t.get("g_path_comp")) {  // [[a_1, b_1], [a_2, b_2], ...]
    const std::string path = "ocp.g_path_comp";
    const toml::array& pairs = r.array(*n, path, "an array of pairs [a, b] of expressions");
    if (pairs.empty())
      r.fail(n->source(), path, "empty (expected at least one pair [a, b] of expressions)");
    // The symbols and then the stage variables y (a name the model uses stays the model's: its
    // stage slot gets a name no expression can spell).
    std::vector<std::string> symbols = sym.all;
    const int n_rk = stage.projected ? 0 : stage.layout.size();
    for (int i = 0; i < n_rk; ++i) {
      const std::string name = stage.layout.name(i);
      const bool taken = std::find(sym.all.begin(), sym.all.end(), name) != sym.all.end();
      symbols.push_back(taken ? "#" + name : name);
    }
    const int first_y = static_cast<int>(sym.all.size());
    std::vector<expr::Expression> a, b, a_rk, b_rk;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const std::string pi = index(path, i);
      const toml::array& pair = r.array(pairs[i], pi, "a pair [a, b] of expressions");
      if (pair.size() != 2)
        r.fail(pairs[i].source(), pi,
               fmt::format("{} expressions (expected a pair [a, b]: 0 <= a perp b >= 0)",
                           pair.size()));
      for (std::size_t s = 0; s < 2; ++s)
        check_stage_names(r, pair[s], index(pi, s), sym, stage, true);
      expr::Expression ea = r.expression(pair[0], index(pi, 0), symbols);
      expr::Expression eb = r.expression(pair[1], index(pi, 1), symbols);
      const auto reads_y = [&](const expr::Expression& x) {
        return !x.dependencies().empty() && x.dependencies().back() >= first_y;
      };
      const bool rk = reads_y(ea) || reads_y(eb);
      (rk ? a_rk : a).push_back(std::move(ea));
      (rk ? b_rk : b).push_back(std::move(eb));
    }
    e.g_path_comp = std::move(a);
    e.g_path_comp.insert(e.g_path_comp.end(), b.begin(), b.end());
    e.g_rk_comp = std::move(a_rk);
    e.g_rk_comp.insert(e.g_rk_comp.end(), b_rk.begin(), b_rk.end());
    if (!e.g_rk_comp.empty()) e.n_rk = n_rk;
  }

  return e;
}

/// The bounds and guesses of [ocp] into `ocp` (n_x_user states in the file, a clock state
/// appended if has_clock; n_u controls; the constraint counts already set). Their rules (lb <= ub,
/// guesses within bounds) are checked with the options (read_options).
void read_ocp_bounds(const Reader& r, const toml::table& t, int n_x_user, int n_u, bool has_clock,
                     OcpData& ocp) {
  // The clock (if any) is unbounded and starts at 0.
  const std::string per_state = "one per state in model.x";
  const std::string per_control = "one per control in model.u";
  Bounds x = read_bounds(r, t, "lbx", "ubx", n_x_user, per_state);
  if (x.lb_node != nullptr || x.ub_node != nullptr) {
    complete_bounds(x, n_x_user, -kInf, kInf);
    ocp.lbx = has_clock ? append(x.lb, -kInf) : x.lb;
    ocp.ubx = has_clock ? append(x.ub, kInf) : x.ub;
  }
  Bounds u = read_bounds(r, t, "lbu", "ubu", n_u, per_control);
  if (u.lb_node != nullptr || u.ub_node != nullptr) {
    complete_bounds(u, n_u, -kInf, kInf);
    ocp.lbu = u.lb;
    ocp.ubu = u.ub;
  }
  Bounds x0 = read_bounds(r, t, "lbx0", "ubx0", n_x_user, per_state);
  if (x0.lb_node != nullptr || x0.ub_node != nullptr) {
    complete_bounds(x0, n_x_user, -kInf, kInf);
    ocp.lbx0 = has_clock ? append(x0.lb, 0.0) : x0.lb;
    ocp.ubx0 = has_clock ? append(x0.ub, 0.0) : x0.ub;
  }
  // Path constraints: g_path <= 0 unless bounds are given; terminal constraints: g_terminal = 0
  // (nosnoc's convention) unless bounds are given. One bound alone leaves the other side open.
  Bounds gp = read_bounds(r, t, "lbg_path", "ubg_path", ocp.n_g_path,
                          "one per path constraint in g_path", "g_path");
  complete_bounds(gp, ocp.n_g_path, -kInf, 0.0);
  ocp.lbg_path = gp.lb;
  ocp.ubg_path = gp.ub;
  Bounds gt = read_bounds(r, t, "lbg_terminal", "ubg_terminal", ocp.n_g_terminal,
                          "one per terminal constraint in g_terminal", "g_terminal");
  complete_bounds(gt, ocp.n_g_terminal, 0.0, 0.0);
  ocp.lbg_terminal = gt.lb;
  ocp.ubg_terminal = gt.ub;
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
  if (const toml::node* m = root.get("model"); m != nullptr && m->as_table() != nullptr)
    if (const toml::node* kind = m->as_table()->get("kind"))
      r.fail(kind->source(), "model.kind",
             "a projected model: read the file with fesd::load_pds_ocp_problem (`fesd solve` "
             "does)");

  OcpProblem problem;
  read_name(r, root, source_name, problem);

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
  check_table_keys(r, t, registry::Table::Ocp, kKind);
  check_required_key(r, t, registry::Table::Ocp);
  int n_theta = 0, n_c = 0;  // the stage variables g_path_comp may read
  for (const RawSubsystem& sub : spec.subsystems) {
    n_theta += sub.n_f;
    n_c += static_cast<int>(sub.expressions.c.size());
  }
  OcpExpressions e = read_ocp_expressions(r, t, sym, {{n_theta, n_c}, false});
  const auto reads_time = [&](const expr::Expression& x) {
    return sym.time_index >= 0 && x.depends_on(sym.time_index);
  };
  bool has_clock = spec.uses_time();
  if (e.f_q) has_clock = has_clock || reads_time(*e.f_q);
  if (e.f_q_T) has_clock = has_clock || reads_time(*e.f_q_T);
  for (const auto* list : {&e.g_path, &e.g_terminal, &e.g_path_comp, &e.g_rk_comp})
    has_clock = has_clock || std::any_of(list->begin(), list->end(), reads_time);

  // [model] x0 and the Pss; the OCP starts at t = 0.
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
  layout.algebraic = built.algebraic;  // the expressions may read z
  ocp.n_g_path = static_cast<int>(e.g_path.size());
  ocp.n_g_terminal = static_cast<int>(e.g_terminal.size());
  ocp.n_g_path_comp = static_cast<int>(e.g_path_comp.size()) / 2;
  ocp.n_g_rk_comp = static_cast<int>(e.g_rk_comp.size()) / 2;
  // Its layout checks are invariants of this reader (fesd::InternalError), not input errors.
  ocp.functions = std::make_shared<const ExpressionOcpFunctions>(layout, std::move(e));

  read_ocp_bounds(r, t, n_x_user, n_u, has_clock, ocp);
  read_options(r, root, problem, [&] {
    read_stage_data(r, t, sym.p, n_x_user, n_u, has_clock, ocp, problem.options);
    read_time_keys(r, t, ocp);
  });
  return problem;
}

PdsOcpProblem parse_pds_ocp_problem(std::string_view toml_text, std::string_view source_name) {
  const Reader r{std::string(source_name)};
  const toml::table root = parse_toml(toml_text, source_name);
  const toml::node* ocp_node = root.get("ocp");
  if (const toml::node* sim = root.get("simulation"))
    r.fail(sim->source(), "simulation",
           "a [simulation] table in an optimal control problem file (expected [ocp]; a "
           "simulation file is run with `fesd simulate`)");
  r.check_keys(root, kTopKeys, "");
  if (ocp_node == nullptr)
    r.fail(toml::source_region{}, "ocp",
           "missing table [ocp] (expected at least T, the length of the horizon)");
  PdsOcpProblem problem;
  read_name(r, root, source_name, problem);
  PdsModelRead m = read_pds_model(r, root);
  const toml::table& t = r.table(*ocp_node, "ocp");
  if (const toml::node* x0 = t.get("x0"))
    r.fail(x0->source(), "ocp.x0", "x0 belongs in [model] (the initial state)");
  check_table_keys(r, t, registry::Table::Ocp, kKind);
  check_required_key(r, t, registry::Table::Ocp);
  OcpExpressions e = read_ocp_expressions(r, t, m.sym, {{}, /*projected=*/true});
  const auto reads_time = [&](const expr::Expression& x) { return x.depends_on(m.sym.time_index); };
  bool uses_time = (e.f_q && reads_time(*e.f_q)) || (e.f_q_T && reads_time(*e.f_q_T));
  for (const auto* list : {&e.g_path, &e.g_terminal, &e.g_path_comp})
    uses_time = uses_time || std::any_of(list->begin(), list->end(), reads_time);
  if (uses_time)
    r.fail(ocp_node->source(), "ocp",
           "an expression uses the time t, which projected models do not support yet");
  PdsOcp& ocp = problem.ocp;
  ocp.model = std::move(m.model);
  ocp.x0 = std::move(m.x0);
  ocp.p = std::move(m.p);
  const int n_x = ocp.model.n_x(), n_u = ocp.model.n_u();
  const ExpressionLayout layout{
      .n_x = n_x, .n_x_slots = n_x + 1, .n_u = n_u, .n_p = ocp.model.n_p()};
  ocp.n_g_path = static_cast<int>(e.g_path.size());
  ocp.n_g_terminal = static_cast<int>(e.g_terminal.size());
  ocp.n_g_path_comp = static_cast<int>(e.g_path_comp.size()) / 2;
  ocp.functions = std::make_shared<const ExpressionOcpFunctions>(layout, std::move(e));
  read_ocp_bounds(r, t, n_x, n_u, /*has_clock=*/false, ocp);
  read_options(r, root, problem, [&] {
    read_stage_data(r, t, m.sym.p, n_x, n_u, /*has_clock=*/false, ocp, problem.options);
  });
  return problem;
}

namespace {
/// The overrides both kinds of OCP file take the same way: the registry's scalars (N_FE: one
/// number for every control interval now) and u_guess (one guess for every interval now).
template <class Problem>
bool set_ocp_override(const OverrideArg& arg, Problem& updated) {
  if (set_scalar_override(arg, target_of(updated))) {
    if (arg.option->key == "N_finite_elements") updated.ocp.N_FE.clear();
    return true;
  }
  if (arg.option == nullptr || arg.option->key != "u_guess") return false;
  updated.ocp.u_guess = override_vector(arg.head, arg.value, updated.ocp.model.n_u(), "ocp.u_guess",
                                        "one per control in model.u");
  updated.ocp.u_guess_stage.clear();
  return true;
}
}  // namespace

void apply_override(PdsOcpProblem& problem, std::string_view key, std::string_view value) {
  const OverrideArg arg = parse_override_arg(key, value, kKind);
  PdsOcpProblem updated = problem;
  if (set_ocp_override(arg, updated)) {
    // registry option or u_guess
  } else if (!set_pds_override(arg, updated.ocp.model, updated.options.nlp.extra, updated.ocp.x0,
                               updated.ocp.p, nullptr)) {
    unknown_override(arg, kKind, Pss{});
  }
  ocp_detail::OcpInputErrors errors = ocp_detail::check_input(updated.ocp, updated.options);
  for (std::string& e : errors.data) errors.options.push_back(std::move(e));
  if (!errors.options.empty()) throw_override_errors(arg, errors.options);
  problem = std::move(updated);
}

PdsOcpProblem load_pds_ocp_problem(const std::string& path) {
  return parse_pds_ocp_problem(read_problem_text(path), path);
}

OcpProblem load_ocp_problem(const std::string& path) {
  return parse_ocp_problem(read_problem_text(path), path);
}

ProblemKind problem_file_kind(const std::string& path) {
  const toml::table root = parse_toml(read_problem_text(path), path);
  return root.get("ocp") != nullptr ? ProblemKind::Ocp : ProblemKind::Simulation;
}

void apply_override(OcpProblem& problem, std::string_view key, std::string_view value) {
  const OverrideArg arg = parse_override_arg(key, value, kKind);
  OcpProblem updated = problem;
  if (set_ocp_override(arg, updated)) {
    // registry option or u_guess
  } else if (set_model_override(arg, updated.ocp.model, updated.has_clock, updated.ocp.x0,
                                updated.ocp.p)) {
    // [model] x0 (the guess of a free x0) or one parameter
  } else if (arg.table == "ipopt" && !arg.key.empty()) {
    set_ipopt_option(updated.options.nlp.extra, arg.key, arg.value);
  } else {
    unknown_override(arg, kKind, updated.ocp.model);
  }

  ocp_detail::OcpInputErrors errors = ocp_detail::check_input(updated.ocp, updated.options);
  for (std::string& e : errors.data) errors.options.push_back(std::move(e));
  if (!errors.options.empty()) throw_override_errors(arg, errors.options);
  problem = std::move(updated);
}

}  // namespace fesd
