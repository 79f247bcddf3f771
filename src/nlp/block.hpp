// src/nlp/block.hpp: a small dense vector function c(w), w in R^k, c in R^m, with exact first and
// second derivatives from forward-mode AD (ad.hpp) and its structural sparsity from ad::Pattern.
// The NLP is a sum of such blocks, each touching a few variables (docs/derivatives.md).
#pragma once
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "fesd/ad.hpp"
#include "fesd/error.hpp"

namespace fesd::nlp {

/// Structural sparsity of one block: per output row the inputs it depends on, and the pairs
/// (i >= j) of inputs with a nonzero entry in some output's Hessian.
struct BlockPattern {
  std::vector<std::vector<int>> jac_rows;
  std::vector<std::pair<int, int>> hess;
  std::vector<int> hess_cols;  // distinct j of hess: the forward passes the Hessian needs
};

class Block {
 public:
  virtual ~Block() = default;
  virtual int num_inputs() const = 0;
  virtual int num_outputs() const = 0;
  /// c = c(w). Returns false if an output is not finite.
  virtual bool eval(const double* w, double* c) const = 0;
  /// c and the dense Jacobian J (m x k, row-major). Returns false if not finite.
  virtual bool jacobian(const double* w, double* c, double* J) const = 0;
  /// H(:, j) = sum_r y_r d^2 c_r / dw dw_j for every j in cols; H is k x k column-major and only
  /// the columns in `cols` are written. Returns false if not finite.
  virtual bool hessian(const double* w, const double* y, const std::vector<int>& cols,
                       double* H) const = 0;
  /// Structure at w (union with a perturbed point, so that accidental zeros do not hide entries).
  virtual BlockPattern pattern(const double* w) const = 0;
};

/// Calls fn.template operator()<N>() with the smallest gradient capacity N >= k.
template <class Fn>
decltype(auto) with_capacity(int k, Fn&& fn) {
  if (k <= ad::kCapacities[0]) return fn.template operator()<ad::kCapacities[0]>();
  if (k <= ad::kCapacities[1]) return fn.template operator()<ad::kCapacities[1]>();
  if (k <= ad::kCapacities[2]) return fn.template operator()<ad::kCapacities[2]>();
  // Inputs above the limit are rejected before building (FesdInterval::block_size_errors).
  throw InternalError("internal: a derivative block has " + std::to_string(k) +
                      " inputs; at most " + std::to_string(ad::kMaxInputs) +
                      " are supported and the input checks should have said so");
}

template <class T>
std::vector<T>& scratch(std::size_t n, int slot) {
  thread_local std::vector<T> buffers[4];
  std::vector<T>& b = buffers[slot];
  if (b.size() < n) b.resize(n);
  return b;
}

/// Wraps a functor F with `int num_inputs() const`, `int num_outputs() const` and
/// `template <class T> void operator()(const T* w, T* c) const` into a Block.
template <class F>
class AutoDiffBlock final : public Block {
 public:
  explicit AutoDiffBlock(F f) : f_(std::move(f)) {
    if (f_.num_inputs() > ad::kMaxInputs) with_capacity(f_.num_inputs(), []<int N>() {});
  }
  int num_inputs() const override { return f_.num_inputs(); }
  int num_outputs() const override { return f_.num_outputs(); }
  const F& functor() const { return f_; }

  bool eval(const double* w, double* c) const override {
    f_(w, c);
    for (int r = 0; r < num_outputs(); ++r)
      if (!std::isfinite(c[r])) return false;
    return true;
  }

  bool jacobian(const double* w, double* c, double* J) const override {
    const int k = num_inputs(), m = num_outputs();
    return with_capacity(k, [&]<int N>() {
      using J_t = ad::Jet<N>;
      auto& in = scratch<J_t>(k, 0);
      auto& out = scratch<J_t>(m, 1);
      for (int i = 0; i < k; ++i) in[i] = J_t::variable(w[i], i, k);
      for (int r = 0; r < m; ++r) out[r] = J_t(0.0);
      f_(in.data(), out.data());
      bool ok = true;
      for (int r = 0; r < m; ++r) {
        c[r] = out[r].v;
        ok = ok && std::isfinite(c[r]);
        for (int i = 0; i < k; ++i) {
          J[r * k + i] = out[r].d(i);
          ok = ok && std::isfinite(J[r * k + i]);
        }
      }
      return ok;
    });
  }

  bool hessian(const double* w, const double* y, const std::vector<int>& cols,
               double* H) const override {
    const int k = num_inputs(), m = num_outputs();
    return with_capacity(k, [&]<int N>() {
      using J_t = ad::Jet<N>;
      using H_t = ad::Hyper<N>;
      auto& in = scratch<H_t>(k, 2);
      auto& out = scratch<H_t>(m, 3);
      bool ok = true;
      for (int j : cols) {
        for (int i = 0; i < k; ++i) in[i] = H_t(J_t::variable(w[i], i, k), J_t(i == j ? 1.0 : 0.0));
        for (int r = 0; r < m; ++r) out[r] = H_t(0.0);
        f_(in.data(), out.data());
        double* col = H + static_cast<std::size_t>(j) * k;
        for (int i = 0; i < k; ++i) col[i] = 0.0;
        for (int r = 0; r < m; ++r) {
          if (y[r] == 0.0) continue;
          const J_t& d = out[r].d;
          for (int i = 0; i < d.n; ++i) col[i] += y[r] * d.g[i];
        }
        for (int i = 0; i < k; ++i) ok = ok && std::isfinite(col[i]);
      }
      return ok;
    });
  }

  BlockPattern pattern(const double* w) const override {
    const int k = num_inputs(), m = num_outputs();
    BlockPattern bp;
    bp.jac_rows.assign(m, {});
    std::vector<std::vector<int>> rows(m);
    std::vector<std::pair<int, int>> hess;
    for (int probe = 0; probe < 2; ++probe) {
      std::vector<ad::Pattern> in(k), out(m);
      for (int i = 0; i < k; ++i) {
        // second probe: a deterministic perturbation, so accidental zeros at w do not hide entries
        const double wi = probe == 0 ? w[i] : w[i] * 1.013 + 0.137 * (i + 1);
        in[i] = ad::Pattern::variable(wi, i);
      }
      f_(in.data(), out.data());
      for (int r = 0; r < m; ++r) {
        rows[r] = ad::pattern_detail::merge(rows[r], out[r].dep);
        hess = ad::pattern_detail::merge(hess, out[r].hess);
      }
    }
    bp.jac_rows = std::move(rows);
    bp.hess = std::move(hess);
    for (const auto& [i, j] : bp.hess) bp.hess_cols.push_back(j);
    std::sort(bp.hess_cols.begin(), bp.hess_cols.end());
    bp.hess_cols.erase(std::unique(bp.hess_cols.begin(), bp.hess_cols.end()), bp.hess_cols.end());
    return bp;
  }

 private:
  F f_;
};

template <class F>
std::shared_ptr<const Block> make_block(F f) {
  return std::make_shared<AutoDiffBlock<F>>(std::move(f));
}

}  // namespace fesd::nlp
