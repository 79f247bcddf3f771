// tests/mpcc/relaxation_test.cpp: the MPCC solution methods (MpccMode, src/mpcc/relaxation.hpp)
// on a two-variable MPCC with a known solution, through the integrator on Example 3(a), and the
// rules every mode keeps: two-sided groups stay Scholtes rows, Fischer-Burmeister needs groups
// with a common factor.
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "discretization/fesd_interval.hpp"
#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/model.hpp"
#include "fesd/problem_file.hpp"
#include "mpcc/problem.hpp"
#include "nlp/block.hpp"
#include "nlp/nlp_solver.hpp"

namespace {

using fesd::MpccMode;

constexpr MpccMode kAllModes[] = {MpccMode::ScholtesIneq,      MpccMode::ScholtesEq,
                                  MpccMode::FischerBurmeister, MpccMode::L1Penalty,
                                  MpccMode::ElasticIneq,       MpccMode::ElasticTwoSided};

std::string mode_name(const ::testing::TestParamInfo<MpccMode>& p) {
  return std::string(fesd::to_string(p.param));
}

// ---- a two-variable MPCC ---------------------------------------------------------------------

/// (x - 1)^2 + (y - a)^2
struct DistanceTo {
  double a = 1.0;
  int num_inputs() const { return 2; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    c[0] = (w[0] - 1.0) * (w[0] - 1.0) + (w[1] - a) * (w[1] - a);
  }
};

/// Adds x, y >= 0 from (0.9, 0.2) and weight * ((x - 1)^2 + (y - a)^2) to `nlp`; returns the pair
/// 0 <= x _|_ y >= 0 (not yet added to any problem).
fesd::mpcc::CompPair add_tiny_mpcc(fesd::nlp::BlockNlp& nlp, double a = 1.0, double weight = 1.0) {
  const int x = nlp.add_variables(1, 0.0, fesd::nlp::kInf, 0.9);
  const int y = nlp.add_variables(1, 0.0, fesd::nlp::kInf, 0.2);
  nlp.add_objective(fesd::nlp::make_block(DistanceTo{a}), {x, y}, weight);
  return {x, y};
}

// min (x - 1)^2 + (y - 1)^2  s.t.  0 <= x _|_ y >= 0, from (0.9, 0.2). The MPCC has two
// minimizers, (1, 0) and (0, 1), both with objective 1; the start lies on the side of (1, 0).
class TinyMpcc : public ::testing::TestWithParam<MpccMode> {};
TEST_P(TinyMpcc, ReachesTheLocalMinimizerOfTheStart) {
  fesd::mpcc::Problem problem;
  const auto [x, y] = add_tiny_mpcc(problem.nlp());
  const std::vector<fesd::mpcc::CompPair> pairs{{x, y}};
  problem.add_complementarity({fesd::mpcc::CompGroup{pairs}}, pairs);
  problem.relax(GetParam());
  EXPECT_EQ(problem.mpcc_mode(), GetParam());
  problem.finalize();

  const auto solver = fesd::nlp::make_solver(fesd::NlpOptions{});
  int rows_seen = 0;
  // Not sigma_0 = 1: the first relaxed NLP would then have its solution on the problem's axis of
  // symmetry x = y ((1, 1) for the Scholtes and Fischer-Burmeister relaxations, (2/3, 2/3) for
  // the penalties) and lose the start; the homotopy then follows x = y = sqrt(sigma) and round-off
  // decides between (1, 0) and (0, 1). From sigma_0 = 0.1 every mode keeps the start's side.
  fesd::HomotopyOptions options;
  options.sigma_0 = 0.1;
  const auto res = problem.solve_homotopy(*solver, options, [&](const fesd::HomotopyRow& r) {
    EXPECT_EQ(r.k, rows_seen);
    ++rows_seen;
  });
  ASSERT_EQ(res.status, fesd::Status::Success) << res.last_nlp_status;
  EXPECT_EQ(rows_seen, static_cast<int>(res.rows.size()));
  EXPECT_LE(res.comp_residual, options.complementarity_tol);
  const std::vector<double>& w = problem.solution();
  EXPECT_NEAR(w[x], 1.0, 1e-6);
  EXPECT_NEAR(w[y], 0.0, 1e-6);
  const double f = (w[x] - 1) * (w[x] - 1) + (w[y] - 1) * (w[y] - 1);
  EXPECT_NEAR(f, 1.0, 1e-6);
}
INSTANTIATE_TEST_SUITE_P(Modes, TinyMpcc, ::testing::ValuesIn(kAllModes), mode_name);

// ---- objective_scaling_direct ------------------------------------------------------------

// The mode classes that the relaxation, the CLI header and these tests share.
static_assert(fesd::is_elastic(MpccMode::ElasticIneq) &&
              fesd::is_elastic(MpccMode::ElasticTwoSided));
static_assert(!fesd::is_elastic(MpccMode::ScholtesIneq) &&
              !fesd::is_elastic(MpccMode::ScholtesEq) &&
              !fesd::is_elastic(MpccMode::FischerBurmeister) &&
              !fesd::is_elastic(MpccMode::L1Penalty));
static_assert(fesd::penalizes(MpccMode::L1Penalty) && fesd::penalizes(MpccMode::ElasticIneq) &&
              fesd::penalizes(MpccMode::ElasticTwoSided));
static_assert(!fesd::penalizes(MpccMode::ScholtesIneq) && !fesd::penalizes(MpccMode::ScholtesEq) &&
              !fesd::penalizes(MpccMode::FischerBurmeister));

// nosnoc's inverse scaling (objective_scaling_direct = false): a penalty mode's NLP objective is
// sigma J + P instead of J + (1/sigma) P, i.e. exactly sigma times it, at every point and sigma,
// with the gradient scaled alike; modes without a penalty term ignore the setting. On the
// two-variable MPCC both scalings reach the start's minimizer (1, 0).
TEST(ObjectiveScaling, InverseIsSigmaTimesDirect) {
  const std::vector<double> point{0.7, 0.3, 0.25};  // x, y, and s where a mode has it
  for (MpccMode mode : kAllModes) {
    const bool penalty = fesd::penalizes(mode);
    fesd::nlp::BlockNlp nlps[2];
    std::vector<fesd::mpcc::Relaxation> relaxations;
    for (const bool direct : {true, false}) {
      fesd::nlp::BlockNlp& nlp = nlps[direct ? 0 : 1];
      const std::vector<fesd::mpcc::CompPair> pairs{add_tiny_mpcc(nlp, 1.0, 2.0)};
      relaxations.emplace_back(nlp, std::vector{fesd::mpcc::CompGroup{pairs}}, mode,
                               fesd::nlp::kInf, 0.0, direct);
      nlp.finalize();
    }
    const int n = nlps[0].num_variables();
    ASSERT_EQ(n, nlps[1].num_variables());
    // Not starting at 1: the weights must come from the saved ones, not the current ones (a
    // retry sets sigma back up).
    for (double sigma : {1e-3, 0.5, 1e-6, 1.0}) {
      double f[2];
      std::vector<double> grad[2];
      for (int k = 0; k < 2; ++k) {
        relaxations[k].set_sigma(nlps[k], sigma);
        std::vector<double> w(nlps[k].x_init);
        for (int i = 0; i < n && i < 3; ++i)
          if (nlps[k].x_lb[i] < nlps[k].x_ub[i]) w[i] = point[i];
        grad[k].resize(n);
        ASSERT_TRUE(nlps[k].eval_f(w.data(), f[k]));
        ASSERT_TRUE(nlps[k].eval_grad_f(w.data(), grad[k].data()));
      }
      const double scale = penalty ? sigma : 1.0;
      EXPECT_NEAR(f[1], scale * f[0], 1e-14 * std::abs(f[1]) + 1e-300)
          << fesd::to_string(mode) << " sigma " << sigma;
      for (int i = 0; i < n; ++i)
        EXPECT_NEAR(grad[1][i], scale * grad[0][i], 1e-14 * std::abs(grad[1][i]) + 1e-300)
            << fesd::to_string(mode) << " sigma " << sigma << " variable " << i;
    }
    if (!penalty) continue;
    fesd::mpcc::Problem problem;
    const auto [x, y] = add_tiny_mpcc(problem.nlp());
    const std::vector<fesd::mpcc::CompPair> pairs{{x, y}};
    problem.add_complementarity({fesd::mpcc::CompGroup{pairs}}, pairs);
    problem.relax(mode, fesd::nlp::kInf, 0.0, /*scaling_direct=*/false);
    problem.finalize();
    const auto solver = fesd::nlp::make_solver(fesd::NlpOptions{});
    fesd::HomotopyOptions options;
    options.sigma_0 = 0.1;  // as TinyMpcc
    const auto res = problem.solve_homotopy(*solver, options);
    ASSERT_EQ(res.status, fesd::Status::Success) << fesd::to_string(mode);
    EXPECT_NEAR(problem.solution()[x], 1.0, 1e-6) << fesd::to_string(mode);
    EXPECT_NEAR(problem.solution()[y], 0.0, 1e-6) << fesd::to_string(mode);
  }
}

// ---- intermediate_tol ---------------------------------------------------------------------

/// IPOPT, recording the tolerance the homotopy asks for in each NLP (0: the configured one).
class RecordingSolver : public fesd::nlp::NlpSolver {
 public:
  fesd::nlp::NlpResult solve(const fesd::nlp::BlockNlp& nlp, fesd::nlp::Iterate& start,
                             bool warm_start, double tol, int max_iter,
                             const fesd::nlp::CallerHandles& caller_handles) override {
    tols.push_back(tol);
    max_iters.push_back(max_iter);
    return inner_->solve(nlp, start, warm_start, tol, max_iter, caller_handles);
  }
  std::vector<double> tols;
  std::vector<int> max_iters;

