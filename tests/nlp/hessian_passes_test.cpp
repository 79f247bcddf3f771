// tests/nlp/hessian_passes_test.cpp: the planned Hessian passes of AutoDiffBlock (one pass per
// input of a vertex cover of the Hessian graph, only that input's partners carried in the
// gradient; src/nlp/block.hpp, docs/derivatives.md) against the reference plan (one pass per
// column with every input carried: the Hessian as computed before the plan), to 1e-12 relative:
// single blocks with C++ functors and with the problem-file OCP functions (expression bytecode),
// and whole FESD NLPs of every step equilibration with a C++ model and with expression models.
#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "discretization/dynamics_block.hpp"
#include "discretization/fesd_interval.hpp"
#include "discretization/stage_state_block.hpp"
#include "discretization/step_equilibration_block.hpp"
#include "fesd/model.hpp"
#include "fesd/problem_file.hpp"
#include "mpcc/relaxation.hpp"
#include "nlp/block.hpp"
#include "nlp/block_nlp.hpp"
#include "nlp/fesd_nlp_fixture.hpp"
#include "support/compare.hpp"

namespace {

using fesd::nlp::BlockPattern;

BlockPattern pattern_of(std::vector<std::pair<int, int>> pairs, int k) {
  BlockPattern bp;
  bp.hess = std::move(pairs);
  std::sort(bp.hess.begin(), bp.hess.end());
  fesd::nlp::plan_hessian_passes(bp, k);
  return bp;
}

/// Every pair in exactly one pass, as the pass's column and one of its rows.
void expect_cover(const BlockPattern& bp) {
  std::vector<int> count(bp.hess.size(), 0);
  int widest = 0;
  for (const auto& pass : bp.passes) {
    ASSERT_EQ(pass.rows.size(), pass.entry.size());
    widest = std::max(widest, static_cast<int>(pass.rows.size()));
    for (std::size_t l = 0; l < pass.rows.size(); ++l) {
      const auto [i, j] = bp.hess.at(static_cast<std::size_t>(pass.entry[l]));
      EXPECT_EQ(std::max(pass.col, pass.rows[l]), i);
      EXPECT_EQ(std::min(pass.col, pass.rows[l]), j);
      ++count[static_cast<std::size_t>(pass.entry[l])];
    }
  }
  for (int c : count) EXPECT_EQ(c, 1);
  EXPECT_EQ(bp.max_pass_rows, widest);
}

TEST(HessianPasses, CoverEveryPairOnceWithFewPasses) {
  // Bilinear theta x (X, u) as in the dynamics rows V - sum_r f_r(X, u) theta_r with linear f_r:
  // inputs 0..3 theta, 4..9 X and u. A vertex cover of K_{4,6}: the 4 theta passes.
  std::vector<std::pair<int, int>> bilinear;
  for (int r = 0; r < 4; ++r)
    for (int i = 4; i < 10; ++i) bilinear.emplace_back(i, r);
  const BlockPattern a = pattern_of(bilinear, 12);
  expect_cover(a);
  ASSERT_EQ(a.passes.size(), 4U);
  for (const auto& pass : a.passes) EXPECT_LT(pass.col, 4);
  EXPECT_EQ(a.max_pass_rows, 6);

  // A diagonal entry is only computed by its own input's pass.
  const BlockPattern b = pattern_of({{2, 2}, {2, 0}, {1, 0}, {3, 1}}, 4);
  expect_cover(b);
  EXPECT_EQ(b.passes.front().col, 2);
  ASSERT_EQ(b.passes.size(), 2U);  // 2, then 1 covers (1, 0) and (3, 1)
  EXPECT_EQ(b.passes.back().col, 1);

  EXPECT_TRUE(pattern_of({}, 5).passes.empty());

  // Dense: k passes at most, |hess| gradient entries in all.
  std::vector<std::pair<int, int>> dense;
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j <= i; ++j) dense.emplace_back(i, j);
  const BlockPattern d = pattern_of(dense, 7);
  expect_cover(d);
  EXPECT_EQ(d.passes.size(), 7U);
}

std::vector<double> random_values(std::size_t n, unsigned seed, double lo, double hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> v(n);
  for (double& x : v) x = u(rng);
  return v;
}

/// h == h_ref to 1e-12 relative to the largest entry (and entrywise).
::testing::AssertionResult near_hessians(const std::vector<double>& h,
                                         const std::vector<double>& h_ref) {
  double scale = 0;
  for (double v : h_ref) scale = std::max(scale, std::abs(v));
  if (scale == 0.0) return ::testing::AssertionFailure() << "the reference Hessian is zero";
  return fesd::testing::near_arrays(h, h_ref, 1e-12 * scale, 1e-12);
}

