// tests/ocp/sliding_ocp_test.cpp: the sliding-mode OCP (61) (Sect. 5.3), Radau IIA n_s = 2,
// N_stages = 6, N_FE = 6, rho = 1e3, q_final = (-pi/6, -pi/4). The full comparison of MPCC
// methods and step-equilibration modes is bench/sliding_ocp (docs/benchmarks.md).
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <fesd/ocp.hpp>
#include <fesd/problem_file.hpp>

#include "../../bench/sliding_ocp.hpp"

namespace {

// Regions: 0 phi_1 > 0, 1 phi_1 < 0, 2 phi_2 > 0, 3 phi_2 < 0 (bench/sliding_ocp.hpp). Both
// regions of a subsystem active = sliding on its surface.
TEST(SlidingModeOcp, SwitchingSequenceOfSection53AndPiecewiseUniformGrid) {
  const fesd::OcpResult r =
      fesd::solve(fesd_bench::sliding_ocp_paper(), fesd_bench::sliding_options());
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_LE(r.comp_residual, 1e-9);
  // The l1 penalty with rho = 1e3 is exact here: q(4) = q_final (to IPOPT's tolerance).
  EXPECT_NEAR(r.x_final()[0], -std::numbers::pi / 6, 1e-6);
  EXPECT_NEAR(r.x_final()[1], -std::numbers::pi / 4, 1e-6);
  // Reach one surface and slide on it, reach the co-dimension-2 set {c = 0}, stay, leave it
  // sliding on the other surface, leave that too: four switches. (The paper's text names
  // phi_1 first; with x(0) = (2 pi/3, pi/3, 0, 0) and v = 0, phi_2 = 0.588 is reached before
  // phi_1 = 2.26: q' = (-1, -1) + v.)
  const std::vector<std::vector<int>> expected = {
      {0, 2}, {0, 2, 3}, {0, 1, 2, 3}, {0, 1, 3}, {1, 3}};
  ASSERT_EQ(r.switches.size(), 4u);
  EXPECT_EQ(r.switches[0].before, expected[0]);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(r.switches[i].after, expected[i + 1]) << i;
  for (std::size_t i = 1; i < 4; ++i) EXPECT_GT(r.switches[i].t, r.switches[i - 1].t);
  // The exit from the co-dimension-2 set lies inside control interval 3: pinned (theta of the
  // region left = 0 at the element end) and solved once more. The exit from phi_1 = 0 is on the
  // control-interval boundary t = 8/3, where exits are not pinned.
  EXPECT_EQ(r.summary.pinned_exits, 1);
  EXPECT_EQ(r.summary.pin_failures, 0);
  EXPECT_NEAR(r.switches[3].t, 8.0 / 3.0, 1e-9);
  // Step equilibration: inside a control interval h changes only where the active set does
  // (Fig. 12, middle). Tolerance 1e-6 of h0 = 1/9: the NLP is solved to 1e-12 but the penalty
  // balances h only to its optimality tolerance.
  for (std::size_t e = 1; e < r.h.size(); ++e) {
    if (r.interval[e] == r.interval[e - 1] && r.active_set[e] == r.active_set[e - 1]) {
      EXPECT_NEAR(r.h[e], r.h[e - 1], 1e-6) << "element " << e;
    }
  }
}

// REAL SOLVE (about 2 s): examples/nosnoc/ocp_sliding_mode_nosnoc.toml, nosnoc_py's example of (61)
// (v' = 2u, heuristic_mean rho_h = 10), with exits free as nosnoc_py leaves them: the last NLP's
// objective (OCP cost + step-equilibration penalty) is nosnoc_py's reported 5.596209 (PEERS.md,
// 7 digits: tolerance 1e-6 covers its rounding and IPOPT's tolerance). The OCP cost alone is
// fesd's own figure (docs/benchmarks-ocp.md), kept to 1e-6.
TEST(SlidingModeOcp, NosnocExampleReachesNosnocPyObjective) {
  fesd::OcpProblem q = fesd::load_ocp_problem(std::string(FESD_SOURCE_DIR) +
                                              "/examples/nosnoc/ocp_sliding_mode_nosnoc.toml");
  q.options.discretization.pin_sliding_exits = false;
  q.options.homotopy.active_set_sigma = 0;  // every NLP of nosnoc_py's homotopy
  const fesd::OcpResult r = fesd::solve(q.ocp, q.options);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_FALSE(r.homotopy.empty());
  EXPECT_NEAR(r.homotopy.back().objective, 5.596209, 1e-6);
  EXPECT_NEAR(r.objective, 5.5944610, 1e-6);
  EXPECT_EQ(r.homotopy.size(), 10u);  // sigma = 1 ... 1e-9, as nosnoc_py's 10 NLPs
  EXPECT_NEAR(r.x_final()[0], -std::numbers::pi / 6, 1e-9);
  EXPECT_NEAR(r.x_final()[1], -std::numbers::pi / 4, 1e-9);
  EXPECT_EQ(r.switches.size(), 4u);
}

// REAL SOLVE (about 0.4 s): nosnoc's superlinear homotopy update (homotopy_update_rule =
// superlinear, exponent 1.5) on nosnoc_py's example of (61): sigma_{k+1} = max(sigma_N,
// min(0.1 sigma_k, sigma_k^1.5)) takes 1, 0.1, 0.01, 1e-3, 10^-4.5, 10^-6.75, 10^-10.125 (then
// sigma_N = 1e-12 if needed): 7 NLPs instead of the linear rule's 10, and the same optimum.
TEST(SlidingModeOcp, SuperlinearHomotopyTakesNosnocsSigmas) {
  fesd::OcpProblem q = fesd::load_ocp_problem(std::string(FESD_SOURCE_DIR) +
                                              "/examples/nosnoc/ocp_sliding_mode_nosnoc.toml");
  q.options.discretization.pin_sliding_exits = false;
  q.options.homotopy.active_set_sigma = 0;
  fesd::apply_override(q, "homotopy_update_rule", "SUPERLINEAR");  // nosnoc's spelling
  ASSERT_EQ(q.options.homotopy.homotopy_update_rule, fesd::HomotopyUpdateRule::Superlinear);
  ASSERT_EQ(q.options.homotopy.sigma_N, 1e-12);
  EXPECT_EQ(fesd::homotopy_length(q.options.homotopy), 8);
  const fesd::OcpResult r = fesd::solve(q.ocp, q.options);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  const std::vector<double> sigma = {
      1, 0.1, 0.01, 1e-3, std::pow(10.0, -4.5), std::pow(10.0, -6.75), std::pow(10.0, -10.125)};
  ASSERT_EQ(r.homotopy.size(), sigma.size());
  for (std::size_t k = 0; k < sigma.size(); ++k)
    EXPECT_NEAR(r.homotopy[k].sigma, sigma[k], 1e-12 * sigma[k]) << "NLP " << k;
  EXPECT_NEAR(r.objective, 5.5944610, 1e-6);  // as the linear homotopy (test above)
  EXPECT_EQ(r.switches.size(), 4u);
}

// REAL SOLVES (about 3 s): HomotopyOptions::active_set_sigma (default 1e-4) ends the homotopy of
// nosnoc_py's example once the active sets are the same after two NLPs at sigma <= 1e-4, with one
// NLP whose active sets are fixed and sliding exits pinned: the cost and switch times of the full
// homotopy (measured 1.1e-10 and 3e-10 apart), exact complementarity, fewer NLPs (7 against 11).
TEST(SlidingModeOcp, StableActiveSetEndsTheHomotopyEarly) {
  fesd::OcpProblem q = fesd::load_ocp_problem(std::string(FESD_SOURCE_DIR) +
                                              "/examples/nosnoc/ocp_sliding_mode_nosnoc.toml");
  ASSERT_EQ(q.options.homotopy.active_set_sigma, 1e-4);
  const fesd::OcpResult early = fesd::solve(q.ocp, q.options);
  q.options.homotopy.active_set_sigma = 0;
  const fesd::OcpResult full = fesd::solve(q.ocp, q.options);
  ASSERT_EQ(early.status, fesd::Status::Success) << early.message;
  ASSERT_EQ(full.status, fesd::Status::Success) << full.message;
  EXPECT_NEAR(early.objective, full.objective, 1e-8);
  ASSERT_EQ(early.switches.size(), full.switches.size());
  for (std::size_t i = 0; i < early.switches.size(); ++i)
    EXPECT_NEAR(early.switches[i].t, full.switches[i].t, 1e-8) << "switch " << i;
  ASSERT_FALSE(early.homotopy.empty());
  EXPECT_TRUE(early.homotopy.back().active_set_fixed);
  EXPECT_GT(early.homotopy.back().sigma, 1e-8);  // the full homotopy goes down to 1e-9
  EXPECT_EQ(early.comp_residual, 0.0);           // theta = 0 or lambda = 0 exactly
  EXPECT_EQ(early.summary.pinned_exits, 2);
  EXPECT_LT(early.homotopy.size() + 3, full.homotopy.size());
  EXPECT_LT(early.summary.nlp_iterations, full.summary.nlp_iterations);
}

}  // namespace

