// src/discretization/dynamics_eq.hpp: the dynamics rows of one stage as an AD functor,
//
//   c = V - rhs(X, y, q, p),   inputs w = (V (n_x), X (n_x), y (n_y), q (n_u), p (n_p)),
//
// one template for the three right-hand sides: Stewart's sum_r theta_r f_r (y = theta, (25);
// DynamicsEq, dynamics_block.hpp), the step form's general inclusion f_alpha (y = alpha;
// AlphaDynamicsEq, fesd_interval.cpp) and the projected dynamical system's f + grad c lambda
// (y = lambda, (6a) of papers/fesd-pds.txt; PdsDynamicsEq, pds_interval.cpp).
#pragma once
#include <cstddef>
#include <vector>

namespace fesd::discretization {

/// V - rhs(X, y, q, p) = 0. Rhs holds `const Model* m` (n_x, n_u, n_p from it), gives
/// `int n_y() const` and writes its value with `rhs(X, y, q, p, out)`. A Rhs with a second term
/// (f + grad c lambda) writes it with `rhs.second(X, y, q, p, out)`; the rows are then
/// (V - first) - second, in a work space per thread and scalar type (no allocation per call).
template <class Rhs>
struct StageDynamicsEq {
  Rhs rhs;
  int num_inputs() const { return 2 * rhs.m->n_x() + rhs.n_y() + rhs.m->n_u() + rhs.m->n_p(); }
  int num_outputs() const { return rhs.m->n_x(); }
  template <class T>
  void operator()(const T* w, T* c) const {
    const int n_x = rhs.m->n_x();
    const T* V = w;
    const T* X = w + n_x;
    const T* y = X + n_x;
    const T* q = y + rhs.n_y();
    const T* p = q + rhs.m->n_u();
    rhs(X, y, q, p, c);
    for (int i = 0; i < n_x; ++i) c[i] = V[i] - c[i];
    if constexpr (requires { rhs.second(X, y, q, p, c); }) {
      thread_local std::vector<T> g;
      g.resize(static_cast<std::size_t>(n_x));
      rhs.second(X, y, q, p, g.data());
      for (int i = 0; i < n_x; ++i) c[i] = c[i] - g[i];
    }
  }
};

}  // namespace fesd::discretization
