// tests/nlp/sum_block_test.cpp: the hand-written Sum and ProductSum blocks (src/nlp/sum_block.hpp)
// against the same functors through AutoDiffBlock: identical values, Jacobians, Hessian columns
// and patterns (bit for bit: the NLPs must not change), and no input limit beyond ad::kMaxInputs.
#include <memory>
#include <random>
#include <type_traits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "fesd/error.hpp"
#include "nlp/block.hpp"
#include "nlp/sum_block.hpp"

namespace {

using fesd::nlp::Block;

std::vector<double> random_point(int k, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::vector<double> w(static_cast<std::size_t>(k));
  for (double& x : w) x = u(rng);
  return w;
}

/// Every output of `a` and `b` at w: value, Jacobian, the Hessian entries of the pattern, and the
/// pattern itself (not the Hessian passes, which only AutoDiffBlock uses), compared exactly.
void expect_identical(const Block& a, const Block& b, const std::vector<double>& w) {
  ASSERT_EQ(a.num_inputs(), b.num_inputs());
  ASSERT_EQ(a.num_outputs(), b.num_outputs());
  const int k = a.num_inputs(), m = a.num_outputs();
  const fesd::nlp::BlockPattern pa = a.pattern(w.data()), pb = b.pattern(w.data());
  EXPECT_EQ(pa.jac_rows, pb.jac_rows);
  EXPECT_EQ(pa.hess, pb.hess);

  std::vector<double> ca(m), cb(m), Ja(static_cast<std::size_t>(m) * k, 7.0), Jb(Ja);
  EXPECT_TRUE(a.eval(w.data(), ca.data()));
  EXPECT_TRUE(b.eval(w.data(), cb.data()));
  EXPECT_EQ(ca, cb);
  EXPECT_TRUE(a.jacobian(w.data(), ca.data(), Ja.data()));
  EXPECT_TRUE(b.jacobian(w.data(), cb.data(), Jb.data()));
  EXPECT_EQ(ca, cb);
  for (int r = 0; r < m; ++r)  // entries outside the pattern are not part of the contract
    for (int i : pa.jac_rows[static_cast<std::size_t>(r)])
      EXPECT_EQ(Ja[static_cast<std::size_t>(r * k + i)], Jb[static_cast<std::size_t>(r * k + i)])
          << "row " << r << " input " << i;

  const std::vector<double> y(static_cast<std::size_t>(m), -1.7);
  std::vector<double> ha(pa.hess.size(), 7.0), hb(ha);
  EXPECT_TRUE(a.hessian(w.data(), y.data(), pa, ha.data()));
  EXPECT_TRUE(b.hessian(w.data(), y.data(), pb, hb.data()));
  for (std::size_t e = 0; e < pa.hess.size(); ++e)
    EXPECT_EQ(ha[e], hb[e]) << "H(" << pa.hess[e].first << ", " << pa.hess[e].second << ")";
}

template <class F>
std::shared_ptr<const Block> autodiff(F f) {
  return std::make_shared<fesd::nlp::AutoDiffBlock<F>>(std::move(f));
}

TEST(SumBlock, MatchesAutoDiff) {
  for (int k : {1, 2, 7, 33, 128})
    for (bool minus_first : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "k = " << k << ", minus_first = " << minus_first);
      const fesd::nlp::Sum f{k, minus_first};
      expect_identical(*fesd::nlp::make_block(f), *autodiff(f), random_point(k, 11U + k));
    }
}

/// A complementarity group: products theta_i * lambda_j over local indices, the last pair
/// repeating an earlier one and one square, as the relaxation may produce.
fesd::nlp::ProductSum product_group(int n_pairs, bool minus_last) {
  fesd::nlp::ProductSum f;
  for (int p = 0; p < n_pairs; ++p) f.pairs.emplace_back(p % 5, 5 + p);
  f.pairs.emplace_back(0, 5);
  f.pairs.emplace_back(3, 3);
  f.k = 5 + n_pairs;
  f.minus_last = minus_last;
  return f;
}

TEST(ProductSumBlock, MatchesAutoDiff) {
  for (int n_pairs : {1, 4, 60, 122})
    for (bool minus_last : {false, true}) {
      SCOPED_TRACE(::testing::Message()
                   << "pairs = " << n_pairs << ", minus_last = " << minus_last);
      const fesd::nlp::ProductSum f = product_group(n_pairs, minus_last);
      expect_identical(*fesd::nlp::make_block(f), *autodiff(f),
                       random_point(f.num_inputs(), 5U + n_pairs));
    }
}

TEST(ProductSumBlock, EmptyGroupIsTheConstantZero) {
  const auto b = fesd::nlp::make_block(fesd::nlp::ProductSum{});
  double c = 1.0;
  EXPECT_EQ(b->num_inputs(), 0);
  EXPECT_TRUE(b->eval(nullptr, &c));
  EXPECT_EQ(c, 0.0);
  EXPECT_TRUE(b->pattern(nullptr).jac_rows.at(0).empty());
}

TEST(SumBlocks, HaveNoInputLimit) {
  // Far beyond ad::kMaxInputs: sum h_n = T with N_FE = 1000, a group of 1000 products.
  const int k = 1000;
  const auto sum = fesd::nlp::make_block(fesd::nlp::Sum{k, true});
  std::vector<double> w(static_cast<std::size_t>(k), 1.0), J(static_cast<std::size_t>(k));
  double c = 0;
  ASSERT_TRUE(sum->jacobian(w.data(), &c, J.data()));
  EXPECT_EQ(c, k - 2.0);
  EXPECT_EQ(J[0], -1.0);
  EXPECT_EQ(J[k - 1], 1.0);

  const fesd::nlp::ProductSum f = product_group(k, false);
  const auto products = fesd::nlp::make_block(f);
  const std::vector<double> v = random_point(f.num_inputs(), 3U);
  std::vector<double> Jp(static_cast<std::size_t>(f.num_inputs()));
  ASSERT_TRUE(products->jacobian(v.data(), &c, Jp.data()));
  double expected = 0;
  for (const auto& [a, b] : f.pairs)
    expected += v[static_cast<std::size_t>(a)] * v[static_cast<std::size_t>(b)];
  EXPECT_EQ(c, expected);
  EXPECT_EQ(Jp[6], v[1]);  // input 6 appears only in the pair (1, 6)
  const fesd::nlp::BlockPattern p = products->pattern(v.data());
  EXPECT_EQ(p.jac_rows.at(0).size(), static_cast<std::size_t>(f.num_inputs()));
  EXPECT_EQ(p.hess.size(), static_cast<std::size_t>(k + 1));  // k distinct pairs + the square
}

TEST(AutoDiffBlock, MoreInputsThanCapacityIsAnInternalError) {
  // The input checks (FesdInterval::block_size_errors) reject such sizes before building, so
  // reaching the AD limit is a bug in fesd (exit code 4), not bad input.
  static_assert(!std::is_base_of_v<fesd::Error, fesd::InternalError>);
  EXPECT_THROW(autodiff(fesd::nlp::Sum{fesd::ad::kMaxInputs + 1}), fesd::InternalError);
  EXPECT_NO_THROW(autodiff(fesd::nlp::Sum{fesd::ad::kMaxInputs}));
}

}  // namespace
