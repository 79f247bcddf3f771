// nosnoc_py's examples written as fesd problem files. The relay feedback, friction block and
// periodic stick-slip simulations (examples/nosnoc/relay_feedback.toml, friction_block.toml,
// periodic_stick_slip.toml):
// their switch lists at complementarity_tol 1e-6 and 1e-12 (issue 13, item 10: the activity rule
// theta against lambda and the re-solve with the active set fixed). With the old rule (theta >
// 1e-6 at some stage) complementarity_tol 1e-6 gave invented switches and failed pinned
// re-solves on these examples. Each test runs the file's model and settings on a shortened
// horizon whose switches are known from an event-driven reference solution (matrix exponentials
// for the relay, RK4 with step 1e-3 and bisection for the others, accurate to 1e-9 or better).
// Then the motor with friction and cart pole OCPs and the temperature control simulation
// (examples/nosnoc/motor_with_friction.toml, cart_pole_with_friction.toml,
// temperature_control.toml) against nosnoc_py's results in NOSNOC-EXAMPLES.md (issue 14).
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

// One tolerance setting: complementarity_tol and a sigma_N below it (sigma_N = complementarity_tol
// would end the homotopy at 0.1^k, a rounding above it).
struct Tolerance {
  const char* complementarity_tol;
  const char* sigma_N;
};

std::string name_of(const ::testing::TestParamInfo<Tolerance>& info) {
  std::string s = std::string("tol_") + info.param.complementarity_tol;
  std::replace(s.begin(), s.end(), '-', 'm');
  return s;
}

SimulationProblem load_example(const std::string& file, const Tolerance& tol) {
  SimulationProblem p =
      fesd::load_simulation_problem(std::string(FESD_SOURCE_DIR) + "/examples/" + file);
  fesd::apply_override(p, "complementarity_tol", tol.complementarity_tol);
  fesd::apply_override(p, "sigma_N", tol.sigma_N);
  return p;
}

IntegratorResult run_example(const SimulationProblem& p) {
  return fesd::integrate(p.model, p.x0, p.T_sim, p.N_sim, p.options, p.u, p.p);
}

const std::vector<Tolerance> kTolerances = {{"1e-6", "1e-8"}, {"1e-12", "1e-13"}};

// ---- Relay feedback: x' = A x - b sign(x1) ------------------------------------------------------
// From its x0 on x1 = 0 the relay slides until x2 = -1 at t = 2.8124 (sliding: x2' = x3 + 2 x2,
// x3' = -x2), then oscillates with crossings and short sliding phases (26 switches to t = 10, 34
// in the exact solution). The test starts at the exact state at t = 2.75 (on the surface, still
// sliding), on the file's grid (step 0.05), and runs 7 steps: exit, entry, exit. Exact times
// (relative to 2.75): 0.0624033760, 0.2916216394, 0.3189768333. fesd's times are equal at every
// tolerance to 1e-9 (the re-solve makes complementarity exact) and off the exact ones by up to
// 3.2e-3, the discretization error of Radau IIA n_s = 2 with elements of 0.025 at omega = 25 (the
// entry is a shallow crossing, x1' = x2 + 1 = 0.02, which turns a state error of 6e-5 into the
// time error); they converge with N_sim (N_sim 1000 over [0, 10]: 1.2e-5).
class RelayFeedback : public ::testing::TestWithParam<Tolerance> {};

TEST_P(RelayFeedback, ExitEntryExitAtEveryTolerance) {
  SimulationProblem p = load_example("nosnoc/relay_feedback.toml", GetParam());
  fesd::apply_override(p, "x0", "0, -0.9190046231960544, 0.5905093536281034");
  fesd::apply_override(p, "T_sim", "0.35");
  fesd::apply_override(p, "N_sim", "7");
  const IntegratorResult r = run_example(p);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_EQ(r.switches.size(), 3u);
  const std::vector<int> both{0, 1}, left{0};
  EXPECT_EQ(r.switches[0].before, both);
  EXPECT_EQ(r.switches[0].after, left);
  EXPECT_EQ(r.switches[1].before, left);
  EXPECT_EQ(r.switches[1].after, both);
  EXPECT_EQ(r.switches[2].before, both);
  EXPECT_EQ(r.switches[2].after, left);
  const double fesd_t[] = {0.0624033963, 0.2948289064, 0.3184829762};  // measured, 1e-12
  const double exact_t[] = {0.0624033760, 0.2916216394, 0.3189768333};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(r.switches[i].located) << i;
    EXPECT_NEAR(r.switches[i].t, fesd_t[i], 1e-8) << i;
    EXPECT_NEAR(r.switches[i].t, exact_t[i], 5e-3) << i;
  }
  EXPECT_NEAR(r.switches[0].t, exact_t[0], 1e-7);  // the exit after the long slide
  EXPECT_EQ(r.summary.pin_failures, 0);
  EXPECT_EQ(r.summary.active_set_failures, 0);
}

