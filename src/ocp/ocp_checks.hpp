// src/ocp/ocp_checks.hpp: the OCP's input checks that the problem-file reader shares with solve().
#pragma once
#include <string>
#include <vector>

#include "fesd/ocp.hpp"

namespace fesd::ocp_detail {

/// One message per block of the OCP's NLP that would have more than ad::kMaxInputs inputs: those
/// of every FESD interval (FesdInterval::block_size_errors) and the Lagrange term (1 + n_s n_x +
/// n_u + n_p inputs per element), Mayer term and terminal constraints. Each message starts with
/// the problem-file key to change. Call with valid options (validate(options) empty).
std::vector<std::string> block_size_errors(const Ocp& ocp, const OcpOptions& options);

/// The step rule (core::step_length_error) for the control interval T / N_stages: one message,
/// or empty.
std::string step_length_error(const OcpData& ocp);

}  // namespace fesd::ocp_detail
