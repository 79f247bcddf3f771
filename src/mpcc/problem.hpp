// src/mpcc/problem.hpp: the MPCC of a discretization, (60) of papers/fesd-filippov.txt: an NLP
// assembled from blocks plus complementarity constraints, solved by a homotopy of relaxed NLPs
// (Sect. 5.2). The integrator (one Problem per step length and element count) and the optimal
// control solver (one Problem per OCP) build it, fix its inputs, set a guess and solve it; neither
// edits NLP bounds nor creates an NLP solver itself.
//
// Two parts, as Crocoddyl's model/data:
//   description  built once: variables, blocks, complementarity groups and residual pairs, the
//                relaxation of the groups in one MpccMode (relaxation.hpp); frozen by finalize().
//   workspace    changed between solves: fixed inputs (start state, controls, parameters), the
//                guess, the last iterate with its duals, and the sigma the last homotopy ended at
//                (solve_again() re-solves at that sigma; sigma never leaves the Problem).
//
// Complementarity residual (what "complementarity_tol" is compared with): the largest single
// product theta_{n,m,i} * lambda_{n,m',i} over all pairs of (28), standard pairs included, i.e.
// max over the residual pairs of |a * b|. It depends neither on cross_comp_mode nor on mpcc_mode.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "fesd/options.hpp"
#include "fesd/status.hpp"
#include "fesd/summary.hpp"
#include "mpcc/relaxation.hpp"
#include "nlp/block_nlp.hpp"
#include "nlp/nlp_solver.hpp"

namespace fesd::mpcc {

/// max |a * b| over the pairs.
double comp_residual(const double* x, const std::vector<CompPair>& pairs);

/// What one homotopy (or one re-solve) did.
struct HomotopyResult {
  Status status = Status::NotRun;
  std::vector<HomotopyRow> rows;
  double comp_residual = 0;
  double eval_s = 0, solver_s = 0;  ///< evaluation time, and NLP solver time without evaluations
  int nlp_iterations = 0;
  std::string last_nlp_status;
  /// Set by the caller when the result is that of a re-solve with the active set fixed.
  bool active_set_fixed = false;
};

/// Appends the rows and work of `from` (a re-solve) to `to`; the residual and last status become
/// those of `from`.
void append(HomotopyResult& to, const HomotopyResult& from);
/// Appends the rows and work of `from`, a re-solve whose point was discarded (it failed, or the
/// caller restored the point before): `to`'s residual and last status stay those of the point
/// kept, so a failed fixed-active-set NLP (residual 0 by construction) cannot pass for a success.
void append_discarded(HomotopyResult& to, const HomotopyResult& from);

/// `o` for one integration step: without the optimal-control rungs of a failed homotopy
/// (homotopy_retries, homotopy_cold_restart); a failed step has the integrators' own retry policy.
inline HomotopyOptions step_homotopy_options(HomotopyOptions o) {
  o.homotopy_retries = 0;
  o.homotopy_cold_restart = false;
  return o;
}

/// The summary's warning for a homotopy that took its cold restart
/// (HomotopyOptions::homotopy_cold_restart), naming the sigma; empty if it took none.
std::string cold_restart_warning(const HomotopyResult& h);

/// Adds a homotopy's (or re-solve's) rows to `rows` and its work (NLPs, iterations, evaluation
/// and solver time) to `summary`: the bookkeeping of every front end.
void add_to_summary(const HomotopyResult& h, Summary& summary, std::vector<HomotopyRow>& rows);

/// Iteration limit of solve_again: a warm-started re-solve with pinned exits converges in 10-30
/// IPOPT iterations when it converges at all; failing ones ran into the configured 500.
inline constexpr int kSolveAgainMaxIter = 100;

/// Iteration limit of the warm-started NLPs (k > 0) of an integration step's homotopy (the
/// integrator passes it to solve_homotopy): they converge in 2-50 IPOPT iterations when they
/// converge at all; in the steps that fail, NLPs ran into the configured 500 before the retry.
/// Periodic stick-slip over [0, 4], N_sim = 20: 8794 -> 4684 iterations, the same result.
inline constexpr int kStepWarmMaxIter = 150;

class Problem {
 public:
  Problem() = default;
  Problem(const Problem&) = delete;
  Problem& operator=(const Problem&) = delete;

  // ---- description: built once ----

