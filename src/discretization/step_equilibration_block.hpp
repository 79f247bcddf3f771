// src/discretization/step_equilibration_block.hpp: the step equilibration term (31) of two
// neighbouring elements, as the AD functor StepEquilibrationEq and as the block FESD builds,
// StepEquilibrationBlock. The term is an outer function G of R + 1 inner values,
//
//   c = G(u),  u_0 = h_n - h_{n-1},  u_{1+r} = P_r = S^{lambda,B}_r S^{lambda,F}_r
//                                                    + S^{theta,B}_r S^{theta,F}_r,
//   G(u) = u_0 prod_r u_{1+r}  (or u_0 tanh(prod), or tanh(prod) (u_0 / h_scale)^2),
//
// with S the sums of the index lists and R = n_theta. u(w) is linear (u_0) or bilinear (P_r), so
//
//   Hessian of y c = J_u' (y d2G/du2) J_u + sum_r y dG/dP_r d2P_r/dw2,
//
// where d2P_r/dw2 is a 0/1 pattern and d2G/du2 is R + 1 dense: a few small AD passes over u
// instead of passes over all 2 + 4 n_theta inputs of w through the whole product
// (docs/derivatives.md). Values, Jacobian and pattern are AutoDiffBlock<StepEquilibrationEq>'s;
// the Hessian agrees with it to round-off (tests/nlp/hessian_passes_test.cpp).
#pragma once
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "nlp/block.hpp"

namespace fesd::discretization {

/// Step equilibration (31): (h_n - h_{n-1}) * eta_n (or tanh(eta_n)), with
///   eta_n = prod_r ( sigma^{lambda,B}_r sigma^{lambda,F}_r + sigma^{theta,B}_r sigma^{theta,F}_r
///   ).
/// Index lists are local positions of the summed lambdas/thetas per region r.
struct StepEquilibrationEq {
  int k = 0;
  int h_prev = 0, h_cur = 1;
  std::vector<std::vector<int>> lam_B, lam_F, th_B, th_F;  // per region
  bool use_tanh = false;
  /// L2Relaxed: the objective term tanh(eta_n) ((h_n - h_{n-1}) / h_scale)^2 instead of the row.
  bool penalty = false;
  double h_scale = 1.0;
  int num_inputs() const { return k; }
  int num_outputs() const { return 1; }
  template <class T>
  static T sum(const T* w, const std::vector<int>& idx) {
    T s(0.0);
    for (int i : idx) s = s + w[i];
    return s;
  }
  /// P_r of region r.
  template <class T>
  T region(const T* w, std::size_t r) const {
    return sum(w, lam_B[r]) * sum(w, lam_F[r]) + sum(w, th_B[r]) * sum(w, th_F[r]);
  }
  /// c from h_n - h_{n-1} and eta_n.
  template <class T>
  T combine(const T& delta, const T& eta) const {
    using std::tanh;
    if (penalty) {
      const T d = delta / h_scale;
      return tanh(eta) * d * d;
    }
    return delta * (use_tanh ? tanh(eta) : eta);
  }
  /// G(u): u[0] = h_n - h_{n-1}, u[1 + r] = P_r.
  template <class T>
  T outer(const T* u) const {
    T e(1.0);
    for (std::size_t r = 0; r < lam_B.size(); ++r) e = e * u[1 + r];
    return combine(u[0], e);
  }
  template <class T>
  void operator()(const T* w, T* c) const {
    T e(1.0);
    for (std::size_t r = 0; r < lam_B.size(); ++r) e = e * region(w, r);
    c[0] = combine(T(w[h_cur] - w[h_prev]), e);
  }
};

/// StepEquilibrationEq's Hessian through its outer function (see the file comment).
class StepEquilibrationBlock final : public nlp::Block {
 public:
  explicit StepEquilibrationBlock(StepEquilibrationEq f)
      : f_(f), ad_(f), outer_(Outer{std::move(f)}) {}
  int num_inputs() const override { return ad_.num_inputs(); }
  int num_outputs() const override { return 1; }
  bool eval(const double* w, double* c) const override { return ad_.eval(w, c); }
  bool jacobian(const double* w, double* c, double* J) const override {
    return ad_.jacobian(w, c, J);
  }
  /// AutoDiffBlock's pattern; parts[0] is the pattern of G over u.
  nlp::BlockPattern pattern(const double* w) const override {
    nlp::BlockPattern bp = ad_.pattern(w);
    std::vector<double>& u = work().u;
    inner(w, u.data());
    bp.parts.push_back(outer_.pattern(u.data()));
    return bp;
  }

