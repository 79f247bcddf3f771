// include/fesd/io.hpp: writing integrator and optimal control results as JSON, CSV and plots.
// Nothing is written unless one of these is called.
#pragma once
#include <string>

#include "fesd/integrator.hpp"
#include "fesd/model.hpp"
#include "fesd/ocp.hpp"
#include "fesd/pds.hpp"

namespace fesd {

/// JSON with keys "status", "message", "t", "x" (one row per time), "h", "switch_times",
/// "x_final", "stats", and the stage data "t_stage", "x_stage", "theta", "lambda", "mu",
/// "active_set", "switches", "homotopy", "state_names". Throws fesd::IoError.
void write_json(const IntegratorResult& result, const Pss& model, const std::string& path);
/// CSV: header "t,<state names>", one row per element boundary. Throws fesd::IoError.
void write_csv(const IntegratorResult& result, const Pss& model, const std::string& path);
/// PNG or SVG (by extension) with gnuplot: the states over time with every switch dashed and
/// labelled with the regions active before and after it ("{0}->{0,1}"), and the step sizes h_n
/// (as h_n / h_ref - 1 when they agree to 4 digits); elements where a subsystem has two or more
/// active regions (sliding) are shaded. A two-state model (no clock) gets a phase portrait with
/// the switching surfaces c(x) = 0 (or g_i = g_j), evaluated with model.p_default. Throws
/// fesd::IoError (also if gnuplot is missing or the extension unknown).
void write_plot(const IntegratorResult& result, const Pss& model, const std::string& path,
                const std::string& title = "");

/// JSON of an OCP solution, keys in this order: "status", "message", "objective", "t", "x" (one
/// row per element boundary), "t_ctrl" (N_stages + 1 control grid points), "u" (one row per
/// control interval), "h", "interval" (control interval of each element), "eta" (per element,
/// null at interval starts), "switch_times", "x0", "x_final", "homotopy" (one object per NLP),
/// "stats" (the keys of the integrator's "stats", i.e. the fields of fesd::Summary, plus
/// comp_residual and mpcc_mode), then "t_stage", "x_stage", "theta",
/// "lambda", "active_set", "switches", "state_names", "control_names". Non-finite numbers are
/// null. Throws fesd::IoError.
void write_json(const OcpResult& result, const Pss& model, const std::string& path);
/// CSV: header "t,<state names>,interval,<control names>", one row per element boundary; each row
/// has the control of the interval it belongs to (the interval of the element starting there; the
/// last row: the last interval). Throws fesd::IoError.
void write_csv(const OcpResult& result, const Pss& model, const std::string& path);
/// PNG or SVG with gnuplot, four panels over time: the states (switches dashed and labelled with
/// the regions before and after), the controls as steps on the control grid, the step sizes h_n
/// (control-interval boundaries dotted, nominal T_k / N_FE and the smallest and largest h_n
/// dashed; relative to h_ref when they agree to 4 digits), and the switching indicator eta_n of
/// (31) on a log scale with a caption (zeros, i.e. switches, marked at the bottom); sliding
/// elements shaded, and a phase portrait for two states as for simulations. Throws
/// fesd::IoError.
void write_plot(const OcpResult& result, const Pss& model, const std::string& path,
                const std::string& title = "");

/// The same JSON and CSV for projected dynamical systems (docs/pds.md): "lambda" holds the PDS
/// multipliers, "theta" and "mu" are empty, "active_set" lists the active constraints, "switches"
/// are contact and leaving events (regions = constraints).
void write_json(const IntegratorResult& result, const Pds& model, const std::string& path);
void write_csv(const IntegratorResult& result, const Pds& model, const std::string& path);
void write_json(const OcpResult& result, const Pds& model, const std::string& path);
void write_csv(const OcpResult& result, const Pds& model, const std::string& path);
/// The same plots for projected dynamical systems: the elements in contact (some constraint
/// active) shaded, contact and leaving times dashed and labelled ("{}->{0}": constraint 0 becomes
/// active), and for two states a phase portrait with the boundary pieces c_k(x) = 0 of C.
void write_plot(const IntegratorResult& result, const Pds& model, const std::string& path,
                const std::string& title = "");
void write_plot(const OcpResult& result, const Pds& model, const std::string& path,
                const std::string& title = "");

/// Throws fesd::IoError if gnuplot, which write_plot runs, is not on PATH: lets a front end fail
/// before a long solve instead of after it. write_plot checks this itself.
void require_gnuplot();

}  // namespace fesd
