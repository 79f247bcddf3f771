// Optimal control of projected dynamical systems (fesd::solve(const PdsOcp&, ...), docs/pds.md
// "Optimal control"): the collaborative manipulation OCP of papers/fesd-pds.txt Sect. IV-B
// (bench/pds_discs_model.hpp) with Radau IIA n_s = 2, 20 control intervals of 3 elements, and
// the input rules.
#include <cmath>

#include <gtest/gtest.h>

#include "../../bench/pds_discs_model.hpp"
#include "fesd/error.hpp"
#include "fesd/ocp.hpp"

namespace {

fesd::OcpOptions discs_options() {
  fesd::OcpOptions o;
  o.discretization.rk_scheme = fesd::RkScheme::RadauIIA;
  o.discretization.n_s = 2;
  o.discretization.N_FE = 3;
  o.constraints_at_stages = true;
  return o;
}

TEST(PdsOcp, CollaborativeManipulation) {
  const fesd::OcpResult r = fesd::solve(pds_discs::ocp(20), discs_options());
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_LE(r.comp_residual, 1e-9);  // the homotopy's complementarity_tol
  // No overlap at any stage point: the discs touch (gap 0 up to round-off) but never overlap.
  double gap = pds_discs::min_gap(r.x.front());
  for (const Eigen::VectorXd& x : r.x_stage) gap = std::min(gap, pds_discs::min_gap(x));
  EXPECT_GE(gap, -1e-9);
  EXPECT_LE(gap, 1e-6);  // and they do touch: the big disc is pushed
  // The state constraints of the actuators hold at every stage point (constraints_at_stages).
  for (const Eigen::VectorXd& x : r.x_stage) {
    EXPECT_LE(x[0], -2.5 + 1e-9);
    EXPECT_GE(x[2], 2.5 - 1e-9);
  }
  // The big disc reaches its target (0, 10) (weight 1e3): measured 4e-6 off. The NLP is
  // nonconvex and its first relaxed NLP stops at IPOPT's iteration limit, so the local minimum
  // depends on round-off: measured 0.0595328 (Release), 0.0572022 (RelWithDebInfo + ASan),
  // 0.0551862 (the problem file), 0.0561 (other rho_h). Asserted: one of these minima's range.
  EXPECT_NEAR(r.x_final()[4], 0.0, 1e-4);
  EXPECT_NEAR(r.x_final()[5], 10.0, 1e-4);
  EXPECT_GT(r.objective, 0.05);
  EXPECT_LT(r.objective, 0.065);
  EXPECT_GE(r.switches.size(), 2u);  // contacts and leavings
  EXPECT_TRUE(r.theta.empty());
  ASSERT_EQ(r.lambda.size(), r.x_stage.size());
  EXPECT_EQ(r.lambda.front().size(), 2);
}

TEST(PdsOcp, RejectsX0OutsideC) {
  fesd::PdsOcp ocp = pds_discs::ocp(4);
  ocp.x0[4] = -9.5;  // the big disc 0.5 from actuator 1 at (-10, 10): overlap
  ocp.x0[5] = 10.0;
  try {
    (void)fesd::solve(ocp, discs_options());
    FAIL() << "expected InvalidModel";
  } catch (const fesd::InvalidModel& e) {
    EXPECT_NE(std::string(e.what()).find("outside C"), std::string::npos) << e.what();
  }
}

TEST(PdsOcp, RejectsSchemesAndSizes) {
  fesd::OcpOptions o = discs_options();
  o.discretization.rk_scheme = fesd::RkScheme::GaussLegendre;
  EXPECT_THROW((void)fesd::solve(pds_discs::ocp(4), o), fesd::InvalidOption);
  fesd::PdsOcp ocp = pds_discs::ocp(4);
  ocp.lbu = Eigen::VectorXd::Constant(3, -1.0);  // n_u = 4
  EXPECT_THROW((void)fesd::solve(ocp, discs_options()), fesd::InvalidModel);
  ocp = pds_discs::ocp(4);
  ocp.N_FE = {3, 3};  // N_stages = 4
  EXPECT_THROW((void)fesd::solve(ocp, discs_options()), fesd::InvalidOption);
}

}  // namespace