 private:
  std::unique_ptr<fesd::nlp::NlpSolver> inner_ = fesd::nlp::make_solver(fesd::NlpOptions{});
};

struct TinyProblem {
  fesd::mpcc::Problem problem;
  int x = 0, y = 0;
  explicit TinyProblem(double a, MpccMode mode = MpccMode::ScholtesIneq) {
    const fesd::mpcc::CompPair xy = add_tiny_mpcc(problem.nlp(), a);
    x = xy.a;
    y = xy.b;
    const std::vector<fesd::mpcc::CompPair> pairs{{x, y}};
    problem.add_complementarity({fesd::mpcc::CompGroup{pairs}}, pairs);
    problem.relax(mode);
    problem.finalize();
  }
  /// The homotopy sigma = 0.1, 0.01, ... with intermediate_tol 1e-6, from (0.9, 0.2).
  fesd::mpcc::HomotopyResult solve(RecordingSolver& solver) {
    fesd::HomotopyOptions options;
    options.sigma_0 = 0.1;
    options.intermediate_tol = 1e-6;
    return problem.solve_homotopy(solver, options);
  }
  double at(int var) const { return problem.solution()[var]; }
};

// sigma = 0.1, 0.01, ..., 1e-9 with complementarity_tol 1e-9: the NLPs with sigma > 1e-8 get
// intermediate_tol, the last two the configured tol; the solution is the same as with tight NLPs.
TEST(IntermediateTol, EarlyNlpsLooseLastNlpsTight) {
  TinyProblem p(1.0);
  RecordingSolver solver;
  const auto res = p.solve(solver);
  ASSERT_EQ(res.status, fesd::Status::Success) << res.last_nlp_status;
  ASSERT_EQ(solver.tols.size(), 9u);  // sigma = 1e-1 .. 1e-9
  for (std::size_t k = 0; k < 7; ++k) EXPECT_EQ(solver.tols[k], 1e-6) << "NLP " << k;
  EXPECT_EQ(solver.tols[7], 0.0);
  EXPECT_EQ(solver.tols[8], 0.0);
  EXPECT_NEAR(p.at(p.x), 1.0, 1e-6);
  EXPECT_NEAR(p.at(p.y), 0.0, 1e-6);
}

// min (x - 1)^2 + (y + 1)^2, 0 <= x _|_ y >= 0: the solution (1, 0) has no active product, so the
// first (loose) NLP already meets complementarity_tol. It is solved once more, tight, at the same
// sigma, and the homotopy stops.
TEST(IntermediateTol, ToleranceMetLooselyIsSolvedAgainTight) {
  TinyProblem p(-1.0);
  RecordingSolver solver;
  const auto res = p.solve(solver);
  ASSERT_EQ(res.status, fesd::Status::Success) << res.last_nlp_status;
  ASSERT_EQ(solver.tols.size(), 2u);
  EXPECT_EQ(solver.tols[0], 1e-6);
  EXPECT_EQ(solver.tols[1], 0.0);
  ASSERT_EQ(res.rows.size(), 2u);
  EXPECT_EQ(res.rows[0].sigma, res.rows[1].sigma);
  EXPECT_NEAR(p.at(p.x), 1.0, 1e-8);
  EXPECT_NEAR(p.at(p.y), 0.0, 1e-8);
}

// ---- solve_again (pinned sliding exits) --------------------------------------------------------

// After the homotopy (solution (1, 0)): bounds changed for one more NLP at the last sigma, then
// restored. A feasible change gives its solution; an infeasible one (x = 2 and y >= 1, so
// x y >= 2 > sigma) leaves the point as it was.
TEST(SolveAgain, ChangesBoundsForOneNlpAndKeepsThePointIfItFails) {
  TinyProblem p(1.0);
  RecordingSolver solver;
  const auto res = p.solve(solver);
  ASSERT_EQ(res.status, fesd::Status::Success) << res.last_nlp_status;
  const double sigma = res.rows.back().sigma;
  const int k_next = static_cast<int>(res.rows.size());
  std::vector<double> lb, ub;
  for (int v : {p.x, p.y}) {
    lb.push_back(p.problem.lower(v));
    ub.push_back(p.problem.upper(v));
  }
  auto bounds_kept = [&] {
    EXPECT_EQ(p.problem.lower(p.x), lb[0]);
    EXPECT_EQ(p.problem.lower(p.y), lb[1]);
    EXPECT_EQ(p.problem.upper(p.x), ub[0]);
    EXPECT_EQ(p.problem.upper(p.y), ub[1]);
  };
  fesd::HomotopyOptions options;

  const auto capped = p.problem.solve_again(solver, options, {{p.x, 0.0, 0.5}}, 1);
  ASSERT_EQ(capped.status, fesd::Status::Success) << capped.last_nlp_status;
  ASSERT_EQ(capped.rows.size(), 1u);
  EXPECT_EQ(capped.rows[0].k, k_next);
  EXPECT_EQ(capped.rows[0].sigma, sigma);  // sigma stays inside the problem
  EXPECT_EQ(capped.rows[0].pinned_exits, 1);
  EXPECT_EQ(solver.tols.back(), 0.0);  // the configured tolerance
  EXPECT_EQ(solver.max_iters.back(), fesd::mpcc::kSolveAgainMaxIter);
  EXPECT_EQ(solver.max_iters.front(), 0);  // the homotopy's NLPs: the configured limit
  EXPECT_NEAR(p.at(p.x), 0.5, 1e-8);
  EXPECT_NEAR(p.at(p.y), 0.0, 1e-8);
  bounds_kept();

  const std::vector<double> before = p.problem.solution();
  const auto infeasible =
      p.problem.solve_again(solver, options, {{p.x, 2.0, 2.0}, {p.y, 1.0, fesd::nlp::kInf}});
  EXPECT_NE(infeasible.status, fesd::Status::Success);
  EXPECT_EQ(infeasible.rows[0].k, k_next + 1);
  EXPECT_EQ(p.problem.solution(), before);
  bounds_kept();
}

// ---- homotopy_retries -------------------------------------------------------------------------

/// IPOPT, except that the NLPs numbered in `fail` (0-based calls) report a failure and leave a
/// useless point (x = y = 5) behind, as a locally infeasible NLP does (reported primal
/// infeasibility `inf_pr`).
class FailingSolver : public fesd::nlp::NlpSolver {
 public:
  /// The calls in `feasible` fail too, but report inf_pr 1e-9 (a failure that ends feasible,
  /// e.g. at max_iter).
  explicit FailingSolver(std::vector<int> fail, double inf_pr = 1.0, std::vector<int> feasible = {})
      : fail_(std::move(fail)), feasible_(std::move(feasible)), inf_pr_(inf_pr) {}
  fesd::nlp::NlpResult solve(const fesd::nlp::BlockNlp& nlp, fesd::nlp::Iterate& start,
                             bool warm_start, double tol, int max_iter,
                             const fesd::nlp::CallerHandles& caller_handles) override {
    starts.push_back(start.x);
    warm.push_back(warm_start);
    const int call = calls_++;
    const bool feasible = std::find(feasible_.begin(), feasible_.end(), call) != feasible_.end();
    if (!feasible && std::find(fail_.begin(), fail_.end(), call) == fail_.end()) {
      caller_handles_failure.push_back(-1);
      return inner_->solve(nlp, start, warm_start, tol, max_iter, caller_handles);
    }
    std::fill(start.x.begin(), start.x.end(), 5.0);
    fesd::nlp::NlpResult r;
    r.status = "Infeasible_Problem_Detected";
    r.inf_pr = feasible ? 1e-9 : inf_pr_;
    // The homotopy's answer for this failure (IPOPT's ladder asks it about the statuses it
    // retries, not Infeasible_Problem_Detected; the answer does not read the status).
    caller_handles_failure.push_back(caller_handles && caller_handles(r) ? 1 : 0);
    return r;
  }
  std::vector<std::vector<double>> starts;  ///< the primal start of every call
  std::vector<bool> warm;                   ///< warm_start of every call
  /// Per call: whether the homotopy said it handles the call's failure itself (1: retries it or
  /// goes on from it) or not (0); -1 for a call that did not fail.
  std::vector<int> caller_handles_failure;

