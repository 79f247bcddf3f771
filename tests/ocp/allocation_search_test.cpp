// tests/ocp/allocation_search_test.cpp: the allocation search of the OCP (issue 14, item 1;
// docs/formulation.md, "Switches held by the grid").
//
// For Radau IIA n_s = 1 and Lobatto IIIC n_s = 2 the quadrature of (56)'s cost is not exact, so
// with step equilibration l2_relaxed (zero on every grid uniform between switches) the discrete
// cost depends on how many elements each segment gets. The OCP must reach the minimizer of the
// discretized problem from any guess. The pinned values are those of the brute-force scan over
// all N_FE - 1 allocations in bench/ocp_robustness ("discrete minimizer (scan over the ...
// allocations)"), with default options otherwise.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include <fesd/ocp.hpp>

#include "../../bench/sensitivity_ocp.hpp"
#include "ocp/resolve_account.hpp"

namespace {

using fesd_bench::sensitivity_ocp;

struct AllocationCase {
  fesd::RkScheme scheme;
  int n_s, N_FE;
  fesd::OcpInitialization init;
  double guess;
  double x0, objective;  // the discrete minimizer (scan)
};

fesd::OcpOptions defaults_with(const AllocationCase& c) {
  fesd::OcpOptions o;
  o.discretization.rk_scheme = c.scheme;
  o.discretization.n_s = c.n_s;
  o.discretization.N_FE = c.N_FE;
  o.initialization = c.init;
  return o;
}

class AllocationSearch : public ::testing::TestWithParam<AllocationCase> {};

// Tolerances: x0 1e-6 (the issue's), the objective 1e-8 (the NLPs are solved to 1e-9 and the
// solution is a smooth minimizer for its allocation).
TEST_P(AllocationSearch, ReachesTheDiscreteMinimizer) {
  const AllocationCase c = GetParam();
  const fesd::OcpResult r = fesd::solve(sensitivity_ocp(c.guess), defaults_with(c));
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.x0()[0], c.x0, 1e-6);
  EXPECT_NEAR(r.objective, c.objective, 1e-8);
  ASSERT_EQ(r.switches.size(), 1u);
  EXPECT_LE(r.summary.allocation_moves, r.summary.allocation_solves);
}

// Lobatto IIIC 2, N_FE 25: 10 elements before the switch, 15 after, uniform on each (the
// trapezoidal rule on these grids: V(x0) is a cubic whose minimum is 1.5280108158 at x0 =
// -1.42646811, also computed in closed form). Radau IIA 1, N_FE 25: 3 elements before the switch,
// each at the upper bound 2 h0 of h_n, so x0 = -3 * 3 * 2 * 2 / 25 = -1.44 (the switch held by
// the bound: the discrete minimizer itself, with a warning). Radau IIA 1, N_FE 10: 2 elements.
constexpr double kLobattoX0 = -1.4264681103779044, kLobattoV = 1.528010815766055;
constexpr double kRadau25X0 = -1.44, kRadau25V = 1.4550706870;
constexpr double kRadau10X0 = -1.9902452943, kRadau10V = 1.3801859262;

using fesd::OcpInitialization;
using fesd::RkScheme;
INSTANTIATE_TEST_SUITE_P(
    Guesses, AllocationSearch,
    ::testing::Values(AllocationCase{RkScheme::LobattoIIIC, 2, 25, OcpInitialization::Constant,
                                     -2.7, kLobattoX0, kLobattoV},
                      AllocationCase{RkScheme::LobattoIIIC, 2, 25, OcpInitialization::Simulation,
                                     -0.9, kLobattoX0, kLobattoV},
                      AllocationCase{RkScheme::LobattoIIIC, 2, 25, OcpInitialization::Constant, 0.9,
                                     kLobattoX0, kLobattoV},
                      AllocationCase{RkScheme::LobattoIIIC, 2, 25, OcpInitialization::Simulation,
                                     2.7, kLobattoX0, kLobattoV},
                      // The three guesses of bench/ocp_robustness (-3 + 6 k / 29, k = 4, 5, 7)
                      // that ended one element off (x0 = -1.4259442, -1.4266360) while the
                      // regrid copied a collapsed element's mixed theta (docs/formulation.md).
                      AllocationCase{RkScheme::LobattoIIIC, 2, 25, OcpInitialization::Constant,
                                     -3.0 + 6.0 * 4 / 29, kLobattoX0, kLobattoV},
                      AllocationCase{RkScheme::LobattoIIIC, 2, 25, OcpInitialization::Constant,
                                     -3.0 + 6.0 * 5 / 29, kLobattoX0, kLobattoV},
                      AllocationCase{RkScheme::LobattoIIIC, 2, 25, OcpInitialization::Constant,
                                     -3.0 + 6.0 * 7 / 29, kLobattoX0, kLobattoV},
                      AllocationCase{RkScheme::RadauIIA, 1, 25, OcpInitialization::Simulation, -2.7,
                                     kRadau25X0, kRadau25V},
                      AllocationCase{RkScheme::RadauIIA, 1, 25, OcpInitialization::Constant, -0.9,
                                     kRadau25X0, kRadau25V},
                      AllocationCase{RkScheme::RadauIIA, 1, 25, OcpInitialization::Simulation, 0.9,
                                     kRadau25X0, kRadau25V},
                      AllocationCase{RkScheme::RadauIIA, 1, 25, OcpInitialization::Constant, 2.7,
                                     kRadau25X0, kRadau25V},
                      AllocationCase{RkScheme::RadauIIA, 1, 10, OcpInitialization::Constant, -2.7,
                                     kRadau10X0, kRadau10V},
                      AllocationCase{RkScheme::RadauIIA, 1, 10, OcpInitialization::Simulation, 2.7,
                                     kRadau10X0, kRadau10V}));

