// fesd::Stepper (include/fesd/stepper.hpp, docs/active-set.md "Stepping API"): the states of
// integrate() step by step, options checked at creation, bad input thrown, a failed step a status.
// The allocation count is in stepper_allocation.cpp (its own executable: it replaces operator new).
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../../bench/oscillator_model.hpp"
#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/stepper.hpp"
#include "integrator/stepper_models.hpp"

namespace {

using fesd::IntegratorOptions;
using fesd::Status;
using fesd::Stepper;

const Eigen::VectorXd none;  // u, p: zero controls, the model's p_default

/// The states of integrate() at the step ends t = k h, k = 1..N (its grid has every element).
std::vector<Eigen::VectorXd> step_ends(const fesd::IntegratorResult& r, double h, int N) {
  std::vector<Eigen::VectorXd> out;
  for (int k = 1; k <= N; ++k)
    for (std::size_t j = 0; j < r.t.size(); ++j)
      if (std::abs(r.t[j] - k * h) <= 1e-12 * (1 + k * h)) {
        out.push_back(r.x[j]);
        break;
      }
  return out;
}

/// N steps of a Stepper from x0 against integrate() over [0, N h]: every step end to tol.
void expect_same_as_integrate(const fesd::Pss& model, const Eigen::VectorXd& x0, double h, int N,
                              const IntegratorOptions& o, double tol) {
  const fesd::IntegratorResult r = fesd::integrate(model, x0, N * h, N, o);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  const std::vector<Eigen::VectorXd> ends = step_ends(r, h, N);
  ASSERT_EQ(static_cast<int>(ends.size()), N);
  Stepper stepper(model, h, o);
  Eigen::VectorXd x = x0;
  for (int k = 0; k < N; ++k) {
    ASSERT_EQ(stepper.step(x, none, none, x), Status::Success)
        << "step " << k << ": " << stepper.last_step().message;
    EXPECT_LE((x - ends[k]).lpNorm<Eigen::Infinity>(), tol) << "step " << k;
  }
  EXPECT_EQ(stepper.stats().steps, N);
  EXPECT_EQ(stepper.stats().active_set_steps, r.summary.active_set_path_steps);
  EXPECT_EQ(stepper.stats().cold_starts, 1);
}

// The oscillator (47) over [0, pi/2] (one crossing at t = 1), 40 steps, every one on the
// active-set path: the same Newton iterations from the same guesses, so the same states up to the
// round-off of another pivot order in KLU (1e-12).
TEST(Stepper, OscillatorSameAsIntegrate) {
  IntegratorOptions o;
  o.discretization.n_s = 3;
  expect_same_as_integrate(fesd_bench::oscillator_model(), fesd_bench::oscillator_x0(),
                           fesd_bench::kOscillatorT / 40, 40, o, 1e-12);
}

// Entering and leaving a sliding mode (stepper_models.hpp), Radau IIA 2 and Gauss-Legendre 2.
TEST(Stepper, SlidingEntryAndExitSameAsIntegrate) {
  IntegratorOptions o;
  expect_same_as_integrate(fesd_test::sliding_exit_model(), fesd_test::sliding_exit_x0(), 0.1, 25,
                           o, 1e-12);
  o.discretization.rk_scheme = fesd::RkScheme::GaussLegendre;
  o.discretization.N_FE = 3;
  expect_same_as_integrate(fesd_test::sliding_exit_model(), fesd_test::sliding_exit_x0(), 0.1, 25,
                           o, 1e-12);
}

// The exact solution: sliding until x2 = -0.5 + t = 1 (t = 1.5), then x1' = -1 + x2 = t - 1.5, so
// x1(2.5) = 1/2, x2(2.5) = 2. The exit lands on a step boundary, so it is exact up to Newton's
// tolerance.
TEST(Stepper, SlidingExitExact) {
  Stepper stepper(fesd_test::sliding_exit_model(), 0.1);
  Eigen::VectorXd x = fesd_test::sliding_exit_x0();
  for (int k = 0; k < 25; ++k) x = stepper.step(x);
  EXPECT_EQ(stepper.status(), Status::Success) << stepper.last_step().message;
  EXPECT_NEAR(x[0], 0.5, 1e-9);
  EXPECT_NEAR(x[1], 2.0, 1e-12);
}

// Controls and parameters per step: the same as integrate() of each step alone (which starts cold,
// from the LP at x: equal to Newton's tolerance, 1e-10).
TEST(Stepper, ControlsAndParametersPerStep) {
  const fesd::Pss model = fesd_test::controlled_relay_model();
  const double h = 0.05;
  Stepper stepper(model, h);
  Eigen::VectorXd x = Eigen::Vector2d(0.2, 0.0), x_ref = x;
  int switched = 0;
  for (int k = 0; k < 60; ++k) {
    const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, 0.8 * std::sin(0.3 * k));
    const Eigen::VectorXd p = Eigen::VectorXd::Constant(1, 1.0 + 0.01 * k);
    ASSERT_EQ(stepper.step(x, u, p, x), Status::Success) << stepper.last_step().message;
    switched += stepper.last_step().switched ? 1 : 0;
    const fesd::IntegratorResult r = fesd::integrate(model, x_ref, h, 1, {}, u, p);
    ASSERT_EQ(r.status, Status::Success) << r.message;
    x_ref = r.x_final();
    EXPECT_LE((x - x_ref).lpNorm<Eigen::Infinity>(), 1e-10) << "step " << k;
  }
  EXPECT_GT(switched, 0);
}

