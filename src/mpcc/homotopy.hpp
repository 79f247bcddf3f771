// src/mpcc/homotopy.hpp: the MPCC of a discretization and its solution by a homotopy of relaxed
// NLPs (Sect. 5.2). Scholtes relaxation: every complementarity constraint (a sum of products of
// nonnegative variables) is imposed as  group(w) <= sigma,  sigma -> 0.
//
// Complementarity residual (what "complementarity_tol" is compared with): the largest single
// product theta_{n,m,i} * lambda_{n,m',i} over all pairs of (28), standard pairs included, i.e.
// max over residual_pairs of |a * b|. It does not depend on cross_comp_mode.
#pragma once
#include <vector>

#include "discretization/fesd_interval.hpp"
#include "fesd/integrator.hpp"
#include "fesd/options.hpp"
#include "fesd/status.hpp"
#include "nlp/block_nlp.hpp"
#include "nlp/nlp_solver.hpp"

namespace fesd::mpcc {

using discretization::CompGroup;
using discretization::CompPair;

/// max |a * b| over the pairs.
double comp_residual(const double* x, const std::vector<CompPair>& pairs);

/// Adds one row per group (Scholtes: -inf <= sum of products <= sigma); returns the rows.
std::vector<int> add_scholtes_rows(nlp::BlockNlp& nlp, const std::vector<CompGroup>& groups);
void set_sigma(nlp::BlockNlp& nlp, const std::vector<int>& rows, double sigma);

struct HomotopyResult {
  Status status = Status::NotRun;
  std::vector<HomotopyRow> rows;
  double comp_residual = 0;
  double eval_s = 0, solver_s = 0;  // evaluation time, and IPOPT time without evaluations
  int nlp_iterations = 0;
  std::string last_nlp_status;
};

/// Solves the sequence of relaxed NLPs, warm-starting each from the last. `it` holds the start
/// point on entry (primal only, or with duals) and the last solution on return.
HomotopyResult solve_homotopy(nlp::BlockNlp& nlp, const std::vector<int>& comp_rows,
                              const std::vector<CompPair>& residual_pairs, nlp::NlpSolver& solver,
                              nlp::Iterate& it, const HomotopyOptions& options);

}  // namespace fesd::mpcc
