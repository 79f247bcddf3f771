// src/io/pds_model_reader.hpp: the [model] table of a projected system ([model] kind =
// "projected", docs/pds.md "Problem files"), shared by simulation files (pds_problem_file.cpp) and
// optimal control files (ocp_problem_file.cpp).
#pragma once
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "fesd/pds.hpp"
#include "io/problem_file_reader.hpp"

namespace fesd::io_detail {

/// The model as read: the Pds (names and p_default set), [model] x0 and p, and the symbols
/// [x, t, u, p] of expressions. has_clock: f reads the time t, so a clock state "t" with t' = 1
/// is the last state (x0's last entry its start value), as in piecewise smooth files.
struct PdsModelRead {
  Pds model;
  Eigen::VectorXd x0, p;
  Symbols sym;
  bool has_clock = false;
};

/// Reads [model] (kind, x, u, p, x0, f, constraints, x0_tol); throws fesd::ProblemFileError at
/// the line of the first mistake (unknown keys, keys of piecewise smooth models, lengths, names).
/// `clock_t0`: simulation files, the start time: if f reads t, a clock state starting at
/// *clock_t0 is appended (constraints reading t are rejected: C is time-independent in
/// papers/fesd-pds.txt). Null (optimal control files): expressions reading t are rejected.
PdsModelRead read_pds_model(const Reader& r, const toml::table& root,
                            const double* clock_t0 = nullptr);

/// The overrides of projected files that are not registry options: [ipopt] keys, model.x0 (n_x
/// numbers), model.p ("NAME=VALUE": p and model.p_default), simulation.u (if `u` is given);
/// tol_sim and t0 are rejected (InvalidOption). False for any other key.
bool set_pds_override(const OverrideArg& a, Pds& model,
                      std::vector<std::pair<std::string, std::string>>& ipopt_extra,
                      Eigen::VectorXd& x0, Eigen::VectorXd& p, Eigen::VectorXd* u,
                      bool has_clock = false);

}  // namespace fesd::io_detail
