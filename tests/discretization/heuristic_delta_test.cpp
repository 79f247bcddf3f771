// tests/discretization/heuristic_delta_test.cpp: the heuristic_delta step equilibration
// (nosnoc_py's HEURISTIC_DELTA): the objective term rho_h * sum_{n >= 1} (h_n - h_{n-1})^2 over the
// neighbouring elements of one interval, unscaled, with its exact gradient and Hessian; nosnoc's
// upper-case names parse.
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "discretization/fesd_interval.hpp"
#include "fesd/model.hpp"
#include "fesd/options.hpp"

namespace {

using fesd::StepEq;

struct Crossing {  // x' in 2 - sign(x), Example 3(a)
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int r, const T*, const T*, const T*, T* f) const {
    f[0] = T(r == 0 ? 1.0 : 3.0);
  }
};

struct Penalty {
  double f = 0;
  std::vector<double> grad;                 // d f / d h_n
  std::map<std::pair<int, int>, double> H;  // lower triangle, (row, col) in h indices
};

// One interval of 4 elements on T = 1 with the given step sizes; every other variable 0. The
// objective of the bare interval is the step-equilibration penalty alone.
Penalty penalty(StepEq eq, double rho_h, const std::vector<double>& h) {
  static const fesd::Pss model = fesd::make_pss(
      Crossing{}, fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
  fesd::DiscretizationOptions d;
  d.rk_scheme = fesd::RkScheme::RadauIIA;
  d.n_s = 2;
  d.N_FE = static_cast<int>(h.size());
  d.step_eq = eq;
  d.rho_h = rho_h;
  fesd::nlp::BlockNlp nlp;
  auto vars = [&](int n) {
    std::vector<int> v;
    const int first = nlp.add_variables(n, 0.0, 0.0, 0.0);
    for (int i = 0; i < n; ++i) v.push_back(first + i);
    return v;
  };
  fesd::discretization::IntervalInputs in;
  in.s0 = vars(1);
  in.lambda_start = vars(model.n_theta());
  in.mu_start = vars(model.n_sys());
  in.T = 1.0;
  fesd::discretization::FesdInterval iv(model, fesd::make_tableau(d.rk_scheme, d.n_s), d);
  iv.build(nlp, in);
  nlp.finalize();
  std::vector<double> x(nlp.num_variables(), 0.0);
  std::map<int, int> h_of;  // NLP index -> element
  for (int n = 0; n < d.N_FE; ++n) {
    x[iv.h(n)] = h[n];
    h_of[iv.h(n)] = n;
  }
  Penalty p;
  EXPECT_TRUE(nlp.eval_f(x.data(), p.f));
  std::vector<double> g(nlp.num_variables());
  EXPECT_TRUE(nlp.eval_grad_f(x.data(), g.data()));
  for (int n = 0; n < d.N_FE; ++n) p.grad.push_back(g[iv.h(n)]);
  const std::vector<double> lambda(nlp.num_constraints(), 0.0);
  std::vector<double> hv(nlp.hess_nnz());
  EXPECT_TRUE(nlp.eval_h(x.data(), 1.0, lambda.data(), hv.data()));
  for (int e = 0; e < nlp.hess_nnz(); ++e) {
    const int r = nlp.hess_rows()[e], c = nlp.hess_cols()[e];
    if (hv[e] == 0.0) continue;
    EXPECT_TRUE(h_of.count(r) && h_of.count(c)) << "Hessian entry outside h: " << r << ", " << c;
    if (h_of.count(r) && h_of.count(c)) p.H[{h_of[r], h_of[c]}] += hv[e];
  }
  return p;
}

TEST(HeuristicDelta, ObjectiveTermGradientAndHessian) {
  // rho_h = 2.5, h = (0.2, 0.3, 0.15, 0.35): differences 0.1, -0.15, 0.2.
  const Penalty p = penalty(StepEq::HeuristicDelta, 2.5, {0.2, 0.3, 0.15, 0.35});
  // 2.5 (0.01 + 0.0225 + 0.04) = 0.18125; unscaled (no division by h0 = 0.25).
  EXPECT_NEAR(p.f, 0.18125, 1e-15);
  // d/dh_n = 2 rho_h ((h_n - h_{n-1}) - (h_{n+1} - h_n)), the missing neighbour's term absent.
  const std::vector<double> grad{-0.5, 1.25, -1.75, 1.0};
  ASSERT_EQ(p.grad.size(), grad.size());
  for (std::size_t n = 0; n < grad.size(); ++n) EXPECT_NEAR(p.grad[n], grad[n], 1e-14) << n;
  // 2 rho_h times the path Laplacian: diagonal (1, 2, 2, 1) * 5, neighbours -5, nothing else.
  const std::map<std::pair<int, int>, double> H{{{0, 0}, 5.0}, {{1, 1}, 10.0}, {{2, 2}, 10.0},
                                                {{3, 3}, 5.0}, {{1, 0}, -5.0}, {{2, 1}, -5.0},
                                                {{3, 2}, -5.0}};
  ASSERT_EQ(p.H.size(), H.size());
  for (const auto& [rc, v] : H) {
    ASSERT_TRUE(p.H.count(rc)) << rc.first << ", " << rc.second;
    EXPECT_NEAR(p.H.at(rc), v, 1e-13) << rc.first << ", " << rc.second;
  }
}

TEST(HeuristicDelta, ZeroOnAUniformGridAndOnlyNeighbourDifferencesCount) {
  // A uniform grid costs nothing whatever its step; heuristic_mean measures the distance from
  // T / N_FE, heuristic_delta only the differences of neighbours.
  EXPECT_EQ(penalty(StepEq::HeuristicDelta, 10.0, {0.25, 0.25, 0.25, 0.25}).f, 0.0);
  const std::vector<double> ramp{0.1, 0.2, 0.3, 0.4};
  EXPECT_NEAR(penalty(StepEq::HeuristicDelta, 10.0, ramp).f, 10.0 * 3 * 0.01, 1e-14);
  EXPECT_NEAR(penalty(StepEq::HeuristicMean, 10.0, ramp).f, 10.0 * 0.05, 1e-14);
}

TEST(HeuristicDelta, NamesIncludingNosnocsSpellings) {
  StepEq e = StepEq::None;
  ASSERT_TRUE(fesd::parse("heuristic_delta", e));
  EXPECT_EQ(e, StepEq::HeuristicDelta);
  EXPECT_EQ(fesd::to_string(StepEq::HeuristicDelta), "heuristic_delta");
  ASSERT_TRUE(fesd::parse("HEURISTIC_DELTA", e));
  EXPECT_EQ(e, StepEq::HeuristicDelta);
  ASSERT_TRUE(fesd::parse("HEURISTIC_MEAN", e));
  EXPECT_EQ(e, StepEq::HeuristicMean);
  // nosnoc's L2_RELAXED_SCALED is not fesd's l2_relaxed (no tanh scaling sigma, no 1 / h0).
  EXPECT_FALSE(fesd::parse("L2_RELAXED_SCALED", e));
  EXPECT_FALSE(fesd::parse("L2_RELAXED", e));
}

}  // namespace
