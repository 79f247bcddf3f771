// The settings a failed NLP is solved again with (src/nlp/retry_ladder.hpp), in order.
#include <vector>

#include <gtest/gtest.h>

#include "nlp/retry_ladder.hpp"

namespace {

using fesd::nlp::fresh_scaling_on;
using fesd::nlp::retry_ladder;
using fesd::nlp::RetryLadderInput;
using Rung = fesd::nlp::RetryRung;

TEST(RetryLadder, SparseLdlTriesTheFreshScalingBeforeTheStricterPivoting) {
  // A warm-started NLP on the sparse LDL' with fesd's defaults: every rung.
  EXPECT_EQ(retry_ladder({.warm_retry = true, .sparse_ldl = true}),
            (std::vector{Rung::OtherMuStrategy, Rung::FreshScaling, Rung::StricterPivoting,
                         Rung::Mumps}));
  // A cold NLP (the first of a homotopy): no other mu strategy.
  EXPECT_EQ(retry_ladder({.sparse_ldl = true}),
            (std::vector{Rung::FreshScaling, Rung::StricterPivoting, Rung::Mumps}));
}

TEST(RetryLadder, SkipsWhatTheFirstRunAlreadyHad) {
  // kkt_scaling = fresh: no fresh-scaling run.
  EXPECT_EQ(retry_ladder({.sparse_ldl = true, .fresh_scaling = true}),
            (std::vector{Rung::StricterPivoting, Rung::Mumps}));
  // [ipopt] ma27_pivtol at or above the retry's: no stricter pivoting.
  EXPECT_EQ(retry_ladder({.sparse_ldl = true, .pivtol = 1e-2, .retry_pivtol = 1e-2}),
            (std::vector{Rung::FreshScaling, Rung::Mumps}));
  EXPECT_EQ(retry_ladder({.sparse_ldl = true, .pivtol = 0.5, .retry_pivtol = 1e-2}),
            (std::vector{Rung::FreshScaling, Rung::Mumps}));
}

TEST(RetryLadder, StricterPivotingFactorizesWithTheFreshScaling) {
  const RetryLadderInput warm{.warm_retry = true, .sparse_ldl = true};
  EXPECT_FALSE(fresh_scaling_on(Rung::OtherMuStrategy, warm));
  EXPECT_TRUE(fresh_scaling_on(Rung::FreshScaling, warm));
  EXPECT_TRUE(fresh_scaling_on(Rung::StricterPivoting, warm));
  const RetryLadderInput fresh{.warm_retry = true, .sparse_ldl = true, .fresh_scaling = true};
  EXPECT_TRUE(fresh_scaling_on(Rung::OtherMuStrategy, fresh));
  EXPECT_TRUE(fresh_scaling_on(Rung::StricterPivoting, fresh));
}

TEST(RetryLadder, OnlyTheMuStrategyRunsBeforeTheCallerHandlesIt) {
  // A caller that handles the failure itself (the homotopy) gets it back after the mu strategy's
  // run: the other rungs only change the linear algebra.
  EXPECT_FALSE(fesd::nlp::changes_linear_algebra_only(Rung::OtherMuStrategy));
  EXPECT_TRUE(fesd::nlp::changes_linear_algebra_only(Rung::FreshScaling));
  EXPECT_TRUE(fesd::nlp::changes_linear_algebra_only(Rung::StricterPivoting));
  EXPECT_TRUE(fesd::nlp::changes_linear_algebra_only(Rung::Mumps));
}

/// climb() with runs that fail until `solved_on` (or never), recording the rungs run.
struct FakeLadder {
  std::vector<Rung> ran;
  bool failed = true;
  std::vector<Rung> run(const std::vector<Rung>& rungs, int caller_handles_from, int solved_on,
                        bool* left) {
    *left = fesd::nlp::climb(
        rungs, [&] { return failed; },
        [&] { return static_cast<int>(ran.size()) >= caller_handles_from; },
        [&](Rung rung) {
          ran.push_back(rung);
          failed = static_cast<int>(ran.size()) != solved_on;
        });
    return ran;
  }
};

TEST(RetryLadder, ClimbStopsWhereTheCallerHandles) {
  const std::vector<Rung> warm = retry_ladder({.warm_retry = true, .sparse_ldl = true});
  constexpr int kNever = 100;
  bool left = false;
  // The caller handles every failure: only the mu strategy's run, then back to the caller.
  EXPECT_EQ(FakeLadder{}.run(warm, 0, kNever, &left), (std::vector{Rung::OtherMuStrategy}));
  EXPECT_TRUE(left);
  // It does not: every rung.
  EXPECT_EQ(FakeLadder{}.run(warm, kNever, kNever, &left), warm);
  EXPECT_FALSE(left);
  // Solved by the fresh scaling: no further rung, nothing left to the caller.
  EXPECT_EQ(FakeLadder{}.run(warm, kNever, 2, &left),
            (std::vector{Rung::OtherMuStrategy, Rung::FreshScaling}));
  EXPECT_FALSE(left);
  // Asked again before each rung about the last run's failure: a caller that handles only the
  // failure of the second run (e.g. the homotopy, with its retries spent, where only that run ends
  // at a feasible point it goes on from) gets it back there.
  EXPECT_EQ(FakeLadder{}.run(warm, 2, kNever, &left),
            (std::vector{Rung::OtherMuStrategy, Rung::FreshScaling}));
  EXPECT_TRUE(left);
  // Without a mu-strategy rung (a cold NLP, or [ipopt] mu_strategy): back before any run.
  EXPECT_TRUE(FakeLadder{}.run(retry_ladder({.sparse_ldl = true}), 0, kNever, &left).empty());
  EXPECT_TRUE(left);
}

TEST(RetryLadder, OtherSolversOnlyChangeTheMuStrategy) {
  // MUMPS, the dense LDL' or an [ipopt] linear_solver: no scaling, pivoting or fallback rungs.
  EXPECT_EQ(retry_ladder({.warm_retry = true}), (std::vector{Rung::OtherMuStrategy}));
  EXPECT_TRUE(retry_ladder({}).empty());
  EXPECT_TRUE(retry_ladder({.fresh_scaling = true}).empty());
}

}  // namespace