 private:
  std::vector<int> fail_, feasible_;
  double inf_pr_ = 1.0;
  int calls_ = 0;
  std::unique_ptr<fesd::nlp::NlpSolver> inner_ = fesd::nlp::make_solver(fesd::NlpOptions{});
};

std::vector<double> sigmas(const fesd::mpcc::HomotopyResult& res) {
  std::vector<double> s;
  for (const fesd::HomotopyRow& r : res.rows) s.push_back(r.sigma);
  return s;
}

// sigma_0 = 0.1, slope 0.1; the third NLP (sigma = 1e-3) fails. With retries the homotopy goes
// back to the point of sigma = 1e-2, solves at sqrt(1e-2 * 1e-3), then at 1e-3 again and on; the
// retried row is marked and the result is the MPCC's solution (1, 0). Without, it goes on from the
// failed point.
TEST(HomotopyRetries, FailedNlpIsSolvedAgainFromTheLastConvergedOne) {
  fesd::HomotopyOptions options;
  options.sigma_0 = 0.1;
  options.homotopy_retries = 4;
  TinyProblem p(1.0);
  FailingSolver solver({2});
  const auto res = p.problem.solve_homotopy(solver, options);
  ASSERT_EQ(res.status, fesd::Status::Success) << res.last_nlp_status;
  const std::vector<double> s = sigmas(res);
  ASSERT_GE(s.size(), 6u);
  EXPECT_NEAR(s[2], 1e-3, 1e-18);
  EXPECT_TRUE(res.rows[2].retried);
  EXPECT_NEAR(s[3], std::pow(10.0, -2.5), 1e-17);
  EXPECT_NEAR(s[4], 1e-3, 1e-18);
  EXPECT_NEAR(s[5], 1e-4, 1e-19);
  for (std::size_t k = 0; k < res.rows.size(); ++k) {
    if (k != 2) {
      EXPECT_FALSE(res.rows[k].retried) << "row " << k;
    }
  }
  // The retry starts from the point of sigma = 1e-2, not from the failed one.
  EXPECT_EQ(solver.starts[3][p.x], solver.starts[2][p.x]);
  EXPECT_NEAR(p.at(p.x), 1.0, 1e-6);
  EXPECT_NEAR(p.at(p.y), 0.0, 1e-6);

  options.homotopy_retries = 0;
  options.homotopy_cold_restart = false;
  TinyProblem q(1.0);
  FailingSolver plain({2});
  const auto res0 = q.problem.solve_homotopy(plain, options);
  const std::vector<double> s0 = sigmas(res0);
  ASSERT_GE(s0.size(), 4u);
  EXPECT_NEAR(s0[3], 1e-4, 1e-19);
  EXPECT_FALSE(res0.rows[2].retried);
  EXPECT_EQ(plain.starts[3][q.x], 5.0);  // on from the failed point

  // A failed NLP whose point satisfies the constraints (reported inf_pr 1e-9) is kept too.
  options.homotopy_retries = 4;
  TinyProblem f(1.0);
  FailingSolver feasible({2}, 1e-9);
  const auto res_f = f.problem.solve_homotopy(feasible, options);
  ASSERT_GE(res_f.rows.size(), 4u);
  EXPECT_FALSE(res_f.rows[2].retried);
  EXPECT_NEAR(res_f.rows[3].sigma, 1e-4, 1e-19);

  // A retry that fails but ends feasible is kept (the homotopy goes on from it to the failed
  // sigma); when the failed sigma fails again, the next retry halves the step to the retry's
  // sigma instead of repeating it (10^-2.5 once, then 10^-2.25).
  TinyProblem r(1.0);
  FailingSolver kept({2, 4}, 1.0, /*feasible=*/{3});
  const auto res_k = r.problem.solve_homotopy(kept, options);
  ASSERT_EQ(res_k.status, fesd::Status::Success) << res_k.last_nlp_status;
  const std::vector<double> sk = sigmas(res_k);
  ASSERT_GE(sk.size(), 7u);
  EXPECT_NEAR(sk[2], 1e-3, 1e-18);
  EXPECT_TRUE(res_k.rows[2].retried);
  EXPECT_NEAR(sk[3], std::pow(10.0, -2.5), 1e-17);  // fails feasible: kept
  EXPECT_FALSE(res_k.rows[3].retried);
  EXPECT_NEAR(sk[4], 1e-3, 1e-18);  // from the kept point; fails
  EXPECT_TRUE(res_k.rows[4].retried);
  EXPECT_NEAR(sk[5], std::pow(10.0, -2.25), 1e-17);
  EXPECT_EQ(kept.starts[5][r.x], kept.starts[2][r.x]);  // from the point of sigma = 1e-2
  EXPECT_NEAR(sk[6], 1e-3, 1e-18);
  EXPECT_NEAR(r.at(r.x), 1.0, 1e-6);
  EXPECT_NEAR(r.at(r.y), 0.0, 1e-6);
}

// Every NLP after the first fails: at most homotopy_retries retries, each halving the logarithmic
// step from the converged sigma = 1, then the homotopy goes on (and fails).
TEST(HomotopyRetries, AtMostTheConfiguredNumber) {
  fesd::HomotopyOptions options;
  options.sigma_0 = 1.0;
  options.homotopy_retries = 3;
  options.homotopy_cold_restart = false;
  TinyProblem p(1.0);
  FailingSolver solver({1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19});
  const auto res = p.problem.solve_homotopy(solver, options);
  EXPECT_EQ(res.status, fesd::Status::NlpFailed);
  const std::vector<double> s = sigmas(res);
  ASSERT_GE(s.size(), 6u);
  EXPECT_NEAR(s[1], 0.1, 1e-16);
  EXPECT_NEAR(s[2], std::pow(10.0, -0.5), 1e-15);
  EXPECT_NEAR(s[3], std::pow(10.0, -0.25), 1e-15);
  EXPECT_NEAR(s[4], std::pow(10.0, -0.125), 1e-15);
  EXPECT_NEAR(s[5], 0.1, 1e-16);  // budget spent: on to the schedule's sigma
  int retried = 0;
  for (const fesd::HomotopyRow& r : res.rows) retried += r.retried ? 1 : 0;
  EXPECT_EQ(retried, 3);
  // The schedule's 13 NLPs (sigma = 1 .. 1e-12) plus the three retried NLPs and the smaller step
  // after the last: those do not count towards N_homotopy.
  EXPECT_EQ(s.size(), 17u);
  EXPECT_NEAR(s.back(), 1e-12, 1e-24);
}

// ---- homotopy_cold_restart --------------------------------------------------------------------

/// sigma = 0.1, 0.01, ... down to sigma_N, which is also complementarity_tol.
fesd::HomotopyOptions homotopy_down_to(double sigma_N, int retries) {
  fesd::HomotopyOptions options;
  options.sigma_0 = 0.1;
  options.sigma_N = sigma_N;
  options.complementarity_tol = sigma_N;
  options.homotopy_retries = retries;
  return options;
}

// The schedule's last NLP (sigma = 1e-3 = sigma_N) fails at a feasible point (as row 28's Stewart
// point N_stages = 84 of docs/nosnoc-examples.md, Restoration_Failed at inf_pr 0): the homotopy
// cannot go on from it, so it is retried like an infeasible failure, from the point of sigma =
// 1e-2, and ends at the MPCC's solution. Without retries: nlp_failed at the failed point.
TEST(HomotopyRetries, FeasibleFailureOfTheLastNlpIsRetried) {
  TinyProblem p(1.0);
  FailingSolver solver({}, 1.0, /*feasible=*/{2});
  const auto res = p.problem.solve_homotopy(solver, homotopy_down_to(1e-3, 4));
  ASSERT_EQ(res.status, fesd::Status::Success) << res.last_nlp_status;
  const std::vector<double> s = sigmas(res);
  ASSERT_EQ(s.size(), 5u);
  EXPECT_TRUE(res.rows[2].retried);
  EXPECT_NEAR(s[3], std::pow(10.0, -2.5), 1e-17);
  EXPECT_NEAR(s[4], 1e-3, 1e-18);
  EXPECT_EQ(solver.starts[3][p.x], solver.starts[2][p.x]);  // from the point of sigma = 1e-2
  EXPECT_NEAR(p.at(p.x), 1.0, 2e-3);
  EXPECT_NEAR(p.at(p.y), 0.0, 2e-3);
  // The NLP solver was told so, and leaves out its linear-algebra fallbacks.
  EXPECT_EQ(solver.caller_handles_failure, (std::vector{-1, -1, 1, -1, -1}));

  TinyProblem q(1.0);
  FailingSolver plain({}, 1.0, /*feasible=*/{2});
  const auto res0 = q.problem.solve_homotopy(plain, homotopy_down_to(1e-3, 0));
  EXPECT_EQ(res0.status, fesd::Status::NlpFailed);
  ASSERT_EQ(res0.rows.size(), 3u);
  EXPECT_FALSE(res0.rows[2].retried);
  EXPECT_EQ(q.at(q.x), 5.0);
  EXPECT_EQ(plain.caller_handles_failure, (std::vector{-1, -1, 0}));  // no retry: every fallback
}

// Which failures the homotopy tells the NLP solver it handles itself (nlp::CallerHandles): those
// it then retries (infeasible, or the schedule's last NLP, with a converged NLP before it and
// retries left) and, after a warm start, those at a feasible point that it goes on from (not the
// schedule's last); no other. Calls: sigma = 0.1 (call 0), 0.01, 1e-3, ... (complementarity_tol
// 1e-6).
TEST(HomotopyRetries, TellsTheNlpSolverWhichFailuresItHandles) {
  fesd::HomotopyOptions options = homotopy_down_to(1e-6, 4);
  options.homotopy_cold_restart = false;
  // The first NLP: nothing converged before it, so no retry (IPOPT keeps its whole ladder).
  TinyProblem p(1.0);
  FailingSolver first({0});
  const auto res_first = p.problem.solve_homotopy(first, options);
  ASSERT_FALSE(first.caller_handles_failure.empty());
  EXPECT_EQ(first.caller_handles_failure[0], 0);
  EXPECT_FALSE(res_first.rows[0].retried);
  // An infeasible failure in the middle (call 1, sigma = 0.01): retried at 10^-1.5 (call 2),
  // whose infeasible failure is retried too (at 10^-1.25, call 3); then 0.01 (call 4) and 1e-3
  // (call 5), whose failure ends feasible: the homotopy goes on from it, and the solver is told
  // so too.
  TinyProblem q(1.0);
  FailingSolver middle({1, 2}, 1.0, /*feasible=*/{5});
  const auto res_middle = q.problem.solve_homotopy(middle, options);
  ASSERT_GE(middle.caller_handles_failure.size(), 6u);
  EXPECT_EQ(
      std::vector(middle.caller_handles_failure.begin(), middle.caller_handles_failure.begin() + 6),
      (std::vector{-1, 1, 1, -1, -1, 1}));
  EXPECT_TRUE(res_middle.rows[1].retried);
  EXPECT_TRUE(res_middle.rows[2].retried);
  EXPECT_FALSE(res_middle.rows[5].retried);
  ASSERT_GE(res_middle.rows.size(), 7u);
  EXPECT_NEAR(res_middle.rows[6].sigma, 1e-4, 1e-18);  // on from the failed point
  EXPECT_EQ(middle.starts[6][q.x], 5.0);
  // A feasible failure of the first (cold) NLP: the homotopy goes on from it too, but the
  // solver keeps its fallbacks, which cure cold NLPs.
  TinyProblem c(1.0);
  FailingSolver cold({}, 1.0, /*feasible=*/{0});
  const auto res_cold = c.problem.solve_homotopy(cold, options);
  ASSERT_FALSE(cold.caller_handles_failure.empty());
  EXPECT_EQ(cold.caller_handles_failure[0], 0);
  ASSERT_GE(res_cold.rows.size(), 2u);
  EXPECT_NEAR(res_cold.rows[1].sigma, 0.01, 1e-17);
  // With the retries used up, a failure is not retried and the solver keeps its fallbacks.
  options.homotopy_retries = 1;
  TinyProblem r(1.0);
  FailingSolver spent({1, 2});
  const auto res_spent = r.problem.solve_homotopy(spent, options);
  ASSERT_GE(spent.caller_handles_failure.size(), 3u);
  EXPECT_EQ(spent.caller_handles_failure[1], 1);
  EXPECT_TRUE(res_spent.rows[1].retried);
  EXPECT_EQ(spent.caller_handles_failure[2], 0);
  EXPECT_FALSE(res_spent.rows[2].retried);
  // ... unless it ends feasible and is not the schedule's last: the homotopy goes on from it.
  // Here the retry step itself (10^-1.5, call 2) fails so, and the homotopy goes on from its
  // point to 0.01.
  TinyProblem f(1.0);
  FailingSolver spent_feasible({1}, 1.0, /*feasible=*/{2});
  const auto res_spent_feasible = f.problem.solve_homotopy(spent_feasible, options);
  ASSERT_GE(spent_feasible.caller_handles_failure.size(), 3u);
  EXPECT_EQ(spent_feasible.caller_handles_failure[1], 1);
  EXPECT_EQ(spent_feasible.caller_handles_failure[2], 1);
  EXPECT_FALSE(res_spent_feasible.rows[2].retried);
  ASSERT_GE(res_spent_feasible.rows.size(), 4u);
  EXPECT_NEAR(res_spent_feasible.rows[3].sigma, 0.01, 1e-17);
  EXPECT_EQ(spent_feasible.starts[3][f.x], 5.0);
  // The tight re-solve at a loosely converged NLP's sigma has no smaller step to take: a failure
  // there is not retried (min (x - 1)^2 + (y + 1)^2 meets complementarity at the first NLP).
  TinyProblem t(-1.0);
  fesd::HomotopyOptions loose = options;
  loose.intermediate_tol = 1e-6;
  loose.homotopy_retries = 4;
  FailingSolver tight({1});
  const auto res_tight = t.problem.solve_homotopy(tight, loose);
  ASSERT_GE(res_tight.rows.size(), 2u);
  EXPECT_EQ(res_tight.rows[1].sigma, res_tight.rows[0].sigma);
  ASSERT_GE(tight.caller_handles_failure.size(), 2u);
  EXPECT_EQ(tight.caller_handles_failure[1], 0);
  EXPECT_FALSE(res_tight.rows[1].retried);
  // A feasible failure there, with NLPs left in the schedule: the homotopy goes on from it to the
  // next sigma, so the solver is told it handles it.
  TinyProblem tf(-1.0);
  FailingSolver tight_feasible({}, 1.0, /*feasible=*/{1});
  const auto res_tight_feasible = tf.problem.solve_homotopy(tight_feasible, loose);
  ASSERT_GE(res_tight_feasible.rows.size(), 3u);
  EXPECT_EQ(res_tight_feasible.rows[1].sigma, res_tight_feasible.rows[0].sigma);
  ASSERT_GE(tight_feasible.caller_handles_failure.size(), 2u);
  EXPECT_EQ(tight_feasible.caller_handles_failure[1], 1);
  EXPECT_NEAR(res_tight_feasible.rows[2].sigma, 0.01, 1e-17);
  // The cold restart's NLP (from the initial guess, without multipliers) keeps the solver's
  // fallbacks even where it fails feasible: sigma = 0.1, 0.01, 1e-3, 1e-4 without retries; 1e-3
  // and 1e-4 fail infeasible (not retried: the solver keeps its fallbacks), the restart at 1e-3
  // (call 4) fails feasible.
  TinyProblem cr(1.0);
  FailingSolver restart({2, 3}, 1.0, /*feasible=*/{4});
  const auto res_restart = cr.problem.solve_homotopy(restart, homotopy_down_to(1e-4, 0));
  ASSERT_GE(res_restart.rows.size(), 5u);
  EXPECT_TRUE(res_restart.rows[4].cold_start);
  ASSERT_GE(restart.caller_handles_failure.size(), 5u);
  EXPECT_EQ(std::vector(restart.caller_handles_failure.begin(),
                        restart.caller_handles_failure.begin() + 5),
            (std::vector{-1, -1, 0, 0, 0}));
}

// sigma = 0.1, 0.01, 1e-3, 1e-4 (complementarity_tol 1e-4), no retries. The NLPs at 1e-3 and 1e-4
// fail at points that violate the constraints, so the homotopy would end nlp_failed: it solves
// sigma = 1e-3 again from the initial guess (cold), and goes on from there to the MPCC's solution
// (1, 0) relaxed by sigma = 1e-4. The rows from the first failure on are marked. Without the
// option: nlp_failed.
TEST(HomotopyColdRestart, FailedHomotopyStartsAgainFromTheInitialGuess) {
  fesd::HomotopyOptions options = homotopy_down_to(1e-4, 0);
  ASSERT_TRUE(options.homotopy_cold_restart);  // the default
  TinyProblem p(1.0);
  FailingSolver solver({2, 3});
  const auto res = p.problem.solve_homotopy(solver, options);
  ASSERT_EQ(res.status, fesd::Status::Success) << res.last_nlp_status;
  const std::vector<double> s = sigmas(res);
  ASSERT_EQ(s.size(), 6u);
  EXPECT_NEAR(s[3], 1e-4, 1e-19);  // on from the failed point first
  EXPECT_EQ(solver.starts[3][p.x], 5.0);
  EXPECT_NEAR(s[4], 1e-3, 1e-18);  // then the cold restart at the first failure's sigma
  EXPECT_TRUE(res.rows[4].cold_start);
  EXPECT_FALSE(solver.warm[4]);
  EXPECT_EQ(solver.starts[4][p.x], solver.starts[0][p.x]);  // the initial guess
  EXPECT_EQ(solver.starts[4][p.y], solver.starts[0][p.y]);
  EXPECT_TRUE(solver.warm[5]);  // and warm again after it
  EXPECT_NEAR(s[5], 1e-4, 1e-19);
  for (std::size_t k = 0; k < res.rows.size(); ++k) {
    EXPECT_EQ(res.rows[k].restarted, k == 2 || k == 3) << "row " << k;
    EXPECT_EQ(res.rows[k].cold_start, k == 4) << "row " << k;
    EXPECT_FALSE(res.rows[k].retried) << "row " << k;
  }
  EXPECT_NEAR(p.at(p.x), 1.0, 2e-4);  // the solution relaxed by sigma_N = 1e-4
  EXPECT_NEAR(p.at(p.y), 0.0, 2e-4);
  EXPECT_NE(fesd::mpcc::cold_restart_warning(res).find("sigma = 0.001"), std::string::npos);

  options.homotopy_cold_restart = false;
  TinyProblem q(1.0);
  FailingSolver plain({2, 3});
  const auto res0 = q.problem.solve_homotopy(plain, options);
  EXPECT_EQ(res0.status, fesd::Status::NlpFailed);
  EXPECT_EQ(res0.rows.size(), 4u);
  for (const fesd::HomotopyRow& r : res0.rows) EXPECT_FALSE(r.cold_start || r.restarted);
  EXPECT_TRUE(fesd::mpcc::cold_restart_warning(res0).empty());
}

// No cold restart where the homotopy does not end failed: a failure it recovers from on the way
// (nosnoc_py's discs, docs/nosnoc-examples.md row 22, go on from an NLP at inf_pr 5.5e-3 to a
// better end than a cold start finds), and a failure that ends feasible.
TEST(HomotopyColdRestart, OnlyWhenTheHomotopyEndsFailed) {
  fesd::HomotopyOptions options = homotopy_down_to(1e-4, 0);
  TinyProblem p(1.0);
  FailingSolver recovers({2});
  const auto res = p.problem.solve_homotopy(recovers, options);
  ASSERT_EQ(res.status, fesd::Status::Success) << res.last_nlp_status;
  ASSERT_EQ(res.rows.size(), 4u);
  EXPECT_EQ(recovers.starts[3][p.x], 5.0);  // on from the failed point
  for (const fesd::HomotopyRow& r : res.rows) EXPECT_FALSE(r.cold_start || r.restarted);

  TinyProblem f(1.0);
  FailingSolver feasible({}, 1.0, /*feasible=*/{2, 3});
  const auto res_f = f.problem.solve_homotopy(feasible, options);
  EXPECT_EQ(res_f.status, fesd::Status::NlpFailed);
  for (const fesd::HomotopyRow& r : res_f.rows) EXPECT_FALSE(r.cold_start || r.restarted);
}

// After the retries: the cold restart goes to the schedule's sigma the failed retry was heading
// to (not the retry's), and it is taken once per homotopy.
TEST(HomotopyColdRestart, AfterTheRetriesAtTheSchedulesSigmaOnce) {
  fesd::HomotopyOptions options = homotopy_down_to(1e-3, 2);
  TinyProblem p(1.0);
  FailingSolver solver({2, 3, 4, 5});
  const auto res = p.problem.solve_homotopy(solver, options);
  ASSERT_EQ(res.status, fesd::Status::Success) << res.last_nlp_status;
  const std::vector<double> s = sigmas(res);
  ASSERT_EQ(s.size(), 7u);
  EXPECT_TRUE(res.rows[2].retried);
  EXPECT_TRUE(res.rows[3].retried);
  EXPECT_NEAR(s[4], std::pow(10.0, -2.25), 1e-17);  // the last retry's sigma; fails
  EXPECT_NEAR(s[5], 1e-3, 1e-18);                   // on from it; fails
  EXPECT_NEAR(s[6], 1e-3, 1e-18);
  for (std::size_t k = 0; k < res.rows.size(); ++k) {
    EXPECT_EQ(res.rows[k].restarted, k == 4 || k == 5) << "row " << k;
    EXPECT_EQ(res.rows[k].cold_start, k == 6) << "row " << k;
  }
  EXPECT_EQ(solver.starts[6][p.x], solver.starts[0][p.x]);

  // Every NLP after the first fails: one cold restart, then the homotopy ends failed.
  TinyProblem q(1.0);
  FailingSolver all({1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19});
  options.homotopy_retries = 0;
  const auto res_all = q.problem.solve_homotopy(all, options);
  EXPECT_EQ(res_all.status, fesd::Status::NlpFailed);
  int cold = 0;
  for (const fesd::HomotopyRow& r : res_all.rows) cold += r.cold_start ? 1 : 0;
  EXPECT_EQ(cold, 1);
  EXPECT_TRUE(res_all.rows[1].restarted);
  EXPECT_NEAR(res_all.rows[1].sigma, 0.01, 1e-17);
}

/// What a scripted call of StallingSolver returns: the point (x, y), and converged or failed.
struct Step {
  double x = 0, y = 0;
  bool ok = true;     ///< Solve_Succeeded; else a failure with inf_pr
  double inf_pr = 0;  ///< 1: a point violating the constraints
};

// An NLP solver that reports given calls as converged (Solve_Succeeded) or failed at a given point
// (x, y) of TinyProblem, and solves the others: a penalty NLP that ends at a stationary point of
// its penalty has the complementarity residual x y.
class StallingSolver : public fesd::nlp::NlpSolver {
 public:
  StallingSolver(int x, int y, std::map<int, Step> steps)
      : x_(x), y_(y), steps_(std::move(steps)) {}
  fesd::nlp::NlpResult solve(const fesd::nlp::BlockNlp& nlp, fesd::nlp::Iterate& start,
                             bool warm_start, double tol, int max_iter,
                             const fesd::nlp::CallerHandles& caller_handles) override {
    starts.push_back(start.x);
    warm.push_back(warm_start);
    tols.push_back(tol);
    const auto it = steps_.find(calls_++);
    if (it == steps_.end())
      return inner_->solve(nlp, start, warm_start, tol, max_iter, caller_handles);
    start.x[x_] = it->second.x;
    start.x[y_] = it->second.y;
    fesd::nlp::NlpResult r;
    r.success = it->second.ok;
    r.inf_pr = it->second.inf_pr;
    r.status = r.success ? "Solve_Succeeded" : "Infeasible_Problem_Detected";
    return r;
  }
  std::vector<std::vector<double>> starts;  ///< the primal start of every call
  std::vector<bool> warm;                   ///< warm_start of every call
  std::vector<double> tols;                 ///< tol of every call (0: the configured one)

