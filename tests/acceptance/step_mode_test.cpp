// The Heaviside step form (discretization.dcs_mode = step; docs/formulation.md, "Heaviside step
// form") against Stewart's form on the examples: every c-form simulation of examples/*.toml run in
// both modes gives the same trajectory and switch times to the scheme's accuracy, the paper's
// exact values (REFERENCE.md) where they exist, and OCP (56) the same optimal value. Then the bad
// inputs: a g-form subsystem with dcs_mode = step, an unknown dcs_mode.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include <fstream>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/io.hpp"
#include "fesd/ocp.hpp"
#include "fesd/problem_file.hpp"
#include "support/temp_dir.hpp"

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
  return s.substr(s.find('/') + 1);  // the file's name without a folder (nosnoc/)
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
    ::testing::Values(
        Case{"crossing.toml", {}, 1e-8, 1e-8}, Case{"sliding.toml", {}, 1e-8, 1e-8},
        Case{"leaving_sliding.toml", {}, 1e-7, 1e-6}, Case{"oscillator.toml", {}, 1e-7, 1e-7},
        Case{"nosnoc/relay_feedback.toml", {{"T_sim", "3.0"}, {"N_sim", "60"}}, 1e-6, 1e-6},
        Case{"nosnoc/friction_block.toml", {{"T_sim", "1.5"}, {"N_sim", "36"}}, 1e-6, 1e-6}),
    case_name);

// ---- codimension 2: the periodic stick-slip (two switching functions, four regions) ------------
// Up to t = 2.5 the state slides on x2 = 0.2 (from t = 0.2443) and then, from t = 0.5550, on
// x2 = 0.2 with x3 > 0.4: regions 1 and 3, a sliding mode of codimension 1 that starts at the
// codimension-2 point x2 = 0.2, x3 = 0.4. Both forms give the same states at every step end
// (measured 1.5e-7 to t = 5, the relaxation's level at complementarity_tol 1e-9). The switch lists
// differ: in Stewart's form the weight theta_0 of region 0 (x2 < 0.2, x3 < 0.4) stays near the
// activity threshold on that mode and region 0 enters and leaves the active set at every step
// (20 listed switches to t = 2.6), while theta_0(alpha) = (1 - alpha_1)(1 - alpha_2) is exactly 0
// once alpha_2 = 1 (x3 > 0.4): the step form lists the two switches only.
TEST(StepMode, PeriodicStickSlipCodimTwoSameStates) {
  SimulationProblem p = fesd::load_simulation_problem(example("nosnoc/periodic_stick_slip.toml"));
  fesd::apply_override(p, "T_sim", "2.5");
  fesd::apply_override(p, "N_sim", "25");
  const IntegratorResult a = run(p, "stewart");
  const IntegratorResult b = run(p, "step");
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  EXPECT_LE((a.x_final() - b.x_final()).cwiseAbs().maxCoeff(), 1e-6);
  ASSERT_EQ(b.switches.size(), 2u);
  EXPECT_EQ(b.switches[0].before, (std::vector<int>{0}));
  EXPECT_EQ(b.switches[0].after, (std::vector<int>{0, 2}));
  EXPECT_EQ(b.switches[1].after, (std::vector<int>{1, 3}));
  ASSERT_GE(a.switches.size(), 2u);
  EXPECT_NEAR(b.switches[0].t, a.switches[0].t, 1e-6);
  EXPECT_NEAR(b.switches[1].t, a.switches[1].t, 1e-6);
  EXPECT_NEAR(b.switches[0].t, 0.244331, 1e-6);
  EXPECT_NEAR(b.switches[1].t, 0.554993, 1e-6);
}

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

// The OCP of `file` solved as written (Stewart's form, .first) and in the step form (.second).
std::pair<fesd::OcpResult, fesd::OcpResult> solve_stewart_and_step(const std::string& file) {
  const fesd::OcpProblem q = fesd::load_ocp_problem(example(file));
  fesd::OcpProblem s = q;
  fesd::apply_override(s, "dcs_mode", "step");
  return {fesd::solve(q.ocp, q.options), fesd::solve(s.ocp, s.options)};
}

