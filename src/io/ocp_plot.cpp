// src/io/ocp_plot.cpp: plots of an OCP solution with gnuplot (PNG or SVG), in the spirit of the
// paper's Figs. 10-12. gnuplot.hpp runs the script; the data go inline; the parts shared with the
// integrator plot are in plot_parts.hpp.
//
// Layout, all panels over time t in [0, T] with the switches as dashed vertical lines (labelled
// in the top panel with the regions active before and after, "{0,2}->{0,2,3}") and the elements
// where a subsystem has two or more active regions (sliding) shaded:
//   1. the states x(t) at the finite-element boundaries;
//   2. the controls, piecewise constant on the control grid (drawn as steps; left out if n_u = 0);
//   3. the step sizes h_n as a step function over [t_n, t_{n+1}], with the control-interval
//      boundaries as dotted vertical lines and, as dashed horizontal lines, the nominal step
//      T_k / N_FE of each interval and the smallest and largest h_n (Fig. 12); h_n / h_ref - 1
//      when all h_n agree to 4 digits;
//   4. the switching indicator eta_n of (31) at the interior element boundaries, on a log scale,
//      with a caption: eta_n = 0 marks a switch (and cannot be drawn on a log scale, so such
//      points are marked at the bottom of the panel), eta_n > 0 is where step equilibration
//      holds h_n = h_{n-1}.
// A two-state system gets a phase portrait on the right: x2 over x1 with the switching surfaces.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fesd/error.hpp"
#include "fesd/io.hpp"
#include "io/gnuplot.hpp"
#include "io/plot_parts.hpp"

