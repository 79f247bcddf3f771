// src/dcs/step.hpp: the Heaviside step form of a Pss with c-form subsystems (nosnoc's
// DcsMode.Step; docs/formulation.md, "Heaviside step form"):
//
//   x' = sum_i theta_i(alpha) f_i(x, u, p),  theta_i(alpha) = prod_j (S_ij = +1 ? alpha_j : 1 -
//   alpha_j), c(x) - lambda_p + lambda_n = 0,  0 <= lambda_n perp alpha >= 0,  0 <= lambda_p perp 1
//   - alpha >= 0.
//
// The discretization writes the complementarity with beta = 1 - alpha as variables of their own,
// so that both pairs are products of two variables: per stage the comp vector (alpha, beta) of
// length 2 n_c pairs index by index with the multipliers (lambda_n, lambda_p).
#pragma once
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "dcs/stewart.hpp"
#include "fesd/model.hpp"
#include "fesd/options.hpp"

namespace fesd::dcs {

/// Multipliers at one point: Stewart lambda (n_theta), step (lambda_n, lambda_p) (2 n_c).
inline int n_lambda(const Pss& m, DcsMode mode) {
  return mode == DcsMode::Step ? 2 * m.n_c() : m.n_theta();
}
/// mu at one point: Stewart n_sys, step none.
inline int n_mu(const Pss& m, DcsMode mode) {
  return mode == DcsMode::Step ? 0 : m.n_sys();
}

/// theta(alpha) of every region (length n_theta) from alpha (length n_c, all subsystems).
template <class T>
void eval_theta_of_alpha(const Pss& m, const T* alpha, T* theta) {
  int c_off = 0;
  for (int k = 0; k < m.n_sys(); ++k) {
    const Subsystem& s = m.dims().subsystems[k];
    const int r0 = m.region_offset(k), n_f = m.region_offset(k + 1) - r0;
    const Eigen::MatrixXd& S = m.S(k);
    for (int i = 0; i < n_f; ++i) {
      T t(1.0);
      for (int j = 0; j < s.n_c; ++j)
        t = t * (S(i, j) > 0 ? alpha[c_off + j] : T(1.0) - alpha[c_off + j]);
      theta[r0 + i] = t;
    }
    c_off += s.n_c;
  }
}

/// The step form's analogue of Stewart's lambda_r for region r (0 exactly where x is in the
/// closure of region r): sum_j (S_rj = +1 ? lambda_n_j : lambda_p_j). `mult` is (lambda_n,
/// lambda_p), length 2 n_c. Used for active sets and reported as the result's lambda.
inline double region_multiplier(const Pss& m, const std::vector<int>& owner, int r,
                                const double* mult) {
  const int k = owner[r];
  int c_off = 0;
  for (int j = 0; j < k; ++j) c_off += m.dims().subsystems[j].n_c;
  const Eigen::MatrixXd& S = m.S(k);
  const int i = r - m.region_offset(k), n_c = m.n_c();
  double l = 0;
  for (int j = 0; j < m.dims().subsystems[k].n_c; ++j)
    l += S(i, j) > 0 ? mult[c_off + j] : mult[n_c + c_off + j];
  return l;
}

/// The step form's solution at a given x (an LpSolution with alpha): alpha_j = 1 where c_j > 0,
/// 0 where c_j < 0, 1/2 on c_j = 0 (|c_j| <= tie_tol); lambda = (lambda_n, lambda_p) =
/// (max(-c, 0), max(c, 0)); theta = theta(alpha); mu empty; g = c.
LpSolution solve_step(const Pss& m, const Eigen::VectorXd& x, const Eigen::VectorXd& p,
                      double tie_tol = 1e-12);
/// solve_lp or solve_step by mode: the multipliers at a given x.
LpSolution solve_start(const Pss& m, DcsMode mode, const Eigen::VectorXd& x,
                       const Eigen::VectorXd& p);
/// The rule of the step form for a model: empty if every subsystem is c-form, else the message.
std::string step_mode_error(const Pss& m);

}  // namespace fesd::dcs
