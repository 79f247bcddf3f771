// Bad input to the C++ API: an exception naming the problem, before any computation. Numerical
// failure (an NLP that does not converge, a model returning NaN): a status and message, no throw.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/model.hpp"

namespace {

struct Crossing {  // x' in 2 - sign(x)
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int r, const T*, const T*, const T*, T* f) const {
    f[0] = T(r == 0 ? 1.0 : 3.0);
  }
};

struct NaNBelowMinusHalf {  // f is NaN for x < -0.5: every trial step there fails
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int, const T* x, const T*, const T*, T* f) const {
    using std::sqrt;
    f[0] = -1.0 - sqrt(x[0] + 0.5) * 0.0 + sqrt(x[0] + 0.5);
  }
};

fesd::Pss crossing() {
  return fesd::make_pss(Crossing{},
                        fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
}

template <class E>
void expect_throw_with(const std::function<void()>& fn, const std::string& needle) {
  try {
    fn();
    FAIL() << "no exception; expected one mentioning '" << needle << "'";
  } catch (const E& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(IntegratorInput, WrongX0Size) {
  expect_throw_with<fesd::InvalidModel>(
      [] { fesd::integrate(crossing(), Eigen::VectorXd::Zero(2), 1.0, 2); },
      "x0 has 2 entries, expected n_x = 1");
}
TEST(IntegratorInput, NaNInX0) {
  Eigen::VectorXd x0(1);
  x0 << std::numeric_limits<double>::quiet_NaN();
  expect_throw_with<fesd::InvalidModel>([&] { fesd::integrate(crossing(), x0, 1.0, 2); },
                                        "x0[0] = nan");
}
TEST(IntegratorInput, NonPositiveHorizon) {
  expect_throw_with<fesd::InvalidOption>(
      [] { fesd::integrate(crossing(), Eigen::VectorXd::Ones(1), -1.0, 2); }, "T_sim = -1");
}
TEST(IntegratorInput, ZeroSteps) {
  expect_throw_with<fesd::InvalidOption>(
      [] { fesd::integrate(crossing(), Eigen::VectorXd::Ones(1), 1.0, 0); }, "N_sim = 0");
}
TEST(IntegratorInput, OptionsOutOfRangeListsEveryRule) {
  fesd::IntegratorOptions o;
  o.discretization.n_s = 0;
  o.homotopy.homotopy_update_slope = 1.5;
  expect_throw_with<fesd::InvalidOption>(
      [&] { fesd::integrate(crossing(), Eigen::VectorXd::Ones(1), 1.0, 2, o); },
      "discretization.n_s = 0");
  expect_throw_with<fesd::InvalidOption>(
      [&] { fesd::integrate(crossing(), Eigen::VectorXd::Ones(1), 1.0, 2, o); },
      "homotopy.homotopy_update_slope = 1.5");
}
TEST(IntegratorInput, FesdWithOneElement) {
  fesd::IntegratorOptions o;
  o.discretization.N_FE = 1;
  expect_throw_with<fesd::InvalidOption>(
      [&] { fesd::integrate(crossing(), Eigen::VectorXd::Ones(1), 1.0, 2, o); }, "FESD needs >= 2");
}
TEST(IntegratorInput, UnknownIpoptOption) {
  fesd::IntegratorOptions o;
  o.nlp.extra = {{"no_such_option", "1"}};
  expect_throw_with<fesd::InvalidOption>(
      [&] { fesd::integrate(crossing(), Eigen::VectorXd::Ones(1), 1.0, 2, o); },
      "ipopt.no_such_option: not an IPOPT option");
}
TEST(IntegratorInput, SignMatrixNotPlusMinusOne) {
  expect_throw_with<fesd::InvalidModel>(
      [] {
        fesd::make_pss(
            Crossing{},
            fesd::PssDims{.n_x = 1,
                          .subsystems = {fesd::Subsystem::from_c(1, Eigen::MatrixXd{{1}, {0.5}})}});
      },
      "entries must be +1 or -1");
}
TEST(IntegratorInput, RepeatedSignRows) {
  expect_throw_with<fesd::InvalidModel>(
      [] {
        fesd::make_pss(
            Crossing{},
            fesd::PssDims{.n_x = 1,
                          .subsystems = {fesd::Subsystem::from_c(1, Eigen::MatrixXd{{1}, {1}})}});
      },
      "repeats an earlier row");
}

// An NLP that cannot converge (one IPOPT iteration allowed): a status, a message, no exception.
TEST(IntegratorStatus, NlpNotConvergingIsAStatus) {
  fesd::IntegratorOptions o;
  o.step_solver = fesd::StepSolver::Homotopy;  // the active-set path runs no NLP
  o.nlp.max_iter = 1;
  o.homotopy.max_homotopy_steps = 2;
  Eigen::VectorXd x0(1);
  x0 << -1.0;
  const auto r = fesd::integrate(crossing(), x0, 1.0, 3, o);
  EXPECT_EQ(r.status, fesd::Status::NlpFailed);
  EXPECT_NE(r.message.find("Maximum_Iterations_Exceeded"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("step 1 of 3"), std::string::npos) << r.message;
}

// A model that returns NaN where the solver goes: a status, never a crash.
TEST(IntegratorStatus, NonFiniteModelIsAStatus) {
  const fesd::Pss m = fesd::make_pss(
      NaNBelowMinusHalf{}, fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
  Eigen::VectorXd x0(1);
  x0 << 0.0;
  fesd::IntegratorOptions o;
  o.homotopy.max_homotopy_steps = 3;
  const auto r = fesd::integrate(m, x0, 2.0, 2, o);
  EXPECT_NE(r.status, fesd::Status::Success);
  EXPECT_FALSE(r.message.empty());
}

}  // namespace
