// The dense LDL' KKT solver (src/nlp/dense_kkt, loaded into IPOPT as MA27) must give IPOPT the
// same steps as MUMPS: same iterates up to round-off, same inertia decisions.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "../../bench/oscillator_model.hpp"
#include "fesd/integrator.hpp"
#include "fesd/model.hpp"
#include "support/compare.hpp"

namespace {

TEST(KktSolver, DenseAndMumpsGiveTheSameIntegration) {
  const fesd::Pss model = fesd_bench::oscillator_model();
  const Eigen::VectorXd x0 = fesd_bench::oscillator_x0();
  fesd::IntegratorOptions automatic, mumps;
  automatic.discretization.n_s = mumps.discretization.n_s = 3;
  // IPOPT's KKT solvers: the homotopy path (the active-set path runs no NLP).
  automatic.step_solver = mumps.step_solver = fesd::StepSolver::Homotopy;
  automatic.nlp.kkt_solver = fesd::KktSolver::Dense;
  mumps.nlp.extra = {{"linear_solver", "mumps"}};
  // 1.2 s with 8 steps crosses the circle at t = 1: switch, sliding-free crossing, both regions.
  const auto a = fesd::integrate(model, x0, 1.2, 8, automatic);
  const auto b = fesd::integrate(model, x0, 1.2, 8, mumps);
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  ASSERT_FALSE(a.homotopy.empty() || a.homotopy.front().empty());
  ASSERT_FALSE(b.homotopy.empty() || b.homotopy.front().empty());
  EXPECT_EQ(a.homotopy.front().front().linear_solver, "dense");
  EXPECT_EQ(b.homotopy.front().front().linear_solver, "mumps");
  ASSERT_EQ(a.switches.size(), 1u);
  ASSERT_EQ(b.switches.size(), 1u);
  // Both factorizations are backward stable; IPOPT's iterates agree to ~1e-12 and the final
  // states to the integration tolerance (IPOPT tol 1e-12, complementarity 1e-9).
  EXPECT_TRUE(fesd::testing::near_arrays(a.x_final(), b.x_final(), 1e-9));
  EXPECT_NEAR(a.switches[0].t, b.switches[0].t, 1e-9);
  EXPECT_EQ(a.summary.homotopy_steps, b.summary.homotopy_steps);
}

// kkt_solver = auto takes the sparse LDL' at every size, also for the integrator's NLPs of
// 61 + 56 rows (where it needed 2.5x fewer instructions than the dense LAPACK solver).
TEST(KktSolver, AutoIsSparseForSmallNlps) {
  fesd::IntegratorOptions o;
  o.discretization.n_s = 3;
  o.step_solver = fesd::StepSolver::Homotopy;
  const auto r =
      fesd::integrate(fesd_bench::oscillator_model(), fesd_bench::oscillator_x0(), 0.3, 2, o);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_FALSE(r.homotopy.empty() || r.homotopy.front().empty());
  EXPECT_EQ(r.homotopy.front().front().linear_solver, "sparse_ldl");
}

}  // namespace
