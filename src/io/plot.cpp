// src/io/plot.cpp: plots of an integrator result with gnuplot (PNG or SVG). The data go inline in
// the script (gnuplot data blocks), the script goes to gnuplot's standard input: no temporary
// files (gnuplot.hpp runs it). The parts shared with the OCP plot are in plot_parts.hpp.
//
// Layout: top panel the states x(t) at the finite-element boundaries, one line per state, with a
// dashed vertical line at every switch, labelled with the regions active before and after it
// ("{0}->{0,1}"); bottom panel the step sizes h_n drawn as a step function over [t_n, t_{n+1}]
// (log scale if they span more than two decades, h_n / h_ref - 1 if they agree to 4 digits). The
// elements where a subsystem has two or more active regions (sliding) are shaded in both. A
// two-state system gets a phase portrait on the right: x2 over x1 with the switching surfaces.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fesd/error.hpp"
#include "fesd/io.hpp"
#include "io/gnuplot.hpp"
#include "io/plot_parts.hpp"

namespace fesd {
namespace io_detail {

std::string plot_script(const IntegratorResult& result, const PlotModel& model,
                        const std::string& path, const std::string& title) {
  const std::size_t n_points = std::min(result.t.size(), result.x.size());
  const std::size_t n_x = n_points > 0 ? static_cast<std::size_t>(result.x[0].size()) : 0;
  const std::vector<std::string> names = names_or_default(model.state_names, n_x, "x");
  const double t0 = result.t.front(), t_end = result.t[n_points - 1];
  const bool portrait = wants_phase_portrait(model, static_cast<int>(n_x));
  const int width_px = portrait ? 1500 : 1000;
  const double left = portrait ? 0.64 : 1.0;  // width of the time panels (screen fraction)

  std::string s = terminal_for(path, width_px, 700);
  s += "set output " + gp_string(path) + "\n";
  s += "set encoding utf8\n";

  // Inline data: the states at the element boundaries ...
  s += "$states << EOD\n";
  for (std::size_t n = 0; n < n_points; ++n) {
    s += gp_number(result.t[n]);
    for (std::size_t i = 0; i < n_x; ++i) {
      s += ' ';
      s += i < static_cast<std::size_t>(result.x[n].size())
               ? gp_number(result.x[n][static_cast<Eigen::Index>(i)])
               : std::string("NaN");
    }
    s += '\n';
  }
  s += "EOD\n";
  // ... and h_n at t_n, with h_{N-1} repeated at t_N so that the last step is drawn to the end.
  const std::size_t n_h = std::min(result.h.size(), n_points > 0 ? n_points - 1 : 0);
  double h_min = INFINITY, h_max = -INFINITY;
  s += "$steps << EOD\n";
  for (std::size_t n = 0; n < n_h; ++n) {
    s += gp_number(result.t[n]) + ' ' + gp_number(result.h[n]) + '\n';
    if (std::isfinite(result.h[n])) {
      h_min = std::min(h_min, result.h[n]);
      h_max = std::max(h_max, result.h[n]);
    }
  }
  if (n_h > 0) s += gp_number(result.t[n_h]) + ' ' + gp_number(result.h[n_h - 1]) + '\n';
  s += "EOD\n";

  s += title.empty() ? "set multiplot\n"
                     : "set multiplot title " + gp_string(title) + " noenhanced font ',12'\n";
  const double top = title.empty() ? 1.0 : 0.95;
  s += "set lmargin 12\nset rmargin 20\n";
  s += "set grid\nset key outside right top noenhanced\n";
  if (t_end > t0) s += "set xrange [" + gp_number(t0) + ":" + gp_number(t_end) + "]\n";

  // Sliding elements shaded and the switches dashed in both panels, labelled in the top one.
  const auto sliding = sliding_intervals(model, result.t, result.active_set);
  s += shade_intervals(sliding);
  int next_tag = 1, label_rows = 0;
  s += switch_markup(result.switches, t0, t_end, width_px * left - 32 * 8, 1, next_tag, label_rows);

  // Top panel: the states.
  s += "set origin 0," + gp_number(0.36) + "\nset size " + gp_number(left) + "," +
       gp_number(top - 0.36) + "\n";
  s += "set tmargin " + gp_number(std::max(2.0, 1.0 + 1.2 * label_rows)) +
       "\nset bmargin 1\nset format x ''\nunset xlabel\nset ylabel 'x(t)'\n";
  s += "set offsets 0, 0, graph 0.05, graph 0.05\n";
  s += "plot ";
  for (std::size_t i = 0; i < n_x; ++i) {
    s += "$states using 1:" + std::to_string(i + 2) + " with lines linewidth 2 title " +
         gp_string(names[i]) + ", ";
  }
  s += result.switches.empty()
           ? "NaN notitle"
           : "NaN with lines dashtype 2 linecolor rgb '#707070' title 'switches'";
  s += sliding.empty() ? "\n" : sliding_key_entry(model.shaded_name) + "\n";
  s += "unset label\n";

  // Bottom panel: the step sizes.
  s += "set origin 0,0\nset size " + gp_number(left) + "," + gp_number(0.36) + "\n";
  s += "set tmargin 0.5\nset bmargin 3.5\nset format x\nset xlabel 't'\nset offsets 0, 0, 0, 0\n";
  const StepAxis axis = step_axis(h_min, h_max);
  s += step_ylabel(axis) + step_reference_label(axis, 0.7);
  if (n_h == 0 || !(h_max >= h_min)) {
    s += "set yrange [0:1]\nplot NaN notitle\n";
  } else {
    const double lo = axis.value(h_min), hi = axis.value(h_max);
    if (!axis.relative && h_min > 0 && h_max > 100 * h_min) {
      s += "set logscale y\nset format y '10^{%L}'\n";
      s += "set yrange [" + gp_number(h_min / 2) + ":" + gp_number(h_max * 2) + "]\n";
    } else if (hi > lo) {
      const double pad = 0.1 * (hi - lo);
      s += "set yrange [" + gp_number(lo - pad) + ":" + gp_number(hi + pad) + "]\n";
    } else {
      const double pad = hi != 0 ? 0.25 * std::abs(hi) : 1.0;
      s += "set yrange [" + gp_number(hi - pad) + ":" + gp_number(hi + pad) + "]\n";
    }
    s += "plot $steps using 1:" + step_column(axis, 2) +
         " with steps linewidth 2 linecolor rgb '#1f77b4' title 'h_n'\n";
  }
  if (portrait) {
    s += phase_portrait(model, phase_data(result, model), left, 0, 1 - left, top, width_px, 700);
  }
  s += "unset multiplot\nunset output\n";
  return s;
}

}  // namespace io_detail

namespace {
void write_integrator_plot(const IntegratorResult& result, const io_detail::PlotModel& model,
                           const std::string& path, const std::string& title) {
  io_detail::terminal_for(path, 1000, 700);  // the extension is checked first
  if (std::min(result.t.size(), result.x.size()) == 0) {
    throw IoError("cannot plot to '" + path + "': the result has no time points");
  }
  io_detail::run_plot_script(path, io_detail::plot_script(result, model, path, title));
}
}  // namespace

void write_plot(const IntegratorResult& result, const Pss& model, const std::string& path,
                const std::string& title) {
  write_integrator_plot(result, model, path, title);
}

void write_plot(const IntegratorResult& result, const Pds& model, const std::string& path,
                const std::string& title) {
  write_integrator_plot(result, model, path, title);
}

}  // namespace fesd
