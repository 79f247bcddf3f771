// IntegratorOptions::sensitivities (docs/sensitivities.md): dx(T)/dx0, dx(T)/du, dx(T)/dp by the
// implicit function theorem on every step's square system, chained. Exact values from
// REFERENCE.md and eq. (24) of papers/fesd-filippov.txt; a finite-difference check on a smooth
// model.
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "../../bench/oscillator_model.hpp"
#include "../../bench/sensitivity_ocp.hpp"
#include "fesd/integrator.hpp"
#include "fesd/model.hpp"
#include "fesd/problem_file.hpp"
#include "integrator/stepper_models.hpp"

namespace {

using fesd::IntegratorOptions;
using fesd::IntegratorResult;
using fesd::RkScheme;
using fesd::StepSolver;

// Example 3(a): x' in 2 - sign(x) (bench/sensitivity_ocp.hpp).
fesd::Pss crossing_model() {
  return fesd::make_pss(fesd_bench::SensitivityModel{},
                        fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
}

// Example 3(b): x' in -sign(x).
struct Sliding {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int region, const T*, const T*, const T*, T* f) const {
    f[0] = T(region == 0 ? -1.0 : 1.0);  // region 0: x > 0
  }
};

IntegratorOptions options(RkScheme scheme, int n_s, StepSolver solver, bool fesd = true) {
  IntegratorOptions o;
  o.discretization.rk_scheme = scheme;
  o.discretization.n_s = n_s;
  o.discretization.use_fesd = fesd;
  o.step_solver = solver;
  o.sensitivities = true;
  return o;
}

Eigen::VectorXd vec1(double v) {
  return Eigen::VectorXd::Constant(1, v);
}

void expect_available(const IntegratorResult& r) {
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_TRUE(r.sensitivities.requested);
  ASSERT_TRUE(r.sensitivities.available) << r.sensitivities.message;
}

struct Case {
  RkScheme scheme;
  int n_s;
  StepSolver solver;
};
std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  return std::string(info.param.scheme == RkScheme::RadauIIA ? "Radau" : "Gauss") +
         std::to_string(info.param.n_s) +
         (info.param.solver == StepSolver::ActiveSet ? "ActiveSet" : "Homotopy");
}
const Case kCases[] = {{RkScheme::RadauIIA, 2, StepSolver::ActiveSet},
                       {RkScheme::RadauIIA, 2, StepSolver::Homotopy},
                       {RkScheme::GaussLegendre, 2, StepSolver::ActiveSet},
                       {RkScheme::GaussLegendre, 2, StepSolver::Homotopy}};

// Example 3(a), x0 = -1, T = 2: dx(T)/dx0 = 1/3 exactly (REFERENCE.md), on both paths. The
// solution is piecewise linear, so FESD reproduces it exactly: 1e-9.
class IftCrossing : public ::testing::TestWithParam<Case> {};
TEST_P(IftCrossing, IsOneThird) {
  const Case c = GetParam();
  for (int N_sim : {7, 10}) {
    const IntegratorResult r = fesd::integrate(crossing_model(), vec1(-1.0), 2.0, N_sim,
                                               options(c.scheme, c.n_s, c.solver));
    expect_available(r);
    ASSERT_EQ(r.sensitivities.x0.rows(), 1);
    ASSERT_EQ(r.sensitivities.x0.cols(), 1);
    EXPECT_EQ(r.sensitivities.u.cols(), 0);
    EXPECT_EQ(r.sensitivities.p.cols(), 0);
    EXPECT_NEAR(r.sensitivities.x0(0, 0), 1.0 / 3.0, 1e-9) << "N_sim = " << N_sim;
    RecordProperty("error_N_sim_" + std::to_string(N_sim),
                   fmt::format("{:.3e}", std::abs(r.sensitivities.x0(0, 0) - 1.0 / 3.0)));
  }
}
INSTANTIATE_TEST_SUITE_P(Paths, IftCrossing, ::testing::ValuesIn(kCases), case_name);