 private:
  int x_, y_;
  std::map<int, Step> steps_;
  int calls_ = 0;
  std::unique_ptr<fesd::nlp::NlpSolver> inner_ = fesd::nlp::make_solver(fesd::NlpOptions{});
};

// A stalled penalty (docs/formulation.md, "A stalled penalty"): elastic_ineq, sigma = 0.1, 0.01,
// 1e-3, 1e-4 (complementarity_tol 1e-4). The first NLP ends with the residual 0.4, those at
// 0.01, 1e-3 and 1e-4 at the same point with 0.21, more than half that of their start although
// the weight 1 / sigma grew: the homotopy would end complementarity_not_met there, so it starts
// again at 0.01 (the first stalled NLP) from the initial guess and reaches the MPCC's solution
// (1, 0). Without the option: complementarity_not_met at 0.21.
TEST(HomotopyColdRestart, StalledPenaltyStartsAgainFromTheInitialGuess) {
  fesd::HomotopyOptions options = homotopy_down_to(1e-4, 0);
  TinyProblem p(1.0, MpccMode::ElasticIneq);
  const Step stuck{0.5, 0.42};
  StallingSolver solver(p.x, p.y, {{0, {0.5, 0.8}}, {1, stuck}, {2, stuck}, {3, stuck}});
  const auto res = p.problem.solve_homotopy(solver, options);
  ASSERT_EQ(res.status, fesd::Status::Success) << res.last_nlp_status;
  ASSERT_GE(res.rows.size(), 5u);
  EXPECT_NEAR(res.rows[1].comp_residual, 0.21, 1e-15);
  EXPECT_NEAR(res.rows[4].sigma, 0.01, 1e-17);
  EXPECT_FALSE(solver.warm[4]);
  EXPECT_EQ(solver.starts[4][p.x], solver.starts[0][p.x]);  // the initial guess
  EXPECT_EQ(solver.starts[4][p.y], solver.starts[0][p.y]);
  for (std::size_t k = 0; k < res.rows.size(); ++k) {
    EXPECT_EQ(res.rows[k].stalled, k == 1) << "row " << k;  // the first stall only
    EXPECT_EQ(res.rows[k].restarted, k >= 1 && k <= 3) << "row " << k;
    EXPECT_EQ(res.rows[k].cold_start, k == 4) << "row " << k;
  }
  EXPECT_NEAR(p.at(p.x), 1.0, 1e-4);
  EXPECT_NEAR(p.at(p.y), 0.0, 1e-4);
  const std::string w = fesd::mpcc::cold_restart_warning(res);
  EXPECT_NE(w.find("stalled since the NLP at sigma = 0.01"), std::string::npos) << w;

  options.homotopy_cold_restart = false;
  TinyProblem q(1.0, MpccMode::ElasticIneq);
  StallingSolver plain(q.x, q.y, {{0, {0.5, 0.8}}, {1, stuck}, {2, stuck}, {3, stuck}});
  const auto res0 = q.problem.solve_homotopy(plain, options);
  EXPECT_EQ(res0.status, fesd::Status::ComplementarityNotMet);
  ASSERT_EQ(res0.rows.size(), 4u);
  EXPECT_TRUE(res0.rows[1].stalled);
  for (const fesd::HomotopyRow& r : res0.rows) EXPECT_FALSE(r.cold_start || r.restarted);
  EXPECT_TRUE(fesd::mpcc::cold_restart_warning(res0).empty());
}

// What a stall is: the residual of a converged penalty NLP above half that of the point it
// started from, sigma having fallen. 0.4 -> 0.19 is not one (less than half), 0.19 -> 0.18 is;
// the restart goes to that NLP's sigma (1e-3). (The first NLP is given too: the real one meets
// complementarity at once.) In the Scholtes modes sigma bounds every product,
// so the same points are no stall: complementarity_not_met, no restart. A stall the homotopy
// recovers from (the next NLP solves) changes nothing.
TEST(HomotopyColdRestart, StallIsAResidualAboveHalfItsStart) {
  const fesd::HomotopyOptions options = homotopy_down_to(1e-4, 0);
  const std::map<int, Step> points{
      {0, {0.5, 0.8}}, {1, {0.5, 0.38}}, {2, {0.5, 0.36}}, {3, {0.5, 0.36}}};
  TinyProblem p(1.0, MpccMode::ElasticIneq);
  StallingSolver solver(p.x, p.y, points);
  const auto res = p.problem.solve_homotopy(solver, options);
  ASSERT_EQ(res.status, fesd::Status::Success) << res.last_nlp_status;
  ASSERT_GE(res.rows.size(), 5u);
  EXPECT_FALSE(res.rows[1].stalled);
  EXPECT_TRUE(res.rows[2].stalled);
  EXPECT_TRUE(res.rows[4].cold_start);
  EXPECT_NEAR(res.rows[4].sigma, 1e-3, 1e-18);

  TinyProblem s(1.0, MpccMode::ScholtesIneq);
  StallingSolver scholtes(s.x, s.y, points);
  const auto res_s = s.problem.solve_homotopy(scholtes, options);
  EXPECT_EQ(res_s.status, fesd::Status::ComplementarityNotMet);
  for (const fesd::HomotopyRow& r : res_s.rows) EXPECT_FALSE(r.stalled || r.cold_start);

  TinyProblem q(1.0, MpccMode::ElasticIneq);
  StallingSolver recovers(q.x, q.y, {{0, {0.5, 0.8}}, {1, {0.5, 0.42}}});
  const auto res_q = q.problem.solve_homotopy(recovers, options);
  ASSERT_EQ(res_q.status, fesd::Status::Success) << res_q.last_nlp_status;
  EXPECT_TRUE(res_q.rows[1].stalled);
  for (const fesd::HomotopyRow& r : res_q.rows) EXPECT_FALSE(r.cold_start || r.restarted);
}

// The stall and the failure rungs together (elastic_ineq, retries 0 unless said; the first NLP
// ends with the residual 0.4, "stuck" converges with 0.21, "infeasible" fails at inf_pr 1):
// a) a stall followed by a failed last NLP (feasible: no failure rung) restarts at the stall;
// b) an infeasible failure the path goes on from, then a stall to the end: restarts at the stall
//    (each rung keeps its own first NLP);
// c) a stall, then infeasible failures to the end: restarts at the failure, as without the stall;
// d) a stall on a retry's smaller step (retries 4): restarts at the schedule's sigma it was
//    heading to, and the warning names both sigmas;
// e) a stall that partly recovers (ends above complementarity_tol but below half the stalled
//    residual): no restart.
TEST(HomotopyColdRestart, StallAndFailureKeepTheirOwnRestartPoints) {
  const Step first{0.5, 0.8}, stuck{0.5, 0.42}, infeasible{5.0, 5.0, false, 1.0};
  const auto run = [](std::map<int, Step> steps, int retries, double sigma_N = 1e-4) {
    auto p = std::make_unique<TinyProblem>(1.0, MpccMode::ElasticIneq);
    StallingSolver solver(p->x, p->y, std::move(steps));
    auto res = p->problem.solve_homotopy(solver, homotopy_down_to(sigma_N, retries));
    return std::pair{std::move(res), std::move(solver)};
  };
  const auto cold_row = [](const fesd::mpcc::HomotopyResult& res) {
    for (std::size_t k = 0; k < res.rows.size(); ++k)
      if (res.rows[k].cold_start) return static_cast<int>(k);
    return -1;
  };
  {  // a)
    const auto [res, solver] =
        run({{0, first}, {1, stuck}, {2, stuck}, {3, {0.5, 0.42, false, 1e-9}}}, 0);
    ASSERT_EQ(cold_row(res), 4);
    EXPECT_NEAR(res.rows[4].sigma, 0.01, 1e-17);
    EXPECT_TRUE(res.rows[1].restarted);
    EXPECT_EQ(res.status, fesd::Status::Success);
  }
  {  // b)
    const auto [res, solver] =
        run({{0, first}, {1, infeasible}, {2, stuck}, {3, stuck}, {4, stuck}}, 0, 1e-5);
    EXPECT_FALSE(res.rows[1].stalled);  // (its start is the failed point: 25)
    EXPECT_TRUE(res.rows[3].stalled);   // 0.21 after 0.21 at sigma = 1e-4
    ASSERT_EQ(cold_row(res), 5);
    EXPECT_NEAR(res.rows[5].sigma, 1e-4, 1e-19);
    EXPECT_FALSE(res.rows[2].restarted);
    EXPECT_TRUE(res.rows[3].restarted);
    EXPECT_NE(fesd::mpcc::cold_restart_warning(res).find("stalled since the NLP at sigma = 0.0001"),
              std::string::npos);
  }
  {  // c)
    const auto [res, solver] = run({{0, first}, {1, stuck}, {2, infeasible}, {3, infeasible}}, 0);
    EXPECT_TRUE(res.rows[1].stalled);
    ASSERT_EQ(cold_row(res), 4);
    EXPECT_NEAR(res.rows[4].sigma, 1e-3, 1e-18);
    EXPECT_FALSE(res.rows[1].restarted);
    EXPECT_NE(fesd::mpcc::cold_restart_warning(res).find("had failed"), std::string::npos);
    EXPECT_EQ(res.status, fesd::Status::Success);
  }
  {  // d) 0.01 fails; the retry at 10^-1.5 stalls (0.21 after 0.4 from the point of 0.1)
    const auto [res, solver] =
        run({{0, first}, {1, infeasible}, {2, stuck}, {3, stuck}, {4, stuck}, {5, stuck}}, 4);
    ASSERT_TRUE(res.rows[1].retried);
    EXPECT_NEAR(res.rows[2].sigma, std::pow(10.0, -1.5), 1e-17);
    EXPECT_TRUE(res.rows[2].stalled);
    const int c = cold_row(res);
    ASSERT_GT(c, 2);
    EXPECT_NEAR(res.rows[static_cast<std::size_t>(c)].sigma, 0.01, 1e-17);
    const std::string w = fesd::mpcc::cold_restart_warning(res);
    EXPECT_NE(w.find("stalled since the NLP at sigma = 0.0316"), std::string::npos) << w;
    EXPECT_NE(w.find("started again at sigma = 0.01"), std::string::npos) << w;
  }
  {  // e)
    const auto [res, solver] = run({{0, first}, {1, stuck}, {2, {0.5, 0.1}}, {3, {0.5, 0.1}}}, 0);
    EXPECT_TRUE(res.rows[1].stalled);
    EXPECT_EQ(cold_row(res), -1);
    EXPECT_EQ(res.status, fesd::Status::ComplementarityNotMet);
  }
}

// A failure of the tight re-solve of the schedule's last NLP (Scholtes, 2 NLPs, intermediate_tol:
// sigma = 0.01 meets complementarity_tol loosely and is solved again tight, which fails
// infeasible): the cold restart solves that tight NLP again from the initial guess. (It used to
// run no NLP: the schedule was already counted without the tight re-solve.)
TEST(HomotopyColdRestart, RestartOfTheTightResolveSolvesIt) {
  fesd::HomotopyOptions o = homotopy_down_to(1e-4, 0);
  o.max_homotopy_steps = 2;
  o.intermediate_tol = 1e-6;
  TinyProblem p(1.0);
  StallingSolver solver(p.x, p.y, {{0, {0.5, 0.8}}, {1, {1.0, 0.0}}, {2, {5.0, 5.0, false, 1.0}}});
  const auto res = p.problem.solve_homotopy(solver, o);
  ASSERT_EQ(res.rows.size(), 4u);
  EXPECT_EQ(res.rows[2].sigma, res.rows[1].sigma);  // the tight re-solve
  EXPECT_TRUE(res.rows[2].restarted);
  EXPECT_TRUE(res.rows[3].cold_start);
  EXPECT_EQ(res.rows[3].sigma, res.rows[1].sigma);
  EXPECT_EQ(solver.tols[1], 1e-6);
  EXPECT_EQ(solver.tols[3], 0.0);  // tight, as the NLP it replaces
  EXPECT_EQ(res.rows[3].nlp_status, "Solve_Succeeded");
  // (That point is the relaxed one of sigma = 0.01, the schedule's last: residual 0.01.)
  EXPECT_EQ(res.status, fesd::Status::ComplementarityNotMet);
}

// ---- Example 3(a) through the integrator ------------------------------------------------------

// x' in 2 - sign(x): c = x, region 0 (x > 0) gives 1, region 1 (x < 0) gives 3.
struct Crossing {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int region, const T*, const T*, const T*, T* f) const {
    f[0] = T(region == 0 ? 1.0 : 3.0);
  }
};

