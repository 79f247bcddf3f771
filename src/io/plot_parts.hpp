// src/io/plot_parts.hpp: what the integrator plot (plot.cpp) and the OCP plot (ocp_plot.cpp) share:
// the step-size axis, the shaded sliding intervals, the labelled switches and the phase portrait
// of a two-state system with its switching surfaces. Each part returns gnuplot script text (or
// the numbers it is made from, for the tests). Internal to src/io.
#pragma once
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "fesd/integrator.hpp"
#include "fesd/model.hpp"
#include "fesd/ocp.hpp"
#include "fesd/pds.hpp"
#include "fesd/summary.hpp"

namespace fesd::io_detail {

// ---- the h_n axis ------------------------------------------------------------------------------

/// How h_n is drawn. When all h_n agree to about 4 significant digits (FESD with step
/// equilibration and no switch: h_n = T / N_FE up to round-off of 1e-9), tick labels printed with
/// 6 digits would all read the same number; then the panel shows h_n / reference - 1 instead, and
/// the reference goes into the axis label.
struct StepAxis {
  bool relative = false;
  double reference = 0;  ///< h_ref: the middle of [h_min, h_max] (relative only)
  /// The value drawn for a step h.
  double value(double h) const { return relative ? h / reference - 1 : h; }
};
/// Relative iff 0 < h_max - h_min <= kRelativeSpan * max(|h_min|, |h_max|) (and both finite).
StepAxis step_axis(double h_min, double h_max);
constexpr double kRelativeSpan = 1e-4;
/// The gnuplot "using" expression of column `column` (h values) for this axis: "2" or
/// "($2/REF - 1)".
std::string step_column(const StepAxis& axis, int column);
/// "set ylabel ..." for the axis: "h_n" or "h_n / h_{ref} - 1".
std::string step_ylabel(const StepAxis& axis);
/// On the relative scale, a label "relative scale: h_ref = 0.1" in the right margin of the panel
/// at height graph_y (below the key); empty otherwise.
std::string step_reference_label(const StepAxis& axis, double graph_y);

// ---- the model as the plots see it --------------------------------------------------------------

struct Segment;
using Surfaces = std::vector<std::pair<std::string, std::vector<Segment>>>;

/// What the plots need of a model, for piecewise smooth systems (Pss) and projected ones (Pds):
/// names, parameter values, which elements to shade (sliding; for a projected system: in
/// contact, some constraint active) and the curves of the phase portrait (switching surfaces;
/// the boundary pieces c_k = 0 of C).
struct PlotModel {
  PlotModel(const Pss& model);  // NOLINT(google-explicit-constructor): plots take either model
  PlotModel(const Pds& model);  // NOLINT(google-explicit-constructor)
  std::vector<std::string> state_names, control_names;
  int n_x = 0;
  Eigen::VectorXd p;        ///< p_default
  std::string shaded_name;  ///< "sliding" or "contact"
  std::function<bool(const std::vector<int>& active_set)> shaded;
  /// The curves in a box with parameter values p (switching_surfaces of the model).
  std::function<Surfaces(const Eigen::VectorXd& p, double xlo, double xhi, double ylo, double yhi,
                         int n_grid)>
      surfaces;
};

// ---- sliding intervals -------------------------------------------------------------------------

/// Whether element n is sliding: some subsystem of `model` has more than one active region in
/// `active_set[n]` (a Filippov sliding mode, or a crossing inside an element without FESD).
bool is_sliding(const Pss& model, const std::vector<int>& active_set);
/// [t_start, t_end] of every maximal run of shaded elements (sliding, or in contact for a
/// projected system; element n spans [t[n], t[n+1]]).
std::vector<std::pair<double, double>> sliding_intervals(
    const PlotModel& model, const std::vector<double>& t,
    const std::vector<std::vector<int>>& active_set);
/// gnuplot rectangles shading the intervals in every later panel (objects 1, 2, ...), drawn
/// behind the data.
std::string shade_intervals(const std::vector<std::pair<double, double>>& intervals);
/// A key entry for the shading (`name`: "sliding", "contact"), to be appended to a plot command
/// (starts with ", ").
std::string sliding_key_entry(const std::string& name = "sliding");
constexpr const char* kSlidingColor = "#f2c46d";

// ---- switches ----------------------------------------------------------------------------------

/// "{0,2}": a set of regions.
std::string region_set(const std::vector<int>& regions);
/// "{0}->{0,1}": which regions were active before and after the switch.
std::string switch_label(const SwitchEvent& s);
/// A row (0, 1, ...) for every label centred at x[i] with width width[i] (same units) such that
/// labels in one row are at least `gap` apart; -1 for a label that fits in none of `max_rows`.
std::vector<int> label_rows(const std::vector<double>& x, const std::vector<double>& width,
                            double gap, int max_rows);
/// Switch lines (dashed arrows `first_tag`, ...) in every later panel, and labels "{0}->{1}" above
/// the next panel, staggered in up to 4 rows so that they do not overlap (`plot_width_px`: the
/// width of the time axis in pixels). `rows` is set to the number of label rows used (the top
/// margin needed). `next_tag` is set past the last arrow.
std::string switch_markup(const std::vector<SwitchEvent>& switches, double t0, double t_end,
                          double plot_width_px, int first_tag, int& next_tag, int& rows);

// ---- phase portrait ----------------------------------------------------------------------------

/// A line segment of a zero contour.
struct Segment {
  double x0, y0, x1, y1;
};
/// The zero set of values (an n x n grid over [xlo, xhi] x [ylo, yhi], values(i, j) at
/// x = xlo + i dx, y = ylo + j dy) as segments, by marching squares with linear interpolation.
/// Cells with a non-finite corner are skipped.
std::vector<Segment> zero_contour(const Eigen::MatrixXd& values, double xlo, double xhi, double ylo,
                                  double yhi);

/// Whether a phase portrait is drawn: exactly two states, neither named "t" (a clock).
bool wants_phase_portrait(const PlotModel& model, int n_x);

/// Everything the phase portrait needs from a result.
struct PhaseData {
  std::vector<double> t;                 ///< element boundaries
  std::vector<Eigen::VectorXd> x;        ///< states at t
  std::vector<double> t_stage;           ///< stage times (may be empty)
  std::vector<Eigen::VectorXd> x_stage;  ///< stage states
  std::vector<std::vector<int>> active_set;
  std::vector<SwitchEvent> switches;
  Eigen::VectorXd p;  ///< parameter values for c and g (model.p_default)
};
PhaseData phase_data(const IntegratorResult& r, const PlotModel& model);
PhaseData phase_data(const OcpResult& r, const PlotModel& model);

/// The switching surfaces of `model` in the box: for each c-form subsystem the zero sets
/// c_j(x) = 0, for each g-form subsystem the boundaries g_i = g_j where both are smallest; one
/// (title, segments) pair per function (pair), empty ones left out. Empty if c or g cannot be
/// evaluated (p of the wrong size, an exception).
std::vector<std::pair<std::string, std::vector<Segment>>> switching_surfaces(
    const Pss& model, const Eigen::VectorXd& p, double xlo, double xhi, double ylo, double yhi,
    int n_grid = 161);

/// The same for a projected system: the boundary pieces c_k(x) = 0 of C = {x : c(x) >= 0}, one
/// ("c[k] = 0", segments) pair per constraint that crosses the box.
Surfaces switching_surfaces(const Pds& model, const Eigen::VectorXd& p, double xlo, double xhi,
                            double ylo, double yhi, int n_grid = 161);

/// The phase-portrait panel (x2 over x1) in the area at `origin` (x, y) with size (width, height)
/// in screen units of a canvas_w x canvas_h pixel picture: a square plot at the top of the area:
/// the trajectory through boundary and stage points, its sliding elements thicker in the sliding
/// colour, the start (circle) and end (square), the states at the switches, and the switching
/// surfaces over the trajectory's bounding box. Unsets arrows, objects and labels of the time
/// panels first.
std::string phase_portrait(const PlotModel& model, const PhaseData& d, double origin_x,
                           double origin_y, double width, double height, int canvas_w,
                           int canvas_h);

// ---- the whole scripts -------------------------------------------------------------------------

/// The gnuplot scripts of write_plot (plot.cpp, ocp_plot.cpp): terminal, data, panels. Throws
/// IoError for an unsupported extension. Exposed for the tests.
std::string plot_script(const IntegratorResult& result, const PlotModel& model,
                        const std::string& path, const std::string& title);
std::string plot_script(const OcpResult& result, const PlotModel& model, const std::string& path,
                        const std::string& title);

}  // namespace fesd::io_detail
