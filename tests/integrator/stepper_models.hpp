// tests/integrator/stepper_models.hpp: small C++ models of the Stepper tests
// (tests/integrator/stepper_test.cpp, stepper_allocation.cpp).
#pragma once
#include <Eigen/Dense>

#include "fesd/model.hpp"

namespace fesd_test {

/// Entering and leaving a sliding mode (Example 3(c) with time as a state): x1' in -sign(x1) + x2,
/// x2' = 1. From x0 = (0.3, -0.5): x1 reaches 0 at t = (3 - sqrt 6.6) / 2 = 0.2155 (x1' = -1.5 +
/// t), slides on x1 = 0 while |x2| < 1 (theta = (1 + x2) / 2), leaves at x2 = 1, i.e. t = 1.5.
/// Region 0: x1 > 0.
struct SlidingExit {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int region, const T* x, const T*, const T*, T* f) const {
    f[0] = (region == 0 ? -1.0 : 1.0) + x[1];
    f[1] = T(1.0);
  }
};

inline fesd::Pss sliding_exit_model() {
  return fesd::make_pss(SlidingExit{},
                        fesd::PssDims{.n_x = 2, .subsystems = {fesd::Subsystem::from_c(1)}});
}

inline Eigen::VectorXd sliding_exit_x0() {
  return Eigen::Vector2d(0.3, -0.5);
}

/// A relay with a control and a parameter: x1' in u - p sign(x1) + x2, x2' = -x1 (region 0:
/// x1 > 0). With p = 1.5 and u = 0 it switches periodically between crossing and sliding.
struct ControlledRelay {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int region, const T* x, const T* u, const T* p, T* f) const {
    f[0] = u[0] - (region == 0 ? 1.0 : -1.0) * p[0] + x[1];
    f[1] = -x[0];
  }
};

inline fesd::Pss controlled_relay_model() {
  fesd::Pss m = fesd::make_pss(
      ControlledRelay{},
      fesd::PssDims{.n_x = 2, .n_u = 1, .n_p = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
  m.p_default = Eigen::VectorXd::Constant(1, 1.5);
  return m;
}

}  // namespace fesd_test
