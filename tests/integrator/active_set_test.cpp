// step_solver = active_set (docs/active-set.md): Newton's method on the square system of Thm 15
// gives the same x(T) and switch times as the homotopy path, with every step (or all but a counted
// few) solved without IPOPT. Exact values from REFERENCE.md.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "../../bench/oscillator_model.hpp"
#include "../../bench/sensitivity_ocp.hpp"
#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/model.hpp"
#include "fesd/problem_file.hpp"

namespace {

using fesd::IntegratorOptions;
using fesd::IntegratorResult;
using fesd::RkScheme;
using fesd::StepSolver;

// Example 3(a): x' in 2 - sign(x), the model of the sensitivity OCP (56)
// (bench/sensitivity_ocp.hpp): region 0 is x > 0 (x' = 1), region 1 is x < 0 (x' = 3).
fesd::Pss crossing_model() {
  return fesd::make_pss(fesd_bench::SensitivityModel{},
                        fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
}

IntegratorOptions options(RkScheme scheme, int n_s, StepSolver solver) {
  IntegratorOptions o;
  o.discretization.rk_scheme = scheme;
  o.discretization.n_s = n_s;
  o.step_solver = solver;
  return o;
}

/// Both paths on one problem: same switches (times to tol), same x(T) (to tol).
struct Both {
  IntegratorResult homotopy, active;
};
Both run_both(const fesd::Pss& model, const Eigen::VectorXd& x0, double T, int N_sim,
              IntegratorOptions o) {
  Both b;
  o.step_solver = StepSolver::Homotopy;
  b.homotopy = fesd::integrate(model, x0, T, N_sim, o);
  o.step_solver = StepSolver::ActiveSet;
  b.active = fesd::integrate(model, x0, T, N_sim, o);
  return b;
}

void expect_same(const Both& b, double tol) {
  ASSERT_EQ(b.homotopy.status, fesd::Status::Success) << b.homotopy.message;
  ASSERT_EQ(b.active.status, fesd::Status::Success) << b.active.message;
  ASSERT_EQ(b.active.switches.size(), b.homotopy.switches.size());
  for (std::size_t i = 0; i < b.active.switches.size(); ++i) {
    EXPECT_NEAR(b.active.switches[i].t, b.homotopy.switches[i].t, tol) << "switch " << i;
    EXPECT_EQ(b.active.switches[i].before, b.homotopy.switches[i].before);
    EXPECT_EQ(b.active.switches[i].after, b.homotopy.switches[i].after);
  }
  EXPECT_LT((b.active.x_final() - b.homotopy.x_final()).lpNorm<Eigen::Infinity>(), tol);
}

// Example 3(a), x0 = -1: switch at t_s = 1/3, x(T) = T - 1/3 (REFERENCE.md). Piecewise linear,
// so both paths are exact up to their solver tolerances: 1e-9. Every step on the active-set path,
// no NLP solved at all.
class ActiveSetCrossing : public ::testing::TestWithParam<std::pair<RkScheme, int>> {};
TEST_P(ActiveSetCrossing, SameAsHomotopyAndExact) {
  const auto [scheme, n_s] = GetParam();
  const double T = 1.9;
  const int N_sim = 7;
  const Eigen::VectorXd x0 = Eigen::VectorXd::Constant(1, -1.0);
  const Both b =
      run_both(crossing_model(), x0, T, N_sim, options(scheme, n_s, StepSolver::Homotopy));
  expect_same(b, 1e-9);
  ASSERT_EQ(b.active.switches.size(), 1u);
  EXPECT_NEAR(b.active.switches[0].t, 1.0 / 3.0, 1e-9);
  EXPECT_NEAR(b.active.x_final()[0], T - 1.0 / 3.0, 1e-9);
  const fesd::Summary& s = b.active.summary;
  EXPECT_EQ(s.active_set_path_steps, N_sim);
  EXPECT_EQ(s.homotopy_path_steps, 0);
  EXPECT_EQ(s.homotopy_steps, 0);  // no NLP
  EXPECT_EQ(b.homotopy.summary.homotopy_path_steps, N_sim);
  EXPECT_EQ(b.homotopy.summary.active_set_path_steps, 0);
  // One square system per step, two more in the step with the switch (prediction, then the
  // crossing at boundary 1).
  EXPECT_EQ(s.active_set_tries, N_sim + 1);
}
INSTANTIATE_TEST_SUITE_P(Schemes, ActiveSetCrossing,
                         ::testing::Values(std::pair{RkScheme::RadauIIA, 1},
                                           std::pair{RkScheme::RadauIIA, 2},
                                           std::pair{RkScheme::RadauIIA, 3},
                                           std::pair{RkScheme::GaussLegendre, 2}));

// The oscillator (47), Radau IIA n_s = 3, N_FE = 2, N_sim = 40 (issue 15's case): the crossing of
// the unit circle at t_s = 1 and x(T) agree with the homotopy path to 1e-9, every step on the
// active-set path; the error against the exact x(T) is the scheme's (REFERENCE.md: 3.8e-7).
TEST(ActiveSetOscillator, SameAsHomotopyRadau3) {
  const fesd::Pss model = fesd_bench::oscillator_model();
  const Both b = run_both(model, fesd_bench::oscillator_x0(), fesd_bench::kOscillatorT, 40,
                          options(RkScheme::RadauIIA, 3, StepSolver::Homotopy));
  expect_same(b, 1e-9);
  ASSERT_EQ(b.active.switches.size(), 1u);
  EXPECT_NEAR(b.active.switches[0].t, fesd_bench::kOscillatorSwitch, 1e-6);
  EXPECT_LT((b.active.x_final() - fesd_bench::oscillator_exact_xT()).norm(), 1e-6);
  EXPECT_EQ(b.active.summary.active_set_path_steps, 40);
  EXPECT_EQ(b.active.summary.homotopy_path_steps, 0);
  // Newton converges quadratically: at most 6 iterations per square system here.
  EXPECT_LE(b.active.summary.newton_iterations, 6 * b.active.summary.active_set_tries);
}

// The same through the problem file and the generic override (as `--step_solver active_set`).
TEST(ActiveSetOscillator, ProblemFileKeyAndOverride) {
  fesd::SimulationProblem q =
      fesd::load_simulation_problem(FESD_SOURCE_DIR "/examples/oscillator.toml");
  EXPECT_EQ(q.options.step_solver, StepSolver::ActiveSet);  // the default
  fesd::apply_override(q, "step_solver", "homotopy");
  EXPECT_EQ(q.options.step_solver, StepSolver::Homotopy);
  fesd::apply_override(q, "step_solver", "active_set");
  EXPECT_EQ(q.options.step_solver, StepSolver::ActiveSet);
  const IntegratorResult r = fesd::integrate(q.model, q.x0, q.T_sim, 40, q.options, q.u, q.p);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_EQ(r.summary.active_set_path_steps, 40);
  ASSERT_EQ(r.switches.size(), 1u);
  EXPECT_NEAR(r.switches[0].t, 1.0, 1e-6);
}

/// Both paths on a problem file, with `overrides` (key, value) applied to both.
Both run_file(const std::string& file,
              const std::vector<std::pair<std::string, std::string>>& overrides = {}) {
  fesd::SimulationProblem q = fesd::load_simulation_problem(FESD_SOURCE_DIR "/examples/" + file);
  for (const auto& [key, value] : overrides) fesd::apply_override(q, key, value);
  Both b;
  fesd::apply_override(q, "step_solver", "homotopy");
  b.homotopy = fesd::integrate(q.model, q.x0, q.T_sim, q.N_sim, q.options, q.u, q.p);
  fesd::apply_override(q, "step_solver", "active_set");
  b.active = fesd::integrate(q.model, q.x0, q.T_sim, q.N_sim, q.options, q.u, q.p);
  return b;
}

// Example 3(b) (examples/sliding.toml, x' in -sign(x), N_sim = 10 on [0, 1]): x reaches 0 at
// t = x0 and slides, x(T) = 0 (REFERENCE.md). x0 = 0.47 and 0.43 put the entry inside a step
// (x0 = 0.5: on a step boundary). The entry is found by Newton: the crossing (region 0 replacing
// region 1) fails its signs, the sliding candidate (region 0 added) has theta = (1/2, 1/2); the
// steps after it stay in the sliding mode by Newton. No NLP at all; same switch time and x(T) as
// the homotopy path to 1e-9 (piecewise linear: both exact up to round-off).
class ActiveSetSlidingEntry : public ::testing::TestWithParam<double> {};
TEST_P(ActiveSetSlidingEntry, ByNewtonSameAsHomotopy) {
  const double x0 = GetParam();
  const Both b = run_file("sliding.toml", {{"x0", std::to_string(x0)}});
  expect_same(b, 1e-9);
  ASSERT_EQ(b.active.switches.size(), 1u);
  EXPECT_NEAR(b.active.switches[0].t, x0, 1e-9);
  EXPECT_EQ(b.active.switches[0].before, (std::vector<int>{1}));
  EXPECT_EQ(b.active.switches[0].after, (std::vector<int>{0, 1}));
  EXPECT_NEAR(b.active.x_final()[0], 0.0, 1e-9);
  const fesd::Summary& s = b.active.summary;
  EXPECT_EQ(s.active_set_path_steps, 10);
  EXPECT_EQ(s.homotopy_path_steps, 0);
  EXPECT_EQ(s.homotopy_steps, 0);  // no NLP
  // One square system per step; in the step of the entry the crossing, then the sliding entry.
  EXPECT_EQ(s.active_set_tries, 10 + 2);
  // Sliding: theta = (1/2, 1/2) at every stage after the entry (Filippov's convex combination).
  for (std::size_t i = 0; i < b.active.t_stage.size(); ++i)
    if (b.active.t_stage[i] > x0 + 1e-9) {
      EXPECT_NEAR(b.active.theta[i][0], 0.5, 1e-9) << "t = " << b.active.t_stage[i];
      EXPECT_NEAR(b.active.theta[i][1], 0.5, 1e-9) << "t = " << b.active.t_stage[i];
    }
}
INSTANTIATE_TEST_SUITE_P(X0, ActiveSetSlidingEntry, ::testing::Values(0.5, 0.47, 0.43));

// Example 3(c) (examples/leaving_sliding.toml, x' in -sign(x) + t, x0 = 0, on [0, 2]): slides
// until t = 1, then x = (t - 1)^2 / 2, x(2) = 1/2 (REFERENCE.md). N_sim = 7 puts the exit inside
// the step [6/7, 8/7]: theta_0 < 0 in the prediction, the exit is pinned (theta_0 = 0 at the
// boundary replaces h_1 = h_0). N_sim = 10: the exit on a step boundary. No NLP; the exit time
// and x(T) as the homotopy path's (with its pinned re-solve) and exact, to 1e-9 (Radau IIA 2 is
// exact for the quadratic).
class ActiveSetSlidingExit : public ::testing::TestWithParam<int> {};
TEST_P(ActiveSetSlidingExit, ByNewtonSameAsHomotopy) {
  const int N_sim = GetParam();
  const Both b = run_file("leaving_sliding.toml", {{"N_sim", std::to_string(N_sim)}});
  expect_same(b, 1e-9);
  ASSERT_EQ(b.active.switches.size(), 1u);
  EXPECT_NEAR(b.active.switches[0].t, 1.0, 1e-9);
  EXPECT_TRUE(b.active.switches[0].located);
  EXPECT_EQ(b.active.switches[0].before, (std::vector<int>{0, 1}));
  EXPECT_EQ(b.active.switches[0].after, (std::vector<int>{1}));
  EXPECT_NEAR(b.active.x_final()[0], 0.5, 1e-9);
  const fesd::Summary& s = b.active.summary;
  EXPECT_EQ(s.active_set_path_steps, N_sim);
  EXPECT_EQ(s.homotopy_path_steps, 0);
  EXPECT_EQ(s.homotopy_steps, 0);
  // One square system per step, one more for the exit: pinned at boundary 1 (N_sim = 7), or the
  // whole step without region 0 (N_sim = 10: theta_0 < 0 at the step's first stage).
  EXPECT_EQ(s.active_set_tries, N_sim + 1);
}
INSTANTIATE_TEST_SUITE_P(NSim, ActiveSetSlidingExit, ::testing::Values(7, 10));

// x1' in -sign(x1), x2' in -sign(x2) from (1, x2_0) on [0, 3] as a problem file of two
// subsystems (Radau IIA n_s = 2, N_FE = 2), with N_sim steps.
fesd::SimulationProblem cartesian_product(const std::string& x2_0, const std::string& N_sim) {
  const std::string text = R"(
[model]
x = ["x1", "x2"]
x0 = [1, )" + x2_0 + R"(]
[[model.subsystem]]
c = ["x1"]
F = [["-1", "0"], ["1", "0"]]
[[model.subsystem]]
g = ["-x2", "x2"]
F = [["0", "-1"], ["0", "1"]]
[simulation]
T_sim = 3.0
N_sim = )" + N_sim + R"(
[discretization]
rk_scheme = "radau_iia"
n_s = 2
N_finite_elements = 2
)";
  return fesd::parse_simulation_problem(text, "product.toml");
}

// Co-dimension 2 in a Cartesian product (docs/problem-files.md): x1' in -sign(x1), x2' in
// -sign(x2) from (1, -2): x1 reaches 0 at t = 1 and slides (subsystem 0: {0} -> {0, 1}), x2 at
// t = 2 (subsystem 1: {3} -> {2, 3}), then both stay at 0. Each subsystem's theta is determined
// by its own surface: the square system is regular. N_sim = 7 on [0, 3] puts both entries inside
// steps. No NLP; exact to 1e-9 and as the homotopy path.
TEST(ActiveSetSliding, CodimensionTwoInACartesianProduct) {
  const fesd::SimulationProblem q = cartesian_product("-2", "7");
  const Both b = run_both(q.model, q.x0, q.T_sim, q.N_sim, q.options);
  expect_same(b, 1e-9);
  ASSERT_EQ(b.active.switches.size(), 2u);
  EXPECT_NEAR(b.active.switches[0].t, 1.0, 1e-9);
  EXPECT_NEAR(b.active.switches[1].t, 2.0, 1e-9);
  EXPECT_EQ(b.active.switches[0].after, (std::vector<int>{0, 1, 3}));
  EXPECT_EQ(b.active.switches[1].after, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_LT(b.active.x_final().lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_EQ(b.active.summary.active_set_path_steps, 7);
  EXPECT_EQ(b.active.summary.homotopy_path_steps, 0);
}

// examples/nosnoc/temperature_control.toml (nosnoc_py's hysteresis example, 4 regions in one
// subsystem, time freezing): the sliding entries {2} -> {2, 3} at t = 0.5 and 2.6 are taken by
// Newton. At the triple point psi = 1, w = 0 region 1's field is 0 (a Filippov equilibrium): the
// sliding candidate {0, 1, 2} there has theta = (0, 1, 0), on the simplex boundary, and is refused
// (sliding_is_filippov); those steps fall back to the homotopy, whose relaxed homotopy (sigma_N
// = 1e-2) carries the state over the equilibrium. The file's complementarity_tol is 1e-2: the
// homotopy path's exact re-solves leave its switch at 2.6 3.9e-7 early (its element starts
// sliding at w = 1 - 9.8e-7), so the paths agree to 1e-6 in the switch times and in x(T): x(T)
// differs by that offset times the state's speed, below 1e-7 in the Release build and 3.86e-7 in
// the Debug sanitizer build (round-off moves where in the offset's range the two paths end).
TEST(ActiveSetSliding, TemperatureControlSameAsHomotopy) {
  const Both b = run_file("nosnoc/temperature_control.toml");
  expect_same(b, 1e-6);
  EXPECT_LT((b.active.x_final() - b.homotopy.x_final()).lpNorm<Eigen::Infinity>(), 1e-6);
  ASSERT_EQ(b.active.switches.size(), 7u);
  EXPECT_NEAR(b.active.switches[1].t, 0.5, 1e-9);
  EXPECT_GE(b.active.summary.active_set_path_steps, 25);
  EXPECT_LE(b.active.summary.homotopy_path_steps, 5);
  // the result says per step which path solved it
  ASSERT_EQ(b.active.step_path.size(), 30u);
  EXPECT_EQ(std::count(b.active.step_path.begin(), b.active.step_path.end(), StepSolver::Homotopy),
            b.active.summary.homotopy_path_steps);
  EXPECT_EQ(
      std::count(b.homotopy.step_path.begin(), b.homotopy.step_path.end(), StepSolver::Homotopy),
      30);
}

// examples/nosnoc/periodic_stick_slip.toml (nosnoc_py's codim-2 example: one subsystem, four
// regions of c = (x2 - 0.2, x3 - 0.4), Radau IIA n_s = 4, N_FE = 3, N_sim = 100 on [0, 20]). On the
// intersection of both surfaces f_0 = f_1, so the four-region set has a one-parameter family of
// theta: its system is not square. Every step runs on the active-set path with the regular
// selection {0, 3} (theta_1 = theta_2 = 0: ActiveSetStep::selections, the two-region sets of an
// entry), and the switches are the 7 events of the event-driven solution (the file's comment;
// here to 10 digits from an RK4 integration with step 1e-3 and 5e-4, events by bisection, which
// agree to 1e-12), x(20) = (1.22894361753, -0.260185061673, -0.0601850616733) from it. The
// homotopy path (66 s CPU, not run here) lists 17 switches on this grid: 10 more than the events
// (changes between {1, 3}, {0, 1, 3} and {0, 1, 2, 3} on the intersection, short visits of region
// 1 at entries and exits), and its x(20) is 3.2e-4 off.
TEST(ActiveSetSliding, StickSlipCodimensionTwoEvents) {
  fesd::SimulationProblem q =
      fesd::load_simulation_problem(FESD_SOURCE_DIR "/examples/nosnoc/periodic_stick_slip.toml");
  fesd::apply_override(q, "step_solver", "active_set");
  const IntegratorResult r = fesd::integrate(q.model, q.x0, q.T_sim, q.N_sim, q.options, q.u, q.p);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_EQ(r.summary.active_set_path_steps, 100);
  EXPECT_EQ(r.summary.homotopy_path_steps, 0);
  const double events[] = {0.2443307896,  0.5549932425,  2.7880473074, 7.5239056551,
                           10.6157314133, 15.3515897609, 18.4434155192};
  ASSERT_EQ(r.switches.size(), 7u);
  for (std::size_t i = 0; i < 7; ++i) {
    EXPECT_NEAR(r.switches[i].t, events[i], 1e-8) << "switch " << i;
    EXPECT_TRUE(r.switches[i].located);
  }
  EXPECT_EQ(r.switches[1].after, (std::vector<int>{0, 3}));  // both surfaces: the selection
  const Eigen::Vector3d x_ref(1.22894361753, -0.260185061673, -0.0601850616733);
  EXPECT_LT((r.x_final() - x_ref).lpNorm<Eigen::Infinity>(), 1e-8);
}

// Two switches in one step: the Cartesian product from (1, -1.1), N_sim = 5 on [0, 3] (steps of
// 0.6): x1 enters its sliding mode at t = 1, x2 at t = 1.1, both inside the step [0.6, 1.2],
// whose N_FE = 2 elements have one free boundary. The homotopy path solves that step with 2 N_FE
// elements (its refined retry); the active-set path as two half steps, the second of which,
// [0.9, 1.2], has both switches too and runs as two quarter steps (entries at 1 and 1.1). Same
// switches and x(T) to 1e-9, exact; every step by Newton.
TEST(ActiveSetTwoSwitches, CartesianProductEntriesInOneStep) {
  const fesd::SimulationProblem q = cartesian_product("-1.1", "5");
  const Both b = run_both(q.model, q.x0, q.T_sim, q.N_sim, q.options);
  expect_same(b, 1e-9);
  EXPECT_EQ(b.homotopy.summary.refined_steps, 1);
  ASSERT_EQ(b.active.switches.size(), 2u);
  EXPECT_NEAR(b.active.switches[0].t, 1.0, 1e-9);
  EXPECT_NEAR(b.active.switches[1].t, 1.1, 1e-9);
  EXPECT_LT(b.active.x_final().lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_EQ(b.active.summary.active_set_path_steps, 5);
  EXPECT_EQ(b.active.summary.homotopy_path_steps, 0);
  EXPECT_EQ(b.active.summary.homotopy_steps, 0);
  // 4 steps of 2 elements; the step with both switches as two halves, of which [0.9, 1.2] (both
  // switches again) as two quarters: 2 + 2 + 2 elements
  EXPECT_EQ(b.active.h.size(), 14u);
}

// examples/nosnoc/relay_feedback.toml at complementarity_tol 1e-9, sigma_N 1e-13 (where the
// homotopy path is tight; it takes ~30 s, so its result is quoted here, not recomputed): the short
// slides whose entry and exit lie in one step of 50 ms (steps from 5.65, 5.9, 8.65, 8.9, 9.1, 9.15)
// are solved as half steps, every step by Newton. The homotopy path lists 22 switches; the
// active-set path lists them too, within 3.5e-3 (this grid's accuracy: against the event list of a
// run with N_sim = 4000, n_s = 3 the homotopy's are within 3.2e-3, the active-set path's within
// 5e-3), and 4 more: the slides at 5.674-5.689 and 8.655-8.670 of the exact solution (34 switches),
// which the homotopy's 4-element retry steps over (the state passes at x1 ~ 1e-4).
TEST(ActiveSetTwoSwitches, RelayFeedbackShortSlidesByNewton) {
  fesd::SimulationProblem q =
      fesd::load_simulation_problem(FESD_SOURCE_DIR "/examples/nosnoc/relay_feedback.toml");
  fesd::apply_override(q, "complementarity_tol", "1e-9");
  fesd::apply_override(q, "sigma_N", "1e-13");
  fesd::apply_override(q, "step_solver", "active_set");
  const IntegratorResult r = fesd::integrate(q.model, q.x0, q.T_sim, q.N_sim, q.options, q.u, q.p);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_EQ(r.summary.active_set_path_steps, 200);
  EXPECT_EQ(r.summary.homotopy_path_steps, 0);
  // the homotopy path's switches (same settings, step_solver = homotopy)
  const double homotopy[] = {
      2.81240446485, 3.04483003986, 3.06848404466, 3.29065002129, 3.33356444961, 3.53838261926,
      4.93288917664, 5.92023679102, 5.94523679102, 6.17094201288, 6.20521581568, 6.41928897358,
      6.49356478046, 6.6701441746,  7.91329315769, 8.90121376151, 8.92556169107, 9.15121473312,
      9.18556499963, 9.39999999997, 9.4735004408,  9.65000000006};
  ASSERT_EQ(r.switches.size(), 26u);
  for (double th : homotopy) {
    double nearest = 1e9;
    for (const auto& s : r.switches) nearest = std::min(nearest, std::abs(s.t - th));
    EXPECT_LT(nearest, 3.5e-3) << "homotopy switch at " << th;
  }
  for (double slide : {5.674, 5.689, 8.655, 8.670}) {
    double nearest = 1e9;
    for (const auto& s : r.switches) nearest = std::min(nearest, std::abs(s.t - slide));
    EXPECT_LT(nearest, 5e-3) << "short slide at " << slide;
  }
  // the homotopy's x(10) = (0, -0.897000402807, 2.35901724221); the event-driven one is
  // (0, -0.89733, 2.35870): both paths are ~4e-4 from it on this grid
  const Eigen::Vector3d x_hom(0.0, -0.897000402806606, 2.35901724221437);
  EXPECT_LT((r.x_final() - x_hom).lpNorm<Eigen::Infinity>(), 2e-4);
}

// Gauss-Legendre (not stiffly accurate: boundary values (33) at every element end) in a sliding
// mode: lambda_end = 0 of both regions would make the end-point LP one row too many (c(x_{n+1}) =
// 0, implied by c = 0 at the stages); one of them stays free. Example 3(b) with the entry inside a
// step (x0 = 0.47) and at a step boundary (x0 = 0.5), Example 3(c) with the exit inside a step
// (N_sim = 7: Gauss-Legendre cannot pin an exit on an interior boundary, so that step runs as two
// half steps with the exit at their common boundary t = 1) and on a step boundary (N_sim = 10).
// Every step by Newton; switch times and x(T) exact to 1e-9 and as the homotopy path's (3(b): to
// 1e-9; 3(c): 2e-8, the homotopy's x(2) is 7e-9 (N_sim = 7) and 1.1e-8 (10) off the exact 1/2).
TEST(ActiveSetGaussLegendre, SlidingEntryAndExitByNewton) {
  for (const double x0 : {0.47, 0.5}) {
    const Both b =
        run_file("sliding.toml", {{"x0", std::to_string(x0)}, {"rk_scheme", "gauss_legendre"}});
    expect_same(b, 1e-9);
    ASSERT_EQ(b.active.switches.size(), 1u);
    EXPECT_NEAR(b.active.switches[0].t, x0, 1e-9);
    EXPECT_NEAR(b.active.x_final()[0], 0.0, 1e-9);
    EXPECT_EQ(b.active.summary.active_set_path_steps, 10);
    EXPECT_EQ(b.active.summary.homotopy_path_steps, 0);
  }
  for (const int N_sim : {7, 10}) {
    const Both b = run_file("leaving_sliding.toml",
                            {{"N_sim", std::to_string(N_sim)}, {"rk_scheme", "gauss_legendre"}});
    expect_same(b, 2e-8);
    ASSERT_EQ(b.active.switches.size(), 1u);
    EXPECT_NEAR(b.active.switches[0].t, 1.0, 1e-9);
    EXPECT_NEAR(b.active.x_final()[0], 0.5, 1e-9);
    EXPECT_EQ(b.active.summary.active_set_path_steps, N_sim);
    EXPECT_EQ(b.active.summary.homotopy_path_steps, 0);
  }
}

TEST(ActiveSetOptions, UnknownValueIsAClearError) {
  fesd::SimulationProblem q =
      fesd::load_simulation_problem(FESD_SOURCE_DIR "/examples/oscillator.toml");
  try {
    fesd::apply_override(q, "step_solver", "newton");
    FAIL() << "expected fesd::InvalidOption";
  } catch (const fesd::InvalidOption& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("step_solver"), std::string::npos) << msg;
    EXPECT_NE(msg.find("active_set"), std::string::npos) << msg;  // the valid names
  }
  const std::string text = R"(
[model]
x = ["x"]
c = ["x"]
F = [["1"], ["3"]]
x0 = [-1.0]
[simulation]
T_sim = 1.0
step_solver = "fast"
)";
  try {
    (void)fesd::parse_simulation_problem(text, "bad.toml");
    FAIL() << "expected an error";
  } catch (const fesd::Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("step_solver"), std::string::npos) << msg;
    EXPECT_NE(msg.find("bad.toml"), std::string::npos) << msg;
  }
}

// The standard method (use_fesd = false) has no free lengths to carry a switch: whatever
// step_solver says (the default is active_set), every step runs on the homotopy path.
TEST(ActiveSetOptions, StandardMethodRunsOnTheHomotopy) {
  IntegratorOptions o = options(RkScheme::RadauIIA, 2, StepSolver::ActiveSet);
  o.discretization.use_fesd = false;
  EXPECT_TRUE(fesd::validate(o).empty());
  const auto r = fesd::integrate(crossing_model(), Eigen::VectorXd::Constant(1, -1.0), 1.0, 2, o);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_EQ(r.summary.active_set_path_steps, 0);
  EXPECT_EQ(r.summary.homotopy_path_steps, 2);
  EXPECT_EQ(r.step_path, (std::vector<StepSolver>{StepSolver::Homotopy, StepSolver::Homotopy}));
}

}  // namespace
