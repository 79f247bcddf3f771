// include/fesd/summary.hpp: what a solve did and what it cost, in one vocabulary for the
// integrator (integrator.hpp) and the optimal control solver (ocp.hpp): one row per NLP of the
// MPCC homotopy (Sect. 5.2 of papers/fesd-filippov.txt), the switches found, the work and time
// summary, the progress callbacks, and the one formatter of each of them.
//
// Regions are numbered from 0 everywhere (reports, JSON, plots, C++): region r of a model is row r
// of its sign matrix S (13), or of the Cartesian product's stacked regions (21).
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "fesd/status.hpp"

namespace fesd {

/// One NLP of a homotopy (one row of the progress table).
struct HomotopyRow {
  int k = 0;                 ///< homotopy iteration
  double sigma = 0;          ///< relaxation parameter
  double comp_residual = 0;  ///< largest complementarity product after the solve
  double objective = 0;      ///< the NLP's objective (penalty terms of the MPCC method included)
  double inf_pr = 0;         ///< IPOPT's final primal infeasibility
  int nlp_iterations = 0;
  std::string nlp_status;  ///< IPOPT's return status, e.g. "Solve_Succeeded"
  /// CPU time of the solving thread (IPOPT, derivatives, KKT solves; threads of a BLAS not
  /// counted) and wall time of the NLP. Until 2026-11-29 cpu_s held the wall time.
  double cpu_s = 0;
  double wall_s = 0;
  /// KKT solver IPOPT used: "dense" (LAPACK LDL', small NLPs), "sparse_ldl", "mumps", or, for a
  /// retried NLP, the last run's with what it changed and the failed runs, e.g. "sparse_ldl (again
  /// with mu_strategy monotone from mu_init 0.0001; first run: STATUS after N iterations)", a
  /// warm start that ran monotone first because an NLP before needed it ("sparse_ldl (mu_strategy
  /// monotone from mu_init 0.0001, as an NLP before needed)"), or
  /// "mumps (sparse_ldl fallback; first run: ...; again with ma27_pivtol 0.01: ...)"
  /// (NlpOptions::kkt_solver, NlpOptions::extra; nlp_iterations, cpu_s and wall_s then count every
  /// run, factor_s and factorizations the last one's).
  std::string linear_solver;
  /// Wall time of IPOPT's KKT factorizations, and their number with fesd's sparse LDL' (0 else).
  double factor_s = 0;
  long long factorizations = 0;
  /// Not a homotopy step but the last NLP solved once more with the active set of every element
  /// fixed (HomotopyOptions::fix_active_set, or sliding exits to pin).
  bool active_set_fixed = false;
  /// > 0: that re-solve pinned this many sliding exits (DiscretizationOptions::pin_sliding_exits).
  int pinned_exits = 0;
  /// The NLP failed and its point was discarded: the homotopy went back to the last converged
  /// NLP and took a smaller sigma step (HomotopyOptions::homotopy_retries).
  bool retried = false;
  /// Part of a path that ended with a failed NLP (or a stalled penalty) and was replaced by the
  /// cold restart (HomotopyOptions::homotopy_cold_restart): from the first NLP that failed at a
  /// point violating the constraints with no retry left, or that stalled, to the end of that path.
  bool restarted = false;
  /// A penalty mode's NLP (ell_1_penalty, elastic_*) that converged with the complementarity
  /// residual above half that of its start although sigma fell: a stationary point of the penalty,
  /// where the cold restart starts if the homotopy ends with the residual still there.
  bool stalled = false;
  /// The NLP started from the initial guess instead of the NLP before it: the cold restart, at
  /// the schedule's sigma the first `restarted` row was heading to.
  bool cold_start = false;
};

/// A detected switch: the active set changes at an element boundary.
struct SwitchEvent {
  double t = 0;             ///< switching time t_s = boundary between the two elements
  int element = 0;          ///< global index of the element that ends at t
  std::vector<int> before;  ///< active regions (0-based region indices) before t
  std::vector<int> after;   ///< active regions after t
  /// false: a sliding exit whose pinned re-solve failed. t is then the element boundary the
  /// relaxed solution put the exit on, which may be off by up to an element length (the FESD
  /// equations leave an exit O(h) free, docs/formulation.md); Summary::warnings names it.
  bool located = true;
};

/// Work and time of a whole run (an integration or an OCP solve).
struct Summary {
  int homotopy_steps = 0;        ///< NLPs solved, re-solves included
  int nlp_iterations = 0;        ///< IPOPT iterations, all NLPs
  double wall_s = 0;             ///< total wall time
  double derivative_s = 0;       ///< time in fesd's function and derivative evaluations
  double solver_s = 0;           ///< time inside IPOPT (incl. MUMPS), excluding the evaluations
  double setup_s = 0;            ///< building the NLP (patterns, index maps)
  double max_comp_residual = 0;  ///< largest final complementarity residual (over the steps)
  int n_variables = 0;           ///< size of the NLP (the first step's, for the integrator)
  int n_constraints = 0;

