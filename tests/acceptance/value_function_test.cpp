// Fig. 9 (left) of papers/fesd-filippov.txt: V(x0) and V'(x0) of the OCP (56) by simulation
// (bench/value_function.hpp, bench/fig9_value_function.cpp) against the exact values
// (REFERENCE.md: x0* = (9 - sqrt 417) / 8, V* = 1.5237727753749571, V(0) = 25/9).
#include <cmath>

#include <gtest/gtest.h>

#include "../../bench/value_function.hpp"

namespace {

// The closed form itself: V(0) = 25/9, V' = 0 at x0* with V(x0*) = V*.
TEST(ValueFunction, ExactFormulas) {
  EXPECT_NEAR(fesd_bench::exact_value(0.0).V, 25.0 / 9.0, 1e-15);
  const double x_star = (9 - std::sqrt(417.0)) / 8;
  EXPECT_NEAR(fesd_bench::exact_value(x_star).V, 1.5237727753749571, 1e-14);
  EXPECT_NEAR(fesd_bench::exact_value(x_star).dV, 0.0, 1e-14);
  // V' is the derivative of V (central differences, both branches)
  for (double x0 : {-2.5, -0.7, 0.6}) {
    const double d = 1e-6;
    const double fd =
        (fesd_bench::exact_value(x0 + d).V - fesd_bench::exact_value(x0 - d).V) / (2 * d);
    EXPECT_NEAR(fesd_bench::exact_value(x0).dV, fd, 1e-8) << "x0 = " << x0;
  }
}

// FESD, Gauss-Legendre n_s = 2, N_FE = 25 (the paper's grid): x is piecewise linear and x^2 a
// quadratic on each piece, which Gauss-Legendre 2 integrates exactly; FESD puts an element
// boundary on the switch. So V and V' are exact up to Newton's tolerance and the round-off of the
// sums: 1e-10. At x0* V' = 0 (the only local minimizer).
TEST(ValueFunction, FesdMatchesExactVAndDerivative) {
  const fesd::Pss model = fesd_bench::value_model();
  const double x_star = (9 - std::sqrt(417.0)) / 8;
  for (double x0 : {-2.9, -2.0, x_star, -1.0, -0.3, 0.4, 1.0}) {
    const fesd_bench::SimulatedValue v =
        fesd_bench::simulated_value(model, x0, 1, fesd_bench::fig9_options(true));
    const fesd_bench::ExactValue e = fesd_bench::exact_value(x0);
    ASSERT_EQ(v.status, fesd::Status::Success) << v.why;
    EXPECT_NEAR(v.V, e.V, 1e-10) << "x0 = " << x0;
    ASSERT_TRUE(std::isfinite(v.dV)) << "x0 = " << x0 << ": " << v.why;
    EXPECT_NEAR(v.dV, e.dV, 1e-10) << "x0 = " << x0;
  }
}

// The standard method on the same grid: its V' misses the exact one by O(1) somewhere (it lacks
// the switch time's motion: the derivative of x(2) is 1 or 3 instead of 1/3), though its V is
// close. Checked at x0 = -1 (a switch at t = 1/3 inside an element).
TEST(ValueFunction, StandardMethodDerivativeIsWrong) {
  const fesd_bench::SimulatedValue v = fesd_bench::simulated_value(
      fesd_bench::value_model(), -1.0, 1, fesd_bench::fig9_options(false));
  ASSERT_EQ(v.status, fesd::Status::Success) << v.why;
  const fesd_bench::ExactValue e = fesd_bench::exact_value(-1.0);
  EXPECT_NEAR(v.V, e.V, 0.1);
  ASSERT_TRUE(std::isfinite(v.dV)) << v.why;
  EXPECT_GT(std::abs(v.dV - e.dV), 0.1);
}

}  // namespace
