// include/fesd/problem_file.hpp: problem files (TOML) describing a model plus a simulation
// ([simulation] table) or an optimal control problem ([ocp] table). The format is documented in
// docs/problem-files.md; examples/ holds the paper's examples.
#pragma once
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "fesd/integrator.hpp"
#include "fesd/model.hpp"
#include "fesd/ocp.hpp"
#include "fesd/options.hpp"

namespace fesd {

/// A model and everything needed to simulate it, as read from a problem file.
struct SimulationProblem {
  std::string name;         ///< `name`, or the file's stem
  std::string description;  ///< `description`, may be empty
  std::string source;       ///< file path (or the name given to parse_simulation_problem)
  Pss model;
  Eigen::VectorXd x0;          ///< [model] x0 (with the clock state appended if `t` is used)
  Eigen::VectorXd u;           ///< [simulation] u: constant control values (size n_u)
  Eigen::VectorXd p;           ///< parameter values from [model] p (size n_p)
  double T_sim = 0;            ///< [simulation] T_sim > 0
  int N_sim = 0;               ///< [simulation] N_sim >= 0; 0: chosen by tol_sim (simulate())
  double tol_sim = 0;          ///< [simulation] tol_sim >= 0 (AccuracyOptions::tol_sim)
  int N_sim_max = 1000;        ///< [simulation] N_sim_max >= 1 (AccuracyOptions::N_sim_max)
  bool error_estimate = true;  ///< [simulation] error_estimate (AccuracyOptions::error_estimate)
  IntegratorOptions options;
  /// True if an expression uses the time `t`: then a clock state named "t" with t' = 1 is
  /// appended to x (nosnoc does the same), and its initial value is [simulation] t0 (default 0).
  bool has_clock = false;
  /// [simulation] t0 (default 0): the start time. The clock state (if any) starts at t0, and
  /// every time of the result of simulate() is absolute (offset by t0), as for projected files.
  double t0 = 0;
};

/// Simulates the problem with simulate(): N_sim steps, or as many as tol_sim needs, with an
/// error estimate (IntegratorResult::accuracy). `on_run`: progress after every run.
IntegratorResult simulate(const SimulationProblem& problem,
                          const std::function<void(const AccuracyRun&)>& on_run = {});

/// Reads and validates a problem file. Throws fesd::ProblemFileError / ExpressionError /
/// InvalidOption with "file:line: what is wrong" messages.
SimulationProblem load_simulation_problem(const std::string& path);
/// Same, from text; `source_name` is used in messages.
SimulationProblem parse_simulation_problem(std::string_view toml_text,
                                           std::string_view source_name);

/// Overrides one option as if it had been written in the file, e.g. ("n_s", "3"),
/// ("rk_scheme", "gauss_legendre"), ("use_fesd", "0"), ("N_sim", "40"). Accepts every key of the
/// [simulation], [discretization], [homotopy] and [ipopt] tables. Throws fesd::InvalidOption
/// naming the key on unknown keys or bad values; re-validates the options.
void apply_override(SimulationProblem& problem, std::string_view key, std::string_view value);

/// An optimal control problem and its solver options, as read from a problem file with an [ocp]
/// table (docs/problem-files.md, "Optimal control problems"). Solve it with
/// fesd::solve(problem.ocp, problem.options).
struct OcpProblem {
  std::string name;         ///< `name`, or the file's stem
  std::string description;  ///< `description`, may be empty
  std::string source;       ///< file path (or the name given to parse_ocp_problem)
  /// The OCP: model, costs and constraints (expressions compiled for every scalar type), horizon,
  /// bounds and guesses. ocp.p holds the [model] p values; ocp.x0 is [model] x0 (the guess of x0
  /// if [ocp] lbx0/ubx0 make it free).
  Ocp ocp;
  /// [discretization], [homotopy], [ipopt] and the solver keys of [ocp]. Defaults are
  /// OcpOptions' own: step_equilibration = l2_relaxed unless the file sets it.
  OcpOptions options;
  /// True if an expression (of the model or of [ocp]) uses the time `t`: then a clock state "t"
  /// with t' = 1 and t(0) = 0 is appended to x (bounds -inf..inf, fixed at 0 in lbx0/ubx0).
  bool has_clock = false;
};

/// Reads and validates an optimal control problem file. Throws fesd::ProblemFileError /
/// ExpressionError / InvalidOption / InvalidModel with "file:line: what is wrong" messages.
OcpProblem load_ocp_problem(const std::string& path);
/// Same, from text; `source_name` is used in messages.
OcpProblem parse_ocp_problem(std::string_view toml_text, std::string_view source_name);

/// Overrides one option of an OCP file as if it had been written in the file: every key of
/// [discretization], [homotopy] and [ipopt] (as for simulation files), and the [ocp] keys T,
/// N_stages, rho_terminal, relax_terminal_constraint, initialization and constraints_at_stages.
/// N_finite_elements (alias N_FE) sets the same number for every control interval. Throws
/// fesd::InvalidOption naming the key; on error the problem is unchanged.
void apply_override(OcpProblem& problem, std::string_view key, std::string_view value);

/// Option overrides as (key, value) pairs, in the order they were given (CLI flags, Python
/// keywords).
using OverrideList = std::vector<std::pair<std::string, std::string>>;

/// Applies several overrides with apply_override(). apply_override re-validates after every key,
/// so a combination that is valid only as a whole (e.g. rk_scheme = lobatto_iiia with n_s = 2
/// when the file has n_s = 1) may fail in one order and succeed in another: keys that fail are
/// retried as long as others succeed. Throws fesd::InvalidOption with the first remaining
/// failure's message.
void apply_overrides(SimulationProblem& problem, const OverrideList& overrides);
/// Same for an optimal control problem.
void apply_overrides(OcpProblem& problem, const OverrideList& overrides);

/// What a problem file describes: a simulation ([simulation]) or an optimal control problem
/// ([ocp]).
enum class ProblemKind { Simulation, Ocp };
/// Reads the file's top level only: Ocp if it has an [ocp] table, else Simulation (the loaders
/// report every other mistake). Throws fesd::ProblemFileError if the file cannot be read or is not
/// valid TOML.
ProblemKind problem_file_kind(const std::string& path);

}  // namespace fesd
