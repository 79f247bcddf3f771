// src/io/problem_file.cpp: simulation problem files (TOML) -> SimulationProblem. The format is
// documented in docs/problem-files.md; every check here has a line there. What simulation and
// optimal control files share (the typed reader, [model], the option tables) is in
// problem_file_reader.{hpp,cpp}; optimal control files are read by ocp_problem_file.cpp.
//
// Reading order: syntax (toml++), unknown keys per table, then [model] (names, expressions, sign
// matrices, vector fields, x0), [simulation], [discretization], [homotopy], [ipopt], and finally
// the option ranges of validate() (options.hpp). The first mistake found is thrown as
// "<file>:<line>: <key path>: <what is wrong> (<expected>, got <got>)".
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "core/limits.hpp"
#include "discretization/fesd_interval.hpp"
#include "fesd/error.hpp"
#include "fesd/pds_problem_file.hpp"
#include "fesd/problem_file.hpp"
#include "integrator/theta_guess.hpp"
#include "io/option_target.hpp"
#include "io/problem_file_reader.hpp"

namespace fesd {
namespace {

using namespace io_detail;

constexpr std::array<std::string_view, 7> kTopKeys{
    "name", "description", "model", "simulation", "discretization", "homotopy", "ipopt"};
constexpr registry::Use kKind = registry::Use::Simulation;

std::vector<std::string> validate_all(const SimulationProblem& q) {
  std::vector<std::string> e = registry::validate_simulation(q.T_sim, q.N_sim, q.tol_sim,
                                                             q.N_sim_max, q.t0, q.error_estimate);
  std::vector<std::string> options = validate(q.options);
  if (options.empty())  // the limits of build(), docs/problem-files.md "Limits"
    options = discretization::FesdInterval::block_size_errors(q.model, q.options.discretization);
  for (std::string& s : options) e.push_back(std::move(s));
  for (std::string& s : integrator::theta_guess_errors(q.model, q.options))
    e.push_back(std::move(s));
  return e;
}

void read_options(const Reader& r, const toml::table& root, SimulationProblem& problem) {
  const registry::OptionTarget target = target_of(problem);
  for (registry::Table table : registry::tables(kKind)) {
    const toml::node* tn = root.get(registry::to_string(table));
    if (tn == nullptr) {
      if (table == registry::Table::Simulation) fail_missing_table(r, table);
      continue;
    }
    const toml::table& t = r.table(*tn, registry::to_string(table));
    check_table_keys(r, t, table, kKind);
    read_option_table(r, t, table, kKind, target, problem.options.nlp.extra);
    check_required_key(r, t, table);
  }
  const std::vector<std::string> errors = validate_all(problem);
  if (!errors.empty()) throw_validation_errors(r, root, errors);
}

}  // namespace

SimulationProblem parse_simulation_problem(std::string_view toml_text,
                                           std::string_view source_name) {
  const Reader r{std::string(source_name)};
  const toml::table root = parse_toml(toml_text, source_name);
  // An optimal control file is not a simulation file: say so instead of "unknown key 'ocp'".
  if (const toml::node* ocp = root.get("ocp"))
    r.fail(ocp->source(), "ocp",
           root.get("simulation") != nullptr
               ? "both [simulation] and [ocp] given (expected exactly one: [simulation] for a "
                 "simulation, [ocp] for an optimal control problem)"
               : "this is an optimal control problem (an [ocp] table, expected [simulation]): "
                 "solve it with `fesd solve` or fesd::load_ocp_problem");
  r.check_keys(root, kTopKeys, "");
  // A projected dynamical system is read by load_pds_simulation_problem (docs/pds.md).
  if (const toml::node* m = root.get("model"))
    if (const toml::table* mt = m->as_table())
      if (const toml::node* kind = mt->get("kind"))
        r.fail(kind->source(), "model.kind",
               "a projected dynamical system (kind = \"projected\") is not a piecewise smooth "
               "model: only `fesd simulate` and fesd::load_pds_simulation_problem read it "
               "(docs/pds.md)");

  SimulationProblem problem;
  read_name(r, root, source_name, problem);

  // t0 is needed by the model (clock initial value); read it first.
  double t0 = 0.0;
  if (const toml::node* sim = root.get("simulation"))
    if (const toml::table* st = sim->as_table())
      if (const toml::node* n = st->get("t0")) t0 = r.number(*n, "simulation.t0");

  ModelSpec spec = read_model_spec(r, root);
  const bool has_clock = spec.uses_time();
  BuiltModel built = build_model(r, std::move(spec), has_clock, t0);
  problem.model = std::move(built.model);
  problem.x0 = std::move(built.x0);
  problem.p = std::move(built.p);
  problem.has_clock = has_clock;
  problem.t0 = t0;

  problem.u = Eigen::VectorXd::Zero(problem.model.n_u());
  if (const toml::node* sim = root.get("simulation"))
    if (const toml::table* st = sim->as_table()) {
      if (const toml::node* un = st->get("u"))
        problem.u =
            r.vector(*un, "simulation.u", problem.model.n_u(), "one per control in model.u");
      if (const toml::node* tn = st->get("theta_guess"))
        problem.options.theta_guess = r.vector(*tn, "simulation.theta_guess",
                                               problem.model.n_theta(), "one per region (n_theta)");
    }

  read_options(r, root, problem);
  return problem;
}

SimulationProblem load_simulation_problem(const std::string& path) {
  return parse_simulation_problem(read_problem_text(path), path);
}

void apply_override(SimulationProblem& problem, std::string_view key, std::string_view value_in) {
  const OverrideArg arg = parse_override_arg(key, value_in, kKind);
  const std::string& value = arg.value;
  const std::string& head = arg.head;
  const std::string_view input = arg.option != nullptr ? arg.option->key : std::string_view{};

  SimulationProblem updated = problem;
  if (set_scalar_override(arg, target_of(updated))) {
    // a registry option with a C++ member
  } else if (input == "t0") {
    const auto d = parse_double(value);
    if (!d) override_error(head, "expected a number");
    if (!std::isfinite(*d)) override_error(head, "must be finite");
    updated.t0 = *d;
    if (updated.has_clock) updated.x0[updated.x0.size() - 1] = *d;
  } else if (input == "u") {
    updated.u =
        override_vector(head, value, updated.model.n_u(), "simulation.u", "one per control");
  } else if (input == "theta_guess") {
    updated.options.theta_guess = override_vector(head, value, updated.model.n_theta(),
                                                  "simulation.theta_guess", "one per region");
  } else if (set_model_override(arg, updated.model, updated.has_clock, updated.x0, updated.p)) {
    // [model] x0 or one parameter
  } else if (arg.table == "ipopt" && !arg.key.empty()) {
    set_ipopt_option(updated.options.nlp.extra, arg.key, value);
  } else {
    unknown_override(arg, kKind, updated.model);
  }

  const std::vector<std::string> errors = validate_all(updated);
  if (!errors.empty()) throw_override_errors(arg, errors);
  problem = std::move(updated);
}

namespace {
template <class Problem>  // SimulationProblem or OcpProblem
void apply_all(Problem& problem, const OverrideList& overrides) {
  OverrideList pending = overrides;
  while (!pending.empty()) {
    OverrideList failed;
    std::string first_error;
    for (const auto& [key, value] : pending) {
      try {
        apply_override(problem, key, value);
      } catch (const InvalidOption& e) {
        if (failed.empty()) first_error = e.what();
        failed.emplace_back(key, value);
      }
    }
    if (failed.size() == pending.size()) throw InvalidOption(first_error);
    pending = std::move(failed);
  }
}
}  // namespace

void apply_overrides(SimulationProblem& problem, const OverrideList& overrides) {
  apply_all(problem, overrides);
}

void apply_overrides(OcpProblem& problem, const OverrideList& overrides) {
  apply_all(problem, overrides);
}

void apply_overrides(PdsSimulationProblem& problem, const OverrideList& overrides) {
  apply_all(problem, overrides);
}

void apply_overrides(PdsOcpProblem& problem, const OverrideList& overrides) {
  apply_all(problem, overrides);
}

}  // namespace fesd
