// include/fesd/integrator.hpp: FESD integrator with exact switch detection, eq. (32) of
// papers/fesd-filippov.txt, and the standard time-stepping method (26) for comparison.
//
// [0, T_sim] is split into N_sim steps of length T_sim / N_sim. Each step is one FESD problem with
// N_FE finite elements whose lengths h_n are free (sum h_n = T), solved as an MPCC by a homotopy of
// NLPs (IPOPT, exact sparse derivatives). The next step starts where the last ended.
#pragma once
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "fesd/model.hpp"
#include "fesd/options.hpp"
#include "fesd/status.hpp"
#include "fesd/summary.hpp"

namespace fesd {

/// One integration made by simulate() to choose N_sim or to estimate the error.
struct AccuracyRun {
  int N_sim = 0;
  Status status = Status::NotRun;
  Eigen::VectorXd x_final;           ///< x(T) of this run (empty if it failed before any step)
  std::vector<double> switch_times;  ///< t_s of its switches
  /// The estimate of this run's ||x(T) - x_exact(T)|| from the runs before it (NaN: none yet).
  double error_estimate = std::numeric_limits<double>::quiet_NaN();
  double wall_s = 0;
};

/// The error estimate of a simulation (simulate(); docs/problem-files.md, "Accuracy"): step
/// doubling with Richardson extrapolation at the scheme's classical order p. Empty (NaN, no runs)
/// for a result of integrate().
struct Accuracy {
  /// Estimated ||x(T) - x_exact(T)|| (Euclidean norm, absolute) of the result; NaN: none (`note`
  /// says why). Never below `noise_floor`.
  double error_estimate = std::numeric_limits<double>::quiet_NaN();
  /// Estimated max |t_s - t_s,exact| over the switches; NaN without switches or estimate, or
  /// where every run gives the same switch times while x(T) differs (an element that no run
  /// refines, e.g. [0, t_s] with t_s shorter than every step: its error is in no difference).
  double switch_time_estimate = std::numeric_limits<double>::quiet_NaN();
  /// The switch times' two estimates (as for `consistent`) agree: false where a switch moves
  /// between the runs by more than order p predicts (a sliding exit located late, say).
  bool switch_times_consistent = false;
  /// The error of the NLP solutions themselves (10 ipopt.tol max(1, ||x(T)||), at least
  /// complementarity_tol where the active set is not fixed): differences below it are noise.
  double noise_floor = 0;
  bool at_noise_floor = false;  ///< the estimate came out below noise_floor and was raised to it
  /// Two estimates from three runs (the last pair, and the pair before carried over at order p)
  /// agree within a factor 8: the runs converge at the scheme's order.
  bool consistent = false;
  int order = 0;       ///< p used: the scheme's classical order (1: standard method with switches)
  double tol_sim = 0;  ///< the target (0: none, N_sim given)
  bool met = false;    ///< tol_sim > 0 and error_estimate <= tol_sim with consistent runs
  int N_sim = 0;       ///< the result's step count (one of the runs)
  std::vector<AccuracyRun> runs;  ///< every integration, in the order made
  std::string note;               ///< one sentence: how the estimate was made, or why there is none
};

/// dx(T)/dx0, dx(T)/du, dx(T)/dp of the simulation (IntegratorOptions::sensitivities;
/// docs/sensitivities.md): per step the implicit function theorem on the step's square system
/// (its active sets fixed; Thm 15, eq. (24) and Thm 19 of papers/fesd-filippov.txt), chained over
/// the steps. u is the one constant control of the whole simulation, so dx(T)/du sums the
/// contributions of every step.
struct Sensitivities {
  bool requested = false;  ///< IntegratorOptions::sensitivities was set
  bool available = false;  ///< computed for every step (x0, u, p valid)
  /// Why not available: the first step whose square system failed, or the integration's failure.
  std::string message;
  Eigen::MatrixXd x0;  ///< n_x x n_x
  Eigen::MatrixXd u;   ///< n_x x n_u
  Eigen::MatrixXd p;   ///< n_x x n_p
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
  /// theta: the region weights (Stewart), theta(alpha) in the step form (dcs_mode = step).
  /// lambda: Stewart's lambda; in the step form per region sum_j (S_rj = +1 ? lambda_n_j :
  /// lambda_p_j), zero exactly in the closure of the region. mu: Stewart only (empty rows else).
  std::vector<Eigen::VectorXd> x_stage, theta, lambda, mu;
  /// The step form's stage values (dcs_mode = step, else empty): alpha, lambda_p, lambda_n per
  /// switching function (n_c each), at the same stage points.
  std::vector<Eigen::VectorXd> alpha, lambda_p, lambda_n;
  /// The algebraic variables z at the same stage points (models with z, else empty).
  std::vector<Eigen::VectorXd> z;

