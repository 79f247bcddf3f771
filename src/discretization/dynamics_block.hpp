// src/discretization/dynamics_block.hpp: the dynamics rows (25) of one stage,
//
//   c = V - sum_r theta_r f_r(X, q, p),   inputs w = (V (n_x), X (n_x), theta (n_theta), q, p),
//
// as the AD functor DynamicsEq and as the composite block DynamicsBlock FESD builds. The rows are
// linear in V and theta, so DynamicsBlock differentiates only the region fields f_r(z),
// z = (X, q, p), one AutoDiffBlock per region:
//   Jacobian       dc/dV = I,  dc/dtheta_r = -f_r,  dc/dz = -sum_r theta_r df_r/dz
//   Hessian of y'c d2/dtheta_r dz = -y' df_r/dz,  d2/dz2 = -sum_r theta_r d2(y' f_r)/dz2
// i.e. one gradient pass of each f_r over z (plus f_r's own Hessian passes if it is nonlinear),
// where AutoDiffBlock<DynamicsEq> evaluates every region in every pass with the theta inputs
// carried along (docs/derivatives.md). Same values, Jacobian, Hessian (to round-off) and
// pattern as AutoDiffBlock<DynamicsEq> (tests/nlp/hessian_passes_test.cpp).
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "dcs/stewart.hpp"
#include "discretization/dynamics_eq.hpp"
#include "fesd/model.hpp"
#include "nlp/block.hpp"

namespace fesd::discretization {

/// sum_r theta_r f_r(X, q, p), the right-hand side of (25): y = theta (n_theta).
struct StewartRhs {
  const Pss* m;
  int n_y() const { return m->n_theta(); }
  template <class T>
  void operator()(const T* X, const T* theta, const T* q, const T* p, T* out) const {
    dcs::eval_F_theta(*m, X, q, p, theta, out);
  }
};

/// V - sum_r f_r(X, q, p) theta_r = 0.  inputs: V (n_x), X (n_x), theta (n_theta), q, p
using DynamicsEq = StageDynamicsEq<StewartRhs>;

/// f_r(z) of one region r, z = (X (n_x), q (n_u), p (n_p)).
struct RegionField {
  const Pss* m;
  int r;
  int num_inputs() const { return m->n_x() + m->n_u() + m->n_p(); }
  int num_outputs() const { return m->n_x(); }
  template <class T>
  void operator()(const T* z, T* f) const {
    m->functions().f(r, z, z + m->n_x(), z + m->n_x() + m->n_u(), f);
  }
};

/// DynamicsEq with its derivatives from the region fields (see the file comment).
class DynamicsBlock final : public nlp::Block {
 public:
  /// `m` must outlive the block (as for DynamicsEq).
  explicit DynamicsBlock(const Pss& m)
      : m_(&m), n_x_(m.n_x()), n_th_(m.n_theta()), n_z_(m.n_x() + m.n_u() + m.n_p()) {
    for (int r = 0; r < n_th_; ++r)
      fields_.push_back(std::make_shared<nlp::AutoDiffBlock<RegionField>>(RegionField{m_, r}));
    // The input limit of AutoDiffBlock<DynamicsEq> is kept (FesdInterval::block_size_errors and
    // docs/problem-files.md "Limits" state it), although only the fields are differentiated.
    if (num_inputs() > ad::kMaxInputs) nlp::with_capacity(num_inputs(), []<int N>() {});
  }
  int num_inputs() const override { return 2 * n_x_ + n_th_ + n_z_ - n_x_; }
  int num_outputs() const override { return n_x_; }

  bool eval(const double* w, double* c) const override {
    Work& s = work();
    gather_z(w, s);
    std::fill_n(c, n_x_, 0.0);
    for (int r = 0; r < n_th_; ++r) {
      RegionField{m_, r}(s.z.data(), s.f.data());
      for (int i = 0; i < n_x_; ++i) c[i] = c[i] + s.f[i] * w[theta(r)];
    }
    bool ok = true;
    for (int i = 0; i < n_x_; ++i) {
      c[i] = w[i] - c[i];
      ok = ok && std::isfinite(c[i]);
    }
    return ok;
  }

  bool jacobian(const double* w, double* c, double* J) const override {
    const int k = num_inputs();
    Work& s = work();
    gather_z(w, s);
    std::fill_n(J, static_cast<std::size_t>(n_x_) * k, 0.0);
    std::fill_n(c, n_x_, 0.0);
    std::fill_n(s.D.begin(), static_cast<std::size_t>(n_x_) * n_z_, 0.0);
    for (int r = 0; r < n_th_; ++r) {
      if (!fields_[r]->jacobian(s.z.data(), s.f.data(), s.Jf.data())) return false;
      const double th = w[theta(r)];
      for (int i = 0; i < n_x_; ++i) {
        c[i] = c[i] + s.f[i] * th;
        J[i * k + theta(r)] = -s.f[i];
        for (int a = 0; a < n_z_; ++a) s.D[i * n_z_ + a] += th * s.Jf[i * n_z_ + a];
      }
    }
    bool ok = true;
    for (int i = 0; i < n_x_; ++i) {
      c[i] = w[i] - c[i];
      J[i * k + i] = 1.0;
      for (int a = 0; a < n_z_; ++a) J[i * k + z_input(a)] = -s.D[i * n_z_ + a];
      ok = ok && std::isfinite(c[i]);
    }
    for (std::size_t e = 0; e < static_cast<std::size_t>(n_x_) * k; ++e)
      ok = ok && std::isfinite(J[e]);
    return ok;
  }

