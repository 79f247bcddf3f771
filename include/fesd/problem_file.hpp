// include/fesd/problem_file.hpp: problem files (TOML) describing a model plus a simulation.
// The format is documented in docs/problem-files.md; examples/ holds the paper's examples.
#pragma once
#include <string>
#include <string_view>

#include <Eigen/Dense>

#include "fesd/model.hpp"
#include "fesd/options.hpp"

namespace fesd {

/// A model and everything needed to simulate it, as read from a problem file.
struct SimulationProblem {
  std::string name;         ///< `name`, or the file's stem
  std::string description;  ///< `description`, may be empty
  std::string source;       ///< file path (or the name given to parse_simulation_problem)
  Pss model;
  Eigen::VectorXd x0;       ///< [model] x0 (with the clock state appended if `t` is used)
  Eigen::VectorXd u;        ///< [simulation] u: constant control values (size n_u)
  Eigen::VectorXd p;        ///< parameter values from [model] p (size n_p)
  double T_sim = 0;         ///< [simulation] T_sim > 0
  int N_sim = 1;            ///< [simulation] N_sim >= 1
  IntegratorOptions options;
  /// True if an expression uses the time `t`: then a clock state named "t" with t' = 1 is
  /// appended to x (nosnoc does the same), and its initial value is [simulation] t0 (default 0).
  bool has_clock = false;
};

/// Reads and validates a problem file. Throws fesd::ProblemFileError / ExpressionError /
/// InvalidOption with "file:line: what is wrong" messages.
SimulationProblem load_simulation_problem(const std::string& path);
/// Same, from text; `source_name` is used in messages.
SimulationProblem parse_simulation_problem(std::string_view toml_text, std::string_view source_name);

/// Overrides one option as if it had been written in the file, e.g. ("n_s", "3"),
/// ("rk_scheme", "gauss_legendre"), ("use_fesd", "0"), ("N_sim", "40"). Accepts every key of the
/// [simulation], [discretization], [homotopy] and [ipopt] tables. Throws fesd::InvalidOption
/// naming the key on unknown keys or bad values; re-validates the options.
void apply_override(SimulationProblem& problem, std::string_view key, std::string_view value);

}  // namespace fesd