  bool hessian(const double* w, const double* y, const nlp::BlockPattern& p,
               double* h) const override {
    const int k = num_inputs(), n_u = n_inner();
    Work& s = work();
    inner(w, s.u.data());
    double G = 0.0;
    // dG/du and y d2G/du2 (dense, from the pattern entries of G)
    if (!outer_.jacobian(s.u.data(), &G, s.gG.data())) return false;
    const nlp::BlockPattern& part = p.parts[0];
    std::fill_n(s.HG.begin(), n_u * n_u, 0.0);
    if (!part.hess.empty()) {
      if (!outer_.hessian(s.u.data(), y, part, s.hG.data())) return false;
      for (std::size_t e = 0; e < part.hess.size(); ++e) {
        const auto [a, b] = part.hess[e];
        s.HG[a * n_u + b] = s.HG[b * n_u + a] = s.hG[e];
      }
    }
    // J_u (n_u x k, dense)
    std::fill_n(s.Ju.begin(), n_u * k, 0.0);
    s.Ju[f_.h_cur] += 1.0;
    s.Ju[f_.h_prev] -= 1.0;
    auto add_partner = [&](int row, const std::vector<int>& idx, const std::vector<int>& partner) {
      const double other = StepEquilibrationEq::sum(w, partner);
      for (int i : idx) s.Ju[row * k + i] += other;
    };
    for (std::size_t r = 0; r < f_.lam_B.size(); ++r) {
      const int row = 1 + static_cast<int>(r);
      add_partner(row, f_.lam_B[r], f_.lam_F[r]);
      add_partner(row, f_.lam_F[r], f_.lam_B[r]);
      add_partner(row, f_.th_B[r], f_.th_F[r]);
      add_partner(row, f_.th_F[r], f_.th_B[r]);
    }
    // H = J_u' HG J_u + sum_r y dG/dP_r d2P_r/dw2, read at the pattern entries
    std::fill_n(s.T.begin(), n_u * k, 0.0);  // T = HG J_u
    for (int a = 0; a < n_u; ++a)
      for (int b = 0; b < n_u; ++b) {
        const double hab = s.HG[a * n_u + b];
        if (hab == 0.0) continue;
        for (int i = 0; i < k; ++i) s.T[a * k + i] += hab * s.Ju[b * k + i];
      }
    std::fill_n(s.H.begin(), k * k, 0.0);
    for (int a = 0; a < n_u; ++a)
      for (int i = 0; i < k; ++i) {
        const double jai = s.Ju[a * k + i];
        if (jai == 0.0) continue;
        for (int j = 0; j < k; ++j) s.H[i * k + j] += jai * s.T[a * k + j];
      }
    auto add_bilinear = [&](double g, const std::vector<int>& A, const std::vector<int>& B) {
      for (int a : A)
        for (int b : B) {
          s.H[a * k + b] += g;
          s.H[b * k + a] += g;
        }
    };
    for (std::size_t r = 0; r < f_.lam_B.size(); ++r) {
      const double g = y[0] * s.gG[1 + r];
      add_bilinear(g, f_.lam_B[r], f_.lam_F[r]);
      add_bilinear(g, f_.th_B[r], f_.th_F[r]);
    }
    bool ok = true;
    for (std::size_t e = 0; e < p.hess.size(); ++e) {
      const auto [i, j] = p.hess[e];
      h[e] = s.H[i * k + j];
      ok = ok && std::isfinite(h[e]);
    }
    return ok;
  }

 private:
  /// G as a functor of u.
  struct Outer {
    StepEquilibrationEq f;
    int num_inputs() const { return 1 + static_cast<int>(f.lam_B.size()); }
    int num_outputs() const { return 1; }
    template <class T>
    void operator()(const T* u, T* c) const {
      c[0] = f.outer(u);
    }
  };
  struct Work {
    std::vector<double> u, gG, hG, HG, Ju, T, H;
  };
  int n_inner() const { return 1 + static_cast<int>(f_.lam_B.size()); }
  Work& work() const {
    thread_local Work s;
    const auto k = static_cast<std::size_t>(num_inputs()), n = static_cast<std::size_t>(n_inner());
    auto fit = [](std::vector<double>& v, std::size_t size) {
      if (v.size() < size) v.resize(size);
    };
    fit(s.u, n);
    fit(s.gG, n);
    fit(s.hG, n * n);
    fit(s.HG, n * n);
    fit(s.Ju, n * k);
    fit(s.T, n * k);
    fit(s.H, k * k);
    return s;
  }
  void inner(const double* w, double* u) const {
    u[0] = w[f_.h_cur] - w[f_.h_prev];
    for (std::size_t r = 0; r < f_.lam_B.size(); ++r) u[1 + r] = f_.region(w, r);
  }

  StepEquilibrationEq f_;
  nlp::AutoDiffBlock<StepEquilibrationEq> ad_;
  nlp::AutoDiffBlock<Outer> outer_;
};

}  // namespace fesd::discretization
