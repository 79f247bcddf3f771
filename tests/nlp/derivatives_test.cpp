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
#include "support/compare.hpp"

namespace {

using fesd::CrossComp;
using fesd::RkScheme;
using fesd::StepEq;

// Two subsystems (Cartesian product, eq. 21) with nonlinear g and f, a control and a parameter:
// subsystem 0 from c0 = x1 - p0 x2^2 (default S), subsystem 1 from two switching functions.
struct Nonlinear {
  template <class T>
  void c(const T* x, const T* p, T* c) const {
    using std::sin;
    c[0] = x[0] - p[0] * x[1] * x[1];
    c[1] = sin(x[1]) + 0.3 * x[0];
    c[2] = x[0] * x[1] - 0.1;
  }
  template <class T>
  void f(int r, const T* x, const T* u, const T* p, T* f) const {
    using std::cos;
    using std::exp;
    const double s = 1.0 + r;
    f[0] = -s * x[1] + u[0] * cos(x[0]) + p[0];
    f[1] = s * x[0] * x[1] - exp(0.1 * x[1]) * (r % 2 ? 1.0 : -1.0);
  }
};

struct Case {
  RkScheme scheme;
  int n_s;
  StepEq step_eq;
  CrossComp cross;
};

class DerivativesTest : public ::testing::TestWithParam<Case> {};

TEST_P(DerivativesTest, MatchCentralDifferences) {
  const Case c = GetParam();
  const fesd::Pss model = fesd::make_pss(
      Nonlinear{},
      fesd::PssDims{.n_x = 2,
                    .n_u = 1,
                    .n_p = 1,
                    .subsystems = {fesd::Subsystem::from_c(1), fesd::Subsystem::from_c(2)}});
  fesd::DiscretizationOptions d;
  d.rk_scheme = c.scheme;
  d.n_s = c.n_s;
  d.N_FE = 3;
  d.step_eq = c.step_eq;
  d.cross_comp = c.cross;
  const fesd::Tableau tab = fesd::make_tableau(c.scheme, c.n_s);
  fesd::nlp::BlockNlp nlp;
  fesd::discretization::IntervalInputs in;
  auto vars = [&](int n) {
    std::vector<int> v;
    const int first = nlp.add_variables(n, -1e20, 1e20, 0.0);
    for (int i = 0; i < n; ++i) v.push_back(first + i);
    return v;
  };
  // Free start state and start multipliers: the OCP case, so every input gets derivatives.
  in.s0 = vars(2);
  in.q = vars(1);
  in.p = vars(1);
  in.lambda_start = vars(model.n_theta());
  in.mu_start = vars(model.n_sys());
  in.T = 0.3;
  in.boundary_at_end = true;
  fesd::discretization::FesdInterval iv(model, tab, d);
  iv.build(nlp, in);
  fesd::mpcc::add_scholtes_rows(nlp, iv.groups());

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
