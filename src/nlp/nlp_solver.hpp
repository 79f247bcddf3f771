// src/nlp/nlp_solver.hpp: the small interface the MPCC layer solves NLPs through. IPOPT (its KKT
// systems solved by fesd's module or MUMPS) is the one backend today; a structure-exploiting solver
// can replace it behind this interface.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fesd/options.hpp"
#include "fesd/summary.hpp"
#include "nlp/block_nlp.hpp"

namespace fesd::nlp {

/// Primal-dual point: x, constraint multipliers, bound multipliers.
struct Iterate {
  std::vector<double> x, lambda, z_L, z_U;
  bool has_duals() const { return !lambda.empty(); }
};

struct NlpResult {
  bool success = false;     ///< converged (to tol or acceptable_tol)
  bool eval_error = false;  ///< stopped because evaluations kept failing (NaN/inf)
  std::string status;       ///< backend status name, e.g. "Solve_Succeeded"
  /// KKT solver that produced the result: "dense" (LAPACK LDL'), "sparse_ldl", "mumps", IPOPT's
  /// linear_solver when the caller set that, or, when runs from the same start failed before,
  /// the last run's solver with what that run changed and the failed runs listed: "sparse_ldl
  /// (again with mu_strategy monotone from mu_init 0.0001; first run: STATUS after N
  /// iterations)", "sparse_ldl (again with ma27_pivtol 0.01; ...)", "mumps (sparse_ldl fallback;
  /// ...)"; a warm start run monotone first because an NLP before needed it: "sparse_ldl
  /// (mu_strategy monotone from mu_init 0.0001, as an NLP before needed)"; failed runs the caller
  /// handles itself (CallerHandles): "sparse_ldl (first run: ...; again with ...: ...; then left
  /// to the caller)".
  std::string linear_solver;
  int iterations = 0;  ///< IPOPT iterations; after a retry or fallback those of every run
  double objective = 0, inf_pr = 0, inf_du = 0;
  double eval_s = 0;   ///< time spent in function and derivative evaluations
  double total_s = 0;  ///< wall time of the whole solve
  double cpu_s = 0;    ///< CPU time of the calling thread in the whole solve (not other threads')
  /// Wall time in IPOPT's factorizations (its LinearSystemFactorization timer), and the number of
  /// factorizations when fesd's KKT module ran them (0 with MUMPS). Of the run reported.
  double factor_s = 0;
  long long factorizations = 0;
};

/// Whether the caller handles a failed NLP itself, given the failed result. The homotopy does
/// for a warm-started NLP: it solves it again from its last converged NLP with a smaller sigma
/// step (homotopy_retries), or goes on from a failed feasible point to the next sigma. A backend
/// then leaves out the retries that change the linear algebra (the fresh scaling, the stricter
/// pivoting and the MUMPS fallback of nlp/retry_ladder.hpp) and returns the failure: on the
/// hopper OCPs, since the retry with the other mu strategy, these cured cold NLPs only; on the last
/// NLPs of two sweep points they failed (1081 s, 1694 s) where the smaller step then solved (60 s,
/// 789 s; docs/kkt-solver.md, "The caller's retry first"), and on two NLPs the homotopy goes on
/// from they failed the fresh-scaling and pivoting runs (docs/kkt-solver.md, "Failures the homotopy
/// goes on from"). The backend asks about the last run's failure before each such retry and returns
/// it on the first yes. Empty: the caller handles no failure.
using CallerHandles = std::function<bool(const NlpResult& failed)>;

class NlpSolver {
 public:
  virtual ~NlpSolver() = default;
  /// Solves from `start` (x; with duals when warm-starting) and overwrites it with the solution.
  /// tol > 0 replaces the configured convergence tolerance for this solve when it is looser
  /// (the early NLPs of a homotopy); 0 keeps it. max_iter > 0 replaces the configured iteration
  /// limit when it is lower; 0 keeps it. `caller_handles` (may be empty): see CallerHandles.
  virtual NlpResult solve(const BlockNlp& nlp, Iterate& start, bool warm_start, double tol,
                          int max_iter, const CallerHandles& caller_handles) = 0;
  /// From now on, each solve calls `on_progress` after an iteration at most every `every_s`
  /// seconds of wall time (0: after every iteration); an empty callback: never (the default).
  void set_progress(NlpProgressCallback on_progress, double every_s) {
    on_progress_ = std::move(on_progress);
    progress_every_s_ = every_s;
  }

 protected:
  NlpProgressCallback on_progress_;
  double progress_every_s_ = 0;
};

/// The NLP solver every front end uses: IPOPT with fesd's KKT module or MUMPS (kkt_solver).
/// One factory, so that another backend can replace IPOPT without touching a front end. Throws
/// fesd::InvalidOption if the backend rejects an option (the message names it).
std::unique_ptr<NlpSolver> make_solver(const NlpOptions& options);

/// Valid settings the backend cannot honour as well as asked, one sentence each: kkt_solver =
/// auto when fesd's KKT module (libfesd_kkt.so, next to libfesd.so) cannot be loaded, so that
/// every KKT system goes to MUMPS (the same iterates up to round-off, 4-5x the time per IPOPT
/// iteration on the hopper OCP). The front ends add them to Summary::warnings; the CLI prints them
/// before a run. An explicit kkt_solver = sparse_ldl or dense without the module is an error
/// (make_solver throws).
std::vector<std::string> warnings(const NlpOptions& options);

}  // namespace fesd::nlp
