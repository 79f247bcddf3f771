// General inclusions f(x, alpha, u, p) in the Heaviside step form ([model] f_alpha; docs/
// formulation.md, "General inclusions f(x, alpha)"): a file written with f_alpha equal to a
// Stewart-expressible system gives the trajectory and switch times of the region form in the step
// form, and a genuinely nonlinear f_alpha reaching a codimension-2 sliding mode its closed-form
// solution.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "fesd/integrator.hpp"
#include "fesd/ocp.hpp"
#include "fesd/problem_file.hpp"

namespace {

using fesd::IntegratorResult;
using fesd::SimulationProblem;

std::string example(const std::string& file) {
  return std::string(FESD_SOURCE_DIR) + "/examples/" + file;
}

IntegratorResult run(const SimulationProblem& p) {
  return fesd::integrate(p.model, p.x0, p.T_sim, p.N_sim, p.options, p.u, p.p);
}

// max |x_a - x_b| over the times both grids have (every step end).
double max_state_difference(const IntegratorResult& a, const IntegratorResult& b, int* common) {
  double dx = 0;
  *common = 0;
  for (std::size_t i = 0, j = 0; i < a.t.size(); ++i) {
    while (j < b.t.size() && b.t[j] < a.t[i] - 1e-12) ++j;
    if (j < b.t.size() && std::abs(b.t[j] - a.t[i]) <= 1e-12) {
      dx = std::max(dx, (a.x[i] - b.x[j]).cwiseAbs().maxCoeff());
      ++*common;
    }
  }
  return dx;
}

// Example 3(a): f_alpha = alpha_1 * 1 + (1 - alpha_1) * 3 against crossing.toml's regions in the
// step form (the same equations: V = f_alpha(X, alpha) is V = sum_i theta_i(alpha) f_i). Measured:
// equal to round-off; the exact switch 1/3 and x(T) = 5/3 to 1e-9.
TEST(FAlpha, CrossingSameAsRegionForm) {
  SimulationProblem r = fesd::load_simulation_problem(example("crossing.toml"));
  fesd::apply_override(r, "dcs_mode", "step");
  const SimulationProblem f = fesd::load_simulation_problem(example("crossing_f_alpha.toml"));
  ASSERT_TRUE(f.model.has_f_alpha());
  const IntegratorResult a = run(r), b = run(f);
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  int common = 0;
  EXPECT_LE(max_state_difference(a, b, &common), 1e-9);
  EXPECT_GE(common, f.N_sim + 1);
  ASSERT_EQ(b.switch_times().size(), 1u);
  ASSERT_EQ(a.switch_times().size(), 1u);
  EXPECT_NEAR(b.switch_times()[0], a.switch_times()[0], 1e-9);
  EXPECT_NEAR(b.switch_times()[0], 1.0 / 3.0, 1e-9);
  EXPECT_NEAR(b.x_final()[0], 5.0 / 3.0, 1e-9);
}

// friction_block.toml (three subsystems of one switching function each) against the same system
// as one f_alpha of three alphas. Both are the step form of the same Filippov system, but the NLPs
// differ (6 lifted theta against 8), so they agree to the relaxed complementarity's level: measured
// 7e-8 in x and 1.6e-8 in the switch times to t = 1.5.
TEST(FAlpha, FrictionBlockSameAsSubsystems) {
  SimulationProblem r = fesd::load_simulation_problem(example("nosnoc/friction_block.toml"));
  SimulationProblem f =
      fesd::load_simulation_problem(example("nosnoc/friction_block_f_alpha.toml"));
  fesd::apply_override(r, "dcs_mode", "step");
  for (SimulationProblem* p : {&r, &f}) {
    fesd::apply_override(*p, "T_sim", "1.5");
    fesd::apply_override(*p, "N_sim", "36");
  }
  const IntegratorResult a = run(r), b = run(f);
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  int common = 0;
  EXPECT_LE(max_state_difference(a, b, &common), 1e-6);
  EXPECT_GE(common, f.N_sim + 1);
  const std::vector<double> ta = a.switch_times(), tb = b.switch_times();
  ASSERT_EQ(ta.size(), 3u);
  ASSERT_EQ(tb.size(), ta.size());
  for (std::size_t i = 0; i < ta.size(); ++i) EXPECT_NEAR(tb[i], ta[i], 1e-6) << "switch " << i;
}

// The nonlinear f_alpha of examples/codim2_f_alpha.toml: x1' = 1 - 2 alpha_1^2, x2' = 1 - 2
// alpha_2, x3' = alpha_1 alpha_2, x(0) = (-0.8, -0.3, 0). Switches at t = 0.3 (x2 slides, alpha_2
// = 1/2) and t = 0.8 (x1 slides, alpha_1 = 1/sqrt(2)); x(T = 1.5) = (0, 0, 0.7 / (2 sqrt(2))).
// The region form (vertex fields, theta-weights 1/2) would give x3(T) = 0.7 / 4. Measured errors
// ~1e-12.
TEST(FAlpha, NonlinearCodimTwoClosedForm) {
  const SimulationProblem f = fesd::load_simulation_problem(example("codim2_f_alpha.toml"));
  const IntegratorResult b = run(f);
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  EXPECT_NEAR(b.x_final()[0], 0.0, 1e-9);
  EXPECT_NEAR(b.x_final()[1], 0.0, 1e-9);
  EXPECT_NEAR(b.x_final()[2], 0.7 / (2.0 * std::sqrt(2.0)), 1e-9);
  const std::vector<double> ts = b.switch_times();
  ASSERT_EQ(ts.size(), 2u);
  EXPECT_NEAR(ts[0], 0.3, 1e-9);
  EXPECT_NEAR(ts[1], 0.8, 1e-9);
  ASSERT_FALSE(b.alpha.empty());
  EXPECT_NEAR(b.alpha.back()[0], 1.0 / std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(b.alpha.back()[1], 0.5, 1e-6);
}

}  // namespace

namespace {

// OCP (56) with f_alpha (examples/ocp_sensitivity_f_alpha.toml) against the region form in the
// step form and the exact optimum V* = 1.5237727753749571, x0* = (9 - sqrt(417)) / 8.
TEST(FAlpha, SensitivityOcpSameObjective) {
  fesd::OcpProblem r = fesd::load_ocp_problem(example("ocp_sensitivity.toml"));
  fesd::apply_override(r, "dcs_mode", "step");
  const fesd::OcpProblem f = fesd::load_ocp_problem(example("ocp_sensitivity_f_alpha.toml"));
  const fesd::OcpResult a = fesd::solve(r.ocp, r.options), b = fesd::solve(f.ocp, f.options);
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  EXPECT_NEAR(b.objective, a.objective, 1e-9);
  EXPECT_NEAR(b.objective, 1.5237727753749571, 1e-6);
  EXPECT_NEAR(b.x0()[0], (9.0 - std::sqrt(417.0)) / 8.0, 1e-5);
}

}  // namespace