INSTANTIATE_TEST_SUITE_P(CompTol, RelayFeedback, ::testing::ValuesIn(kTolerances), name_of);

// ---- Friction block: three blocks with Coulomb friction, one subsystem per block ---------------
// 12 switches on [0, 5] at every tolerance (nosnoc_py lists the same 12). The first quarter second
// has two crossings: block 2 (v2 > 0 -> v2 < 0, regions {1,2,4} -> {1,3,4}) and block 1 (v1 < 0 ->
// v1 > 0, -> {0,3,4}). Over [0, 5] fesd's 12 times agree with the reference to 1.7e-7 and across
// complementarity_tol 1e-6, 1e-9, 1e-12 to 7e-13.
class FrictionBlock : public ::testing::TestWithParam<Tolerance> {};

// Both step solvers: the active-set path (the default) gives equal element lengths around the
// switches, the homotopy's heuristic_delta a penalty minimizer: their switch times differ by
// 1.6e-8 and 1.2e-8, both ~1.5e-7 from the exact ones.
TEST_P(FrictionBlock, TwoCrossingsInTheFirstQuarterSecond) {
  struct Path {
    const char* step_solver;
    double fesd_t[2];  // measured, 1e-12
  };
  const Path paths[] = {{"active_set", {0.2077365256, 0.2486855377}},
                        {"homotopy", {0.2077365411, 0.2486855502}}};
  const double exact_t[] = {0.207736371, 0.248685443};
  for (const Path& path : paths) {
    SCOPED_TRACE(path.step_solver);
    SimulationProblem p = load_example("nosnoc/friction_block.toml", GetParam());
    fesd::apply_override(p, "T_sim", "0.25");
    fesd::apply_override(p, "N_sim", "6");  // the file's step, 5 / 120
    fesd::apply_override(p, "step_solver", path.step_solver);
    const IntegratorResult r = run_example(p);
    ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
    ASSERT_EQ(r.switches.size(), 2u);
    EXPECT_EQ(r.switches[0].before, (std::vector<int>{1, 2, 4}));
    EXPECT_EQ(r.switches[0].after, (std::vector<int>{1, 3, 4}));
    EXPECT_EQ(r.switches[1].after, (std::vector<int>{0, 3, 4}));
    for (std::size_t i = 0; i < 2; ++i) {
      EXPECT_NEAR(r.switches[i].t, path.fesd_t[i], 1e-9) << i;
      EXPECT_NEAR(r.switches[i].t, exact_t[i], 1e-6) << i;
    }
    EXPECT_EQ(r.summary.pinned_exits, 0);  // crossings only: nothing to pin
    EXPECT_EQ(r.summary.active_set_failures, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(CompTol, FrictionBlock, ::testing::ValuesIn(kTolerances), name_of);

// ---- Periodic stick-slip (codimension 2) -------------------------------------------------------
// From x0 in region 0 (x2 < 0.2, x3 < 0.4): x2 reaches 0.2 at t = 0.2443307896 and sticks
// (regions {0, 2}); x3 reaches 0.4 at t = 0.5549932425, and the state sticks on both surfaces.
// There theta_2 = 0 and theta_3 = (1 - x1) / 2, so x1' = 0.3 + x1 (1 - x1) / 2, but the split
// of (1 + x1) / 2 between regions 0 and 1 is free (their fields agree on x3 = 0.4), so which of
// them the active set lists is not determined (and at complementarity_tol 1e-6, where every
// lambda is ~0 on the intersection, region 2 is listed too): the test checks region 3 only.
// Two steps of the file's grid (step 0.2) plus one in the codimension-2 phase.
class PeriodicStickSlip : public ::testing::TestWithParam<Tolerance> {};

TEST_P(PeriodicStickSlip, SticksOnOneSurfaceThenOnBoth) {
  SimulationProblem p = load_example("nosnoc/periodic_stick_slip.toml", GetParam());
  fesd::apply_override(p, "step_solver", "homotopy");  // the file uses active_set
  fesd::apply_override(p, "T_sim", "0.6");
  fesd::apply_override(p, "N_sim", "3");
  const IntegratorResult r = run_example(p);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_EQ(r.switches.size(), 2u);
  EXPECT_EQ(r.switches[0].before, std::vector<int>{0});
  EXPECT_EQ(r.switches[0].after, (std::vector<int>{0, 2}));
  EXPECT_NEAR(r.switches[0].t, 0.2443307896, 1e-9);  // reference and fesd at 1e-6 and 1e-12
  EXPECT_EQ(r.switches[1].before, (std::vector<int>{0, 2}));
  const std::vector<int>& after = r.switches[1].after;
  EXPECT_NE(std::find(after.begin(), after.end(), 3), after.end());
  // Measured: 0.5549932425 at 1e-12 (and 1e-9), 0.5549918710 at 1e-6.
  EXPECT_NEAR(r.switches[1].t, 0.5549932425, 3e-6);
  // x(0.6) = (0.1487622129, 0.2, 0.4); measured errors 8e-8 (1e-6), 1.2e-12 (1e-12).
  EXPECT_NEAR(r.x_final()[0], 0.1487622129, 1e-6);
  EXPECT_NEAR(r.x_final()[1], 0.2, 1e-6);
  EXPECT_NEAR(r.x_final()[2], 0.4, 1e-5);
}

INSTANTIATE_TEST_SUITE_P(CompTol, PeriodicStickSlip, ::testing::ValuesIn(kTolerances), name_of);

// The end of the codimension-2 stick: from the exact state at t = 2.6 (x1 = 0.9409579470, on both
// surfaces) x1 reaches 1 at t = 2.6 + 0.1880473077, where both contacts slip at once (region 0
// alone). Two steps of the file's grid. At complementarity_tol 1e-9 the exit is pinned and
// located (measured 4.8e-7 early); at 1e-12 it comes 5.5e-4 early with located = false.
SimulationProblem stick_slip_from_the_intersection(const Tolerance& tol) {
  SimulationProblem p = load_example("nosnoc/periodic_stick_slip.toml", tol);
  fesd::apply_override(p, "step_solver", "homotopy");  // the file uses active_set
  fesd::apply_override(p, "x0", "0.9409579470134545, 0.2, 0.4");
  fesd::apply_override(p, "T_sim", "0.4");
  fesd::apply_override(p, "N_sim", "2");
  return p;
}

constexpr double kCodim2Exit = 0.1880473077;

TEST(PeriodicStickSlipExit, BothContactsSlipWhenX1ReachesOne) {
  const IntegratorResult r = run_example(stick_slip_from_the_intersection({"1e-9", "1e-10"}));
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_EQ(r.switches.size(), 1u);
  EXPECT_EQ(r.switches[0].after, std::vector<int>{0});
  EXPECT_TRUE(r.switches[0].located);
  EXPECT_NEAR(r.switches[0].t, kCodim2Exit, 1e-6);
  EXPECT_EQ(r.summary.pin_failures, 0);
}

// Known gap (disabled until fixed): at complementarity_tol 1e-6 the homotopy keeps every element
// of the first step on the intersection (regions {0, 1, 2, 3}), the pinned re-solve of step 0 ends
// in "Infeasible_Problem_Detected" (pin_failures = 1, a warning names "the step from t = 0"), and
// the exit is listed at the step boundary t = 0.2, 1.2e-2 late, with located = true: the switch
// at a step boundary is recorded by the next step, and only the switches recorded by the step
// whose pin failed are marked (Integrator::mark_unlocated).
TEST(PeriodicStickSlipExit, AnExitAtAStepBoundaryIsLocatedOrMarked) {
  const IntegratorResult r = run_example(stick_slip_from_the_intersection({"1e-6", "1e-8"}));
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_EQ(r.switches.size(), 1u);
  const fesd::SwitchEvent& s = r.switches[0];
  EXPECT_TRUE(!s.located || std::abs(s.t - kCodim2Exit) < 1e-6) << "t = " << s.t;
}

// ---- Cart pole with friction (OCP) ----------------------------------------------------------
// nosnoc_py's solve_example() ends at J = 678.50 (NOSNOC-EXAMPLES.md). The file's step
// equilibration, heuristic_delta (nosnoc_py's default there), reaches the same local minimum
// (measured 678.5005953, 2 switches as in nosnoc_py; heuristic_mean: 678.4998927); fesd's OCP
// default l2_relaxed ends in another one (702.27).
// Measured: about 6 s of CPU in a Release build.
TEST(NosnocCartPole, ReachesNosnocPysObjective) {
  const fesd::OcpProblem p = fesd::load_ocp_problem(
      std::string(FESD_SOURCE_DIR) + "/examples/nosnoc/cart_pole_with_friction.toml");
  ASSERT_EQ(p.options.discretization.step_eq, fesd::StepEq::HeuristicDelta);
  ASSERT_TRUE(p.options.constraints_at_stages);
  const fesd::OcpResult r = fesd::solve(p.ocp, p.options);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.objective, 678.50, 5e-3);
  const Eigen::VectorXd xT = r.x_final();
  ASSERT_EQ(xT.size(), 4);
  EXPECT_NEAR(xT[1], M_PI, 1e-3);  // the pole upright (measured 3.1415872)
  EXPECT_NEAR(xT[0], 0.0, 1e-2);   // the cart back near 0 (measured -3.6e-3)
  EXPECT_EQ(r.switches.size(), 2u);
  for (const Eigen::VectorXd& x : r.x) EXPECT_LE(std::abs(x[0]), 5.0 + 1e-8);
}

// ---- Motor with friction (OCP) -----------------------------------------------------------------
// The file's settings (30 stages x 2 FE, comp_tol 1e-6, l2_relaxed for nosnoc_py's
// L2_RELAXED_SCALED) give fesd's earlier J = 0.85396 (measured 0.8539600487, 2 switches).
// nosnoc_py's 0.83969 (4 switches) is another local minimum, the one fesd reaches with
// heuristic_delta (0.8396952), heuristic_mean or no step equilibration: l2_relaxed ends in the
// 2-switch solution. x(T) is the target exactly (a hard terminal constraint). Measured: about
// 10 s of CPU in a Release build, the slowest of these tests.
TEST(NosnocMotorWithFriction, ObjectiveAndTarget) {
  const fesd::OcpProblem p = fesd::load_ocp_problem(std::string(FESD_SOURCE_DIR) +
                                                    "/examples/nosnoc/motor_with_friction.toml");
  ASSERT_EQ(p.options.discretization.step_eq, fesd::StepEq::L2Relaxed);
  const fesd::OcpResult r = fesd::solve(p.ocp, p.options);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.objective, 0.85396, 1e-5);
  const Eigen::VectorXd xT = r.x_final();
  const double target[] = {0.01, 0.0, 0.01, 0.0, 0.0};
  ASSERT_EQ(xT.size(), 5);
  for (Eigen::Index i = 0; i < 5; ++i) EXPECT_NEAR(xT[i], target[i], 1e-8) << i;
  ASSERT_EQ(r.u.size(), 30u);
  for (const Eigen::VectorXd& u : r.u) EXPECT_LE(std::abs(u[0]), 5.0 + 1e-8);
}

// ---- Temperature control with hysteresis (simulation, g-form, time freezing) ------------------
// The exact temperature as a function of the physical time t (the state named t, which stands
// still while w jumps): heating y' = -y/5 + 20 from 20 up to 21, then cooling y' = -y/5 down to
// 17, heating up to 21, and so on.
double exact_temperature(double t) {
  double y0 = 20.0;
  bool heating = true;
  for (;;) {
    const double duration =
        heating ? 5.0 * std::log((100.0 - y0) / (100.0 - 21.0)) : 5.0 * std::log(y0 / 17.0);
    if (t <= duration)
      return heating ? 100.0 - (100.0 - y0) * std::exp(-t / 5.0) : y0 * std::exp(-t / 5.0);
    t -= duration;
    y0 = heating ? 21.0 : 17.0;
    heating = !heating;
  }
}

// NOSNOC-EXAMPLES.md gives, with the example's loose tolerances (sigma_N = complementarity_tol =
// 1e-2), a largest error against the exact y(t) of 0.18 for nosnoc_py and 0.36 for fesd: the test
// asserts 0.36 along the trajectory and at the end. Measured now: 0.078 (at t_phys = 1.12,
// near the switch-on at 17) and 0.045 at the end, y(3) = 19.4075 (NOSNOC-EXAMPLES.md: 19.58
// nosnoc_py, 20.60 fesd main 0d0c9fc) at t_phys = 1.7724. The file's own run at N_sim = 30 only
// (no companion runs); measured about 5 s of CPU in a Release build.
TEST(NosnocTemperatureControl, FollowsTheHysteresisInPhysicalTime) {
  SimulationProblem p = fesd::load_simulation_problem(std::string(FESD_SOURCE_DIR) +
                                                      "/examples/nosnoc/temperature_control.toml");
  const IntegratorResult r = run_example(p);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  double worst = 0;
  for (const Eigen::VectorXd& x : r.x)
    worst = std::max(worst, std::abs(x[0] - exact_temperature(x[2])));
  EXPECT_LE(worst, 0.36);
  const Eigen::VectorXd xT = r.x_final();
  EXPECT_LE(std::abs(xT[0] - exact_temperature(xT[2])), 0.36) << "y(3) = " << xT[0];
  // Two jumps of w (0 -> 1 at 21, 1 -> 0 at 17) and the third (0 -> 1) done by t = 3: w(3) = 1,
  // and about 3 - 3 * 0.4 of physical time has passed (exact 1.80).
  EXPECT_NEAR(xT[1], 1.0, 1e-2);
  EXPECT_NEAR(xT[2], 1.8, 0.1);
}

}  // namespace
