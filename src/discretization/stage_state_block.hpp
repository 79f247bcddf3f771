// src/discretization/stage_state_block.hpp: the stage and continuity equations of one state
// component, X - x - h sum_j a_j V_j, as the AD functor StageStateEq and as the hand-written block
// FESD builds (StageStateBlock): the most numerous block of an OCP (n_x per stage and element),
// bilinear in h and V, so its derivatives are a few products; AutoDiffBlock's per-call set-up
// (Jet/Hyper inputs, one pass) cost more than the arithmetic. Values, Jacobian and Hessian are
// bit-identical to AutoDiffBlock<StageStateEq>, the pattern identical
// (tests/nlp/hessian_passes_test.cpp).
#pragma once
#include <cmath>
#include <utility>
#include <vector>

#include "nlp/block.hpp"

namespace fesd::discretization {

/// X - x - h sum_j a_j V_j = 0 for one state component.  inputs: X, x, h, V_j (j with a_j != 0)
struct StageStateEq {
  std::vector<double> a;
  int num_inputs() const { return 3 + static_cast<int>(a.size()); }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    T s(0.0);
    for (std::size_t j = 0; j < a.size(); ++j) s = s + a[j] * w[3 + j];
    c[0] = w[0] - w[1] - w[2] * s;
  }
};

class StageStateBlock final : public nlp::OneOutputBlock<StageStateEq> {
 public:
  explicit StageStateBlock(StageStateEq f) : OneOutputBlock(std::move(f)) {}
  /// dc/dX = 1, dc/dx = -1, dc/dh = -s, dc/dV_j = -(h a_j), s = sum_j a_j V_j.
  bool jacobian(const double* w, double* c, double* J) const override {
    double s = 0.0;
    for (std::size_t j = 0; j < f_.a.size(); ++j) s = s + f_.a[j] * w[3 + j];
    c[0] = w[0] - w[1] - w[2] * s;
    J[0] = 1.0;
    J[1] = -1.0;
    J[2] = -s;
    bool ok = std::isfinite(c[0]) && std::isfinite(s);
    for (std::size_t j = 0; j < f_.a.size(); ++j) {
      J[3 + j] = -(w[2] * f_.a[j]);
      ok = ok && std::isfinite(J[3 + j]);
    }
    return ok;
  }
  /// The pairs (V_j, h): -a_j y.
  bool hessian(const double*, const double* y, const nlp::BlockPattern& p,
               double* h) const override {
    for (std::size_t e = 0; e < p.hess.size(); ++e) h[e] = y[0] * -f_.a[p.hess[e].first - 3];
    return std::isfinite(y[0]);
  }
  nlp::BlockPattern pattern(const double*) const override {
    nlp::BlockPattern bp;
    bp.jac_rows.assign(1, {});
    for (int i = 0; i < num_inputs(); ++i) bp.jac_rows[0].push_back(i);
    for (int j = 0; j < static_cast<int>(f_.a.size()); ++j) bp.hess.emplace_back(3 + j, 2);
    return bp;
  }
};

}  // namespace fesd::discretization