/// Planned passes vs the reference plan of the same block at w (Hessian entries of the pattern).
void expect_same_hessian(const fesd::nlp::Block& block, const std::vector<double>& w,
                         unsigned seed) {
  const BlockPattern planned = block.pattern(w.data());
  BlockPattern reference = planned;
  fesd::nlp::plan_column_passes(reference, block.num_inputs());
  ASSERT_FALSE(planned.hess.empty());
  const std::vector<double> y =
      random_values(static_cast<std::size_t>(block.num_outputs()), seed, -1.0, 1.0);
  std::vector<double> h(planned.hess.size(), 7.0), h_ref(planned.hess.size(), -7.0);
  ASSERT_TRUE(block.hessian(w.data(), y.data(), planned, h.data()));
  ASSERT_TRUE(block.hessian(w.data(), y.data(), reference, h_ref.data()));
  EXPECT_TRUE(near_hessians(h, h_ref));
}

/// Every operation of ad.hpp, nonlinear in several inputs, two outputs.
struct Mixed {
  int num_inputs() const { return 9; }
  int num_outputs() const { return 2; }
  template <class T>
  void operator()(const T* w, T* c) const {
    namespace m = fesd::math;
    using std::pow;  // pow(T, T) by argument-dependent lookup
    c[0] = w[0] * w[1] * m::sin(w[2]) + m::exp(w[3] * w[4]) / (1.0 + w[5] * w[5]) +
           m::pow(w[6], 2.5) - m::log(w[7]) * m::sqrt(w[8]) + 3.0 * w[0];
    c[1] = m::tanh(w[1] - w[2]) * m::cos(w[3]) + pow(w[4], w[5]) + m::atan(w[6] * w[0]) +
           m::sinh(w[7]) * m::cosh(w[8]) + m::tan(0.3 * w[2]) - 2.0 / w[5];
  }
};

/// The step equilibration product (31) of two elements with lifted sums: the densest block.
struct EtaProduct {
  int n_theta = 4;
  int num_inputs() const { return 2 + 4 * n_theta; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    T e(1.0);
    for (int r = 0; r < n_theta; ++r) {
      const T* s = w + 2 + 4 * r;
      e = e * (s[0] * s[1] + s[2] * s[3]);
    }
    c[0] = (w[1] - w[0]) * e;
  }
};

TEST(HessianPasses, AutoDiffBlocksMatchTheColumnPasses) {
  const auto mixed = fesd::nlp::make_block(Mixed{});
  expect_same_hessian(*mixed, random_values(9, 1U, 0.3, 1.2), 2U);
  const auto eta = fesd::nlp::make_block(EtaProduct{});
  expect_same_hessian(*eta, random_values(18, 3U, -1.0, 1.0), 4U);
  const auto eta32 = fesd::nlp::make_block(EtaProduct{8});  // 34 inputs: capacity 128 reference
  expect_same_hessian(*eta32, random_values(34, 5U, -1.0, 1.0), 6U);
}

std::string example(const char* name) {
  return std::string(FESD_SOURCE_DIR) + "/examples/" + name;
}

/// The OCP cost and constraints of a problem file (expression bytecode) as one block: inputs
/// h, X_1, X_2 (n_x each), q (n_u), p: h (b_1 f_q(X_1) + b_2 f_q(X_2)) + f_q_T(X_2), g_terminal.
struct OcpTerms {
  const fesd::OcpFunctions* f;
  int n_x, n_u, n_p, n_g;
  int num_inputs() const { return 1 + 2 * n_x + n_u + n_p; }
  int num_outputs() const { return 1 + n_g; }
  template <class T>
  void operator()(const T* w, T* c) const {
    const T* q = w + 1 + 2 * n_x;
    const T* p = q + n_u;
    T s = 0.25 * f->f_q(w + 1, q, p) + 0.75 * f->f_q(w + 1 + n_x, q, p);
    c[0] = w[0] * s;
    if (f->has_f_q_T()) c[0] = c[0] + f->f_q_T(w + 1 + n_x, p);
    f->g_terminal(w + 1 + n_x, p, c + 1);
  }
};

TEST(HessianPasses, ProblemFileOcpFunctionsMatchTheColumnPasses) {
  for (const char* file : {"nosnoc/ocp_sliding_mode_nosnoc.toml", "ocp_sliding_mode.toml"}) {
    SCOPED_TRACE(file);
    const fesd::OcpProblem problem = fesd::load_ocp_problem(example(file));
    const fesd::Ocp& ocp = problem.ocp;
    const OcpTerms terms{ocp.functions.get(), ocp.model.n_x(), ocp.model.n_u(), ocp.model.n_p(),
                         ocp.n_g_terminal};
    const auto block = fesd::nlp::make_block(terms);
    expect_same_hessian(
        *block, random_values(static_cast<std::size_t>(terms.num_inputs()), 7U, 0.2, 1.5), 8U);
  }
}

