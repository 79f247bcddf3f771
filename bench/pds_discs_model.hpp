// The collaborative manipulation OCP of papers/fesd-pds.txt Sect. IV-B (issue 16, item 3b;
// docs/pds.md "Optimal control"), shared by tests/pds/pds_ocp_test.cpp and bench/pds_discs.cpp
// (examples/ocp_pds_discs.toml is the same problem as a file). Two actuator discs x1, x2 in R^2
// (radius R1 = R2 = 1, velocity controls u1, u2 in R^2) push an unactuated disc x3 (R3 = 2):
//
//   f(x, u) = (u1, u2, 0, 0),  c_j(x) = ||x3 - x_j||^2 - (R3 + R_j)^2 >= 0  (j = 1, 2),
//   min int_0^5 u' R u dt + (x(5) - x_T)' Q_T (x(5) - x_T),  R = 1e-4 I (u in R^4),
//   Q_T = diag(1, 1, 1, 1, 1e3, 1e3),  x_T = (-10, 0, 10, 0, 0, 10),
//   x(0) = (-10, 10, 5, -5, 0, 0),  |u_i| <= 10,  x_{1,1} <= -2.5,  x_{2,1} >= 2.5.
#pragma once
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "fesd/ocp.hpp"
#include "fesd/pds.hpp"

namespace pds_discs {

inline constexpr double kR1 = 1, kR2 = 1, kR3 = 2, kT = 5;

struct Model {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    const double R[2] = {kR1, kR2};
    for (int j = 0; j < 2; ++j) {
      const T dx = x[4] - x[2 * j], dy = x[5] - x[2 * j + 1];
      c[j] = dx * dx + dy * dy - (kR3 + R[j]) * (kR3 + R[j]);
    }
  }
  template <class T>
  void f(const T*, const T* u, const T*, T* f) const {
    for (int i = 0; i < 4; ++i) f[i] = u[i];
    f[4] = T(0.0);
    f[5] = T(0.0);
  }
};

inline const std::array<double, 6> kXT{-10, 0, 10, 0, 0, 10};
inline const std::array<double, 6> kQT{1, 1, 1, 1, 1e3, 1e3};

struct Cost {
  template <class T>
  T f_q(const T*, const T* u, const T*) const {
    T s(0.0);
    for (int i = 0; i < 4; ++i) s = s + 1e-4 * u[i] * u[i];
    return s;
  }
  template <class T>
  T f_q_T(const T* x, const T*) const {
    T s(0.0);
    for (int i = 0; i < 6; ++i) s = s + kQT[i] * (x[i] - kXT[i]) * (x[i] - kXT[i]);
    return s;
  }
};

inline Eigen::VectorXd x0() {
  Eigen::VectorXd x(6);
  x << -10, 10, 5, -5, 0, 0;
  return x;
}

/// The OCP with N_stages control intervals (N_FE per interval from the options).
inline fesd::PdsOcp ocp(int N_stages) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  fesd::PdsOcp o;
  o.model = fesd::make_pds(Model{}, fesd::PdsDims{.n_x = 6, .n_u = 4, .n_c = 2});
  o.functions = fesd::make_ocp_functions(Cost{});
  o.T = kT;
  o.N_stages = N_stages;
  o.x0 = x0();
  o.lbu = Eigen::VectorXd::Constant(4, -10.0);
  o.ubu = Eigen::VectorXd::Constant(4, 10.0);
  o.lbx = Eigen::VectorXd::Constant(6, -inf);
  o.ubx = Eigen::VectorXd::Constant(6, inf);
  o.ubx[0] = -2.5;  // x_{1,1} <= -2.5
  o.lbx[2] = 2.5;   // x_{2,1} >= 2.5
  return o;
}

/// The smallest distance between the rims of an actuator and the big disc at x (< 0: overlap).
inline double min_gap(const Eigen::VectorXd& x) {
  const double R[2] = {kR1, kR2};
  double g = std::numeric_limits<double>::infinity();
  for (int j = 0; j < 2; ++j)
    g = std::min(g, std::hypot(x[4] - x[2 * j], x[5] - x[2 * j + 1]) - (kR3 + R[j]));
  return g;
}

}  // namespace pds_discs