  /// p.entry_maps[2 r]: per z input a the entry of (theta_r, z_a) or -1; p.entry_maps[2 r + 1]:
  /// per Hessian pair of f_r (p.parts[r]) its entry.
  bool hessian(const double* w, const double* y, const nlp::BlockPattern& p,
               double* h) const override {
    Work& s = work();
    gather_z(w, s);
    std::fill_n(h, p.hess.size(), 0.0);
    bool ok = true;
    for (int r = 0; r < n_th_; ++r) {
      const std::vector<int>& cross = p.entry_maps[2 * r];
      if (!fields_[r]->jacobian(s.z.data(), s.f.data(), s.Jf.data())) return false;
      for (int a = 0; a < n_z_; ++a) {
        if (cross[a] < 0) continue;
        double g = 0.0;
        for (int i = 0; i < n_x_; ++i)
          if (y[i] != 0.0) g += y[i] * s.Jf[i * n_z_ + a];
        h[cross[a]] -= g;
      }
      const nlp::BlockPattern& part = p.parts[r];
      if (part.hess.empty()) continue;
      if (!fields_[r]->hessian(s.z.data(), y, part, s.h.data())) return false;
      const double th = w[theta(r)];
      const std::vector<int>& entry = p.entry_maps[2 * r + 1];
      for (std::size_t e = 0; e < part.hess.size(); ++e) h[entry[e]] -= th * s.h[e];
    }
    for (std::size_t e = 0; e < p.hess.size(); ++e) ok = ok && std::isfinite(h[e]);
    return ok;
  }

  /// As ad::Pattern finds it for DynamicsEq: row i depends on V_i, every theta_r and what f_r,i
  /// depends on; the Hessian pairs are theta_r x dep(f_r,i) (f_r,i not constant) and f_r's own.
  nlp::BlockPattern pattern(const double* w) const override {
    Work& s = work();
    gather_z(w, s);
    nlp::BlockPattern bp;
    bp.jac_rows.assign(n_x_, {});
    for (int i = 0; i < n_x_; ++i) {
      bp.jac_rows[i].push_back(i);
      for (int r = 0; r < n_th_; ++r) bp.jac_rows[i].push_back(theta(r));
    }
    std::vector<std::pair<int, int>> hess;
    auto pair = [&](int u, int v) { return std::make_pair(std::max(u, v), std::min(u, v)); };
    for (int r = 0; r < n_th_; ++r) {
      bp.parts.push_back(fields_[r]->pattern(s.z.data()));
      const nlp::BlockPattern& part = bp.parts.back();
      for (int i = 0; i < n_x_; ++i)
        for (int a : part.jac_rows[i]) {
          bp.jac_rows[i].push_back(z_input(a));
          hess.push_back(pair(theta(r), z_input(a)));
        }
      for (const auto& [a, b] : part.hess) hess.push_back(pair(z_input(a), z_input(b)));
    }
    for (auto& row : bp.jac_rows) sort_unique(row);
    sort_unique(hess);
    bp.hess = std::move(hess);
    auto entry = [&](std::pair<int, int> e) {
      const auto it = std::lower_bound(bp.hess.begin(), bp.hess.end(), e);
      return it != bp.hess.end() && *it == e ? static_cast<int>(it - bp.hess.begin()) : -1;
    };
    for (int r = 0; r < n_th_; ++r) {
      std::vector<int> cross(n_z_), own;
      for (int a = 0; a < n_z_; ++a) cross[a] = entry(pair(theta(r), z_input(a)));
      for (const auto& [a, b] : bp.parts[r].hess)
        own.push_back(entry(pair(z_input(a), z_input(b))));
      bp.entry_maps.push_back(std::move(cross));
      bp.entry_maps.push_back(std::move(own));
    }
    return bp;
  }

 private:
  struct Work {
    std::vector<double> z, f, Jf, D, h;
  };
  Work& work() const {
    thread_local Work s;
    const std::size_t jz = static_cast<std::size_t>(n_x_) * n_z_;
    if (s.z.size() < static_cast<std::size_t>(n_z_)) s.z.resize(n_z_);
    if (s.f.size() < static_cast<std::size_t>(n_x_)) s.f.resize(n_x_);
    if (s.Jf.size() < jz) s.Jf.resize(jz);
    if (s.D.size() < jz) s.D.resize(jz);
    if (s.h.size() < jz * n_z_) s.h.resize(jz * n_z_);  // >= the pairs of f_r's Hessian
    return s;
  }
  int theta(int r) const { return 2 * n_x_ + r; }
  /// The input of z_a: X_a for a < n_x, then q and p after theta.
  int z_input(int a) const { return a < n_x_ ? n_x_ + a : n_x_ + n_th_ + a; }
  void gather_z(const double* w, Work& s) const {
    for (int a = 0; a < n_z_; ++a) s.z[a] = w[z_input(a)];
  }
  template <class V>
  static void sort_unique(V& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }

  const Pss* m_;
  int n_x_, n_th_, n_z_;
  std::vector<std::shared_ptr<const nlp::AutoDiffBlock<RegionField>>> fields_;
};

}  // namespace fesd::discretization
