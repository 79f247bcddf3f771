// include/fesd/integrator.hpp: FESD integrator with exact switch detection, eq. (32) of
// papers/fesd-filippov.txt, and the standard time-stepping method (26) for comparison.
//
// [0, T_sim] is split into N_sim steps of length T_sim / N_sim. Each step is one FESD problem with
// N_FE finite elements whose lengths h_n are free (sum h_n = T), solved as an MPCC by a homotopy of
// NLPs (IPOPT, exact sparse derivatives). The next step starts where the last ended.
#pragma once
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "fesd/model.hpp"
#include "fesd/options.hpp"
#include "fesd/status.hpp"

namespace fesd {

/// One NLP of a homotopy (one row of the progress table).
struct HomotopyRow {
  int k = 0;                 ///< homotopy iteration
  double sigma = 0;          ///< relaxation parameter
  double comp_residual = 0;  ///< largest complementarity product after the solve
  double objective = 0;
  double inf_pr = 0;  ///< IPOPT's final primal infeasibility
  int nlp_iterations = 0;
  std::string nlp_status;  ///< IPOPT's return status, e.g. "Solve_Succeeded"
  double cpu_s = 0;
  std::string
      linear_solver;  ///< KKT solver IPOPT used: "dense" (LAPACK LDL', small NLPs) or "mumps"
};

/// A detected switch: the active set changes at an element boundary.
struct SwitchEvent {
  double t = 0;             ///< switching time t_s = boundary between the two elements
  int element = 0;          ///< global index of the element that ends at t
  std::vector<int> before;  ///< active regions (global region indices) before t
  std::vector<int> after;   ///< active regions after t
};

/// Work and time of a whole run.
struct Summary {
  int homotopy_steps = 0;        ///< NLPs solved
  int nlp_iterations = 0;        ///< IPOPT iterations, all NLPs
  double wall_s = 0;             ///< total wall time
  double derivative_s = 0;       ///< time in fesd's function and derivative evaluations
  double solver_s = 0;           ///< time inside IPOPT (incl. MUMPS), excluding the evaluations
  double setup_s = 0;            ///< building the NLP (patterns, index maps)
  double max_comp_residual = 0;  ///< largest final complementarity residual over the steps
  /// Steps whose homotopy failed with the chosen cross_comp_mode and were solved again with the
  /// sparse form (28) from the same start (their rows follow in `homotopy`).
  int fallback_steps = 0;
  /// Steps that failed in both forms and were solved again with 2 N_FE finite elements (two
  /// switches closer together than a step need two free element boundaries between them); such
  /// a step has 2 N_FE elements in the grid. refine_attempts counts the tries, refined_steps the
  /// successes; every try follows a failed attempt in `homotopy`.
  int refine_attempts = 0;
  int refined_steps = 0;
  /// Steps that failed also with 2 N_FE elements and were replaced by two half steps (recursively,
  /// at most twice: quarter steps). Each half step has N_FE elements of its own, so the grid then
  /// has more than N_sim * N_FE elements.
  int split_steps = 0;
  /// Sliding exits pinned (DiscretizationOptions::pin_sliding_exits): exits at an element
  /// boundary where the leaving region's theta was still > 1e-6, each moved to where it reaches
  /// 0 by solving the step's last NLP once more (its row follows in `homotopy`).
  int pinned_exits = 0;
  /// Steps whose pinned re-solve failed; they keep the unpinned solution.
  int pin_failures = 0;
};

/// The result of integrate(). Time grid = all finite-element boundaries t_0 < ... < t_{N_sim N_FE}
/// (more elements where steps were refined or split, Summary::refined_steps, split_steps).
struct IntegratorResult {
  Status status = Status::NotRun;
  std::string message = "integrate() was not called";

  std::vector<double> t;           ///< element boundaries, size N_sim * N_FE + 1
  std::vector<Eigen::VectorXd> x;  ///< x_n at t_n
  std::vector<double> h;           ///< h_n, size N_sim * N_FE

  /// Stage points t_n + c_m h_n and the stage values there (size N_sim * N_FE * n_s each).
  std::vector<double> t_stage;
  std::vector<Eigen::VectorXd> x_stage, theta, lambda, mu;

  /// Active regions per element (global region indices, sorted), size N_sim * N_FE.
  std::vector<std::vector<int>> active_set;
  std::vector<SwitchEvent> switches;

  /// One homotopy per solve attempt: one per integration step, more where a step was retried as
  /// half steps (Summary::split_steps; the failed attempt comes first).
  std::vector<std::vector<HomotopyRow>> homotopy;
  Summary summary;

  Eigen::VectorXd x_final() const { return x.empty() ? Eigen::VectorXd() : x.back(); }
  std::vector<double> switch_times() const;
  /// One line: status, final state, number of switches, time.
  std::string brief_report() const;
  /// Several lines: the switches, statistics and timing split.
  std::string full_report() const;
};

/// Simulates the PSS from x0 over [0, T_sim] with N_sim steps. p: parameter values (empty: the
/// model's defaults); u: constant controls (empty: zero). Bad input (sizes, NaN, options) throws
/// fesd::Error before any computation; numerical failure is reported in the result's status.
IntegratorResult integrate(const Pss& model, const Eigen::VectorXd& x0, double T_sim, int N_sim,
                           const IntegratorOptions& options = {}, const Eigen::VectorXd& u = {},
                           const Eigen::VectorXd& p = {});

}  // namespace fesd
