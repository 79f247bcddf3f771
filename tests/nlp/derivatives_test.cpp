// Exact derivatives of the assembled FESD NLP against central differences: the constraint
// Jacobian, the objective gradient and the Hessian of the Lagrangian, for every block type
// (stage equations, LP, boundary LP (33), step equilibration (31) with and without tanh, the
// heuristic penalties, complementarity rows), several schemes and a two-subsystem model.
// Also checks that no nonzero of the finite-difference Jacobian lies outside the declared pattern.
#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include <gtest/gtest.h>

#include "discretization/fesd_interval.hpp"
#include "fesd/model.hpp"
#include "mpcc/relaxation.hpp"
#include "nlp/fesd_nlp_fixture.hpp"
#include "support/compare.hpp"

namespace {

using fesd::CrossComp;
using fesd::RkScheme;
using fesd::StepEq;

struct Case {
  RkScheme scheme;
  int n_s;
  StepEq step_eq;
  CrossComp cross;
};

class DerivativesTest : public ::testing::TestWithParam<Case> {};

TEST_P(DerivativesTest, MatchCentralDifferences) {
  const Case c = GetParam();
  const fesd::Pss model = fesd_test::nonlinear_model();
  const fesd::DiscretizationOptions d = fesd_test::options(c.scheme, c.n_s, c.step_eq, c.cross);
  fesd::nlp::BlockNlp nlp;
  fesd::discretization::FesdInterval iv(model, fesd::make_tableau(c.scheme, c.n_s), d);
  fesd_test::build_interval(model, iv, nlp);

  const int n = nlp.num_variables(), m = nlp.num_constraints();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0.2, 0.9);
  for (double& v : nlp.x_init) v = U(rng);  // positive: theta, lambda, h in their domains
  nlp.finalize();
  const std::vector<double> x = nlp.x_init;
  std::vector<double> lambda(m);
  for (double& v : lambda) v = U(rng) - 0.5;
  const double obj_factor = 0.7;

  // Jacobian: assembled sparse vs dense central differences.
  std::vector<double> jac(nlp.jac_nnz());
  ASSERT_TRUE(nlp.eval_jac_g(x.data(), jac.data()));
  std::map<std::pair<int, int>, double> sparse;
  for (int e = 0; e < nlp.jac_nnz(); ++e) sparse[{nlp.jac_rows()[e], nlp.jac_cols()[e]}] = jac[e];
  const double eps = 1e-6;
  std::vector<double> xp = x, gp(m), gm(m);
  std::vector<double> fd_col(m), ad_col(m);
  for (int j = 0; j < n; ++j) {
    xp[j] = x[j] + eps;
    ASSERT_TRUE(nlp.eval_g(xp.data(), gp.data()));
    xp[j] = x[j] - eps;
    ASSERT_TRUE(nlp.eval_g(xp.data(), gm.data()));
    xp[j] = x[j];
    for (int i = 0; i < m; ++i) {
      fd_col[i] = (gp[i] - gm[i]) / (2 * eps);
      auto it = sparse.find({i, j});
      ad_col[i] = it == sparse.end() ? 0.0 : it->second;
    }
    // Central differences with eps = 1e-6 on O(1) functions: error ~1e-9; 1e-6 absolute +
    // relative leaves room for the larger second derivatives of the product blocks.
    ASSERT_TRUE(fesd::testing::near_arrays(ad_col, fd_col, 1e-6, 1e-6)) << "Jacobian column " << j;
  }

  // Hessian of the Lagrangian vs central differences of its gradient.
  auto lagrangian_gradient = [&](const std::vector<double>& xx, std::vector<double>& out) {
    std::vector<double> gf(n), jv(nlp.jac_nnz());
    EXPECT_TRUE(nlp.eval_grad_f(xx.data(), gf.data()));
    EXPECT_TRUE(nlp.eval_jac_g(xx.data(), jv.data()));
    out.assign(n, 0.0);
    for (int i = 0; i < n; ++i) out[i] = obj_factor * gf[i];
    for (int e = 0; e < nlp.jac_nnz(); ++e)
      out[nlp.jac_cols()[e]] += lambda[nlp.jac_rows()[e]] * jv[e];
  };
  std::vector<double> hv(nlp.hess_nnz());
  ASSERT_TRUE(nlp.eval_h(x.data(), obj_factor, lambda.data(), hv.data()));
  std::map<std::pair<int, int>, double> hess;
  for (int e = 0; e < nlp.hess_nnz(); ++e) {
    ASSERT_GE(nlp.hess_rows()[e], nlp.hess_cols()[e]) << "Hessian entries must be lower triangle";
    hess[{nlp.hess_rows()[e], nlp.hess_cols()[e]}] += hv[e];
  }
  std::vector<double> lp, lm, fd(n), ad(n);
  for (int j = 0; j < n; ++j) {
    xp[j] = x[j] + eps;
    lagrangian_gradient(xp, lp);
    xp[j] = x[j] - eps;
    lagrangian_gradient(xp, lm);
    xp[j] = x[j];
    for (int i = 0; i < n; ++i) {
      fd[i] = (lp[i] - lm[i]) / (2 * eps);
      auto it = hess.find({std::max(i, j), std::min(i, j)});
      ad[i] = it == hess.end() ? 0.0 : it->second;
    }
    ASSERT_TRUE(fesd::testing::near_arrays(ad, fd, 1e-5, 1e-6)) << "Hessian column " << j;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Blocks, DerivativesTest,
    ::testing::Values(Case{RkScheme::RadauIIA, 2, StepEq::Eta, CrossComp::StageSum},
                      Case{RkScheme::RadauIIA, 1, StepEq::EtaTanh, CrossComp::Sparse},
                      Case{RkScheme::GaussLegendre, 2, StepEq::Eta, CrossComp::Neighbor},
                      Case{RkScheme::LobattoIIIC, 3, StepEq::HeuristicMean, CrossComp::Element},
                      Case{RkScheme::RadauIIA, 3, StepEq::HeuristicDelta, CrossComp::StageSum},
                      Case{RkScheme::ExplicitRK, 4, StepEq::EtaTanh, CrossComp::StageSum}));

}  // namespace
