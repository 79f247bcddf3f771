// src/dcs/stewart.hpp: Stewart's dynamic complementarity system (8)/(21) of a Pss,
//
//   x' = sum_k F^k(x, u, p) theta^k,   g^k(x) - lambda^k - mu^k e = 0,   e' theta^k = 1,
//   0 <= theta^k  perp  lambda^k >= 0,
//
// with g^k = -S^k c^k (13) for c-form subsystems. All functions are templates on the scalar type.
#pragma once
#include <algorithm>
#include <vector>

#include <Eigen/Dense>

#include "fesd/model.hpp"

namespace fesd::dcs {

/// g(x) for all subsystems, concatenated (length n_theta); c, gd: work space (no allocation once
/// sized).
template <class T>
void eval_g(const Pss& m, const T* x, const T* p, T* g, std::vector<T>& c, std::vector<T>& gd) {
  c.resize(static_cast<std::size_t>(std::max(m.n_c(), m.n_g())));
  if (m.n_c() > 0) m.functions().c(x, p, c.data());
  int c_off = 0, g_off = 0;
  if (m.n_g() > 0) {
    gd.resize(m.n_g());
    m.functions().g(x, p, gd.data());
  }
  for (int k = 0; k < m.n_sys(); ++k) {
    const Subsystem& s = m.dims().subsystems[k];
    const int r0 = m.region_offset(k), n_f = m.region_offset(k + 1) - r0;
    if (s.n_c > 0) {
      const Eigen::MatrixXd& S = m.S(k);
      for (int i = 0; i < n_f; ++i) {
        T gi(0.0);
        for (int j = 0; j < s.n_c; ++j) gi = gi - S(i, j) * c[c_off + j];  // (13)
        g[r0 + i] = gi;
      }
      c_off += s.n_c;
    } else {
      for (int i = 0; i < n_f; ++i) g[r0 + i] = gd[g_off + i];
      g_off += s.n_g;
    }
  }
}
/// The same with a work space per thread and scalar type (no allocation once sized: the blocks
/// of the active-set path's Newton iterations call it).
template <class T>
void eval_g(const Pss& m, const T* x, const T* p, T* g) {
  thread_local std::vector<T> c, gd;
  eval_g(m, x, p, g, c, gd);
}

/// xdot = sum_r f_r(x, u, p) theta_r over all regions r of all subsystems (8a)/(21a).
/// fr: work space (no allocation once sized).
template <class T>
void eval_F_theta(const Pss& m, const T* x, const T* u, const T* p, const T* theta, T* xdot,
                  std::vector<T>& fr) {
  const int n_x = m.n_x();
  fr.resize(static_cast<std::size_t>(n_x));
  for (int i = 0; i < n_x; ++i) xdot[i] = T(0.0);
  for (int r = 0; r < m.n_theta(); ++r) {
    m.functions().f(r, x, u, p, fr.data());
    for (int i = 0; i < n_x; ++i) xdot[i] = xdot[i] + fr[i] * theta[r];
  }
}
/// The same with a work space per thread and scalar type (as eval_g).
template <class T>
void eval_F_theta(const Pss& m, const T* x, const T* u, const T* p, const T* theta, T* xdot) {
  thread_local std::vector<T> fr;
  eval_F_theta(m, x, u, p, theta, xdot, fr);
}

/// The subsystem each region belongs to.
inline std::vector<int> region_subsystem(const Pss& m) {
  std::vector<int> owner(m.n_theta());
  for (int k = 0; k < m.n_sys(); ++k)
    for (int r = m.region_offset(k); r < m.region_offset(k + 1); ++r) owner[r] = k;
  return owner;
}

/// Solution of LP(x) (7) at a given x: mu^k = min_i g^k_i(x), lambda = g(x) - mu^k e, and
/// theta^k spread equally over the minimizers (one valid choice, e.g. lambda_{0,0}, mu_{0,0}).
struct LpSolution {
  Eigen::VectorXd g, lambda, mu, theta;
  /// The Heaviside step form only (dcs/step.hpp): alpha per switching function (n_c); lambda
  /// then holds (lambda_n, lambda_p) and mu is empty.
  Eigen::VectorXd alpha;
};
LpSolution solve_lp(const Pss& m, const Eigen::VectorXd& x, const Eigen::VectorXd& p,
                    double tie_tol = 1e-12);
/// The same into `s` with the work space c, gd of eval_g (no allocation once sized: the Stepper).
void solve_lp(const Pss& m, const double* x, const double* p, LpSolution& s, std::vector<double>& c,
              std::vector<double>& gd, double tie_tol = 1e-12);

}  // namespace fesd::dcs
