// include/fesd/pds_problem_file.hpp: simulation problem files of projected dynamical systems
// (docs/pds.md, "Problem files"): [model] kind = "projected" with a vector field `f` and
// `constraints` (C = {x : constraints >= 0}), read into a fesd::Pds.
#pragma once
#include <functional>
#include <string>
#include <string_view>

#include <Eigen/Dense>

#include "fesd/integrator.hpp"
#include "fesd/ocp.hpp"
#include "fesd/options.hpp"
#include "fesd/pds.hpp"
#include "fesd/problem_file.hpp"

namespace fesd {

/// A projected dynamical system and its simulation, as read from a problem file.
struct PdsSimulationProblem {
  std::string name;         ///< `name`, or the file's stem
  std::string description;  ///< `description`, may be empty
  std::string source;       ///< file path (or the name given to parse_pds_simulation_problem)
  Pds model;
  Eigen::VectorXd x0, u, p;
  double T_sim = 0;
  int N_sim = 0;         ///< [simulation] N_sim >= 0; 0: chosen by tol_sim (as SimulationProblem)
  double tol_sim = 0;    ///< [simulation] tol_sim >= 0 (as SimulationProblem)
  int N_sim_max = 1000;  ///< [simulation] N_sim_max
  bool error_estimate = true;  ///< [simulation] error_estimate
  double t0 = 0;  ///< [simulation] t0: the start time; every time of the result is offset by it
  /// True if f reads the time `t`: then a clock state "t" with t' = 1 is the last state of the
  /// model (as in piecewise smooth files), and x0's last entry is t0.
  bool has_clock = false;
  IntegratorOptions options;
  PdsOptions pds;
};

/// Whether the file's [model] table says kind = "projected" (only the top level and [model] kind
/// are read; other mistakes are the loaders'). Throws fesd::ProblemFileError if the file cannot be
/// read or is not valid TOML.
bool is_projected_problem_file(const std::string& path);

/// Reads and validates a projected-system simulation file. Throws fesd::ProblemFileError /
/// ExpressionError / InvalidOption / InvalidModel with "file:line: what is wrong" messages.
PdsSimulationProblem load_pds_simulation_problem(const std::string& path);
/// Same, from text; `source_name` is used in messages.
PdsSimulationProblem parse_pds_simulation_problem(std::string_view toml_text,
                                                  std::string_view source_name);

/// An optimal control problem of a projected system and its solver options, as read from a
/// problem file with [model] kind = "projected" and an [ocp] table (docs/pds.md, "Optimal
/// control"; the [ocp], [discretization], [homotopy] and [ipopt] keys of piecewise smooth OCP
/// files). Solve it with fesd::solve(problem.ocp, problem.options).
struct PdsOcpProblem {
  std::string name;         ///< `name`, or the file's stem
  std::string description;  ///< `description`, may be empty
  std::string source;       ///< file path (or the name given to parse_pds_ocp_problem)
  PdsOcp ocp;               ///< ocp.x0 and ocp.p from [model]
  OcpOptions options;
};

/// Reads and validates a projected-system OCP file (errors as load_pds_simulation_problem).
PdsOcpProblem load_pds_ocp_problem(const std::string& path);
/// Same, from text; `source_name` is used in messages.
PdsOcpProblem parse_pds_ocp_problem(std::string_view toml_text, std::string_view source_name);

/// Overrides one option of a projected file as if it had been written in the file (`fesd
/// simulate/solve FILE --key value`): the registry options of its kind ([simulation] or [ocp],
/// [discretization], [homotopy]), [ipopt] keys, model.x0, model.p ("NAME=VALUE"), simulation.u /
/// ocp.u_guess, and for simulations t0 (OCPs: no t0). Throws fesd::InvalidOption naming the key; on
/// error the problem is unchanged.
void apply_override(PdsSimulationProblem& problem, std::string_view key, std::string_view value);
void apply_override(PdsOcpProblem& problem, std::string_view key, std::string_view value);
/// Several overrides, retried in the order fesd::apply_overrides (problem_file.hpp) uses.
void apply_overrides(PdsSimulationProblem& problem, const OverrideList& overrides);
void apply_overrides(PdsOcpProblem& problem, const OverrideList& overrides);

/// simulate() of the problem (N_sim steps with an error estimate, or as many as tol_sim needs, as
/// for SimulationProblem), its times offset by t0; on_run is called after every run.
IntegratorResult simulate(const PdsSimulationProblem& problem,
                          const std::function<void(const AccuracyRun&)>& on_run = {});

}  // namespace fesd
