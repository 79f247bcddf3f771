// src/io/pds_problem_file.cpp: simulation problem files of projected dynamical systems
// ([model] kind = "projected", docs/pds.md "Problem files") -> PdsSimulationProblem. Shares the
// typed reader and the option tables with problem_file.cpp; the [model] table has its own keys.
#include "fesd/pds_problem_file.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "core/accuracy_options.hpp"
#include "fesd/error.hpp"
#include "fesd/problem_file.hpp"
#include "io/option_target.hpp"
#include "io/pds_model_reader.hpp"
#include "io/problem_file_reader.hpp"
#include "model/expression_pds.hpp"

namespace fesd {
namespace {

using namespace io_detail;

constexpr std::array<std::string_view, 7> kTopKeys{
    "name", "description", "model", "simulation", "discretization", "homotopy", "ipopt"};
constexpr std::array<std::string_view, 8> kPdsModelKeys{"kind", "x",           "u", "p",
                                                        "x0",   "constraints", "f", "x0_tol"};
// Keys of piecewise smooth models: a projected model must not have them.
constexpr std::array<std::string_view, 5> kPssKeys{"c", "S", "g", "F", "subsystem"};
constexpr registry::Use kKind = registry::Use::Simulation;

const toml::table* model_table(const toml::table& root) {
  const toml::node* m = root.get("model");
  return m != nullptr ? m->as_table() : nullptr;
}

/// The [simulation] keys (as for piecewise smooth files, with the start time t0) and the options.
std::vector<std::string> validate_all(const PdsSimulationProblem& q) {
  std::vector<std::string> e = registry::validate_simulation(q.T_sim, q.N_sim, q.tol_sim,
                                                             q.N_sim_max, q.t0, q.error_estimate);
  for (std::string& s : validate(q.options)) e.push_back(std::move(s));
  return e;
}

}  // namespace

namespace io_detail {

PdsModelRead read_pds_model(const Reader& r, const toml::table& root, const double* clock_t0) {
  PdsModelRead model_read;
  const toml::node* model_node = root.get("model");
  if (model_node == nullptr)
    r.fail(toml::source_region{}, "model",
           "missing table [model] (expected kind = \"projected\", x, x0, f and constraints)");
  const toml::table& model = r.table(*model_node, "model");
  for (std::string_view k : kPssKeys)
    if (const toml::node* n = model.get(k))
      r.fail(n->source(), join("model", k),
             fmt::format("'{}' belongs to piecewise smooth models; a projected model (kind = "
                         "\"projected\") has one vector field `f` and its set C = {{x : "
                         "constraints(x) >= 0}} in `constraints`: the two kinds cannot be mixed",
                         k));
  r.check_keys(model, kPdsModelKeys, "model");
  const toml::node* kind = model.get("kind");
  if (kind == nullptr || r.string(*kind, "model.kind") != "projected")
    r.fail(kind != nullptr ? kind->source() : model.source(), "model.kind",
           "expected \"projected\"");
  auto required = [&](std::string_view key, std::string_view what) -> const toml::node& {
    const toml::node* n = model.get(key);
    if (n == nullptr)
      r.fail(model.source(), "model", fmt::format("missing key '{}' (expected {})", key, what));
    return *n;
  };
  std::vector<std::string> x_names, u_names, p_names;
  std::vector<double> p_values;
  std::set<std::string> seen;
  auto add_names = [&](const toml::node& n, std::string_view path, std::vector<std::string>& out) {
    for (const auto& [name, node] : r.names(n, path)) {
      if (!is_identifier(name))
        r.fail(node->source(), path, fmt::format("'{}' is not a valid name", name));
      if (name == "t")
        r.fail(node->source(), path, "'t' is the time, which projected models do not support yet");
      if (!seen.insert(name).second)
        r.fail(node->source(), path, fmt::format("'{}' is used twice", name));
      out.push_back(name);
    }
  };
  add_names(required("x", "the state names, e.g. x = [\"x1\", \"x2\"]"), "model.x", x_names);
  if (x_names.empty()) r.fail(model.source(), "model.x", "no states (expected at least one)");
  if (const toml::node* n = model.get("u")) add_names(*n, "model.u", u_names);
  if (const toml::node* n = model.get("p")) {
    const toml::table* pt = n->as_table();
    if (pt == nullptr)
      r.wrong_type(*n, "model.p", "a table of name = value, e.g. { omega = 6.28 }");
    for (const auto& [k, v] : in_file_order(*pt)) {
      if (!is_identifier(k->str()) || k->str() == "t" || !seen.insert(std::string(k->str())).second)
        r.fail(v->source(), join("model.p", k->str()), "not a valid, unused name");
      p_names.emplace_back(k->str());
      p_values.push_back(r.number(*v, join("model.p", k->str())));
    }
  }
  // Symbols [x, t (unused slot), u, p] as ExpressionLayout expects.
  std::vector<std::string> symbols = x_names;
  symbols.push_back("t");
  symbols.insert(symbols.end(), u_names.begin(), u_names.end());
  symbols.insert(symbols.end(), p_names.begin(), p_names.end());
  const int n_x = static_cast<int>(x_names.size()), time_slot = n_x;
  // f may read t in a simulation (a clock state, below); constraints never (C(t) would be a
  // moving set, a sweeping process with time-dependent C, which the paper does not treat).
  auto expressions = [&](const toml::node& n, std::string_view path, int length,
                         std::string_view what, bool time_allowed) {
    const toml::array& a = r.array(n, path, "an array of expressions");
    if (length >= 0 && static_cast<int>(a.size()) != length)
      r.fail(n.source(), path,
             fmt::format("wrong length (expected {}, {}, got {})", length, what, a.size()));
    if (a.empty()) r.fail(n.source(), path, fmt::format("empty (expected {})", what));
    std::vector<expr::Expression> out;
    for (std::size_t i = 0; i < a.size(); ++i) {
      out.push_back(r.expression(a[i], index(path, i), symbols));
      if (out.back().depends_on(time_slot) && !time_allowed)
        r.fail(a[i].source(), index(path, i),
               clock_t0 == nullptr
                   ? "uses the time t, which projected optimal control files do not support yet"
                   : "uses the time t: the set C = {x : constraints(x) >= 0} must not depend on "
                     "time (papers/fesd-pds.txt treats time-independent sets; t is allowed in f)");
    }
    return out;
  };
  std::vector<expr::Expression> f =
      expressions(required("f", "the vector field, one expression per state"), "model.f", n_x,
                  "one expression per state in x", clock_t0 != nullptr);
  std::vector<expr::Expression> c =
      expressions(required("constraints", "the constraints c(x) >= 0 that define C"),
                  "model.constraints", -1, "at least one constraint c(x) >= 0", false);
  model_read.x0 =
      r.vector(required("x0", "the initial state"), "model.x0", n_x, "one per state in x");
  // The clock: t' = 1 appended to f, t0 to x0; the symbol t then reads state n_x (the slot after
  // the user's states). grad c has no t component (no constraint reads t).
  model_read.has_clock = std::any_of(
      f.begin(), f.end(), [&](const expr::Expression& e) { return e.depends_on(time_slot); });
  const int n_x_all = n_x + (model_read.has_clock ? 1 : 0);
  if (model_read.has_clock) {
    f.push_back(expr::Expression::parse("1", symbols, "clock t' = 1"));
    model_read.x0.conservativeResize(n_x_all);
    model_read.x0[n_x] = *clock_t0;
  }
  ExpressionLayout layout{.n_x = n_x_all,
                          .n_x_slots = n_x + 1,
                          .n_u = static_cast<int>(u_names.size()),
                          .n_p = static_cast<int>(p_names.size())};
  const int n_c = static_cast<int>(c.size());  // (c is moved in the call below)
  try {
    model_read.model = make_expression_pds(
        PdsDims{.n_x = n_x_all, .n_u = layout.n_u, .n_p = layout.n_p, .n_c = n_c}, layout,
        std::move(f), std::move(c));
  } catch (const InvalidModel& e) {
    throw InvalidModel(fmt::format("{}: {}", r.at(model.source()), e.what()));
  }
  model_read.model.state_names = x_names;
  if (model_read.has_clock) model_read.model.state_names.push_back("t");
  model_read.model.control_names = u_names;
  model_read.model.parameter_names = p_names;
  model_read.p = Eigen::Map<const Eigen::VectorXd>(p_values.data(),
                                                   static_cast<Eigen::Index>(p_values.size()));
  model_read.model.p_default = model_read.p;
  if (const toml::node* n = model.get("x0_tol")) {
    model_read.model.x0_tol = r.number(*n, "model.x0_tol");
    if (model_read.model.x0_tol < 0) r.fail(n->source(), "model.x0_tol", "must be >= 0");
  }
  model_read.sym.x = x_names;
  model_read.sym.u = u_names;
  model_read.sym.p = p_names;
  model_read.sym.all = symbols;
  model_read.sym.time_index = time_slot;
  return model_read;
}

}  // namespace io_detail

bool is_projected_problem_file(const std::string& path) {
  const toml::table root = parse_toml(read_problem_text(path), path);
  const toml::table* m = model_table(root);
  if (m == nullptr) return false;
  const toml::node* kind = m->get("kind");
  return kind != nullptr && kind->as_string() != nullptr && kind->as_string()->get() == "projected";
}

PdsSimulationProblem parse_pds_simulation_problem(std::string_view toml_text,
                                                  std::string_view source_name) {
  const Reader r{std::string(source_name)};
  const toml::table root = parse_toml(toml_text, source_name);
  if (const toml::node* ocp = root.get("ocp"))
    r.fail(ocp->source(), "ocp",
           "this is an optimal control problem file (an [ocp] table, expected [simulation]): run "
           "it with `fesd solve` or fesd::load_pds_ocp_problem");
  r.check_keys(root, kTopKeys, "");
  PdsSimulationProblem problem;
  read_name(r, root, source_name, problem);

  // t0 first: it is the clock's start value if f reads t.
  if (const toml::node* sim = root.get("simulation"))
    if (const toml::table* st = sim->as_table())
      if (const toml::node* t0 = st->get("t0")) problem.t0 = r.number(*t0, "simulation.t0");
  PdsModelRead m = read_pds_model(r, root, &problem.t0);
  problem.model = std::move(m.model);
  problem.x0 = std::move(m.x0);
  problem.p = std::move(m.p);
  problem.has_clock = m.has_clock;
  const int n_u = problem.model.n_u();
  problem.u = Eigen::VectorXd::Zero(n_u);

  // ---- [simulation] and the option tables (the keys of simulation files) ----
  SimulationProblem options_only;  // the registry writes into its fields
  const registry::OptionTarget target = target_of(options_only);
  for (registry::Table table : registry::tables(kKind)) {
    const toml::node* tn = root.get(registry::to_string(table));
    if (tn == nullptr) {
      if (table == registry::Table::Simulation) fail_missing_table(r, table);
      continue;
    }
    const toml::table& t = r.table(*tn, registry::to_string(table));
    if (table == registry::Table::Simulation) {
      if (const toml::node* un = t.get("u"))
        problem.u = r.vector(*un, "simulation.u", n_u, "one per control in model.u");
    }
    check_table_keys(r, t, table, kKind);
    read_option_table(r, t, table, kKind, target, options_only.options.nlp.extra);
    check_required_key(r, t, table);
  }
  problem.options = options_only.options;
  problem.T_sim = options_only.T_sim;
  problem.N_sim = options_only.N_sim;
  problem.tol_sim = options_only.tol_sim;
  problem.N_sim_max = options_only.N_sim_max;
  problem.error_estimate = options_only.error_estimate;
  const std::vector<std::string> errors = validate_all(problem);
  if (!errors.empty()) throw_validation_errors(r, root, errors);
  return problem;
}

PdsSimulationProblem load_pds_simulation_problem(const std::string& path) {
  return parse_pds_simulation_problem(read_problem_text(path), path);
}

IntegratorResult simulate(const PdsSimulationProblem& q,
                          const std::function<void(const AccuracyRun&)>& on_run) {
  AccuracyOptions a = accuracy_options(q);
  a.on_run = on_run;
  IntegratorResult r = simulate(q.model, q.x0, q.T_sim, a, q.options, q.u, q.p, q.pds);
  shift_times(r, q.t0);
  return r;
}

namespace io_detail {

bool set_pds_override(const OverrideArg& a, Pds& model,
                      std::vector<std::pair<std::string, std::string>>& ipopt_extra,
                      Eigen::VectorXd& x0, Eigen::VectorXd& p, Eigen::VectorXd* u, bool has_clock) {
  const std::string_view key = a.option != nullptr ? a.option->key : a.key;
  const int n_x = model.n_x() - (has_clock ? 1 : 0), n_u = model.n_u();
  if (a.table == "ipopt" && !a.key.empty()) {
    set_ipopt_option(ipopt_extra, a.key, a.value);
  } else if ((a.table.empty() || a.table == "model") && a.key == "x0") {
    // the states of model.x; a clock keeps its start value t0
    Eigen::VectorXd v = override_vector(a.head, a.value, n_x, "model.x0", "one per state");
    x0.head(n_x) = v;
  } else if (u != nullptr && key == "u") {
    *u = override_vector(a.head, a.value, n_u, "simulation.u", "one per control");
  } else if (set_parameter_override(a, model.parameter_names, p, model.p_default)) {
    // one parameter of model.p
  } else {
    return false;
  }
  return true;
}

}  // namespace io_detail

void apply_override(PdsSimulationProblem& problem, std::string_view key, std::string_view value) {
  const OverrideArg arg = parse_override_arg(key, value, kKind);
  // The registry writes into the fields of a SimulationProblem (as when reading the file).
  SimulationProblem s;
  s.options = problem.options;
  s.T_sim = problem.T_sim;
  s.N_sim = problem.N_sim;
  s.tol_sim = problem.tol_sim;
  s.N_sim_max = problem.N_sim_max;
  s.error_estimate = problem.error_estimate;
  PdsSimulationProblem updated = problem;
  const std::string_view input = arg.option != nullptr ? arg.option->key : std::string_view{};
  if (set_scalar_override(arg, target_of(s))) {
    // a registry option with a C++ member
  } else if (input == "t0") {
    const auto d = parse_double(arg.value);
    if (!d) override_error(arg.head, "expected a number");
    if (!std::isfinite(*d)) override_error(arg.head, "must be finite");
    updated.t0 = *d;
    if (updated.has_clock) updated.x0[updated.x0.size() - 1] = *d;
  } else if (!set_pds_override(arg, updated.model, s.options.nlp.extra, updated.x0, updated.p,
                               &updated.u, updated.has_clock)) {
    unknown_override(arg, kKind, Pss{});
  }
  updated.options = s.options;
  updated.T_sim = s.T_sim;
  updated.N_sim = s.N_sim;
  updated.tol_sim = s.tol_sim;
  updated.N_sim_max = s.N_sim_max;
  updated.error_estimate = s.error_estimate;
  const std::vector<std::string> errors = validate_all(updated);
  if (!errors.empty()) throw_override_errors(arg, errors);
  problem = std::move(updated);
}

}  // namespace fesd