TEST(StepMode, SensitivityOcpSameObjective) {
  const auto [a, b] = solve_stewart_and_step("ocp_sensitivity.toml");
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  EXPECT_NEAR(b.objective, a.objective, 1e-8);
  EXPECT_NEAR(b.objective, 1.5237727753749571, 1e-6);
  EXPECT_NEAR(b.x0()[0], (9.0 - std::sqrt(417.0)) / 8.0, 1e-5);
  EXPECT_FALSE(b.alpha.empty());
}

// The sliding-mode OCP (61) with nosnoc_py's settings: two subsystems of one switching function
// each, so both forms have the same Filippov sets; the same solution (measured: J equal to 1e-10,
// states at the element boundaries to 1.6e-10, switch times to 3.4e-11).
TEST(StepMode, SlidingModeOcpSameObjective) {
  const auto [a, b] = solve_stewart_and_step("nosnoc/ocp_sliding_mode_nosnoc.toml");
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  EXPECT_NEAR(b.objective, a.objective, 1e-7);
  EXPECT_NEAR(b.objective, 5.5942052, 1e-6);
  ASSERT_EQ(a.switches.size(), b.switches.size());
  for (std::size_t i = 0; i < a.switches.size(); ++i)
    EXPECT_NEAR(a.switches[i].t, b.switches[i].t, 1e-7) << "switch " << i;
}

// ---- the JSON result: alpha, lambda_p, lambda_n per stage in step mode, absent in Stewart's
// ------

TEST(StepMode, JsonHasStepValues) {
  const SimulationProblem p = fesd::load_simulation_problem(example("crossing.toml"));
  const fesd::testing::TempDir dir("fesd_step_json");
  const IntegratorResult b = run(p, "step");
  const IntegratorResult a = run(p, "stewart");
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  fesd::write_json(b, p.model, dir.file("step.json"));
  fesd::write_json(a, p.model, dir.file("stewart.json"));
  std::ifstream fb(dir.file("step.json")), fa(dir.file("stewart.json"));
  const nlohmann::json jb = nlohmann::json::parse(fb), ja = nlohmann::json::parse(fa);
  ASSERT_TRUE(jb.contains("alpha"));
  EXPECT_EQ(jb["alpha"].size(), jb["theta"].size());
  EXPECT_EQ(jb["lambda_p"].size(), jb["theta"].size());
  EXPECT_EQ(jb["lambda_n"].size(), jb["theta"].size());
  EXPECT_EQ(jb["alpha"][0].size(), 1u);  // n_c = 1
  // first stage: x < 0, so alpha = 0 and theta = (1 - alpha, alpha) = (1, 0) (S = [[-1], [1]])
  EXPECT_NEAR(jb["alpha"][0][0].get<double>(), 0.0, 1e-6);
  EXPECT_NEAR(jb["theta"][0][0].get<double>(), 1.0, 1e-6);
  EXPECT_NEAR(jb["lambda_p"][0][0].get<double>(), 0.0, 1e-8);
  EXPECT_FALSE(ja.contains("alpha"));
}

// ---- bad input ---------------------------------------------------------------------------------

// A g-form subsystem (examples/nosnoc/temperature_control.toml gives g directly) cannot be written
// in the step form: the library throws InvalidModel naming the key.
TEST(StepMode, GFormRejected) {
  SimulationProblem p = fesd::load_simulation_problem(example("nosnoc/temperature_control.toml"));
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
                          example("nosnoc/temperature_control.toml") +
                          " --dcs_mode step > /dev/null 2>&1";
  const int rc = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(rc));
  EXPECT_EQ(WEXITSTATUS(rc), 2);
}

}  // namespace