/// One FESD interval with free start state, controls and multipliers (every input has
/// derivatives), its complementarity rows, and the whole Hessian of the Lagrangian compared.
void expect_same_nlp_hessian(const fesd::Pss& model, fesd::StepEq step_eq, fesd::CrossComp cross,
                             int n_s) {
  const fesd::DiscretizationOptions d =
      fesd_test::options(fesd::RkScheme::RadauIIA, n_s, step_eq, cross);
  fesd::nlp::BlockNlp nlp;
  fesd::discretization::FesdInterval iv(model, fesd::make_tableau(d.rk_scheme, n_s), d);
  fesd_test::build_interval(model, iv, nlp);
  std::vector<double> x =
      random_values(static_cast<std::size_t>(nlp.num_variables()), 11U, 0.2, 0.9);
  nlp.x_init = x;
  nlp.finalize();
  const std::vector<double> lambda =
      random_values(static_cast<std::size_t>(nlp.num_constraints()), 12U, -0.5, 0.5);
  std::vector<double> h(static_cast<std::size_t>(nlp.hess_nnz())), h_ref(h);
  ASSERT_TRUE(nlp.eval_h(x.data(), 0.7, lambda.data(), h.data()));
  nlp.use_column_hessian_passes();
  ASSERT_TRUE(nlp.eval_h(x.data(), 0.7, lambda.data(), h_ref.data()));
  EXPECT_TRUE(near_hessians(h, h_ref));
}

/// The composite DynamicsBlock against AutoDiffBlock<DynamicsEq>: same pattern, same values,
/// Jacobian and Hessian of y'c to 1e-12 relative.
void expect_same_dynamics(const fesd::Pss& model, unsigned seed) {
  const fesd::discretization::DynamicsBlock composite(model);
  const fesd::nlp::AutoDiffBlock<fesd::discretization::DynamicsEq> ad({&model});
  const int k = ad.num_inputs(), m = ad.num_outputs();
  ASSERT_EQ(composite.num_inputs(), k);
  ASSERT_EQ(composite.num_outputs(), m);
  const std::vector<double> w = random_values(static_cast<std::size_t>(k), seed, 0.2, 1.5);
  const BlockPattern pc = composite.pattern(w.data()), pa = ad.pattern(w.data());
  EXPECT_EQ(pc.jac_rows, pa.jac_rows);
  EXPECT_EQ(pc.hess, pa.hess);

  const auto km = static_cast<std::size_t>(k) * m;
  std::vector<double> cc(m), ca(m), Jc(km), Ja(km);
  ASSERT_TRUE(composite.eval(w.data(), cc.data()));
  ASSERT_TRUE(ad.eval(w.data(), ca.data()));
  EXPECT_TRUE(fesd::testing::near_arrays(cc, ca, 1e-14, 1e-14));
  ASSERT_TRUE(composite.jacobian(w.data(), cc.data(), Jc.data()));
  ASSERT_TRUE(ad.jacobian(w.data(), ca.data(), Ja.data()));
  EXPECT_TRUE(fesd::testing::near_arrays(cc, ca, 1e-14, 1e-14));
  EXPECT_TRUE(fesd::testing::near_arrays(Jc, Ja, 1e-14, 1e-13));

  const std::vector<double> y = random_values(static_cast<std::size_t>(m), seed + 1, -1.0, 1.0);
  std::vector<double> hc(pa.hess.size(), 7.0), ha(pa.hess.size(), -7.0);
  ASSERT_TRUE(composite.hessian(w.data(), y.data(), pc, hc.data()));
  ASSERT_TRUE(ad.hessian(w.data(), y.data(), pa, ha.data()));
  EXPECT_TRUE(near_hessians(hc, ha));
}

TEST(HessianPasses, DynamicsBlockMatchesAutoDiff) {
  const fesd::Pss cpp_model = fesd_test::nonlinear_model();
  expect_same_dynamics(cpp_model, 21U);
  for (const char* file : {"nosnoc/ocp_sliding_mode_nosnoc.toml", "ocp_sliding_mode.toml"}) {
    SCOPED_TRACE(file);
    expect_same_dynamics(fesd::load_ocp_problem(example(file)).ocp.model, 23U);
  }
}

