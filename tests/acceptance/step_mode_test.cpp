// The Heaviside step form (discretization.dcs_mode = step; docs/formulation.md, "Heaviside step
// form") against Stewart's form on the examples: every c-form simulation of examples/*.toml run in
// both modes gives the same trajectory and switch times to the scheme's accuracy, the paper's
// exact values (REFERENCE.md) where they exist, and OCP (56) the same optimal value. Then the bad
// inputs: a g-form subsystem with dcs_mode = step, an unknown dcs_mode.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/io.hpp"
#include "fesd/ocp.hpp"
#include "fesd/problem_file.hpp"

namespace {

using fesd::IntegratorResult;
using fesd::SimulationProblem;

std::string example(const std::string& file) {
  return std::string(FESD_SOURCE_DIR) + "/examples/" + file;
}

IntegratorResult run(SimulationProblem p, const char* mode) {
  fesd::apply_override(p, "dcs_mode", mode);
  return fesd::integrate(p.model, p.x0, p.T_sim, p.N_sim, p.options, p.u, p.p);
}

struct Case {
  const char* file;
  // Overrides applied to both modes (a shorter horizon for the long examples).
  std::vector<std::pair<const char*, const char*>> overrides;
  double tol_x;  // max |x_step - x_stewart| over the element boundaries
  double tol_t;  // max |t_step - t_stewart| over the switch times
};

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string s = info.param.file;
  s = s.substr(0, s.find('.'));
  return s;
}

class StepVsStewart : public ::testing::TestWithParam<Case> {};

// Same trajectory (at every step end) and the same switch list. The tolerances are those of the
// relaxed complementarity: both runs solve the same FESD equations where n_c = 1 per subsystem
// (theta(alpha) is Stewart's theta), so they differ only by the homotopy's last sigma and IPOPT's
// tol (measured up to ~1e-9 in x).
TEST_P(StepVsStewart, SameTrajectoryAndSwitches) {
  const Case& c = GetParam();
  SimulationProblem p = fesd::load_simulation_problem(example(c.file));
  for (const auto& [k, v] : c.overrides) fesd::apply_override(p, k, v);
  const IntegratorResult a = run(p, "stewart");
  const IntegratorResult b = run(p, "step");
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  // The states at the times both grids have (every step end; element boundaries inside a step
  // are placed by the step penalties where nothing switches, not by the dynamics).
  double dx = 0;
  int common = 0;
  for (std::size_t i = 0, j = 0; i < a.t.size(); ++i) {
    while (j < b.t.size() && b.t[j] < a.t[i] - 1e-12) ++j;
    if (j < b.t.size() && std::abs(b.t[j] - a.t[i]) <= 1e-12) {
      dx = std::max(dx, (a.x[i] - b.x[j]).cwiseAbs().maxCoeff());
      ++common;
    }
  }
  EXPECT_GE(common, p.N_sim + 1);
  EXPECT_LE(dx, c.tol_x);
  const std::vector<double> ta = a.switch_times(), tb = b.switch_times();
  ASSERT_EQ(ta.size(), tb.size());
  for (std::size_t i = 0; i < ta.size(); ++i) EXPECT_NEAR(ta[i], tb[i], c.tol_t) << "switch " << i;
  for (std::size_t i = 0; i < a.switches.size(); ++i) {
    EXPECT_EQ(a.switches[i].before, b.switches[i].before) << "switch " << i;
    EXPECT_EQ(a.switches[i].after, b.switches[i].after) << "switch " << i;
  }
  // The step form's own stage values: alpha in [0, 1], theta = theta(alpha).
  ASSERT_EQ(b.alpha.size(), b.theta.size());
  ASSERT_TRUE(a.alpha.empty());
  for (std::size_t st = 0; st < b.alpha.size(); ++st) {
    EXPECT_GE(b.alpha[st].minCoeff(), -1e-9);
    EXPECT_LE(b.alpha[st].maxCoeff(), 1 + 1e-9);
    EXPECT_GE(b.lambda_p[st].minCoeff(), -1e-9);
    EXPECT_GE(b.lambda_n[st].minCoeff(), -1e-9);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Examples, StepVsStewart,
    ::testing::Values(Case{"crossing.toml", {}, 1e-8, 1e-8}, Case{"sliding.toml", {}, 1e-8, 1e-8},
                      Case{"leaving_sliding.toml", {}, 1e-7, 1e-6},
                      Case{"oscillator.toml", {}, 1e-7, 1e-7},
                      Case{"relay_feedback.toml", {{"T_sim", "3.0"}, {"N_sim", "60"}}, 1e-6, 1e-6},
                      Case{"friction_block.toml", {{"T_sim", "1.5"}, {"N_sim", "36"}}, 1e-6, 1e-6}),
    case_name);

// ---- the exact values of REFERENCE.md ----------------------------------------------------------

TEST(StepMode, Example3aCrossingExact) {
  const IntegratorResult r = run(fesd::load_simulation_problem(example("crossing.toml")), "step");
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.x_final()[0], 5.0 / 3.0, 1e-9);
  ASSERT_EQ(r.switch_times().size(), 1u);
  EXPECT_NEAR(r.switch_times()[0], 1.0 / 3.0, 1e-9);
  // x < 0 before the switch: alpha = 0 (S = [[-1], [1]]: region 0 is x < 0, theta_0 = 1 - alpha).
  EXPECT_NEAR(r.alpha.front()[0], 0.0, 1e-6);
  EXPECT_NEAR(r.alpha.back()[0], 1.0, 1e-6);
  EXPECT_NEAR(r.lambda_n.front()[0], -r.x_stage.front()[0], 1e-8);
}