fesd::Pss crossing_model() {
  return fesd::make_pss(Crossing{},
                        fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
}

// x(0) = -1: switch at t_s = 1/3, x(T) = T - 1/3. With stage_sum every mode reaches
// complementarity_tol = 1e-9 on every step.
class CrossingEveryMode : public ::testing::TestWithParam<MpccMode> {};
TEST_P(CrossingEveryMode, SwitchAtOneThird) {
  fesd::IntegratorOptions o;
  o.discretization.cross_comp = fesd::CrossComp::StageSum;
  o.homotopy.mpcc_mode = GetParam();
  Eigen::VectorXd x0(1);
  x0 << -1.0;
  const double T = 1.9;
  const auto r = fesd::integrate(crossing_model(), x0, T, 7, o);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_EQ(r.switches.size(), 1U);
  EXPECT_NEAR(r.switches[0].t, 1.0 / 3.0, 1e-6);
  EXPECT_NEAR(r.x_final()[0], T - 1.0 / 3.0, 1e-6);
  EXPECT_LE(r.summary.max_comp_residual, 1e-9);
}
INSTANTIATE_TEST_SUITE_P(Modes, CrossingEveryMode, ::testing::ValuesIn(kAllModes), mode_name);

// ---- the interval's groups, built without solving --------------------------------------------

struct Built {
  fesd::nlp::BlockNlp nlp;
  std::unique_ptr<fesd::discretization::FesdInterval> iv;
};

std::unique_ptr<Built> build(fesd::RkScheme scheme, int n_s, fesd::StageLambdaSign sign,
                             fesd::CrossComp cross) {
  static const fesd::Pss model = crossing_model();
  fesd::DiscretizationOptions d;
  d.rk_scheme = scheme;
  d.n_s = n_s;
  d.N_FE = 3;
  d.stage_lambda_sign = sign;
  d.cross_comp = cross;
  auto b = std::make_unique<Built>();
  auto fixed = [&](int n) {
    std::vector<int> v;
    const int first = b->nlp.add_variables(n, 0.0, 0.0, 0.0);
    for (int i = 0; i < n; ++i) v.push_back(first + i);
    return v;
  };
  fesd::discretization::IntervalInputs in;
  in.s0 = fixed(1);
  in.lambda_start = fixed(model.n_theta());
  in.mu_start = fixed(model.n_sys());
  in.T = 1.0;
  b->iv = std::make_unique<fesd::discretization::FesdInterval>(model,
                                                               fesd::make_tableau(scheme, n_s), d);
  b->iv->build(b->nlp, in);
  return b;
}

// Element and neighbor groups sum products of different thetas and lambdas: not one pair that a
// C-function could smooth.
TEST(FischerBurmeister, NeedsGroupsWithACommonFactor) {
  for (auto cross : {fesd::CrossComp::Element, fesd::CrossComp::Neighbor}) {
    auto b = build(fesd::RkScheme::RadauIIA, 2, fesd::StageLambdaSign::All, cross);
    try {
      fesd::mpcc::Relaxation(b->nlp, b->iv->groups(), MpccMode::FischerBurmeister);
      ADD_FAILURE() << "no exception for cross_comp_mode " << fesd::to_string(cross);
    } catch (const fesd::InvalidOption& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("fischer_burmeister"), std::string::npos) << msg;
      EXPECT_NE(msg.find("cross_comp_mode sparse or stage_sum"), std::string::npos) << msg;
    }
  }
  for (auto cross : {fesd::CrossComp::Sparse, fesd::CrossComp::StageSum}) {
    auto b = build(fesd::RkScheme::RadauIIA, 2, fesd::StageLambdaSign::All, cross);
    EXPECT_NO_THROW(fesd::mpcc::Relaxation(b->nlp, b->iv->groups(), MpccMode::FischerBurmeister));
  }
}

