// src/nlp/retry_ladder.hpp: the settings a failed NLP is solved again with (IpoptSolver::solve).
//
// A failed IPOPT solve that another setting may cure is repeated from a copy of the same start,
// each run only if the one before failed too. The rungs, in order (docs/kkt-solver.md, "Retry,
// then fallback"):
//   OtherMuStrategy   a warm-started NLP whose mu strategy fesd chooses: IPOPT's monotone one
//                     (or, after a monotone first run, the adaptive one);
//   FreshScaling      on fesd's sparse LDL' with the warm-started scaling: the scaling from the
//                     identity at every factorization (kkt_scaling = fresh);
//   StricterPivoting  on the sparse LDL' below the retry's pivot tolerance: ma27_pivtol raised,
//                     with the scaling from the identity (kkt_scaling = fresh) as well;
//   Mumps             on the sparse LDL': IPOPT's MUMPS.
// The last three change the linear algebra only; a caller that handles the failure itself (the
// homotopy's smaller sigma step, or its next sigma from a feasible point; nlp::CallerHandles)
// gets it back before them.
#pragma once
#include <vector>

namespace fesd::nlp {

enum class RetryRung { OtherMuStrategy, FreshScaling, StricterPivoting, Mumps };

struct RetryLadderInput {
  bool warm_retry = false;     ///< warm-started, and [ipopt] does not set mu_strategy
  bool sparse_ldl = false;     ///< the first run factorizes with fesd's sparse LDL'
  bool fresh_scaling = false;  ///< kkt_scaling = fresh already
  double pivtol = 1e-8;        ///< the first run's ma27_pivtol
  double retry_pivtol = 1e-2;  ///< the stricter pivoting's ma27_pivtol
};

/// The rungs to try, in order, after a failed first run.
inline std::vector<RetryRung> retry_ladder(const RetryLadderInput& in) {
  std::vector<RetryRung> rungs;
  if (in.warm_retry) rungs.push_back(RetryRung::OtherMuStrategy);
  if (!in.sparse_ldl) return rungs;
  if (!in.fresh_scaling) rungs.push_back(RetryRung::FreshScaling);
  if (in.pivtol < in.retry_pivtol) rungs.push_back(RetryRung::StricterPivoting);
  rungs.push_back(RetryRung::Mumps);
  return rungs;
}

/// Whether a rung changes only how the KKT systems are solved (scaling, pivoting, solver), not
/// IPOPT's path: the rungs left out when the caller handles the failure itself. Measured on the
/// hopper sweeps since the monotone run (docs/kkt-solver.md, "The caller's retry first"): these
/// rungs solved cold NLPs only; every warm-started NLP they ran on failed on all of them (the
/// last NLPs of three sweep points, 912-1694 s per NLP) or on all that finished (two NLPs the
/// homotopy goes on from, each stopped on its MUMPS run after four failed runs: "Failures the
/// homotopy goes on from"). Before the monotone run, MUMPS solved warm NLPs that the
/// monotone run now solves.
inline bool changes_linear_algebra_only(RetryRung rung) {
  return rung != RetryRung::OtherMuStrategy;
}

/// Climbs the ladder after a failed first run: each rung in turn while `may_cure()` (the last
/// run failed in a way another setting may cure), `run(rung)` running it. Before each rung that
/// changes only the linear algebra it asks `caller_handles()` about the last run's failure and
/// stops on yes. Returns true if it stopped so (the failure is left to the caller).
template <class MayCure, class CallerHandlesNow, class Run>
bool climb(const std::vector<RetryRung>& rungs, MayCure may_cure, CallerHandlesNow caller_handles,
           Run run) {
  for (const RetryRung rung : rungs) {
    if (!may_cure()) return false;
    if (changes_linear_algebra_only(rung) && caller_handles()) return true;
    run(rung);
  }
  return false;
}

/// Whether a rung factorizes with the scaling from the identity (kkt_scaling = fresh) on the
/// sparse LDL'. The stricter pivoting does, whatever the first run's scaling: a raised pivot
/// tolerance on the warm-started scaling cascades into delayed pivots on the hopper OCPs (3.6 s
/// per IPOPT iteration on average and up to minutes, against 0.4 s fresh; docs/kkt-solver.md,
/// "The stricter pivoting's scaling").
inline bool fresh_scaling_on(RetryRung rung, const RetryLadderInput& in) {
  switch (rung) {
    case RetryRung::FreshScaling:
    case RetryRung::StricterPivoting:
      return true;
    case RetryRung::OtherMuStrategy:
      return in.fresh_scaling;
    case RetryRung::Mumps:
      return false;
  }
  return false;
}

}  // namespace fesd::nlp
