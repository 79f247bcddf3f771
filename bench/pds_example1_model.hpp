// Example 1 of papers/fesd-pds.txt (REFERENCE.md), shared by tests/pds and bench/pds_example1.cpp:
// f(x) = (x2, -x1) (circles), C = {x : x2 + 1 >= 0}, x0 = (sqrt 2, sqrt 2). Contact with x2 = -1
// at 5 pi/12, sliding to (0, -1), leaving at 5 pi/12 + sqrt 3, x(T) = (-1, 0) at
// T = 11 pi/12 + sqrt 3.
#pragma once
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

#include "fesd/pds.hpp"

namespace pds_example1 {

struct Model {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[1] + 1.0;
  }
  template <class T>
  void f(const T* x, const T*, const T*, T* f) const {
    f[0] = x[1];
    f[1] = -x[0];
  }
};

inline fesd::Pds model() {
  return fesd::make_pds(Model{}, fesd::PdsDims{.n_x = 2, .n_c = 1});
}
inline const double kT = 11 * std::numbers::pi / 12 + std::sqrt(3.0);
inline const double kContact = 5 * std::numbers::pi / 12;
inline const double kLeave = 5 * std::numbers::pi / 12 + std::sqrt(3.0);
inline Eigen::VectorXd x0() {
  return Eigen::Vector2d(std::sqrt(2.0), std::sqrt(2.0));
}
inline Eigen::VectorXd x_T() {
  return Eigen::Vector2d(-1.0, 0.0);
}

}  // namespace pds_example1
