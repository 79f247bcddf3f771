// src/nlp/sum_block.hpp: the blocks whose number of inputs grows with the problem (N_FE, the
// complementarity pairs of a group), written with their exact derivatives by hand, so that they
// have no input limit (AutoDiffBlock has at most ad::kMaxInputs):
//   Sum         c = sum_i w_i, or sum_{i >= 1} w_i - w_0 (sum h_n = T, the lifted sums of (31), the
//               OCP's l1 slack penalty)
//   ProductSum  c = sum_p w_{a_p} w_{b_p}, optionally - w_k (complementarity rows of a group, the
//               elastic mode's row)
// `make_block(Sum{...})` and `make_block(ProductSum{...})` give these hand-written blocks; the
// functors keep a templated operator() so that tests can compare them with AutoDiffBlock. Values
// and derivatives are summed in the same order as the AD versions, so results are bit-identical.
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "nlp/block.hpp"

namespace fesd::nlp {

/// c[0] = sum_{i >= 0} w_i, or with `minus_first` c[0] = sum_{i >= 1} w_i - w_0 (a lifted sum
/// S = w_0 of the other inputs, imposed as c = 0).
struct Sum {
  int k = 0;
  bool minus_first = false;
  int num_inputs() const { return k; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    T s(0.0);
    for (int i = minus_first ? 1 : 0; i < k; ++i) s = s + w[i];
    c[0] = minus_first ? s - w[0] : s;
  }
};

/// c[0] = sum_p w[a_p] * w[b_p] over local indices (pairs), with `minus_last` minus the extra
/// input w[k] (the elastic variable s: sum - s), with `plus_last` plus it (sum + s). Inputs: k
/// (+ 1 with minus_last or plus_last).
struct ProductSum {
  std::vector<std::pair<int, int>> pairs;
  int k = 0;  ///< inputs read by the pairs (local indices 0..k-1)
  bool minus_last = false;
  bool plus_last = false;
  bool has_last() const { return minus_last || plus_last; }
  int num_inputs() const { return has_last() ? k + 1 : k; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    T s(0.0);
    for (const auto& [a, b] : pairs) s = s + w[a] * w[b];
    c[0] = minus_last ? s - w[k] : plus_last ? s + w[k] : s;
  }
};

/// Sum as a Block: the Jacobian is constant (+-1), the Hessian zero.
class SumBlock final : public OneOutputBlock<Sum> {
 public:
  explicit SumBlock(Sum f) : OneOutputBlock(f) {}
  bool jacobian(const double* w, double* c, double* J) const override {
    f_(w, c);
    for (int i = 0; i < f_.k; ++i) J[i] = 1.0;
    if (f_.minus_first && f_.k > 0) J[0] = -1.0;
    return std::isfinite(c[0]);
  }
  bool hessian(const double*, const double*, const BlockPattern&, double*) const override {
    return true;  // no Hessian entries
  }
  BlockPattern pattern(const double*) const override {
    BlockPattern bp;
    bp.jac_rows.assign(1, {});
    for (int i = 0; i < f_.k; ++i) bp.jac_rows[0].push_back(i);
    return bp;
  }
};

/// ProductSum as a Block: dc/dw_a = sum of the partners of a, the Hessian a constant 0/1 matrix.
class ProductSumBlock final : public OneOutputBlock<ProductSum> {
 public:
  explicit ProductSumBlock(ProductSum f) : OneOutputBlock(std::move(f)) {
    for (const auto& [a, b] : f_.pairs)
      hess_.emplace_back(std::max(a, b), std::min(a, b));  // (i >= j), as ad::Pattern
    std::sort(hess_.begin(), hess_.end());
    hess_.erase(std::unique(hess_.begin(), hess_.end()), hess_.end());
    for (const auto& [a, b] : f_.pairs) {
      const std::pair<int, int> e(std::max(a, b), std::min(a, b));
      pair_entry_.push_back(
          static_cast<int>(std::lower_bound(hess_.begin(), hess_.end(), e) - hess_.begin()));
    }
  }
  bool jacobian(const double* w, double* c, double* J) const override {
    const int k = num_inputs();
    f_(w, c);
    std::fill_n(J, k, 0.0);
    for (const auto& [a, b] : f_.pairs) {  // d(w_a w_b) = w_b dw_a + w_a dw_b
      if (a == b) {
        J[a] += 2.0 * w[a];
      } else {
        J[a] += w[b];
        J[b] += w[a];
      }
    }
    if (f_.has_last()) J[f_.k] = f_.minus_last ? -1.0 : 1.0;
    bool ok = std::isfinite(c[0]);
    for (int i = 0; i < k; ++i) ok = ok && std::isfinite(J[i]);
    return ok;
  }
  bool hessian(const double*, const double* y, const BlockPattern&, double* h) const override {
    // d^2(w_a w_b) = e_a e_b' + e_b e_a': count the entries, then scale by y (as AD does).
    std::fill_n(h, hess_.size(), 0.0);
    for (std::size_t p = 0; p < f_.pairs.size(); ++p) {
      const auto& [a, b] = f_.pairs[p];
      h[pair_entry_[p]] += a == b ? 2.0 : 1.0;
    }
    for (std::size_t e = 0; e < hess_.size(); ++e) h[e] *= y[0];
    return std::isfinite(y[0]);
  }
  BlockPattern pattern(const double*) const override {
    BlockPattern bp;
    std::vector<int> row;
    for (const auto& [a, b] : f_.pairs) {
      row.push_back(a);
      row.push_back(b);
    }
    if (f_.has_last()) row.push_back(f_.k);
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    bp.jac_rows.assign(1, std::move(row));
    bp.hess = hess_;  // no passes: hessian() needs none
    return bp;
  }

 private:
  std::vector<std::pair<int, int>> hess_;
  std::vector<int> pair_entry_;  // per pair of f_: its entry in hess_
};

/// The hand-written blocks for Sum and ProductSum (exact match: preferred over the AD template).
inline std::shared_ptr<const Block> make_block(Sum f) {
  return std::make_shared<SumBlock>(f);
}
inline std::shared_ptr<const Block> make_block(ProductSum f) {
  return std::make_shared<ProductSumBlock>(std::move(f));
}

}  // namespace fesd::nlp
