// src/ocp/ocp_input.hpp: the input rules of an optimal control problem, written once: solve()
// (ocp.cpp) and the problem-file loader (src/io/ocp_problem_file.cpp) both call check_input.
// Messages name the problem-file keys ("ocp.T = -1: must be > 0", "model.x0[0]: 2 is outside
// [lbx0, ubx0] = [-1, 1] (...)"), so that the loader can point at the line of the key.
#pragma once
#include <string>
#include <vector>

#include "fesd/ocp.hpp"

namespace fesd::ocp_detail {

/// The broken rules, by kind.
struct OcpInputErrors {
  /// Option ranges and rules (the [ocp] scalars, the per-interval N_finite_elements and
  /// validate(OcpOptions)): fesd::InvalidOption.
  std::vector<std::string> options;
  /// The problem's data: sizes, NaN, empty bounds, x0 and u_guess outside their bounds, constraint
  /// functions: fesd::InvalidModel (fesd::ProblemFileError from a file).
  std::vector<std::string> data;
};

/// Every input rule of an OCP.
OcpInputErrors check_input(const Ocp& ocp, const OcpOptions& options);
/// The same for a projected system, plus its scheme rules (PdsInterval::errors) and x0 in C.
OcpInputErrors check_input(const PdsOcp& ocp, const OcpOptions& options);

/// Throws InvalidOption with every option message if there is one, else InvalidModel with every
/// data message if there is one.
void require_valid_input(const Ocp& ocp, const OcpOptions& options);
void require_valid_input(const PdsOcp& ocp, const OcpOptions& options);

}  // namespace fesd::ocp_detail
