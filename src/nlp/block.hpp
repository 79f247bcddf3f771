// src/nlp/block.hpp: a small dense vector function c(w), w in R^k, c in R^m, with exact first and
// second derivatives from forward-mode AD (ad.hpp) and its structural sparsity from ad::Pattern.
// The NLP is a sum of such blocks, each touching a few variables (docs/derivatives.md).
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "fesd/ad.hpp"
#include "fesd/error.hpp"

namespace fesd::nlp {

/// One forward pass of a block's Hessian: the dual part seeded with e_col, the gradient part with
/// the inputs `rows` only (gradient entry l is input rows[l]), so that the pass gives
/// H(rows[l], col) = pattern entry entry[l]. Its cost is proportional to rows.size(), not to k.
struct HessPass {
  int col = 0;
  std::vector<int> rows;
  std::vector<int> entry;  // index into BlockPattern::hess, per row
  bool operator==(const HessPass&) const = default;
};

/// Structural sparsity of one block: per output row the inputs it depends on, and the pairs
/// (i >= j) of inputs with a nonzero entry in some output's Hessian.
struct BlockPattern {
  std::vector<std::vector<int>> jac_rows;
  std::vector<std::pair<int, int>> hess;
  /// The Hessian passes (plan_hessian_passes): every pair of `hess` in exactly one pass.
  std::vector<HessPass> passes;
  int max_pass_rows = 0;  // the largest rows.size(): the gradient capacity the passes need
  /// Composite blocks (made of other blocks, e.g. discretization/dynamics_block.hpp): the parts'
  /// own patterns and block-specific maps from the parts' derivatives to entries of `hess`.
  std::vector<BlockPattern> parts;
  std::vector<std::vector<int>> entry_maps;
};

/// Splits the pairs of bp.hess into passes: a pair (i, j) is computed in the pass of i or of j,
/// as one gradient entry. The number of gradient entries over all passes is |hess| whatever the
/// choice, so the plan minimizes the number of passes (a vertex cover of the Hessian graph):
/// inputs with a diagonal entry first (only their own pass can compute it), then greedily the
/// input covering most of the remaining pairs (docs/derivatives.md).
inline void plan_hessian_passes(BlockPattern& bp, int k) {
  bp.passes.clear();
  bp.max_pass_rows = 0;
  std::vector<std::vector<int>> incident(static_cast<std::size_t>(k));  // entries per input
  std::vector<int> degree(static_cast<std::size_t>(k), 0);
  std::vector<char> diagonal(static_cast<std::size_t>(k), 0), covered(bp.hess.size(), 0);
  for (std::size_t e = 0; e < bp.hess.size(); ++e) {
    const auto [i, j] = bp.hess[e];
    incident[i].push_back(static_cast<int>(e));
    if (i != j) incident[j].push_back(static_cast<int>(e));
    if (i == j) diagonal[i] = 1;
  }
  for (int v = 0; v < k; ++v) degree[v] = static_cast<int>(incident[v].size());
  std::size_t left = bp.hess.size();
  auto take = [&](int v) {
    HessPass pass{v, {}, {}};
    for (int e : incident[v]) {
      if (covered[e]) continue;
      const auto [i, j] = bp.hess[e];
      covered[e] = 1;
      --left;
      --degree[i];
      if (i != j) --degree[j];
      pass.rows.push_back(i == v ? j : i);
      pass.entry.push_back(e);
    }
    if (pass.rows.empty()) return;
    bp.max_pass_rows = std::max(bp.max_pass_rows, static_cast<int>(pass.rows.size()));
    bp.passes.push_back(std::move(pass));
  };
  for (int v = 0; v < k; ++v)
    if (diagonal[v]) take(v);
  while (left > 0)
    take(static_cast<int>(std::max_element(degree.begin(), degree.end()) - degree.begin()));
}

/// The reference plan: one pass per column j of the pairs (i >= j), every input carried in the
/// gradient (entry -1 where (i, j) is not a pair): the Hessian as computed before the plan above,
/// for tests (BlockNlp::use_column_hessian_passes).
inline void plan_column_passes(BlockPattern& bp, int k) {
  bp.passes.clear();
  std::vector<int> pass_of(static_cast<std::size_t>(k), -1);
  for (const auto& [i, j] : bp.hess) pass_of[j] = 0;
  for (int j = 0; j < k; ++j) {  // the distinct columns j, in order
    if (pass_of[j] < 0) continue;
    pass_of[j] = static_cast<int>(bp.passes.size());
    HessPass pass{j, {}, std::vector<int>(static_cast<std::size_t>(k), -1)};
    for (int r = 0; r < k; ++r) pass.rows.push_back(r);
    bp.passes.push_back(std::move(pass));
  }
  for (std::size_t e = 0; e < bp.hess.size(); ++e) {
    const auto [i, j] = bp.hess[e];
    bp.passes[pass_of[j]].entry[i] = static_cast<int>(e);
  }
  bp.max_pass_rows = bp.passes.empty() ? 0 : k;
}

class Block {
 public:
  virtual ~Block() = default;
  virtual int num_inputs() const = 0;
  virtual int num_outputs() const = 0;
  /// c = c(w). Returns false if an output is not finite.
  virtual bool eval(const double* w, double* c) const = 0;
  /// c and the dense Jacobian J (m x k, row-major). Returns false if not finite.
  virtual bool jacobian(const double* w, double* c, double* J) const = 0;
  /// h[e] = sum_r y_r d^2 c_r / dw_i dw_j for every pair e = (i, j) of p.hess, where p is this
  /// block's pattern(). Returns false if not finite.
  virtual bool hessian(const double* w, const double* y, const BlockPattern& p,
                       double* h) const = 0;
  /// Structure at w (union with a perturbed point, so that accidental zeros do not hide entries).
  virtual BlockPattern pattern(const double* w) const = 0;
};

/// Base of the hand-written blocks with one output: sizes and value from the functor F
/// (`num_inputs()`, `operator()(const double*, double*)`); the derived block writes the rest.
template <class F>
class OneOutputBlock : public Block {
 public:
  explicit OneOutputBlock(F f) : f_(std::move(f)) {}
  int num_inputs() const override { return f_.num_inputs(); }
  int num_outputs() const override { return 1; }
  bool eval(const double* w, double* c) const override {
    f_(w, c);
    return std::isfinite(c[0]);
  }

