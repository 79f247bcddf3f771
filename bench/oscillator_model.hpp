// bench/oscillator_model.hpp: the nonsmooth oscillator, eq. (47) of papers/fesd-filippov.txt
// (Sect. 4.4, Fig. 8), as a C++ model. Shared by bench/fig8_accuracy.cpp,
// bench/oscillator_timing.cpp and tests/acceptance/convergence_order_test.cpp.
//
//   x' = A1 x  inside the unit circle  (c(x) < 0),   A1 = [[1,  w], [-w, 1]]
//   x' = A2 x  outside                 (c(x) > 0),   A2 = [[1, -w], [ w, 1]]
//   c(x) = x1^2 + x2^2 - 1,   w = 2 pi,   x(0) = (e^-1, 0),   T = pi / 2.
//
// Exact solution (REFERENCE.md): x(t) = e^(t-1) (cos 2 pi t, -sin 2 pi t) until the crossing at
// t_s = 1 in x = (1, 0), then x(t) = e^(t-1) (cos 2 pi (t-1), sin 2 pi (t-1)).
//
// One switching function, default sign matrix S = [[1], [-1]]: region 0 is c > 0 (outside, A2 x),
// region 1 is c < 0 (inside, A1 x).
#pragma once
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include <Eigen/Dense>

#include <fesd/integrator.hpp>
#include <fesd/model.hpp>

namespace fesd_bench {

struct Oscillator {
  double omega = 2.0 * std::numbers::pi;

  template <class T>
  void c(const T* x, const T*, T* c_out) const {
    c_out[0] = x[0] * x[0] + x[1] * x[1] - 1.0;
  }
  template <class T>
  void f(int region, const T* x, const T*, const T*, T* f_out) const {
    // region 0: outside, A2 x; region 1: inside, A1 x. Only the sign of w differs.
    const double w = region == 0 ? -omega : omega;
    f_out[0] = x[0] + w * x[1];
    f_out[1] = -w * x[0] + x[1];
  }
};

inline fesd::Pss oscillator_model() {
  fesd::Pss m = fesd::make_pss(Oscillator{},
                               fesd::PssDims{.n_x = 2, .subsystems = {fesd::Subsystem::from_c(1)}});
  m.state_names = {"x1", "x2"};
  return m;
}

inline constexpr double kOscillatorT = std::numbers::pi / 2.0;  // T = pi / 2
inline constexpr double kOscillatorSwitch = 1.0;                // exact t_s

inline Eigen::VectorXd oscillator_x0() {
  Eigen::VectorXd x0(2);
  x0 << std::exp(-1.0), 0.0;
  return x0;
}

/// x(T) of (47) as printed (REFERENCE.md).
inline Eigen::VectorXd oscillator_exact_xT() {
  Eigen::VectorXd x(2);
  x << -1.5974603774506984, -0.7614936206060108;
  return x;
}

/// The errors of one run against the exact solution.
struct OscillatorErrors {
  double x_T = std::numeric_limits<double>::quiet_NaN();  ///< ||x(T) - x_exact||_2
  /// |t_s - 1| for the detected switch nearest to t = 1; empty if the run detected none (e.g. a
  /// trajectory damped so much that it never reaches the circle).
  std::optional<double> t_s;
  int n_switches = 0;  ///< number of detected active-set changes (1 expected)
};

inline OscillatorErrors oscillator_errors(const fesd::IntegratorResult& r) {
  OscillatorErrors e;
  if (!r.x.empty()) e.x_T = (r.x_final() - oscillator_exact_xT()).norm();
  e.n_switches = static_cast<int>(r.switches.size());
  for (const fesd::SwitchEvent& s : r.switches) {
    const double d = std::abs(s.t - kOscillatorSwitch);
    if (!e.t_s || d < *e.t_s) e.t_s = d;
  }
  return e;
}

}  // namespace fesd_bench
