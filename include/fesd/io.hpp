// include/fesd/io.hpp: writing integrator results as JSON, CSV and plots. Nothing is written
// unless one of these is called.
#pragma once
#include <string>

#include "fesd/integrator.hpp"
#include "fesd/model.hpp"

namespace fesd {

/// JSON with keys "status", "message", "t", "x" (one row per time), "h", "switch_times",
/// "x_final", "stats", and the stage data "t_stage", "x_stage", "theta", "lambda", "mu",
/// "active_set", "switches", "homotopy", "state_names". Throws fesd::IoError.
void write_json(const IntegratorResult& result, const Pss& model, const std::string& path);
/// CSV: header "t,<state names>", one row per element boundary. Throws fesd::IoError.
void write_csv(const IntegratorResult& result, const Pss& model, const std::string& path);
/// PNG or SVG (by extension) with gnuplot: states over time with switching times marked, and
/// the step sizes h_n. Throws fesd::IoError (also if gnuplot is missing or the extension unknown).
void write_plot(const IntegratorResult& result, const Pss& model, const std::string& path,
                const std::string& title = "");

}  // namespace fesd