 protected:
  F f_;
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

  /// One pass per HessPass: only the pass's rows carry a gradient (entry l = input rows[l]), the
  /// other inputs are constants, so a pass costs O(rows) per operation instead of O(k).
  bool hessian(const double* w, const double* y, const BlockPattern& p, double* h) const override {
    if (p.passes.empty()) return true;
    const int k = num_inputs(), m = num_outputs();
    return with_capacity(p.max_pass_rows, [&]<int N>() {
      using J_t = ad::Jet<N>;
      using H_t = ad::Hyper<N>;
      auto& in = scratch<H_t>(k, 2);
      auto& out = scratch<H_t>(m, 3);
      for (int i = 0; i < k; ++i) in[i] = H_t(w[i]);
      bool ok = true;
      for (const HessPass& pass : p.passes) {
        const int n = static_cast<int>(pass.rows.size());
        for (int l = 0; l < n; ++l) in[pass.rows[l]].v = J_t::variable(w[pass.rows[l]], l, n);
        in[pass.col].d = J_t(1.0);
        for (int r = 0; r < m; ++r) out[r] = H_t(0.0);
        f_(in.data(), out.data());
        for (int l = 0; l < n; ++l) {
          double s = 0.0;
          for (int r = 0; r < m; ++r)
            if (y[r] != 0.0) s += y[r] * out[r].d.d(l);
          if (pass.entry[l] < 0) continue;  // only in the reference plan (plan_column_passes)
          h[pass.entry[l]] = s;
          ok = ok && std::isfinite(s);
        }
        for (int l = 0; l < n; ++l) in[pass.rows[l]].v = J_t(w[pass.rows[l]]);
        in[pass.col].d = J_t(0.0);
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
    plan_hessian_passes(bp, k);
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