TEST(FischerBurmeister, IntegratorRejectsElementForm) {
  fesd::IntegratorOptions o;
  o.discretization.cross_comp = fesd::CrossComp::Element;
  o.homotopy.mpcc_mode = MpccMode::FischerBurmeister;
  Eigen::VectorXd x0(1);
  x0 << -1.0;
  EXPECT_THROW(fesd::integrate(crossing_model(), x0, 1.0, 2, o), fesd::InvalidOption);
  // ... and so does the option validation (fesd check), naming both keys.
  const std::vector<std::string> e = fesd::validate(o);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("homotopy.mpcc_mode = fischer_burmeister"), std::string::npos) << e[0];
  EXPECT_NE(e[0].find("discretization.cross_comp_mode sparse or stage_sum (got element"),
            std::string::npos)
      << e[0];
  o.discretization.cross_comp = fesd::CrossComp::StageSum;
  EXPECT_TRUE(fesd::validate(o).empty());
}

// Free-sign lambdas (stage_lambda_sign = boundary, explicit RK: 3 elements x 2 stages x 2 regions)
// give two-sided groups. In every mode they stay rows -sigma <= theta * lambda <= sigma, with the
// plain product as the row function; the other groups take the mode's form.
class TwoSided : public ::testing::TestWithParam<MpccMode> {};
TEST_P(TwoSided, StayScholtesRowsInEveryMode) {
  const MpccMode mode = GetParam();
  auto b = build(fesd::RkScheme::ExplicitRK, 2, fesd::StageLambdaSign::Boundary,
                 fesd::CrossComp::StageSum);
  auto& nlp = b->nlp;
  const auto& groups = b->iv->groups();
  const fesd::mpcc::Relaxation relaxation(nlp, groups, mode);
  const double sigma = 1e-3;
  relaxation.set_sigma(nlp, sigma);
  for (std::size_t i = 0; i < nlp.x_init.size(); ++i)  // a point with nonzero products
    nlp.x_init[i] = 0.3 + 0.01 * static_cast<double>(i % 17);
  nlp.finalize();
  std::vector<double> g(nlp.num_constraints());
  ASSERT_TRUE(nlp.eval_g(nlp.x_init.data(), g.data()));

  ASSERT_EQ(relaxation.group_rows().size(), groups.size());
  int two_sided = 0;
  for (std::size_t k = 0; k < groups.size(); ++k) {
    const int row = relaxation.group_rows()[k];
    double product_sum = 0;
    for (const auto& p : groups[k].pairs) product_sum += nlp.x_init[p.a] * nlp.x_init[p.b];
    if (mode == MpccMode::ElasticTwoSided) {  // every group: G - s <= 0 (and G + s >= 0)
      two_sided += groups[k].two_sided ? 1 : 0;
      ASSERT_GE(row, 0);
      EXPECT_EQ(nlp.g_lb[row], -fesd::nlp::kInf);
      EXPECT_EQ(nlp.g_ub[row], 0.0);
      EXPECT_DOUBLE_EQ(g[row], product_sum - nlp.x_init[relaxation.elastic_variable()]);
      EXPECT_EQ(nlp.g_lb[row + 1], 0.0);
      EXPECT_EQ(nlp.g_ub[row + 1], fesd::nlp::kInf);
      EXPECT_DOUBLE_EQ(g[row + 1], product_sum + nlp.x_init[relaxation.elastic_variable()]);
      continue;
    }
    if (groups[k].two_sided) {
      ++two_sided;
      ASSERT_GE(row, 0);
      EXPECT_EQ(nlp.g_lb[row], -sigma);
      EXPECT_EQ(nlp.g_ub[row], sigma);
      EXPECT_DOUBLE_EQ(g[row], product_sum);
      continue;
    }
    switch (mode) {
      case MpccMode::ScholtesIneq:
        EXPECT_EQ(nlp.g_lb[row], -fesd::nlp::kInf);
        EXPECT_EQ(nlp.g_ub[row], sigma);
        break;
      case MpccMode::ScholtesEq:
        EXPECT_EQ(nlp.g_lb[row], sigma);
        EXPECT_EQ(nlp.g_ub[row], sigma);
        break;
      case MpccMode::FischerBurmeister:
        EXPECT_EQ(nlp.g_lb[row], 0.0);
        EXPECT_EQ(nlp.g_ub[row], 0.0);
        break;
      case MpccMode::L1Penalty:
        EXPECT_EQ(row, -1);  // an objective term
        break;
      case MpccMode::ElasticIneq:
        EXPECT_EQ(nlp.g_ub[row], 0.0);
        EXPECT_DOUBLE_EQ(g[row], product_sum - nlp.x_init[relaxation.elastic_variable()]);
        break;
      case MpccMode::ElasticTwoSided:
        break;  // above
    }
  }
  EXPECT_EQ(two_sided, 3 * 2 * 2);
  if (mode == MpccMode::FischerBurmeister) {
    const int v = relaxation.sigma_variable();
    ASSERT_GE(v, 0);
    EXPECT_EQ(nlp.x_lb[v], sigma);
    EXPECT_EQ(nlp.x_ub[v], sigma);
  } else {
    EXPECT_EQ(relaxation.sigma_variable(), -1);
  }
  EXPECT_EQ(relaxation.elastic_variable() >= 0, fesd::is_elastic(mode));
}
INSTANTIATE_TEST_SUITE_P(Modes, TwoSided, ::testing::ValuesIn(kAllModes), mode_name);

