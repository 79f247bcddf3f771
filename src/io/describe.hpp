// src/io/describe.hpp: the model and problem as fesd understood them, as text for `fesd check`
// (the library never prints; the CLI prints what these return).
//
// For every region: its sign pattern (row i of S: "c[0] < 0, c[1] > 0"; or "g[2] smallest" for
// indicator functions) and the vector field that applies there (row i of F, one expression per
// state: "x1' = ..., x2' = ..."), so that a model written with nosnoc's transposed F (one column
// per region) is visible even where it passes every check (n_x equal to the number of regions).
// Regions are numbered from 0 over all subsystems, as everywhere in fesd (summary.hpp).
#pragma once
#include <string>

#include "fesd/model.hpp"
#include "fesd/options.hpp"
#include "fesd/pds_problem_file.hpp"
#include "fesd/problem_file.hpp"

namespace fesd::io_detail {

/// Lines "  <label>  <text>\n": the controls, each subsystem's switching (or indicator)
/// functions, every region's sign pattern and vector field, and a hint where a transposed F would
/// pass the checks. `has_clock`: the last state is the clock t' = 1 of a problem file (not counted
/// as a user state for the hint). A model not made from expressions (a C++ model) shows its sign
/// patterns only.
std::string describe_model(const Pss& model, bool has_clock);

/// The FESD settings the one-line headers leave out (gamma_h, rho_h, stage_lambda_sign,
/// pin_sliding_exits), one line; empty without use_fesd.
std::string describe_discretization(const DiscretizationOptions& d);

/// The OCP's costs and constraints as written (expressions with their bounds); empty if the OCP's
/// functions are not expressions of a problem file.
std::string describe_ocp_functions(const OcpData& ocp);

/// A projected system (docs/pds.md): its controls and parameters, every constraint c_k(x) >= 0
/// and the vector field f, one line per state (C++ models: "(given in C++)").
std::string describe_model(const Pds& model);
/// The FESD settings of a projected system the header leaves out (gamma_h, rho_h, M,
/// h_penalty), one line; empty without use_fesd.
std::string describe_discretization(const DiscretizationOptions& d, const PdsOptions& pds);

/// Everything `fesd check` prints after the header: describe_discretization, then a blank line and
/// describe_model (and for an OCP describe_ocp_functions).
std::string describe(const SimulationProblem& problem);
std::string describe(const OcpProblem& problem);
std::string describe(const PdsSimulationProblem& problem);
std::string describe(const PdsOcpProblem& problem);

}  // namespace fesd::io_detail