// The standard method (h fixed) on the same problem: its sensitivity does not converge to 1/3
// (Sect. 2.4; Stewart and Anitescu). Measured with Radau IIA n_s = 2: -0.8 for N_sim = 7, 10, 13,
// 40 (one stage lands on the surface x = 0 with theta = (0.8, 0.2), a "spurious sliding" stage
// whose theta moves with x0; central differences of the standard method's x(T) give -0.8 too).
TEST(IftStandard, CrossingIsNotOneThird) {
  for (int N_sim : {7, 10, 13, 40}) {
    const IntegratorResult r =
        fesd::integrate(crossing_model(), vec1(-1.0), 2.0, N_sim,
                        options(RkScheme::RadauIIA, 2, StepSolver::Homotopy, /*fesd=*/false));
    expect_available(r);
    EXPECT_GT(std::abs(r.sensitivities.x0(0, 0) - 1.0 / 3.0), 0.5) << "N_sim = " << N_sim;
    RecordProperty("value_N_sim_" + std::to_string(N_sim),
                   fmt::format("{:.17g}", r.sensitivities.x0(0, 0)));
  }
}

// Example 3(b), T = 1: the state reaches 0 at t = x0 and slides; dx(T)/dx0 = 0. x0 = 0.47, 0.43:
// the entry inside a step (N_sim = 10), on a free element boundary.
class IftSliding : public ::testing::TestWithParam<Case> {};
TEST_P(IftSliding, IsZeroAfterSliding) {
  const Case c = GetParam();
  const fesd::Pss model = fesd::make_pss(
      Sliding{}, fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
  for (double x0 : {0.47, 0.43}) {
    const IntegratorResult r =
        fesd::integrate(model, vec1(x0), 1.0, 10, options(c.scheme, c.n_s, c.solver));
    expect_available(r);
    EXPECT_NEAR(r.sensitivities.x0(0, 0), 0.0, 1e-9) << "x0 = " << x0;
    RecordProperty("value_x0_" + std::to_string(x0),
                   fmt::format("{:.17g}", r.sensitivities.x0(0, 0)));
  }
}

// A sliding entry exactly on a step boundary (a fixed time, not a free element boundary: the IFT
// cannot move it) gets the jump (24) with the sliding field f* (Prop. 9's remark): Example 3(b)
// with x0 = 0.5, N_sim = 10 (the entry at t = 0.5): J = 1 + (0 - (-1)) / (-1) = 0, so 0 exactly
// (before the jump: not available; before that check Radau IIA gave 0 by R(inf) = 0 and
// Gauss-Legendre 1).
TEST_P(IftSliding, SlidingEntryOnAStepBoundaryHasTheJump) {
  const Case c = GetParam();
  const fesd::Pss model = fesd::make_pss(
      Sliding{}, fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
  const IntegratorResult r =
      fesd::integrate(model, vec1(0.5), 1.0, 10, options(c.scheme, c.n_s, c.solver));
  expect_available(r);
  ASSERT_EQ(r.switches.size(), 1u);
  EXPECT_NEAR(r.switches[0].t, 0.5, 1e-12);
  EXPECT_NEAR(r.sensitivities.x0(0, 0), 0.0, 1e-12);
}

// A sliding exit exactly on a step boundary is outside what is done (its jump needs the exit
// condition's gradient): not available, with the reason. x1' in -sign(x1) + x2, x2' = 1 from
// (0.3, -0.5) (tests/integrator/stepper_models.hpp): the exit at t = 1.5, step boundary 15 of 25
// (where a path places the exit inside a step instead, the value must be the exact
// [[0, 1], [0, 1]]: the slide forgets x1(0), and x1(T) = (T - t_e)^2 / 2 with t_e = 1 - x2(0)).
TEST_P(IftSliding, SlidingExitOnAStepBoundaryIsNotAvailable) {
  const Case c = GetParam();
  const IntegratorResult r =
      fesd::integrate(fesd_test::sliding_exit_model(), fesd_test::sliding_exit_x0(), 2.5, 25,
                      options(c.scheme, c.n_s, c.solver));
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  if (r.sensitivities.available) {
    Eigen::Matrix2d exact;
    exact << 0, 1, 0, 1;
    EXPECT_LT((r.sensitivities.x0 - exact).lpNorm<Eigen::Infinity>(), 1e-6) << r.sensitivities.x0;
  } else {
    EXPECT_NE(r.sensitivities.message.find("lies on a step boundary"), std::string::npos)
        << r.sensitivities.message;
  }
}

// A crossing exactly on a step boundary: the jump (24) is applied between the two steps
// (Integrator::jump_at_step_start). Example 3(a) with N_sim = 6 (t_s = 1/3 on the boundary of
// steps 1 and 2): 1/3 exactly (without the jump: 1, and before it was reported: not available).
TEST_P(IftSliding, CrossingOnAStepBoundaryHasTheJump) {
  const Case c = GetParam();
  const IntegratorResult r =
      fesd::integrate(crossing_model(), vec1(-1.0), 2.0, 6, options(c.scheme, c.n_s, c.solver));
  expect_available(r);
  ASSERT_EQ(r.switches.size(), 1u);
  EXPECT_NEAR(r.switches[0].t, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(r.sensitivities.x0(0, 0), 1.0 / 3.0, 1e-12);
}
INSTANTIATE_TEST_SUITE_P(Paths, IftSliding, ::testing::ValuesIn(kCases), case_name);

/// e^(A t) for A = [[a, b], [-b, a]]: e^(a t) times the rotation by -b t.
Eigen::Matrix2d exp_rotation(double a, double b, double t) {
  Eigen::Matrix2d e;
  e << std::cos(b * t), std::sin(b * t), -std::sin(b * t), std::cos(b * t);
  return std::exp(a * t) * e;
}

// The oscillator (47): X(T) = e^(A2 (T - t_s)) J e^(A1 t_s) with t_s = 1 and the jump matrix (24)
// J = I + (f_2 - f_1) grad c' / (grad c' f_1) at x(t_s) = (1, 0): f_1 = A1 x = (1, -w),
// f_2 = A2 x = (1, w), grad c = (2, 0), so J = [[1, 0], [2 w, 1]].
TEST(IftOscillator, ExactJumpMatrixProduct) {
  const double w = 2 * std::numbers::pi, T = fesd_bench::kOscillatorT;
  Eigen::Matrix2d J;
  J << 1, 0, 2 * w, 1;
  const Eigen::Matrix2d exact = exp_rotation(1, -w, T - 1) * J * exp_rotation(1, w, 1);
  for (StepSolver solver : {StepSolver::ActiveSet, StepSolver::Homotopy}) {
    const IntegratorResult r =
        fesd::integrate(fesd_bench::oscillator_model(), fesd_bench::oscillator_x0(), T, 100,
                        options(RkScheme::RadauIIA, 3, solver));
    expect_available(r);
    const double err = (r.sensitivities.x0 - exact).lpNorm<Eigen::Infinity>();
    // Radau IIA n_s = 3 (order 5), h = T / 100: measured 2.8e-7 on both paths against max |X| = 57.
    EXPECT_LT(err, 1e-6) << "error " << err << "\n" << r.sensitivities.x0;
    RecordProperty(solver == StepSolver::ActiveSet ? "error_active_set" : "error_homotopy",
                   fmt::format("{:.3e}", err));
  }
}

// The oscillator with its crossing t_s = 1 on a step boundary (T = 1.5, N_sim = 60, h = 0.025).
// The homotopy path keeps the switch at the boundary (t_s = 1 exactly): the jump J of (24) between
// steps 40 and 41 gives e^(A2 (T - 1)) J e^(A1) to the scheme's error, measured 1.5e-7 against
// max |X| = 39 (4.8e-6, 1.5e-7, 4.5e-9 at N_sim = 30, 60, 120: order 5; before: not available).
// The active-set path's numerical crossing lands 1.7e-9 after the boundary, inside step 41 (a
// first element of that length): no jump needed there, measured 1.6e-6 (N_sim = 61, the switch
// inside a step: 2.2e-6 on both paths).
TEST(IftOscillator, CrossingOnAStepBoundary) {
  const double w = 2 * std::numbers::pi, T = 1.5;
  Eigen::Matrix2d J;
  J << 1, 0, 2 * w, 1;
  const Eigen::Matrix2d exact = exp_rotation(1, -w, T - 1) * J * exp_rotation(1, w, 1);
  for (StepSolver solver : {StepSolver::ActiveSet, StepSolver::Homotopy}) {
    const IntegratorResult r =
        fesd::integrate(fesd_bench::oscillator_model(), fesd_bench::oscillator_x0(), T, 60,
                        options(RkScheme::RadauIIA, 3, solver));
    expect_available(r);
    ASSERT_EQ(r.switches.size(), 1u);
    EXPECT_NEAR(r.switches[0].t, 1.0, 1e-8);
    if (solver == StepSolver::Homotopy) {
      EXPECT_NEAR(r.switches[0].t, 1.0, 1e-14);
    }
    const double err = (r.sensitivities.x0 - exact).lpNorm<Eigen::Infinity>();
    EXPECT_LT(err, solver == StepSolver::Homotopy ? 1e-6 : 5e-6) << "error " << err << "\n"
                                                                 << r.sensitivities.x0;
    RecordProperty(solver == StepSolver::ActiveSet ? "error_active_set" : "error_homotopy",
                   fmt::format("{:.3e}", err));
  }
}

// The oscillator as printed in examples/oscillator.toml, omega a parameter: x(T) = e^(T - 1)
// Rot(omega (T - 2)) (1, 0) for every omega near 2 pi (the crossing stays at t_s = 1, where the
// radius e^(t - 1) reaches 1), so dx(T)/domega = e^(T - 1) (T - 2) (-sin omega (T - 2),
// cos omega (T - 2)). Measured: 5.3e-9 (Radau IIA 3, N_FE = 2, N_sim = 100, both paths).
TEST(IftOscillator, ParameterOmega) {
  fesd::SimulationProblem q =
      fesd::load_simulation_problem(FESD_SOURCE_DIR "/examples/oscillator.toml");
  ASSERT_EQ(q.model.n_p(), 1);
  const double w = 2 * std::numbers::pi, T = q.T_sim, a = w * (T - 2);
  const Eigen::Vector2d exact =
      std::exp(T - 1) * (T - 2) * Eigen::Vector2d(-std::sin(a), std::cos(a));
  q.options.sensitivities = true;
  for (StepSolver solver : {StepSolver::ActiveSet, StepSolver::Homotopy}) {
    q.options.step_solver = solver;
    const IntegratorResult r = fesd::integrate(q.model, q.x0, T, q.N_sim, q.options);
    expect_available(r);
    ASSERT_EQ(r.sensitivities.p.rows(), 2);
    ASSERT_EQ(r.sensitivities.p.cols(), 1);
    const double err = (r.sensitivities.p.col(0) - exact).lpNorm<Eigen::Infinity>();
    EXPECT_LT(err, 1e-6) << r.sensitivities.p;
    RecordProperty(solver == StepSolver::ActiveSet ? "error_active_set" : "error_homotopy",
                   fmt::format("{:.3e}", err));
  }
}

// A smooth model with controls and parameters and no switch near the trajectory: a forced,
// damped oscillator x1' = x2, x2' = -p0 x1 - p1 x2 + u0 + u1 x1, c = x1 - 10 (never reached;
// region 1, c < 0, the whole time).
struct Forced {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0] - 10.0;
  }
  template <class T>
  void f(int region, const T* x, const T* u, const T* p, T* f) const {
    f[0] = x[1];
    f[1] = -p[0] * x[0] - p[1] * x[1] + u[0] + u[1] * x[0] + (region == 0 ? 1.0 : 0.0);
  }
};

// Central differences of the active-set path's x(T) (Newton to 1e-13) on x0, u, p agree with the
// IFT sensitivity to 1e-6 (measured: below 1e-9); the homotopy path's IFT (at its polished
// solution) agrees with the active-set path's.
TEST(IftFiniteDifferences, SmoothModel) {
  fesd::Pss model = fesd::make_pss(
      Forced{},
      fesd::PssDims{.n_x = 2, .n_u = 2, .n_p = 2, .subsystems = {fesd::Subsystem::from_c(1)}});
  Eigen::VectorXd x0(2), u(2), p(2);
  x0 << 0.5, -0.2;
  u << 0.3, 0.1;
  p << 2.0, 0.4;
  const double T = 2.0;
  const int N_sim = 20;
  const IntegratorOptions o = options(RkScheme::RadauIIA, 2, StepSolver::ActiveSet);
  const IntegratorResult r = fesd::integrate(model, x0, T, N_sim, o, u, p);
  expect_available(r);
  ASSERT_TRUE(r.switches.empty());
  IntegratorOptions plain = o;
  plain.sensitivities = false;
  const double eps = 1e-5;
  const auto xT = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                      const Eigen::VectorXd& c) {
    const IntegratorResult q = fesd::integrate(model, a, T, N_sim, plain, b, c);
    EXPECT_EQ(q.status, fesd::Status::Success);
    EXPECT_FALSE(q.sensitivities.requested);
    return q.x_final();
  };
  double err = 0;
  for (int which = 0; which < 3; ++which)
    for (int j = 0; j < 2; ++j) {
      Eigen::VectorXd ap = x0, am = x0, bp = u, bm = u, cp = p, cm = p;
      Eigen::VectorXd& plus = which == 0 ? ap : which == 1 ? bp : cp;
      Eigen::VectorXd& minus = which == 0 ? am : which == 1 ? bm : cm;
      plus[j] += eps;
      minus[j] -= eps;
      const Eigen::VectorXd fd = (xT(ap, bp, cp) - xT(am, bm, cm)) / (2 * eps);
      const Eigen::MatrixXd& ift = which == 0   ? r.sensitivities.x0
                                   : which == 1 ? r.sensitivities.u
                                                : r.sensitivities.p;
      err = std::max(err, (fd - ift.col(j)).lpNorm<Eigen::Infinity>());
    }
  EXPECT_LT(err, 1e-6);
  RecordProperty("fd_error", fmt::format("{:.3e}", err));

  IntegratorOptions h = o;
  h.step_solver = StepSolver::Homotopy;
  const IntegratorResult rh = fesd::integrate(model, x0, T, N_sim, h, u, p);
  expect_available(rh);
  EXPECT_LT((rh.sensitivities.x0 - r.sensitivities.x0).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_LT((rh.sensitivities.u - r.sensitivities.u).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_LT((rh.sensitivities.p - r.sensitivities.p).lpNorm<Eigen::Infinity>(), 1e-8);
}

// Outside Thm 19's setting: x1' in -sign(x1), x2' in -sign(x2) from (1, 1) reach both surfaces at
// t = 1 at once (two regions enter in one switch, co-dimension 2). The step from 6/7 has no regular
// square system at its final active set: not available, with the step named, on both paths;
// the simulation itself succeeds.
TEST(IftNotAvailable, TwoSimultaneousEntries) {
  const std::string text = R"(
[model]
x = ["x1", "x2"]
x0 = [1, 1]
[[model.subsystem]]
c = ["x1"]
F = [["-1", "0"], ["1", "0"]]
[[model.subsystem]]
g = ["-x2", "x2"]
F = [["0", "-1"], ["0", "1"]]
[simulation]
T_sim = 3.0
N_sim = 7
sensitivities = true
[discretization]
rk_scheme = "radau_iia"
n_s = 2
N_finite_elements = 2
)";
  fesd::SimulationProblem q = fesd::parse_simulation_problem(text, "product.toml");
  ASSERT_TRUE(q.options.sensitivities);
  for (StepSolver solver : {StepSolver::ActiveSet, StepSolver::Homotopy}) {
    q.options.step_solver = solver;
    const IntegratorResult r = fesd::integrate(q.model, q.x0, q.T_sim, q.N_sim, q.options);
    ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
    EXPECT_TRUE(r.sensitivities.requested);
    EXPECT_FALSE(r.sensitivities.available);
    EXPECT_NE(r.sensitivities.message.find("the step from t = 0.857143"), std::string::npos)
        << r.sensitivities.message;
    EXPECT_EQ(r.sensitivities.x0.size(), 0);
    EXPECT_NE(r.full_report().find("sensitivities        not available"), std::string::npos);
  }
}

// Not requested: nothing computed, nothing reported.
TEST(IftOff, NotRequested) {
  IntegratorOptions o = options(RkScheme::RadauIIA, 2, StepSolver::ActiveSet);
  o.sensitivities = false;
  const IntegratorResult r = fesd::integrate(crossing_model(), vec1(-1.0), 2.0, 10, o);
  ASSERT_EQ(r.status, fesd::Status::Success);
  EXPECT_FALSE(r.sensitivities.requested);
  EXPECT_FALSE(r.sensitivities.available);
  EXPECT_EQ(r.full_report().find("sensitivities"), std::string::npos);
}

}  // namespace