  // ---- integrator only: the retry policy of integrate() ----
  /// Steps whose homotopy failed with the chosen cross_comp_mode and were solved again with the
  /// sparse form (28) from the same start (their rows follow in the step's homotopy).
  int fallback_steps = 0;
  /// Steps that failed in both forms and were solved again with 2 N_FE finite elements (two
  /// switches closer together than a step need two free element boundaries between them); such
  /// a step has 2 N_FE elements in the grid. refine_attempts counts the tries, refined_steps the
  /// successes; every try follows a failed attempt in the result's homotopy list.
  int refine_attempts = 0;
  int refined_steps = 0;
  /// Steps that failed also with 2 N_FE elements and were replaced by two half steps (recursively,
  /// at most twice: quarter steps). Each half step has N_FE elements of its own, so the grid then
  /// has more than N_sim * N_FE elements.
  int split_steps = 0;

  // ---- which path solved each step (IntegratorOptions::step_solver; docs/active-set.md) ----
  /// Steps solved by Newton's method on the square system of their (predicted or switched)
  /// active set, without IPOPT (step_solver = active_set).
  int active_set_path_steps = 0;
  /// Steps solved by the homotopy: every step with step_solver = homotopy, the fallbacks (no
  /// consistent active set found) with active_set.
  int homotopy_path_steps = 0;
  /// Newton iterations of the active-set path, failed tries included.
  int newton_iterations = 0;
  /// Jacobians evaluated and LU-factored by the active-set path: simplified Newton reuses the LU
  /// of a step before while the iteration contracts (docs/active-set.md).
  int newton_factorizations = 0;
  /// Square systems solved (or tried) by the active-set path: 1 per step without a switch,
  /// more where a switch is located.
  int active_set_tries = 0;
  /// Time in the active-set path (failed tries included).
  double active_set_s = 0;

