// src/io/pds_model_reader.hpp: the [model] table of a projected system ([model] kind =
// "projected", docs/pds.md "Problem files"), shared by simulation files (pds_problem_file.cpp) and
// optimal control files (ocp_problem_file.cpp).
#pragma once
#include <Eigen/Dense>

#include "fesd/pds.hpp"
#include "io/problem_file_reader.hpp"

namespace fesd::io_detail {

/// The model as read: the Pds (names and p_default set), [model] x0 and p, and the symbols
/// [x, t, u, p] of expressions (the time slot t is not supported: expressions reading it are
/// rejected).
struct PdsModelRead {
  Pds model;
  Eigen::VectorXd x0, p;
  Symbols sym;
};

/// Reads [model] (kind, x, u, p, x0, f, constraints, x0_tol); throws fesd::ProblemFileError at
/// the line of the first mistake (unknown keys, keys of piecewise smooth models, lengths, names).
PdsModelRead read_pds_model(const Reader& r, const toml::table& root);

}  // namespace fesd::io_detail
