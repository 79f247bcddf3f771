// nosnoc_py's gene-network examples (examples/Acary2014 at commit 0c3f3bb, rows 10-12 of
// docs/nosnoc-examples.md) as fesd problem files: examples/nosnoc/two_gene.toml and
// examples/nosnoc/irma.toml, in the Heaviside step form with a general inclusion f_alpha. Both are
// piecewise affine, x' = b(alpha) - gamma x, so between threshold crossings x(t) has a closed form
// and the crossing times follow from it (bench/gene_network_exact.hpp).
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "../../bench/gene_network_exact.hpp"
#include "fesd/integrator.hpp"
#include "fesd/problem_file.hpp"

namespace {

std::string example_path(const std::string& file) {
  return std::string(FESD_SOURCE_DIR) + "/examples/nosnoc/" + file;
}

fesd::IntegratorResult run(const fesd::SimulationProblem& p) {
  return fesd::integrate(p.model, p.x0, p.T_sim, p.N_sim, p.options, p.u, p.p);
}

// From x0 = (6, 3) (the file as written): x2 reaches 4 at t1 = ln(71/68)/1.5, reaches 8 at t2 =
// ln(71/56)/1.5 and slides there (alpha_4 = 0.7), x1 reaches 8 at t3 = t1 + ln((80 - 9 x1(t1))/8)
// / 4.5 with x1(t1) = 6 (68/71)^3, and x stays at (8, 8) with alpha_2 = 0.1, alpha_4 = 0.7
// (x1' = 40 (1 - alpha_2) - 36 = 0, x2' = 40 (1 - alpha_4) - 12 = 0). Measured: x(1) exact to
// 1e-12, the switch times to 3e-8, 1.1e-7 and 1.1e-5 (t3: x1 arrives while x2 slides).
TEST(NosnocGeneNetworks, TwoGeneSlidesIntoTheEquilibriumOnTheThresholds) {
  const fesd::SimulationProblem p = fesd::load_simulation_problem(example_path("two_gene.toml"));
  const fesd::IntegratorResult r = run(p);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.x_final()[0], 8.0, 1e-8);
  EXPECT_NEAR(r.x_final()[1], 8.0, 1e-8);
  const double t1 = std::log(71.0 / 68.0) / 1.5;
  const double t2 = std::log(71.0 / 56.0) / 1.5;
  const double x1_t1 = 6.0 * std::pow(68.0 / 71.0, 3);
  const double t3 = t1 + std::log((80.0 - 9.0 * x1_t1) / 8.0) / 4.5;
  ASSERT_EQ(r.switches.size(), 3u);
  EXPECT_NEAR(r.switches[0].t, t1, 1e-6);
  EXPECT_NEAR(r.switches[1].t, t2, 1e-6);
  EXPECT_NEAR(r.switches[2].t, t3, 5e-5);
  ASSERT_FALSE(r.alpha.empty());
  const Eigen::VectorXd& a = r.alpha.back();  // at the equilibrium (8, 8)
  EXPECT_NEAR(a[0], 1.0, 1e-6);
  EXPECT_NEAR(a[1], 0.1, 1e-6);
  EXPECT_NEAR(a[2], 1.0, 1e-6);
  EXPECT_NEAR(a[3], 0.7, 1e-6);
}

// From (3, 3), another of the script's 16 initial states: nothing is activated and both decay,
// x(1) = 3 (e^-4.5, e^-1.5) without a switch (measured errors 2.9e-6 in x1, the decay at the
// rate 4.5 by Radau IIA 3 with h = 0.025, and 7.3e-7 in x2).
TEST(NosnocGeneNetworks, TwoGeneFromThreeThreeDecays) {
  fesd::SimulationProblem p = fesd::load_simulation_problem(example_path("two_gene.toml"));
  fesd::apply_override(p, "x0", "3,3");
  const fesd::IntegratorResult r = run(p);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.x_final()[0], 3.0 * std::exp(-4.5), 1e-5);
  EXPECT_NEAR(r.x_final()[1], 3.0 * std::exp(-1.5), 1e-6);
  EXPECT_TRUE(r.switches.empty());
}

// The reference itself: IRMA (switch-on) crosses its thresholds transversally and reaches a
// periodic orbit with 12 crossings per period T_p = 347.0813954 (sustained oscillations): the
// crossings 12 apart are T_p apart, the same threshold in the same direction, from the third
// period on to 1e-8 (the first period after the transient, crossings 12 to 24, is 4.3e-6 shorter).
TEST(NosnocGeneNetworks, IrmaExactSolutionIsPeriodic) {
  const fesd_bench::GeneSolution s =
      fesd_bench::exact_solution(fesd_bench::irma_network(), fesd_bench::irma_x0(), 1000.0);
  ASSERT_EQ(s.events.size(), 36u);
  EXPECT_NEAR(s.events[0].t, 25.5412811883, 1e-9);  // x4 falls through 0.04
  EXPECT_EQ(s.events[0].state, 3);
  EXPECT_NEAR(s.events[1].t, 39.1909582151, 1e-9);  // x1 falls through 0.01
  EXPECT_EQ(s.events[1].state, 0);
  const double period = s.events[35].t - s.events[23].t;
  EXPECT_NEAR(period, 347.0813954, 1e-6);
  EXPECT_NEAR(s.events[24].t - s.events[12].t, period, 1e-5);
  for (std::size_t k = 14; k + 12 < s.events.size(); ++k) {
    EXPECT_NEAR(s.events[k + 12].t - s.events[k].t, period, 1e-8) << k;
    EXPECT_EQ(s.events[k + 12].alpha, s.events[k].alpha) << k;
    EXPECT_EQ(s.events[k + 12].up, s.events[k].up) << k;
  }
}

// irma.toml over nosnoc_py's order-experiment horizon T = 100 with its tolerance (comp_tol =
// sigma_N = 1e-12) and 18 steps (one of its N_sim values): x(100) and the two crossings against
// the closed form. Measured: max |x(100) - x_exact| 5.3e-6 (in x2), crossings off by 1.7e-5 and
// 1.4e-4 (Radau IIA 3 with h = 5.6 on rates up to 0.6).
TEST(NosnocGeneNetworks, IrmaMatchesTheExactSolutionOverOneHundred) {
  fesd::SimulationProblem p = fesd::load_simulation_problem(example_path("irma.toml"));
  fesd::apply_override(p, "T_sim", "100");
  fesd::apply_override(p, "N_sim", "18");
  fesd::apply_override(p, "complementarity_tol", "1e-12");
  fesd::apply_override(p, "sigma_N", "1e-12");
  const fesd::IntegratorResult r = run(p);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  const fesd_bench::GeneSolution s =
      fesd_bench::exact_solution(fesd_bench::irma_network(), fesd_bench::irma_x0(), 100.0);
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(r.x_final()[i], s.x_T[i], 2e-5) << i;
  ASSERT_EQ(s.events.size(), 2u);
  ASSERT_EQ(r.switches.size(), 2u);
  EXPECT_NEAR(r.switches[0].t, s.events[0].t, 1e-3);
  EXPECT_NEAR(r.switches[1].t, s.events[1].t, 1e-3);
}

}  // namespace
