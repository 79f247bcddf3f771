// tests/acceptance/convergence_order_test.cpp: a reduced Fig. 8 of papers/fesd-filippov.txt
// (Sect. 4.4). The nonsmooth oscillator (47) is integrated with Radau IIA n_s = 2 (classical order
// 3) and N_FE = 2 at N_sim = 16, 32, 64, by FESD and by the standard time-stepping method. FESD
// must recover the classical order in x(T) and in the switching time t_s (Theorem 17); the standard
// method places the switch on its fixed grid and is at best first order.
//
// The full sweep over all schemes is bench/fig8_accuracy.cpp; its measured numbers are in
// docs/benchmarks.md. No timing is asserted here.
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <fesd/integrator.hpp>
#include <fesd/options.hpp>

#include "../../bench/oscillator_model.hpp"

namespace {

// N_sim = 16, 32, 64. Why these: below N_sim = 16 the error of Radau IIA n_s = 2 is above the
// fit window (E = 0.42 at N_sim = 8, 0.16 at 11: an O(1) error says nothing about the order); at
// 64 it is still ~1e-3, far above round-off, so all three points measure the order; doubling N_sim
// gives the widest h range for the cost. 112 steps per method: ~8 s per TEST in a Release build on
// an idle 2-core machine (measured: ctest -R ConvergenceOrder, 15.6 s for both).
const std::vector<int> kN = {16, 32, 64};
constexpr int kOrder = 3;  // Radau IIA, n_s = 2: 2 n_s - 1

struct Point {
  int N_sim = 0;
  double h = 0;
  fesd::IntegratorResult result;
  fesd_bench::OscillatorErrors err;
};

std::vector<Point> sweep(bool use_fesd, fesd::RkScheme scheme = fesd::RkScheme::RadauIIA,
                         int n_s = 2, const std::vector<int>& Ns = kN) {
  fesd::IntegratorOptions opt;
  opt.discretization.rk_scheme = scheme;
  opt.discretization.n_s = n_s;
  opt.discretization.N_FE = 2;  // as in the paper
  opt.discretization.use_fesd = use_fesd;
  // The peer figures' settings (REFERENCE.md): IPOPT tol = complementarity_tol = 1e-12. sigma_N
  // one decade lower so that the last relaxed NLP can meet complementarity_tol = 1e-12 with room
  // to spare. IPOPT's tol is 1e-12 by default.
  opt.homotopy.complementarity_tol = 1e-12;
  opt.homotopy.sigma_N = 1e-13;
  const fesd::Pss model = fesd_bench::oscillator_model();
  std::vector<Point> pts;
  for (int N : Ns) {
    Point p;
    p.N_sim = N;
    p.h = fesd_bench::kOscillatorT / N;
    p.result =
        fesd::integrate(model, fesd_bench::oscillator_x0(), fesd_bench::kOscillatorT, N, opt);
    p.err = fesd_bench::oscillator_errors(p.result);
    std::printf(
        "  %s %s n_s = %d, N_sim = %2d: E(T) = %.3e, |t_s - 1| = %.3e, %d switch(es), "
        "%.2f s\n",
        use_fesd ? "FESD    " : "standard", std::string(to_string(scheme)).c_str(), n_s, N,
        p.err.x_T, p.err.t_s ? *p.err.t_s : -1.0, p.err.n_switches, p.result.summary.wall_s);
    pts.push_back(std::move(p));
  }
  return pts;
}

/// The runs are shared by all tests of this file and computed once.
const std::vector<Point>& runs(bool use_fesd) {
  static std::map<bool, std::vector<Point>> cache;
  auto it = cache.find(use_fesd);
  if (it == cache.end()) it = cache.emplace(use_fesd, sweep(use_fesd)).first;
  return it->second;
}

/// Least-squares slope of log y against log h.
double fitted_slope(const std::vector<std::pair<double, double>>& h_y) {
  double mx = 0, my = 0;
  for (const auto& [h, y] : h_y) {
    mx += std::log(h);
    my += std::log(y);
  }
  const double n = static_cast<double>(h_y.size());
  mx /= n;
  my /= n;
  double sxy = 0, sxx = 0;
  for (const auto& [h, y] : h_y) {
    sxy += (std::log(h) - mx) * (std::log(y) - my);
    sxx += (std::log(h) - mx) * (std::log(h) - mx);
  }
  return sxy / sxx;
}

// One TEST per method: ctest runs every TEST in its own process, so splitting the assertions over
// several TESTs would repeat the integrations.
TEST(ConvergenceOrder, FesdRadau2RecoversOrderThreeInXAndSwitchTime) {
  std::vector<std::pair<double, double>> h_x, h_ts;
  for (const Point& p : runs(true)) {
    SCOPED_TRACE(::testing::Message() << "N_sim = " << p.N_sim);
    ASSERT_EQ(p.result.status, fesd::Status::Success) << p.result.message;
    EXPECT_EQ(p.err.n_switches, 1);  // (47) has exactly one crossing
    ASSERT_TRUE(p.err.t_s.has_value()) << "no switch detected";
    // Every point must lie in the asymptotic range and far above round-off, else the fit would
    // measure pre-asymptotics (E >= 1e-1) or IPOPT's tolerance 1e-12 (E <= 1e-10), not the order.
    EXPECT_GT(p.err.x_T, 1e-10);
    EXPECT_LT(p.err.x_T, 1e-1);
    EXPECT_GT(*p.err.t_s, 1e-11);
    h_x.emplace_back(p.h, p.err.x_T);
    h_ts.emplace_back(p.h, *p.err.t_s);
  }
  const double slope_x = fitted_slope(h_x);
  const double slope_ts = fitted_slope(h_ts);
  RecordProperty("fesd_x_slope", std::to_string(slope_x));
  RecordProperty("fesd_t_s_slope", std::to_string(slope_ts));
  std::printf("  FESD fitted slopes: x(T) %.2f, t_s %.2f (classical order %d)\n", slope_x, slope_ts,
              kOrder);
  // The acceptance rule of Fig. 8: the fitted slope within 0.3 of the classical order. The local
  // slopes measured between N_sim = 16 and 64 range 2.8 .. 3.25 (bench/fig8_accuracy), so 0.3
  // covers the pre-asymptotic wobble without admitting order 2 or 4.
  EXPECT_NEAR(slope_x, kOrder, 0.3);
  // Theorem 17, (46): |t_s - t_s_hat| = O(h^p) with the same p as x. At least order - 0.3 (the
  // same allowance as for x(T)); converging faster is not a failure.
  EXPECT_GE(slope_ts, kOrder - 0.3);
}

TEST(ConvergenceOrder, StandardRadau2IsLockedToItsGridAndFirstOrder) {
  std::vector<std::pair<double, double>> h_x, h_ts;
  for (const Point& p : runs(false)) {
    SCOPED_TRACE(::testing::Message() << "N_sim = " << p.N_sim);
    ASSERT_EQ(p.result.status, fesd::Status::Success) << p.result.message;
    ASSERT_TRUE(p.err.t_s.has_value()) << "no switch detected";
    // The standard method has fixed h_n = h / N_FE, so an active-set change can only happen on that
    // grid: the reason it cannot be better than first order. Tolerance 1e-9 (relative to the
    // element length): grid times are sums of equal h_n, exact up to a few ulps.
    const double h_fe = p.h / 2;
    for (const fesd::SwitchEvent& s : p.result.switches)
      EXPECT_NEAR(s.t / h_fe, std::round(s.t / h_fe), 1e-9) << "switch at t = " << s.t;
    h_x.emplace_back(p.h, p.err.x_T);
    h_ts.emplace_back(p.h, *p.err.t_s);
  }
  const double slope_x = fitted_slope(h_x);
  const double slope_ts = fitted_slope(h_ts);
  RecordProperty("standard_x_slope", std::to_string(slope_x));
  RecordProperty("standard_t_s_slope", std::to_string(slope_ts));
  std::printf("  standard fitted slopes: x(T) %.2f, t_s %.2f\n", slope_x, slope_ts);
  // Order <= 1, tested as fitted slope < 1.5 (halfway to 2, far from the classical 3). Caveat, on
  // purpose not hidden: the standard method's errors depend on where t = 1 falls inside an element
  // and are not monotone in h (E = 0.41, 7.0e-3, 7.2e-2 at N_sim = 16, 32, 64; |t_s - 1| is the
  // distance of t = 1 to the grid, 1.8e-2, 6.3e-3, 6.0e-3). A fit through three points of such a
  // scatter measures the envelope only roughly: with N_sim = 8, 16, 32 the same fit gives 3.2 for
  // x(T), and this assertion would fail. The N_sim here are the FESD ones; the grid assertion
  // above is the robust one. The full scatter over seven N_sim per scheme is in
  // bench/fig8_accuracy and docs/benchmarks.md.
  EXPECT_LT(slope_x, 1.5);
  EXPECT_LT(slope_ts, 1.5);
}

// Schemes of low stage order (Sect. "Stage sign" in docs/formulation.md): with the paper's (32)
// their stage *states* leave the region of the element's vector field next to the switch and the
// FESD system has no solution; with stage_lambda_sign = auto (lambda >= 0 only at element
// boundaries for these schemes) they reach their orders.
//
// Lobatto IIIC n_s = 3, classical order 4, at N_sim = 16, 23, 32: E = 1.8e-3, 4.4e-4, 1.1e-4
// (bench/fig8_accuracy, local slopes 3.8, 4.1), all inside the fit window; ~6 s.
TEST(ConvergenceOrder, FesdLobattoIIIC3RecoversOrderFour) {
  std::vector<std::pair<double, double>> h_x, h_ts;
  for (const Point& p : sweep(true, fesd::RkScheme::LobattoIIIC, 3, {16, 23, 32})) {
    SCOPED_TRACE(::testing::Message() << "N_sim = " << p.N_sim);
    ASSERT_EQ(p.result.status, fesd::Status::Success) << p.result.message;
    EXPECT_EQ(p.err.n_switches, 1);
    ASSERT_TRUE(p.err.t_s.has_value()) << "no switch detected";
    EXPECT_GT(p.err.x_T, 1e-10);
    EXPECT_LT(p.err.x_T, 1e-1);
    h_x.emplace_back(p.h, p.err.x_T);
    h_ts.emplace_back(p.h, *p.err.t_s);
  }
  const double slope_x = fitted_slope(h_x), slope_ts = fitted_slope(h_ts);
  std::printf("  FESD Lobatto IIIC 3 fitted slopes: x(T) %.2f, t_s %.2f (classical order 4)\n",
              slope_x, slope_ts);
  EXPECT_NEAR(slope_x, 4, 0.3);
  EXPECT_GE(slope_ts, 4 - 0.3);
}

// Explicit RK n_s = 2 (Heun), classical order 2, at N_sim = 32, 64: E = 0.30, 0.069. Heun's error
// constant on (47) is large (omega = 2 pi), so N_sim = 32 is just above the bench's fit window
// (its local slopes from 32 to 256 are 2.2, 2.1, 2.1, 2.0, 2.0); two points keep the test at ~6 s.
// Before stage_lambda_sign = boundary every run failed (Infeasible_Problem_Detected one or two
// steps before the switch).
TEST(ConvergenceOrder, FesdHeunRecoversOrderTwo) {
  std::vector<std::pair<double, double>> h_x, h_ts;
  for (const Point& p : sweep(true, fesd::RkScheme::ExplicitRK, 2, {32, 64})) {
    SCOPED_TRACE(::testing::Message() << "N_sim = " << p.N_sim);
    ASSERT_EQ(p.result.status, fesd::Status::Success) << p.result.message;
    EXPECT_EQ(p.err.n_switches, 1);
    ASSERT_TRUE(p.err.t_s.has_value()) << "no switch detected";
    h_x.emplace_back(p.h, p.err.x_T);
    h_ts.emplace_back(p.h, *p.err.t_s);
  }
  const double slope_x = fitted_slope(h_x), slope_ts = fitted_slope(h_ts);
  std::printf("  FESD Heun fitted slopes: x(T) %.2f, t_s %.2f (classical order 2)\n", slope_x,
              slope_ts);
  EXPECT_NEAR(slope_x, 2, 0.3);
  EXPECT_GE(slope_ts, 2 - 0.3);
}

}  // namespace