  /// The NLP that the discretization and the front end add variables and blocks to. Before
  /// relax() only.
  nlp::BlockNlp& nlp();
  /// Adds complementarity constraints (relaxed by the homotopy) and the pairs whose largest
  /// product is the complementarity residual. Before relax() only.
  void add_complementarity(const std::vector<CompGroup>& groups,
                           const std::vector<CompPair>& residual_pairs);
  /// Relaxes the groups in `mode` (Relaxation: rows, variables or objective terms; throws
  /// fesd::InvalidOption when the mode cannot express a group). After the last
  /// add_complementarity(); the variables are then complete (copy_inputs_from() works).
  /// `s_elastic_max`, `s_elastic_0`: bounds [0, s_elastic_max] and guess of the elastic variable
  /// (elastic modes; HomotopyOptions); `scaling_direct`: HomotopyOptions::objective_scaling_direct.
  void relax(MpccMode mode, double s_elastic_max = nlp::kInf, double s_elastic_0 = 0.0,
             bool scaling_direct = true);
  /// relax() in the options' mpcc_mode with their elastic variable (s_elastic_max, s_elastic_0)
  /// and objective scaling: the optimal-control solvers.
  void relax(const HomotopyOptions& options) {
    relax(options.mpcc_mode, options.s_elastic_max, options.s_elastic_0,
          options.objective_scaling_direct);
  }
  /// Builds the sparsity of the NLP, probed at the current guess. After relax().
  void finalize();
  bool finalized() const { return nlp_.finalized(); }
  int num_variables() const { return nlp_.num_variables(); }
  int num_constraints() const { return nlp_.num_constraints(); }
  MpccMode mpcc_mode() const { return relaxation_ ? relaxation_->mode() : MpccMode::ScholtesIneq; }
  const std::vector<CompPair>& residual_pairs() const { return residual_pairs_; }

  // ---- workspace: inputs and guess ----

  /// Fixes the variables to the values by their bounds (start state, controls, parameters); the
  /// guess takes the values too.
  void fix(const std::vector<int>& vars, const Eigen::VectorXd& values);
  /// Bounds a variable to [lb, ub] (OCP controls and states, a free x0).
  void bound(int var, double lb, double ub);
  double lower(int var) const { return nlp_.x_lb[var]; }
  double upper(int var) const { return nlp_.x_ub[var]; }
  /// The point the next solve_homotopy() starts from (primal only).
  std::vector<double>& guess() { return nlp_.x_init; }
  const std::vector<double>& guess() const { return nlp_.x_init; }
  void set_guess(const std::vector<int>& vars, const Eigen::VectorXd& values);
  /// Copies bounds and guess from a Problem with the same variables (another form of the same
  /// discretization, e.g. the integrator's retry with the sparse cross complementarity (28)).
  void copy_inputs_from(const Problem& other);

  // ---- solving ----

  /// The homotopy from the guess: sigma_0, then sigma_{k+1} = next_sigma(sigma_k) (update rule)
  /// down to sigma_N, each NLP warm-started from the last, until an NLP converges with a
  /// complementarity residual <= complementarity_tol (Success), or sigma reaches sigma_N / the
  /// step limit is hit. NLPs far from the end (sigma > 10 complementarity_tol) are solved to
  /// intermediate_tol. `on_row` (if set) is called after each NLP.
  /// `warm_max_iter` > 0: at most that many IPOPT iterations in each NLP after the first (never
  /// more than the configured max_iter).
  /// `finish` (if set) is called after each converged NLP that does not end the homotopy
  /// anyway, with the result so far; it may solve once more (solve_again(), its rows appended to
  /// the result) and return true to end the homotopy there with status Success (the OCP's
  /// early switch to the fixed active set, HomotopyOptions::active_set_sigma).
  HomotopyResult solve_homotopy(nlp::NlpSolver& solver, const HomotopyOptions& options,
                                const HomotopyCallback& on_row = {}, int warm_max_iter = 0,
                                const std::function<bool(HomotopyResult&)>& finish = {});
  /// Solves the last NLP of the last homotopy once more (its sigma, the configured tolerance, at
  /// most kSolveAgainMaxIter iterations, warm start) with the bounds of some variables changed,
  /// e.g. sliding exits pinned, then restores the bounds. The point is moved into the new bounds
  /// first. One row, numbered after the homotopy's, with `pinned_exits` as given. Success when it
  /// converges with a complementarity residual <= complementarity_tol; then solution() is the
  /// new point, otherwise it stays the homotopy's. `start` (if given) replaces the primal point
  /// of the warm start (the duals stay): a re-gridded solution (FesdInterval::regrid).
  HomotopyResult solve_again(nlp::NlpSolver& solver, const HomotopyOptions& options,
                             const std::vector<nlp::Bound>& changes, int pinned_exits = 0,
                             const std::vector<double>* start = nullptr);
  /// The last solution (the last iterate of the last solve; empty before the first).
  const std::vector<double>& solution() const { return it_.x; }
  /// The last primal-dual iterate, and putting one back (a re-solve whose result is rejected).
  const nlp::Iterate& iterate() const { return it_; }
  void restore(nlp::Iterate it) { it_ = std::move(it); }

 private:
  nlp::BlockNlp nlp_;
  std::vector<CompGroup> groups_;
  std::vector<CompPair> residual_pairs_;
  std::optional<Relaxation> relaxation_;
  nlp::Iterate it_;
  double sigma_ = 0;  // of the last homotopy's last NLP
  int next_row_ = 0;  // k of the next re-solve row
};

}  // namespace fesd::mpcc
