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
#include "fesd/problem_file.hpp"
#include "io/problem_file_reader.hpp"

namespace fesd {
namespace {

using namespace io_detail;

constexpr std::array<std::string_view, 7> kTopKeys{
    "name", "description", "model", "simulation", "discretization", "homotopy", "ipopt"};
constexpr std::array<std::string_view, 4> kSimulationKeys{"T_sim", "N_sim", "u", "t0"};

using Sp = SimulationProblem;
using Ov = OptionValue;

// Every scalar option: table, file key, kind, and where it goes.
constexpr std::array<OptionSpec<Sp>, 2> kSimulationOptions{{
    {"simulation", "T_sim", Kind::Double, [](Sp& q, const Ov& v) { q.T_sim = v.d; }},
    {"simulation", "N_sim", Kind::Int, [](Sp& q, const Ov& v) { q.N_sim = v.i; }},
}};
constexpr auto kOptions = concat(kSimulationOptions, solver_option_specs<Sp>());

std::vector<std::string_view> keys_of(std::string_view table) {
  return table == "simulation" ? keys_of_table(kOptions, table, kSimulationKeys)
                               : keys_of_table(kOptions, table);
}

/// Rules for [simulation] that validate() (options.hpp) does not cover.
std::vector<std::string> validate_simulation(const SimulationProblem& q) {
  std::vector<std::string> e;
  if (!(std::isfinite(q.T_sim) && q.T_sim > 0))
    e.push_back(fmt::format("simulation.T_sim = {}: must be > 0", q.T_sim));
  if (q.N_sim < 1) e.push_back(fmt::format("simulation.N_sim = {}: must be >= 1", q.N_sim));
  const double t0 = q.has_clock ? q.x0[q.x0.size() - 1] : 0.0;  // the clock starts at t0
  if (std::string s =
          core::step_length_error("simulation.T_sim", q.T_sim, "simulation.N_sim", q.N_sim, t0);
      !s.empty())
    e.push_back(std::move(s));
  if (validate(q.options).empty())  // the limits of build(), docs/problem-files.md "Limits"
    for (std::string& s :
         discretization::FesdInterval::block_size_errors(q.model, q.options.discretization))
      e.push_back(std::move(s));
  return e;
}

std::vector<std::string> validate_all(const SimulationProblem& q) {
  std::vector<std::string> e = validate_simulation(q);
  for (std::string& s : validate(q.options)) e.push_back(std::move(s));
  return e;
}

void read_options(const Reader& r, const toml::table& root, SimulationProblem& problem) {
  for (std::string_view table_name : {"simulation", "discretization", "homotopy", "ipopt"}) {
    const toml::node* tn = root.get(table_name);
    const bool required = table_name == "simulation";
    if (tn == nullptr) {
      if (required)
        r.fail(toml::source_region{}, table_name,
               "missing table [simulation] (expected at least T_sim, the length of the time "
               "interval)");
      continue;
    }
    const toml::table& t = r.table(*tn, table_name);
    const std::vector<std::string_view> keys = keys_of(table_name);
    if (table_name != "ipopt") r.check_keys(t, keys, table_name);
    for (const OptionSpec<Sp>& o : kOptions) {
      if (o.table != table_name) continue;
      if (const toml::node* n = t.get(o.key))
        o.set(problem, read_option(r, o.table, o.key, o.kind, *n));
    }
    if (required && t.get("T_sim") == nullptr)
      r.fail(t.source(), "simulation",
             "missing key 'T_sim' (expected the length of the time interval, a number > 0)");
    if (table_name == "ipopt") read_ipopt_extra(r, t, keys, problem.options.nlp.extra);
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

  SimulationProblem problem;
  problem.source = std::string(source_name);
  problem.name = std::filesystem::path(std::string(source_name)).stem().string();
  if (const toml::node* n = root.get("name")) {
    problem.name = r.string(*n, "name");
    if (problem.name.empty()) r.fail(n->source(), "name", "empty (expected a non-empty name)");
  }
  if (const toml::node* n = root.get("description"))
    problem.description = r.string(*n, "description");

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

  problem.u = Eigen::VectorXd::Zero(problem.model.n_u());
  if (const toml::node* sim = root.get("simulation"))
    if (const toml::table* st = sim->as_table())
      if (const toml::node* un = st->get("u"))
        problem.u =
            r.vector(*un, "simulation.u", problem.model.n_u(), "one per control in model.u");

  read_options(r, root, problem);
  return problem;
}

SimulationProblem load_simulation_problem(const std::string& path) {
  return parse_simulation_problem(read_problem_text(path), path);
}

constexpr std::array<std::string_view, 4> kOverrideTables{"simulation", "discretization",
                                                          "homotopy", "ipopt"};

void apply_override(SimulationProblem& problem, std::string_view key_in,
                    std::string_view value_in) {
  const OverrideArg arg = parse_override_arg(key_in, value_in, kOverrideTables);
  const std::string_view table = arg.table, key = arg.key;
  const std::string& value = arg.value;
  const std::string& head = arg.head;

  SimulationProblem updated = problem;
  const OptionSpec<Sp>* spec = find_option(kOptions, table, key);

  if (spec != nullptr) {
    spec->set(updated, override_value(spec->kind, value, head));
  } else if ((table.empty() || table == "simulation") && key == "t0") {
    const auto d = parse_double(value);
    if (!d) override_error(head, "expected a number");
    if (!std::isfinite(*d)) override_error(head, "must be finite");
    if (updated.has_clock) updated.x0[updated.x0.size() - 1] = *d;
  } else if ((table.empty() || table == "simulation") && key == "u") {
    std::vector<double> u;
    std::string_view rest = value;
    while (!rest.empty()) {
      const std::size_t comma = rest.find(',');
      const auto d = parse_double(trim(rest.substr(0, comma)));
      if (!d) override_error(head, "expected comma-separated numbers, one per control");
      if (!std::isfinite(*d)) override_error(head, "must be finite");
      u.push_back(*d);
      rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    }
    if (static_cast<int>(u.size()) != updated.model.n_u())
      override_error(
          head,
          fmt::format("wrong length (expected {}, one per control, got {})",
                      count(static_cast<std::size_t>(updated.model.n_u()), "number"), u.size()));
    updated.u = Eigen::Map<const Eigen::VectorXd>(u.data(), static_cast<Eigen::Index>(u.size()));
  } else if (table == "ipopt" && !key.empty()) {
    set_ipopt_option(updated.options.nlp.extra, key, value);
  } else {
    std::vector<std::string_view> valid;
    for (std::string_view t : kOverrideTables)
      if (table.empty() || t == table)
        for (std::string_view k : keys_of(t)) valid.push_back(k);
    if (table.empty() || table == "discretization") valid.push_back("N_FE");
    override_error(head, fmt::format("unknown option '{}' {}", key, key_hint(key, valid)));
  }

  const std::vector<std::string> errors = validate_all(updated);
  if (!errors.empty())
    throw_override_errors(
        head, spec != nullptr ? fmt::format("{}.{}", spec->table, spec->key) : std::string{},
        errors);
  problem = std::move(updated);
}

}  // namespace fesd
