// src/core/limits.hpp: the smallest step length fesd accepts, one rule for the integrator, the OCP
// and the problem-file checks (docs/problem-files.md, "Limits").
#pragma once
#include <string>
#include <string_view>

namespace fesd::core {

/// A step T / N (T_sim / N_sim, or an OCP's control interval T / N_stages) must be at least
/// kMinStep * max(1, |t0|), t0 the start time. IPOPT's tolerances (tol = 1e-12) are absolute: a
/// shorter step moves the state by less than the solver resolves, and a step below 1e-12 |t0|
/// is lost in the rounding of t0 + h (at 5e-324 every h_n is 0). Rescale time for faster dynamics.
inline constexpr double kMinStep = 1e-12;

/// Empty if the step T / N is long enough (or T, N are invalid anyway: other rules report
/// those), else one message starting with "<T_key> = <T>: ", e.g. "simulation.T_sim = 5e-324:
/// the step T_sim / N_sim = 5e-324 is shorter than 1e-12 ...".
std::string step_length_error(std::string_view T_key, double T, std::string_view N_key, int N,
                              double t0 = 0.0);

}  // namespace fesd::core