  // ---- the re-solve with the active set fixed (HomotopyOptions::fix_active_set) ----
  /// Successful re-solves of a step's (the OCP's) last NLP with every element's active set fixed:
  /// complementarity then holds exactly, not to complementarity_tol.
  int active_set_solves = 0;
  /// Such re-solves without exits to pin that failed: the homotopy's solution stays.
  int active_set_failures = 0;
  /// Steps whose homotopy converged but missed complementarity_tol, completed by that re-solve.
  int rescued_steps = 0;
  // ---- pinned sliding exits (DiscretizationOptions::pin_sliding_exits) ----
  /// Exits that left a sliding mode early (at an element boundary where the leaving region's
  /// theta was still > 0), each moved to where it reaches 0 in the re-solve.
  int pinned_exits = 0;
  /// Re-solves with pinned exits that failed; those solutions stay unpinned and their exits are
  /// marked SwitchEvent::located = false.
  int pin_failures = 0;
  // ---- switches held by the grid (OCP; docs/formulation.md, "Switches held by the grid") ----
  /// Re-solves from a re-gridded solution (a switch held by the bounds of h_n moved into the
  /// middle of its range) that were kept: they converged and did not raise the cost.
  int grid_moves = 0;
  /// Re-solves from a probe of a touch (a switch born where the solution touched a switching
  /// surface) that were kept: they converged and lowered the cost.
  int born_switches = 0;
  /// Re-solves of the allocation search (the OCP moved one element from a segment between two
  /// switches to its neighbour), and those of them that were kept (they lowered the cost).
  int allocation_solves = 0;
  int allocation_moves = 0;
  /// Switches still held by an h_n bound in the result (each also named in `warnings`).
  int held_switches = 0;
  /// What the user should know about the result although it succeeded (settings that cannot
  /// reach complementarity_tol, switch times that could not be located), one sentence each.
  std::vector<std::string> warnings = {};
};

/// Progress of the integrator: one call per integration step (all its attempts included).
struct StepProgress {
  int step = 0;   ///< 1-based
  int N_sim = 0;  ///< steps in all
  double t = 0;   ///< time reached
  int nlps = 0;   ///< NLPs of the step's last attempt
  int nlp_iterations = 0;
  double comp_residual = 0;
  Status status = Status::NotRun;  ///< of the step's last attempt
  int run = 0;  ///< simulate(): which of its runs (1-based); 0: a plain integrate()
  /// The step was solved on the active-set path (Newton, no NLP; nlps, nlp_iterations and
  /// comp_residual are 0), with newton_iterations iterations over its square systems.
  bool active_set_path = false;
  int newton_iterations = 0;
};
using StepCallback = std::function<void(const StepProgress&)>;
/// Progress of a homotopy: one call per NLP solved (the OCP; re-solves included).
using HomotopyCallback = std::function<void(const HomotopyRow&)>;

/// Progress inside one NLP: IPOPT's iterate after an iteration (OcpOptions::on_nlp_progress).
struct NlpProgress {
  /// IPOPT iterations of this NLP so far; when the NLP is solved again from the same start (a
  /// retry with another mu strategy or pivot tolerance, the MUMPS fallback) those of every run.
  int iteration = 0;
  int run = 1;  ///< 1: the first run of this NLP, 2, 3, ...: its retries
  double objective = 0, inf_pr = 0, inf_du = 0, mu = 0;
  double wall_s = 0;  ///< since the NLP started
};
/// Called from inside IPOPT; must not throw.
using NlpProgressCallback = std::function<void(const NlpProgress&)>;

/// "    t_s = 1.5   active regions {0,2} -> {0,1,2}\n"
std::string format_switch(const SwitchEvent& s);
/// The header line of the homotopy table ("   k     sigma       comp ...\n").
std::string homotopy_table_header();
/// One row of the homotopy table, aligned with homotopy_table_header() (a pinned re-solve is
/// marked as such).
std::string format_homotopy_row(const HomotopyRow& r);
/// "       ... IPOPT iteration 2500, objective 1.1810464e+01, inf_pr 1.8e-09, inf_du 3.1e-04,
/// mu 1.0e-09, 300 s\n" (", run 2" after the iteration count for a retry): the line the CLI prints
/// while a long NLP runs, under the row of the NLP before it.
std::string format_nlp_progress(const NlpProgress& p);
/// "  step   12/40  t = 0.3  NLPs  5  iter   45  comp 1.2e-12  success\n" ("  run 2  step ..."
/// for a run of simulate())
std::string format_step_progress(const StepProgress& p);
/// The work and time lines every full report ends with: NLPs, iterations, pinned exits, wall
/// time split into derivatives, IPOPT + MUMPS and setup. `per_step` > 0 adds per-step figures.
std::string format_work(const Summary& s, double per_step = 0);
/// "  warning: ...\n" per Summary::warnings entry (empty if none).
std::string format_warnings(const Summary& s);

}  // namespace fesd
