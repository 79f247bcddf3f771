// src/mpcc/homotopy.hpp: the MPCC of a discretization and its solution by a homotopy of relaxed
// NLPs (Sect. 5.2): a sequence of smooth NLPs in which the complementarity constraints are
// relaxed, smoothed or penalized by a Relaxation (relaxation.hpp) with parameter sigma,
// sigma_0, then sigma_{k+1} = homotopy_update_slope * sigma_k down to sigma_N, each NLP
// warm-started from the last.
//
// Complementarity residual (what "complementarity_tol" is compared with): the largest single
// product theta_{n,m,i} * lambda_{n,m',i} over all pairs of (28), standard pairs included, i.e.
// max over residual_pairs of |a * b|. It depends neither on cross_comp_mode nor on mpcc_mode.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "discretization/fesd_interval.hpp"
#include "fesd/integrator.hpp"
#include "fesd/options.hpp"
#include "fesd/status.hpp"
#include "mpcc/relaxation.hpp"
#include "nlp/block_nlp.hpp"
#include "nlp/nlp_solver.hpp"

namespace fesd::mpcc {

/// max |a * b| over the pairs.
double comp_residual(const double* x, const std::vector<CompPair>& pairs);

struct HomotopyResult {
  Status status = Status::NotRun;
  std::vector<HomotopyRow> rows;
  double comp_residual = 0;
  double eval_s = 0, solver_s = 0;  // evaluation time, and IPOPT time without evaluations
  int nlp_iterations = 0;
  std::string last_nlp_status;
};

/// Solves the sequence of relaxed NLPs, warm-starting each from the last, until an NLP converges
/// with a complementarity residual <= complementarity_tol (Success), or sigma reaches sigma_N /
/// the step limit is hit. `it` holds the start point on entry (primal only, or with duals) and
/// the last solution on return. `on_row` (if set) is called after each NLP with its row.
HomotopyResult solve_homotopy(nlp::BlockNlp& nlp, const Relaxation& relaxation,
                              const std::vector<CompPair>& residual_pairs, nlp::NlpSolver& solver,
                              nlp::Iterate& it, const HomotopyOptions& options,
                              const std::function<void(const HomotopyRow&)>& on_row = {});

/// Iteration limit of solve_again: a warm-started re-solve with pinned exits converges in 10-30
/// IPOPT iterations when it converges at all; failing ones ran into the configured 500.
inline constexpr int kSolveAgainMaxIter = 100;

/// Solves the last NLP of a homotopy once more (the same sigma, the configured tolerance, at most
/// kSolveAgainMaxIter iterations, warm start from `it`) with the variable bounds and start point
/// changed by `change` (e.g. sliding exits pinned), then restores the bounds. One row, numbered
/// k; Success when it converges with a complementarity residual <= complementarity_tol. On
/// Success `it` holds the new solution, otherwise it is left as it was.
HomotopyResult solve_again(nlp::BlockNlp& nlp, const Relaxation& relaxation,
                           const std::vector<CompPair>& residual_pairs, nlp::NlpSolver& solver,
                           nlp::Iterate& it, double sigma, int k, const HomotopyOptions& options,
                           const std::function<void(nlp::BlockNlp&, std::vector<double>&)>& change);

}  // namespace fesd::mpcc