TEST(HessianPasses, StepEquilibrationBlockMatchesAutoDiff) {
  // n_theta = 4 regions with lifted sums (one input each) and n_theta = 2 with longer sums, for
  // the row (31), its tanh form and the l2_relaxed penalty.
  for (const int n_theta : {4, 2})
    for (const int variant : {0, 1, 2}) {
      SCOPED_TRACE(testing::Message() << "n_theta " << n_theta << " variant " << variant);
      fesd::discretization::StepEquilibrationEq f;
      const int per = n_theta == 4 ? 1 : 3;  // inputs per sum
      f.h_prev = 0;
      f.h_cur = 1;
      int next = 2;
      auto list = [&] {
        std::vector<int> v;
        for (int i = 0; i < per; ++i) v.push_back(next++);
        return v;
      };
      for (int r = 0; r < n_theta; ++r) {
        f.lam_B.push_back(list());
        f.lam_F.push_back(list());
        f.th_B.push_back(list());
        f.th_F.push_back(list());
      }
      f.k = next;
      f.use_tanh = variant == 1;
      f.penalty = variant == 2;
      f.h_scale = 0.3;
      const fesd::discretization::StepEquilibrationBlock composite(f);
      const fesd::nlp::AutoDiffBlock<fesd::discretization::StepEquilibrationEq> ad(f);
      const std::vector<double> w = random_values(static_cast<std::size_t>(f.k), 31U, -1.0, 1.0);
      const BlockPattern pc = composite.pattern(w.data()), pa = ad.pattern(w.data());
      EXPECT_EQ(pc.jac_rows, pa.jac_rows);
      EXPECT_EQ(pc.hess, pa.hess);
      const double y = -0.8;
      std::vector<double> hc(pa.hess.size(), 7.0), ha(pa.hess.size(), -7.0);
      ASSERT_TRUE(composite.hessian(w.data(), &y, pc, hc.data()));
      ASSERT_TRUE(ad.hessian(w.data(), &y, pa, ha.data()));
      EXPECT_TRUE(near_hessians(hc, ha));
    }
}

TEST(HessianPasses, StageStateBlockIsBitIdenticalToAutoDiff) {
  for (const std::vector<double>& a :
       {std::vector<double>{0.2, -0.7, 1.3}, std::vector<double>{0.5}, std::vector<double>{}}) {
    const fesd::discretization::StageStateEq f{a};
    const fesd::discretization::StageStateBlock hand(f);
    const fesd::nlp::AutoDiffBlock<fesd::discretization::StageStateEq> ad(f);
    const int k = f.num_inputs();
    const std::vector<double> w = random_values(static_cast<std::size_t>(k), 41U, -1.0, 2.0);
    const BlockPattern ph = hand.pattern(w.data()), pa = ad.pattern(w.data());
    EXPECT_EQ(ph.jac_rows, pa.jac_rows);
    EXPECT_EQ(ph.hess, pa.hess);
    double ch = 0, ca = 0;
    std::vector<double> Jh(static_cast<std::size_t>(k)), Ja(Jh);
    ASSERT_TRUE(hand.jacobian(w.data(), &ch, Jh.data()));
    ASSERT_TRUE(ad.jacobian(w.data(), &ca, Ja.data()));
    EXPECT_EQ(ch, ca);
    EXPECT_EQ(Jh, Ja);
    const double y = -1.7;
    std::vector<double> hh(pa.hess.size(), 7.0), ha(pa.hess.size(), -7.0);
    ASSERT_TRUE(hand.hessian(w.data(), &y, ph, hh.data()));
    ASSERT_TRUE(ad.hessian(w.data(), &y, pa, ha.data()));
    EXPECT_EQ(hh, ha);
  }
}

TEST(HessianPasses, FesdNlpsMatchTheColumnPasses) {
  const fesd::Pss cpp_model = fesd_test::nonlinear_model();
  const fesd::Pss nosnoc =
      fesd::load_ocp_problem(example("nosnoc/ocp_sliding_mode_nosnoc.toml")).ocp.model;
  const fesd::Pss paper = fesd::load_ocp_problem(example("ocp_sliding_mode.toml")).ocp.model;
  for (const fesd::StepEq step_eq :
       {fesd::StepEq::Eta, fesd::StepEq::EtaTanh, fesd::StepEq::L2Relaxed,
        fesd::StepEq::HeuristicMean, fesd::StepEq::HeuristicDelta}) {
    SCOPED_TRACE(static_cast<int>(step_eq));
    expect_same_nlp_hessian(cpp_model, step_eq, fesd::CrossComp::StageSum, 2);
    expect_same_nlp_hessian(nosnoc, step_eq, fesd::CrossComp::StageSum, 2);
    expect_same_nlp_hessian(paper, step_eq, fesd::CrossComp::Sparse, 3);
  }
}

}  // namespace