  /// Active regions per element (global region indices, sorted), size N_sim * N_FE.
  std::vector<std::vector<int>> active_set;
  std::vector<SwitchEvent> switches;

  /// One homotopy per solve attempt: one per integration step, more where a step was retried as
  /// half steps (Summary::split_steps; the failed attempt comes first).
  std::vector<std::vector<HomotopyRow>> homotopy;
  /// Per integration step (N_sim entries for a complete run): the path that solved it, active_set
  /// (Newton, the step possibly in half or quarter pieces) or homotopy (every step of the
  /// standard method and of step_solver = homotopy, the active-set path's fallbacks).
  std::vector<StepSolver> step_path;
  Summary summary;
  /// The error estimate and the runs behind it (simulate() only).
  Accuracy accuracy;
  /// dx(T)/dx0, dx(T)/du, dx(T)/dp (IntegratorOptions::sensitivities).
  Sensitivities sensitivities;

  Eigen::VectorXd x_final() const { return x.empty() ? Eigen::VectorXd() : x.back(); }
  std::vector<double> switch_times() const;
  /// One line: status, final state, number of switches, time.
  std::string brief_report() const;
  /// Several lines: the switches (regions numbered from 0), work and timing split.
  std::string full_report() const;
};

/// Simulates the PSS from x0 over [0, T_sim] with N_sim steps. p: parameter values (empty: the
/// model's defaults); u: constant controls (empty: zero). Bad input (sizes, NaN, options) throws
/// fesd::Error before any computation; numerical failure is reported in the result's status.
IntegratorResult integrate(const Pss& model, const Eigen::VectorXd& x0, double T_sim, int N_sim,
                           const IntegratorOptions& options = {}, const Eigen::VectorXd& u = {},
                           const Eigen::VectorXd& p = {});

/// The default target of simulate() when neither tol_sim nor N_sim is given (docs/formulation.md,
/// "Accuracy by tolerance", for the measurements behind it).
inline constexpr double kDefaultTolSim = 1e-6;

/// How simulate() chooses the number of steps (problem-file keys of [simulation]).
struct AccuracyOptions {
  /// `tol_sim` >= 0: target for the estimated ||x(T) - x_exact(T)||. 0: kDefaultTolSim if N_sim
  /// is 0, no target if N_sim is given.
  double tol_sim = 0;
  /// `N_sim` >= 0: 0 = chosen by tol_sim. Given without tol_sim: exactly N_sim steps, the error
  /// estimated from two companion runs at about N_sim / 2 and N_sim / 4. Given with tol_sim: the
  /// first step count tried.
  int N_sim = 0;
  /// `N_sim_max` >= 1: the largest N_sim tried for tol_sim (also capped so that T_sim / N_sim stays
  /// above the smallest step, docs/problem-files.md "Limits").
  int N_sim_max = 1000;
  /// `error_estimate`: with N_sim given (no tol_sim), run the two companions and estimate the
  /// error (default). false: only the run at N_sim (about 3/7 less work, no estimate); needs N_sim.
  bool error_estimate = true;
  /// Called after every run (the CLI prints format_accuracy_run() of it); the library never prints.
  std::function<void(const AccuracyRun&)> on_run;
};

/// Adds t0 to every time of a result that starts at 0 (t, t_stage, the switches, the switch times
/// of accuracy.runs): the result of a simulation that starts at t0 (`[simulation] t0` of both
/// kinds of problem files: every time of their results is absolute).
void shift_times(IntegratorResult& result, double t0);

/// Simulates like integrate() with a step count chosen by AccuracyOptions and estimates the error
/// of the result (IntegratorResult::accuracy) from runs at several N_sim (docs/problem-files.md,
/// "Accuracy"). Returns the run at the given N_sim, or the last run of a search for tol_sim;
/// Status::ToleranceNotMet if tol_sim was not reached within N_sim_max steps (the finest successful
/// run is still returned, with its estimate). Bad input throws fesd::Error as integrate() does.
IntegratorResult simulate(const Pss& model, const Eigen::VectorXd& x0, double T_sim,
                          const AccuracyOptions& accuracy, const IntegratorOptions& options = {},
                          const Eigen::VectorXd& u = {}, const Eigen::VectorXd& p = {});

/// How simulate() will choose N_sim and estimate the error, one line for headers and `fesd check`:
/// "N_sim chosen for tol_sim = 1e-06 (default): N_sim = 10, 20, ... up to N_sim_max = 1000".
std::string format_accuracy_rule(const AccuracyOptions& a, double T_sim);
/// The accuracy lines of IntegratorResult::full_report() (empty without an estimate).
std::string format_accuracy(const Accuracy& a);
/// One progress line per run of simulate(): "  run 2: N_sim = 20, ... estimate 1.2e-05".
std::string format_accuracy_run(const AccuracyRun& r, double tol_sim);

}  // namespace fesd