// The elastic variable s of elastic_ineq and elastic_two_sided is nosnoc's s_elastic: s in
// [0, s_elastic_max] starting at s_elastic_0, fesd's defaults unbounded (1e20) and 0, nosnoc's
// (MATLAB nosnoc and nosnoc_py alike) 10 and 1; sigma changes only its objective weight 1 / sigma,
// not its bounds.
TEST(ElasticVariable, BoundsAndStart) {
  for (MpccMode mode : {MpccMode::ElasticIneq, MpccMode::ElasticTwoSided}) {
    for (const bool nosnoc : {false, true}) {
      auto b =
          build(fesd::RkScheme::RadauIIA, 2, fesd::StageLambdaSign::All, fesd::CrossComp::StageSum);
      auto& nlp = b->nlp;
      const fesd::HomotopyOptions def;
      const double s_max = nosnoc ? 10.0 : def.s_elastic_max;
      const double s_0 = nosnoc ? 1.0 : def.s_elastic_0;
      const fesd::mpcc::Relaxation relaxation(nlp, b->iv->groups(), mode, s_max, s_0);
      const int v = relaxation.elastic_variable();
      ASSERT_GE(v, 0) << fesd::to_string(mode);
      for (double sigma : {1.0, 1e-3}) {
        relaxation.set_sigma(nlp, sigma);
        EXPECT_EQ(nlp.x_lb[v], 0.0) << fesd::to_string(mode);
        EXPECT_EQ(nlp.x_ub[v], nosnoc ? 10.0 : 1e20) << fesd::to_string(mode);
        EXPECT_EQ(nlp.x_init[v], nosnoc ? 1.0 : 0.0) << fesd::to_string(mode);
      }
    }
  }
}

// ---- the option -------------------------------------------------------------------------------

TEST(MpccModeOption, ReadFromProblemFilesAndOverrides) {
  auto q = fesd::parse_simulation_problem(R"toml(
[model]
x = ["x"]
c = ["x"]
F = [["3"], ["1"]]
x0 = [-1.0]
[simulation]
T_sim = 1.0
[homotopy]
mpcc_mode = "ell_1_penalty"
)toml",
                                          "mpcc.toml");
  EXPECT_EQ(q.options.homotopy.mpcc_mode, MpccMode::L1Penalty);
  for (MpccMode m : kAllModes) {
    fesd::apply_override(q, "mpcc_mode", fesd::to_string(m));
    EXPECT_EQ(q.options.homotopy.mpcc_mode, m);
  }
  EXPECT_EQ(fesd::IntegratorOptions{}.homotopy.mpcc_mode, MpccMode::ScholtesIneq);
  EXPECT_THROW(fesd::apply_override(q, "homotopy.mpcc_mode", "fb"), fesd::Error);
}

}  // namespace