// A warm-started NLP that fails with IPOPT's adaptive mu strategy and solves on the monotone
// retry makes the homotopy's later warm-started NLPs run monotone first (IpoptSolver::solve). In
// this case (the allocation search's re-solves) one NLP ends Search_Direction_Becomes_Too_Small
// with the adaptive strategy after 14 iterations and solves monotone in 12; the four NLPs after it
// then solve monotone at once (9, 6, 8, 7 iterations) instead of adaptive first.
TEST(AllocationSearchWarmStarts, MonotoneFirstOnceAnNlpNeededIt) {
  const AllocationCase c{RkScheme::RadauIIA, 1,        25, OcpInitialization::Constant, -0.9,
                         kRadau25X0,         kRadau25V};
  const fesd::OcpResult r = fesd::solve(sensitivity_ocp(c.guess), defaults_with(c));
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.objective, c.objective, 1e-8);
  const std::string retry = "again with mu_strategy monotone from mu_init 0.0001";
  const std::string first =
      "sparse_ldl (mu_strategy monotone from mu_init 0.0001, as an NLP before";
  std::size_t cured = r.homotopy.size();
  for (std::size_t k = 0; k < r.homotopy.size(); ++k)
    if (r.homotopy[k].linear_solver.find(retry) != std::string::npos) {
      cured = k;
      break;
    }
  ASSERT_LT(cured + 1, r.homotopy.size()) << "no NLP needed the monotone retry";
  EXPECT_EQ(r.homotopy[cured].nlp_status, "Solve_Succeeded");
  for (std::size_t k = cured + 1; k < r.homotopy.size(); ++k) {
    EXPECT_EQ(r.homotopy[k].linear_solver.rfind(first, 0), 0u)
        << "NLP " << k << ": " << r.homotopy[k].linear_solver;
    EXPECT_EQ(r.homotopy[k].nlp_status, "Solve_Succeeded") << "NLP " << k;
  }
}

// Where the quadrature is exact (Gauss-Legendre n_s = 2 on (56)) the allocation does not change
// the cost: the re-gridded points predict no gain and the search solves nothing.
TEST(AllocationSearchExactQuadrature, SolvesNothing) {
  const AllocationCase c{
      RkScheme::GaussLegendre, 2, 25, OcpInitialization::Simulation, -2.7, NAN, NAN};
  const fesd::OcpResult r = fesd::solve(sensitivity_ocp(c.guess), defaults_with(c));
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.x0()[0], fesd_bench::kSensitivityX0Star, 1e-6);
  EXPECT_EQ(r.summary.allocation_solves, 0);
}

// The re-solves after the homotopy give up after three in a row that did not converge (a
// converged one resets the count, whatever its cost); every one is booked. (Row 30 of
// docs/nosnoc-examples.md: 3 re-solves instead of 5, the same result.)
TEST(ResolveAccount, GivesUpAfterThreeFailuresInARow) {
  fesd::Summary summary;
  std::vector<fesd::HomotopyRow> rows;
  fesd::ocp_detail::ResolveAccount account{summary, rows};
  auto resolve = [&](fesd::Status status) {
    fesd::mpcc::HomotopyResult h;
    h.status = status;
    h.rows.resize(1);
    h.nlp_iterations = 100;
    account(h);
  };
  resolve(fesd::Status::NlpFailed);
  resolve(fesd::Status::ComplementarityNotMet);
  EXPECT_FALSE(account.exhausted());
  resolve(fesd::Status::Success);  // converged: the count starts again
  resolve(fesd::Status::NlpFailed);
  resolve(fesd::Status::EvaluationFailed);
  EXPECT_FALSE(account.exhausted());
  EXPECT_FALSE(account.skip());
  resolve(fesd::Status::NlpFailed);
  EXPECT_TRUE(account.exhausted());
  EXPECT_TRUE(account.skip());
  EXPECT_TRUE(account.skip());
  EXPECT_EQ(account.skipped, 2);
  EXPECT_EQ(rows.size(), 6u);
  EXPECT_EQ(summary.homotopy_steps, 6);
  EXPECT_EQ(summary.nlp_iterations, 600);
}

}  // namespace
