// src/io/ocp_plot.cpp: plots of an OCP solution with gnuplot (PNG or SVG), in the spirit of the
// paper's Figs. 10-12. gnuplot.hpp runs the script; the data go inline.
//
// Layout, all panels over time t in [0, T] with the switching times as dashed vertical lines:
//   1. the states x(t) at the finite-element boundaries;
//   2. the controls, piecewise constant on the control grid (drawn as steps; left out if n_u = 0);
//   3. the step sizes h_n as a step function over [t_n, t_{n+1}], with the control-interval
//      boundaries as dotted vertical lines and, as dashed horizontal lines, the nominal step
//      T_k / N_FE of each interval and the smallest and largest h_n (Fig. 12);
//   4. the switching indicator eta_n of (31) at the interior element boundaries, on a log scale;
//      eta_n = 0 marks a switch and cannot be drawn on a log scale, so such points are marked at
//      the bottom of the panel.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fesd/error.hpp"
#include "fesd/io.hpp"
#include "io/gnuplot.hpp"

namespace fesd {
namespace {

using io_detail::gp_number;
using io_detail::gp_string;
using io_detail::names_or_default;

struct Panel {
  double origin = 0, height = 0;
};

/// Sets origin and size of a panel and its vertical margins (character units).
std::string place(const Panel& p, double tmargin, double bmargin) {
  return "set origin 0," + gp_number(p.origin) + "\nset size 1," + gp_number(p.height) +
         "\nset tmargin " + gp_number(tmargin) + "\nset bmargin " + gp_number(bmargin) + "\n";
}

/// A y range with 10 % padding around [lo, hi] (a unit band if the data are flat or missing).
std::string padded_yrange(double lo, double hi) {
  if (!(hi >= lo)) return "set yrange [0:1]\n";
  double pad = 0.1 * (hi - lo);
  if (pad == 0) pad = hi != 0 ? 0.25 * std::abs(hi) : 1.0;
  return "set yrange [" + gp_number(lo - pad) + ":" + gp_number(hi + pad) + "]\n";
}

std::string make_script(const OcpResult& r, const Pss& model, const std::string& path,
                        const std::string& title, const std::string& terminal) {
  const std::size_t n_points = std::min(r.t.size(), r.x.size());
  const std::size_t n_x = static_cast<std::size_t>(r.x[0].size());
  const std::size_t n_u = r.u.empty() ? 0 : static_cast<std::size_t>(r.u[0].size());
  const std::vector<std::string> x_names = names_or_default(model.state_names, n_x, "x");
  const std::vector<std::string> u_names = names_or_default(model.control_names, n_u, "u");
  const double t0 = r.t.front(), t_end = r.t[n_points - 1];
  const std::size_t n_h = std::min({r.h.size(), n_points - 1});

  std::string s = terminal;
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
    panels.push_back({std::max(0.0, y), height});
  }
  std::size_t next = 0;

  s += title.empty() ? "set multiplot\n"
                     : "set multiplot title " + gp_string(title) + " noenhanced font ',12'\n";
  s += "set lmargin 12\nset rmargin 22\n";
  s += "set grid\nset key outside right top noenhanced\n";
  if (t_end > t0) s += "set xrange [" + gp_number(t0) + ":" + gp_number(t_end) + "]\n";

  // The switching times: dashed lines in every panel, labelled in the top one.
  int tag = 1;
  const bool label_switches = r.switches.size() <= 20;
  for (const SwitchEvent& e : r.switches) {
    if (!std::isfinite(e.t)) continue;
    s += "set arrow " + std::to_string(tag) + " from " + gp_number(e.t) + ", graph 0 to " +
         gp_number(e.t) + ", graph 1 nohead dashtype 2 linewidth 1 linecolor rgb '#707070' back\n";
    if (label_switches)
      s += "set label " + std::to_string(tag) + " 't_s' at " + gp_number(e.t) +
           ", graph 1 offset 0,0.6 center textcolor rgb '#505050'\n";
    ++tag;
  }
  const std::string switch_key =
      r.switches.empty() ? "NaN notitle"
                         : "NaN with lines dashtype 2 linecolor rgb '#707070' title 'switches'";

  // 1. states.
  s += place(panels[next++], 2, 0.5);
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
  s += "set ylabel 'h_n' enhanced\n";
  if (n_h == 0 || !(h_max >= h_min)) {
    s += "set yrange [0:1]\nplot NaN notitle\n";
  } else {
    s += padded_yrange(std::min(h_min, nom_min), std::max(h_max, nom_max));
    s += "plot $steps using 1:2 with steps linewidth 2 linecolor rgb '#1f77b4' title 'h_n', "
         "$steps using 1:3 with steps dashtype 2 linewidth 1 linecolor rgb '#000000' "
         "title 'nominal', " +
         gp_number(h_min) + " with lines dashtype 2 linecolor rgb '#d62728' title 'min h_n', " +
         gp_number(h_max) + " with lines dashtype 2 linecolor rgb '#ff7f0e' title 'max h_n'" +
         (r.t_ctrl.size() > 2
              ? ", NaN with lines dashtype 3 linecolor rgb '#2ca02c' title 'control grid'\n"
              : "\n");
  }

  // 4. switching indicator.
  s += place(panels[next++], 0.5, 3.5);
  s += "set format x\nset xlabel 't'\nset ylabel 'eta_n' enhanced\n";
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
  s += "unset multiplot\nunset output\n";
  return s;
}

}  // namespace

void write_plot(const OcpResult& result, const Pss& model, const std::string& path,
                const std::string& title) {
  const std::string terminal = io_detail::terminal_for(path, 1000, 1000);
  if (std::min(result.t.size(), result.x.size()) == 0)
    throw IoError("cannot plot to '" + path + "': the result has no time points");
  io_detail::run_plot_script(path, make_script(result, model, path, title, terminal));
}

}  // namespace fesd