// REAL SOLVES (about 1 s): OcpOptions::on_nlp_progress. With nlp_progress_every_s = 0 it is
// called after every IPOPT iteration: once per iteration 0..n of each NLP, so the calls are the
// homotopy's IPOPT iterations plus one per NLP (no NLP of this run is solved twice: each reports
// run 1), counting up inside an NLP; with a long interval never; a negative one is refused.
TEST(SlidingModeOcp, NlpProgressAfterEveryIterationOrNever) {
  fesd::OcpProblem q = fesd::load_ocp_problem(std::string(FESD_SOURCE_DIR) +
                                              "/examples/nosnoc/ocp_sliding_mode_nosnoc.toml");
  std::vector<fesd::NlpProgress> calls;
  q.options.on_nlp_progress = [&](const fesd::NlpProgress& p) { calls.push_back(p); };
  q.options.nlp_progress_every_s = 0;
  const fesd::OcpResult r = fesd::solve(q.ocp, q.options);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  for (const fesd::HomotopyRow& row : r.homotopy)
    ASSERT_EQ(row.linear_solver.find("first run"), std::string::npos) << row.linear_solver;
  EXPECT_EQ(calls.size(), static_cast<std::size_t>(r.summary.nlp_iterations) + r.homotopy.size());
  int starts = 0;
  for (std::size_t i = 0; i < calls.size(); ++i) {
    EXPECT_EQ(calls[i].run, 1);
    if (calls[i].iteration == 0) {
      ++starts;
    } else {
      ASSERT_GT(i, 0u);
      EXPECT_EQ(calls[i].iteration, calls[i - 1].iteration + 1) << "call " << i;
    }
    EXPECT_GE(calls[i].wall_s, 0.0);
  }
  EXPECT_EQ(starts, static_cast<int>(r.homotopy.size()));
  EXPECT_EQ(calls.back().iteration, r.homotopy.back().nlp_iterations);

  calls.clear();
  q.options.nlp_progress_every_s = 1e9;
  ASSERT_EQ(fesd::solve(q.ocp, q.options).status, fesd::Status::Success);
  EXPECT_TRUE(calls.empty());

  q.options.nlp_progress_every_s = -1;
  const std::vector<std::string> errors = fesd::validate(q.options);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("nlp_progress_every_s"), std::string::npos);
}
