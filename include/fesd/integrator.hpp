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
#include "fesd/summary.hpp"

namespace fesd {

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
  /// Several lines: the switches (regions numbered from 0), work and timing split.
  std::string full_report() const;
};

/// Simulates the PSS from x0 over [0, T_sim] with N_sim steps. p: parameter values (empty: the
/// model's defaults); u: constant controls (empty: zero). Bad input (sizes, NaN, options) throws
/// fesd::Error before any computation; numerical failure is reported in the result's status.
IntegratorResult integrate(const Pss& model, const Eigen::VectorXd& x0, double T_sim, int N_sim,
                           const IntegratorOptions& options = {}, const Eigen::VectorXd& u = {},
                           const Eigen::VectorXd& p = {});

}  // namespace fesd