namespace fesd {
namespace {

using io_detail::gp_number;
using io_detail::gp_string;
using io_detail::names_or_default;

struct Panel {
  double origin = 0, height = 0, width = 1;
};

/// Sets origin and size of a panel and its vertical margins (character units).
std::string place(const Panel& p, double tmargin, double bmargin) {
  return "set origin 0," + gp_number(p.origin) + "\nset size " + gp_number(p.width) + "," +
         gp_number(p.height) + "\nset tmargin " + gp_number(tmargin) + "\nset bmargin " +
         gp_number(bmargin) + "\n";
}

/// A y range with 10 % padding around [lo, hi] (a unit band if the data are flat or missing).
std::string padded_yrange(double lo, double hi) {
  if (!(hi >= lo)) return "set yrange [0:1]\n";
  double pad = 0.1 * (hi - lo);
  if (pad == 0) pad = hi != 0 ? 0.25 * std::abs(hi) : 1.0;
  return "set yrange [" + gp_number(lo - pad) + ":" + gp_number(hi + pad) + "]\n";
}

std::string make_script(const OcpResult& r, const io_detail::PlotModel& model,
                        const std::string& path, const std::string& title) {
  const std::size_t n_points = std::min(r.t.size(), r.x.size());
  const std::size_t n_x = static_cast<std::size_t>(r.x[0].size());
  const std::size_t n_u = r.u.empty() ? 0 : static_cast<std::size_t>(r.u[0].size());
  const std::vector<std::string> x_names = names_or_default(model.state_names, n_x, "x");
  const std::vector<std::string> u_names = names_or_default(model.control_names, n_u, "u");
  const double t0 = r.t.front(), t_end = r.t[n_points - 1];
  const std::size_t n_h = std::min({r.h.size(), n_points - 1});
  const bool portrait = io_detail::wants_phase_portrait(model, static_cast<int>(n_x));
  const int width_px = portrait ? 1500 : 1000;
  const double left = portrait ? 0.64 : 1.0;  // width of the time panels (screen fraction)

  std::string s = io_detail::terminal_for(path, width_px, 1000);
  s += "set output " + gp_string(path) + "\n";
  s += "set encoding utf8\n";

  // ---- inline data ----
  s += "$states << EOD\n";
  for (std::size_t n = 0; n < n_points; ++n) {
    s += gp_number(r.t[n]);
    for (std::size_t i = 0; i < n_x; ++i) {
      s += ' ';
      s += i < static_cast<std::size_t>(r.x[n].size())
               ? gp_number(r.x[n][static_cast<Eigen::Index>(i)])
               : std::string("NaN");
    }
    s += '\n';
  }
  s += "EOD\n";

  // Controls at the start of each interval, the last one repeated at T to draw its step.
  const std::size_t n_ctrl = std::min(r.u.size(), r.t_ctrl.size() > 0 ? r.t_ctrl.size() - 1 : 0);
  double u_min = INFINITY, u_max = -INFINITY;
  s += "$controls << EOD\n";
  for (std::size_t k = 0; k <= n_ctrl && n_ctrl > 0; ++k) {
    const Eigen::VectorXd& q = r.u[std::min(k, n_ctrl - 1)];
    s += gp_number(r.t_ctrl[k]);
    for (std::size_t i = 0; i < n_u; ++i) {
      const double v =
          i < static_cast<std::size_t>(q.size()) ? q[static_cast<Eigen::Index>(i)] : NAN;
      s += ' ' + gp_number(v);
      if (std::isfinite(v)) {
        u_min = std::min(u_min, v);
        u_max = std::max(u_max, v);
      }
    }
    s += '\n';
  }
  s += "EOD\n";

  // h_n and the nominal step of its interval, at t_n; the last step repeated at t_N.
  std::vector<int> elements_in(r.t_ctrl.size(), 0);
  for (std::size_t n = 0; n < n_h; ++n) {
    const int k = n < r.interval.size() ? r.interval[n] : -1;
    if (k >= 0 && static_cast<std::size_t>(k) < elements_in.size()) ++elements_in[k];
  }
  const auto nominal = [&](std::size_t n) -> double {
    const int k = n < r.interval.size() ? r.interval[n] : -1;
    if (k < 0 || static_cast<std::size_t>(k) + 1 >= r.t_ctrl.size() || elements_in[k] == 0)
      return NAN;
    return (r.t_ctrl[k + 1] - r.t_ctrl[k]) / elements_in[k];
  };
  double h_min = INFINITY, h_max = -INFINITY, nom_min = INFINITY, nom_max = -INFINITY;
  s += "$steps << EOD\n";
  for (std::size_t n = 0; n < n_h; ++n) {
    s += gp_number(r.t[n]) + ' ' + gp_number(r.h[n]) + ' ' + gp_number(nominal(n)) + '\n';
    if (std::isfinite(r.h[n])) {
      h_min = std::min(h_min, r.h[n]);
      h_max = std::max(h_max, r.h[n]);
    }
    if (std::isfinite(nominal(n))) {
      nom_min = std::min(nom_min, nominal(n));
      nom_max = std::max(nom_max, nominal(n));
    }
  }
  if (n_h > 0)
    s += gp_number(r.t[n_h]) + ' ' + gp_number(r.h[n_h - 1]) + ' ' + gp_number(nominal(n_h - 1)) +
         '\n';
  s += "EOD\n";

  // eta_n at t_n: positive values on the log scale, zeros (switches) separately.
  double eta_min = INFINITY, eta_max = -INFINITY;
  bool any_zero = false;
  s += "$eta << EOD\n";
  for (std::size_t n = 0; n < std::min(r.eta.size(), n_points); ++n) {
    if (std::isfinite(r.eta[n]) && r.eta[n] > 0) {
      s += gp_number(r.t[n]) + ' ' + gp_number(r.eta[n]) + '\n';
      eta_min = std::min(eta_min, r.eta[n]);
      eta_max = std::max(eta_max, r.eta[n]);
    } else if (!std::isfinite(r.eta[n])) {
      s += '\n';  // an interval start has no eta: a blank line breaks the line there
    }
  }
  s += "EOD\n$eta_zero << EOD\n";
  for (std::size_t n = 0; n < std::min(r.eta.size(), n_points); ++n)
    if (std::isfinite(r.eta[n]) && r.eta[n] <= 0) {
      s += gp_number(r.t[n]) + '\n';
      any_zero = true;
    }
  s += "EOD\n";

  // ---- layout ----
  const double top = title.empty() ? 1.0 : 0.95;
  const bool with_controls = n_u > 0;
  // Relative heights: states, (controls), h, eta; the bottom panel also holds the t axis.
  std::vector<double> weights{0.30};
  if (with_controls) weights.push_back(0.22);
  weights.push_back(0.22);
  weights.push_back(0.26);
  double total = 0;
  for (double w : weights) total += w;
  std::vector<Panel> panels;
  double y = top;
  for (double w : weights) {
    const double height = top * w / total;
    y -= height;
    panels.push_back({std::max(0.0, y), height, left});
  }
  std::size_t next = 0;

  s += title.empty() ? "set multiplot\n"
                     : "set multiplot title " + gp_string(title) + " noenhanced font ',12'\n";
  s += "set lmargin 12\nset rmargin 22\n";
  s += "set grid\nset key outside right top noenhanced\n";
  if (t_end > t0) s += "set xrange [" + gp_number(t0) + ":" + gp_number(t_end) + "]\n";

  // Sliding elements shaded and the switches dashed in every panel, labelled in the top one.
  const auto sliding = io_detail::sliding_intervals(model, r.t, r.active_set);
  s += io_detail::shade_intervals(sliding);
  int tag = 1, label_rows = 0;
  s +=
      io_detail::switch_markup(r.switches, t0, t_end, width_px * left - 34 * 8, 1, tag, label_rows);
  const std::string switch_key =
      (r.switches.empty()
           ? std::string("NaN notitle")
           : std::string("NaN with lines dashtype 2 linecolor rgb '#707070' title 'switches'")) +
      (sliding.empty() ? "" : io_detail::sliding_key_entry(model.shaded_name));

  // 1. states.
  s += place(panels[next++], std::max(2.0, 1.0 + 1.2 * label_rows), 0.5);
  s += "set format x ''\nunset xlabel\nset ylabel 'x(t)'\nset offsets 0, 0, graph 0.05, graph "
       "0.05\n";
  s += "plot ";
  for (std::size_t i = 0; i < n_x; ++i)
    s += "$states using 1:" + std::to_string(i + 2) + " with lines linewidth 2 title " +
         gp_string(x_names[i]) + ", ";
  s += switch_key + "\n";
  s += "unset label\nset offsets 0, 0, 0, 0\n";

  // 2. controls.
  if (with_controls) {
    s += place(panels[next++], 0.5, 0.5);
    s += "set ylabel 'u(t)'\n" + padded_yrange(u_min, u_max);
    s += "plot ";
    for (std::size_t i = 0; i < n_u; ++i)
      s += "$controls using 1:" + std::to_string(i + 2) + " with steps linewidth 2 title " +
           gp_string(u_names[i]) + (i + 1 < n_u ? ", " : "\n");
    s += "set autoscale y\n";
  }

  // The control-interval boundaries (interior ones): dotted, from here on.
  for (std::size_t k = 1; k + 1 < r.t_ctrl.size(); ++k) {
    s += "set arrow " + std::to_string(tag++) + " from " + gp_number(r.t_ctrl[k]) +
         ", graph 0 to " + gp_number(r.t_ctrl[k]) +
         ", graph 1 nohead dashtype 3 linewidth 1 linecolor rgb '#2ca02c' back\n";
  }

  // 3. step sizes.
  s += place(panels[next++], 0.5, 0.5);
  // On the relative scale (all h_n and nominal steps agree to 4 digits) every curve is
  // h / h_ref - 1.
  const io_detail::StepAxis axis =
      io_detail::step_axis(std::min(h_min, nom_min), std::max(h_max, nom_max));
  s += io_detail::step_ylabel(axis) + io_detail::step_reference_label(axis, 0.2);
  if (n_h == 0 || !(h_max >= h_min)) {
    s += "set yrange [0:1]\nplot NaN notitle\n";
  } else {
    s += padded_yrange(axis.value(std::min(h_min, nom_min)), axis.value(std::max(h_max, nom_max)));
    s += "plot $steps using 1:" + io_detail::step_column(axis, 2) +
         " with steps linewidth 2 linecolor rgb '#1f77b4' title 'h_n', $steps using 1:" +
         io_detail::step_column(axis, 3) +
         " with steps dashtype 2 linewidth 1 linecolor rgb '#000000' title 'nominal', " +
         gp_number(axis.value(h_min)) +
         " with lines dashtype 2 linecolor rgb '#d62728' title 'min h_n', " +
         gp_number(axis.value(h_max)) +
         " with lines dashtype 2 linecolor rgb '#ff7f0e' title 'max h_n'" +
         (r.t_ctrl.size() > 2
              ? ", NaN with lines dashtype 3 linecolor rgb '#2ca02c' title 'control grid'\n"
              : "\n");
  }

  // 4. switching indicator.
  s += place(panels[next++], 0.5, 3.5);
  s += "unset label\nset format x\nset xlabel 't'\nset ylabel 'eta_n' enhanced\n";
  // The caption, in the right margin below the key.
  s += "set label 1 \"switching indicator (31)\\neta_n = 0: active set\\nchanges at t_n (switch)"
       "\\neta_n > 0: step\\nequilibration holds\\nh_n = h_{n-1}\" at graph 1.03, graph 0.66 left "
       "noenhanced font ',9' textcolor rgb '#404040'\n";
  if (eta_max >= eta_min) {
    // The zero markers sit a decade below the smallest positive eta.
    const double floor_value = eta_min / 10;
    s += "set logscale y\nset format y '10^{%L}'\n";
    s += "set yrange [" + gp_number(floor_value / 2) + ":" + gp_number(eta_max * 2) + "]\n";
    s += "plot $eta using 1:2 with linespoints pointtype 7 pointsize 0.6 linecolor rgb '#9467bd' "
         "title 'eta_n'";
    if (any_zero)
      s += ", $eta_zero using 1:(" + gp_number(floor_value) +
           ") with points pointtype 9 pointsize 1.2 linecolor rgb '#d62728' title 'eta_n = 0'";
    s += "\nunset logscale y\nset format y\n";
  } else if (any_zero) {
    s += "set yrange [-1:1]\n";
    s += "plot $eta_zero using 1:(0) with points pointtype 9 pointsize 1.2 linecolor rgb "
         "'#d62728' title 'eta_n = 0'\n";
  } else {
    s += "set yrange [0:1]\nplot NaN notitle\n";
  }
  if (portrait) {
    s += io_detail::phase_portrait(model, io_detail::phase_data(r, model), left, 0, 1 - left, top,
                                   width_px, 1000);
  }
  s += "unset multiplot\nunset output\n";
  return s;
}

}  // namespace

std::string io_detail::plot_script(const OcpResult& r, const io_detail::PlotModel& model,
                                   const std::string& path, const std::string& title) {
  return make_script(r, model, path, title);
}

namespace {
void write_ocp_plot(const OcpResult& result, const io_detail::PlotModel& model,
                    const std::string& path, const std::string& title) {
  io_detail::terminal_for(path, 1000, 1000);  // the extension is checked first
  if (std::min(result.t.size(), result.x.size()) == 0)
    throw IoError("cannot plot to '" + path + "': the result has no time points");
  io_detail::run_plot_script(path, make_script(result, model, path, title));
}
}  // namespace

void write_plot(const OcpResult& result, const Pss& model, const std::string& path,
                const std::string& title) {
  write_ocp_plot(result, model, path, title);
}

void write_plot(const OcpResult& result, const Pds& model, const std::string& path,
                const std::string& title) {
  write_ocp_plot(result, model, path, title);
}

}  // namespace fesd