TEST(StepMode, Example3bSlidingExact) {
  const IntegratorResult r = run(fesd::load_simulation_problem(example("sliding.toml")), "step");
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.x_final()[0], 0.0, 1e-9);
  ASSERT_EQ(r.switch_times().size(), 1u);
  EXPECT_NEAR(r.switch_times()[0], 0.5, 1e-9);
  EXPECT_NEAR(r.alpha.back()[0], 0.5, 1e-6);  // sliding: x' = 1 - 2 alpha = 0
}

TEST(StepMode, Example3cLeavingSlidingExact) {
  const IntegratorResult r =
      run(fesd::load_simulation_problem(example("leaving_sliding.toml")), "step");
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.x_final()[0], 0.5, 1e-6);  // (T - 1)^2 / 2
  ASSERT_EQ(r.switch_times().size(), 1u);
  EXPECT_NEAR(r.switch_times()[0], 1.0, 1e-5);
}

TEST(StepMode, OscillatorExact) {
  const IntegratorResult r = run(fesd::load_simulation_problem(example("oscillator.toml")), "step");
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.x_final()[0], -1.5974603774506984, 1e-6);
  EXPECT_NEAR(r.x_final()[1], -0.7614936206060108, 1e-6);
  ASSERT_EQ(r.switch_times().size(), 1u);
  EXPECT_NEAR(r.switch_times()[0], 1.0, 1e-6);
}

// ---- an OCP: (56), the sensitivity OCP, x0* = (9 - sqrt(417)) / 8, V* = 1.5237727753749571 -----

TEST(StepMode, SensitivityOcpSameObjective) {
  fesd::OcpProblem q = fesd::load_ocp_problem(example("ocp_sensitivity.toml"));
  fesd::OcpProblem s = q;
  fesd::apply_override(s, "dcs_mode", "step");
  const fesd::OcpResult a = fesd::solve(q.ocp, q.options);
  const fesd::OcpResult b = fesd::solve(s.ocp, s.options);
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  EXPECT_NEAR(b.objective, a.objective, 1e-8);
  EXPECT_NEAR(b.objective, 1.5237727753749571, 1e-6);
  EXPECT_NEAR(b.x0()[0], (9.0 - std::sqrt(417.0)) / 8.0, 1e-5);
  EXPECT_FALSE(b.alpha.empty());
}

// ---- bad input ---------------------------------------------------------------------------------

// A g-form subsystem (examples/temperature_control.toml gives g directly) cannot be written in
// the step form: the library throws InvalidModel naming the key.
TEST(StepMode, GFormRejected) {
  SimulationProblem p = fesd::load_simulation_problem(example("temperature_control.toml"));
  try {  // the problem file's override is checked at once
    fesd::apply_override(p, "dcs_mode", "step");
    FAIL() << "no exception";
  } catch (const fesd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("dcs_mode = step: subsystem 0 is given by indicator "
                                         "functions g (g-form)"),
              std::string::npos)
        << e.what();
  }
  fesd::IntegratorOptions o = p.options;  // the library API
  o.discretization.dcs_mode = fesd::DcsMode::Step;
  EXPECT_THROW(fesd::integrate(p.model, p.x0, p.T_sim, p.N_sim, o, p.u, p.p), fesd::InvalidModel);
}

TEST(StepMode, UnknownValueRejected) {
  SimulationProblem p = fesd::load_simulation_problem(example("crossing.toml"));
  try {
    fesd::apply_override(p, "dcs_mode", "heaviside");
    FAIL() << "no exception";
  } catch (const fesd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("dcs_mode"), std::string::npos) << e.what();
  }
}

// The CLI: one line naming the problem, exit code 2.
TEST(StepMode, CliGFormExitCode2) {
  const std::string cmd = std::string(FESD_CLI) + " simulate " +
                          example("temperature_control.toml") + " --dcs_mode step > /dev/null 2>&1";
  const int rc = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(rc));
  EXPECT_EQ(WEXITSTATUS(rc), 2);
}

}  // namespace