TEST(Stepper, OptionsCheckedAtCreation) {
  const fesd::Pss model = fesd_bench::oscillator_model();
  const auto message = [&](double h, const IntegratorOptions& o) -> std::string {
    try {
      Stepper s(model, h, o);
    } catch (const fesd::InvalidOption& e) {
      return e.what();
    }
    return "";
  };
  IntegratorOptions o;
  EXPECT_NE(message(0.0, o).find("h = 0"), std::string::npos);
  EXPECT_NE(message(std::numeric_limits<double>::quiet_NaN(), o).find("must be finite"),
            std::string::npos);
  o.discretization.n_s = 0;
  EXPECT_NE(message(0.1, o).find("n_s = 0"), std::string::npos);
  o = {};
  o.discretization.use_fesd = false;
  EXPECT_NE(message(0.1, o).find("use_fesd = false"), std::string::npos);
  o = {};
  o.step_solver = fesd::StepSolver::Homotopy;
  EXPECT_NE(message(0.1, o).find("step_solver = homotopy"), std::string::npos);
  o = {};
  o.sensitivities = true;
  EXPECT_NE(message(0.1, o).find("sensitivities"), std::string::npos);
  o = {};
  o.theta_guess = Eigen::Vector2d(1, 0);
  EXPECT_NE(message(0.1, o).find("theta_guess"), std::string::npos);
  EXPECT_EQ(message(0.1, {}), "");
}

TEST(Stepper, BadInputThrows) {
  Stepper stepper(fesd_bench::oscillator_model(), 0.1);
  Eigen::VectorXd x_next(2);
  EXPECT_THROW(stepper.step(Eigen::VectorXd::Zero(3), none, none, x_next), fesd::InvalidModel);
  EXPECT_THROW(stepper.step(Eigen::VectorXd::Zero(2), Eigen::VectorXd::Zero(1), none, x_next),
               fesd::InvalidModel);
  Eigen::VectorXd x_short(1);
  EXPECT_THROW(stepper.step(Eigen::VectorXd::Zero(2), none, none, x_short), fesd::InvalidModel);
  EXPECT_THROW(stepper.step(Eigen::Vector2d(std::nan(""), 0.0)), fesd::InvalidModel);
  EXPECT_EQ(stepper.stats().steps, 0);
}

// A model whose field is NaN beyond x = 0.5: the step that reaches it fails with a status and a
// message, x_next untouched; no exception, no crash.
struct NanBeyond {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int, const T* x, const T*, const T*, T* f) const {
    f[0] = x[0] > 0.5 ? T(std::numeric_limits<double>::quiet_NaN()) : T(1.0);
  }
};

TEST(Stepper, FailedStepIsAStatus) {
  IntegratorOptions o;
  o.homotopy.max_homotopy_steps = 2;  // the fallback gives up early
  Stepper stepper(
      fesd::make_pss(NanBeyond{},
                     fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}}),
      0.3, o);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 0.1), x_next = Eigen::VectorXd::Constant(1, 7.0);
  const Status s = stepper.step(x, none, none, x_next);  // reaches 0.4: fine
  ASSERT_EQ(s, Status::Success) << stepper.last_step().message;
  x = x_next;
  x_next[0] = 7.0;
  const Status failed = stepper.step(x, none, none, x_next);  // NaN beyond 0.5
  EXPECT_NE(failed, Status::Success);
  EXPECT_EQ(stepper.status(), failed);
  EXPECT_FALSE(stepper.last_step().message.empty());
  EXPECT_EQ(x_next[0], 7.0);
  EXPECT_EQ(stepper.stats().failed_steps, 1);
}

// reset() forgets the warm start: the next step starts cold, as the first.
TEST(Stepper, ResetStartsCold) {
  Stepper stepper(fesd_bench::oscillator_model(), 0.05);
  Eigen::VectorXd x = fesd_bench::oscillator_x0();
  const Eigen::VectorXd x1 = stepper.step(x);
  stepper.step(x1);
  EXPECT_EQ(stepper.stats().cold_starts, 1);
  stepper.reset();
  const Eigen::VectorXd again = stepper.step(x);
  EXPECT_EQ(stepper.stats().cold_starts, 2);
  EXPECT_LE((again - x1).lpNorm<Eigen::Infinity>(), 1e-13);
}

}  // namespace
