// src/io/plot.cpp: plots of an integrator result with gnuplot (PNG or SVG). The data go inline in
// the script (gnuplot data blocks), the script goes to gnuplot's standard input: no temporary
// files (gnuplot.hpp runs it).
//
// Layout: top panel the states x(t) at the finite-element boundaries, one line per state, with a
// dashed vertical line at every switching time t_s; bottom panel the step sizes h_n drawn as a
// step function over [t_n, t_{n+1}] (log scale if they span more than two decades).
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

std::string make_script(const IntegratorResult& result, const Pss& model, const std::string& path,
                        const std::string& title, const std::string& terminal) {
  const std::size_t n_points = std::min(result.t.size(), result.x.size());
  const std::size_t n_x = n_points > 0 ? static_cast<std::size_t>(result.x[0].size()) : 0;
  const std::vector<std::string> names = names_or_default(model.state_names, n_x, "x");
  const double t0 = result.t.front(), t_end = result.t[n_points - 1];

  std::string s = terminal;
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

  // The switching times: dashed lines in both panels, labels in the top one.
  const std::vector<double> ts = result.switch_times();
  const bool label_switches = ts.size() <= 20;
  int tag = 1;
  for (double t_s : ts) {
    if (!std::isfinite(t_s)) continue;
    s += "set arrow " + std::to_string(tag) + " from " + gp_number(t_s) + ", graph 0 to " +
         gp_number(t_s) + ", graph 1 nohead dashtype 2 linewidth 1 linecolor rgb '#707070' back\n";
    if (label_switches) {
      s += "set label " + std::to_string(tag) + " 't_s' at " + gp_number(t_s) +
           ", graph 1 offset 0,0.6 center textcolor rgb '#505050'\n";
    }
    ++tag;
  }

  // Top panel: the states.
  s += "set origin 0," + gp_number(0.36) + "\nset size 1," + gp_number(top - 0.36) + "\n";
  s += "set tmargin 2\nset bmargin 1\nset format x ''\nunset xlabel\nset ylabel 'x(t)'\n";
  s += "set offsets 0, 0, graph 0.05, graph 0.05\n";
  s += "plot ";
  for (std::size_t i = 0; i < n_x; ++i) {
    s += "$states using 1:" + std::to_string(i + 2) + " with lines linewidth 2 title " +
         gp_string(names[i]) + ", ";
  }
  s += ts.empty() ? "NaN notitle\n"
                  : "NaN with lines dashtype 2 linecolor rgb '#707070' title 'switches'\n";
  s += "unset label\n";

  // Bottom panel: the step sizes.
  s += "set origin 0,0\nset size 1," + gp_number(0.36) + "\n";
  s += "set tmargin 0.5\nset bmargin 3.5\nset format x\nset xlabel 't'\nset offsets 0, 0, 0, 0\n";
  s += "set ylabel 'h_n' enhanced\n";
  if (n_h == 0 || !(h_max >= h_min)) {
    s += "set yrange [0:1]\nplot NaN notitle\n";
  } else {
    if (h_min > 0 && h_max > 100 * h_min) {
      s += "set logscale y\nset format y '10^{%L}'\n";
      s += "set yrange [" + gp_number(h_min / 2) + ":" + gp_number(h_max * 2) + "]\n";
    } else if (h_max > h_min) {
      const double pad = 0.1 * (h_max - h_min);
      s += "set yrange [" + gp_number(h_min - pad) + ":" + gp_number(h_max + pad) + "]\n";
    } else {
      const double pad = h_max != 0 ? 0.25 * std::abs(h_max) : 1.0;
      s += "set yrange [" + gp_number(h_max - pad) + ":" + gp_number(h_max + pad) + "]\n";
    }
    s += "plot $steps using 1:2 with steps linewidth 2 linecolor rgb '#1f77b4' title 'h_n'\n";
  }
  s += "unset multiplot\nunset output\n";
  return s;
}

}  // namespace

void write_plot(const IntegratorResult& result, const Pss& model, const std::string& path,
                const std::string& title) {
  const std::string terminal = io_detail::terminal_for(path, 1000, 700);
  if (std::min(result.t.size(), result.x.size()) == 0) {
    throw IoError("cannot plot to '" + path + "': the result has no time points");
  }
  io_detail::run_plot_script(path, make_script(result, model, path, title, terminal));
}

}  // namespace fesd
