// bench/fig9_value_function.cpp: Fig. 9 (left) of papers/fesd-filippov.txt (issue 15 item 6):
// V(x0) and V'(x0) of the OCP (56) on a grid of x0 in [-3, 1], simulated with FESD and with the
// standard method (26), both Gauss-Legendre n_s = 2, N_FE = 25 on [0, 2] (N_sim = 1), against the
// exact V and V' (bench/value_function.hpp, REFERENCE.md). No optimisation: x0 is the only
// decision, V(x0) is the cost of the simulated trajectory, V'(x0) comes from the sensitivities
// (IntegratorOptions::sensitivities; the integral of x^2 is a second state, value_function.hpp).
// FESD matches the exact V and V'; the standard method's V converges but its V' does not, and V has
// spurious local minima (counted on the grid: points below both neighbours).
//
//   fig9_value_function [--points 81] [--csv FILE] [--json FILE] [--plot FILE.png]
//
// One table to stdout (every 4th point and the summary), progress to stderr.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "bench_args.hpp"
#include "value_function.hpp"

namespace fesd_bench {
[[noreturn]] void usage(const std::string& why, int exit_code) {
  std::fprintf(stderr,
               "fig9_value_function: %s\nusage: fig9_value_function [--points 81] [--csv FILE] "
               "[--json FILE] [--plot FILE.png]\n",
               why.c_str());
  std::exit(exit_code);
}
}  // namespace fesd_bench

namespace {

struct Point {
  double x0 = 0;
  fesd_bench::ExactValue exact;
  fesd_bench::SimulatedValue fesd, standard;
};

/// Interior grid points where V is below both neighbours.
std::vector<double> local_minima(const std::vector<Point>& pts, bool fesd) {
  std::vector<double> out;
  for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
    const auto V = [&](std::size_t j) { return fesd ? pts[j].fesd.V : pts[j].standard.V; };
    if (V(i) < V(i - 1) && V(i) < V(i + 1)) out.push_back(pts[i].x0);
  }
  return out;
}

nlohmann::json num(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

}  // namespace

int main(int argc, char** argv) {
  int points = 81;
  std::string csv, json_path, plot;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) fesd_bench::usage(a + ": missing value");
    const std::string v = argv[++i];
    if (a == "--points")
      points = fesd_bench::parse_int(a, v);
    else if (a == "--csv")
      csv = v;
    else if (a == "--json")
      json_path = v;
    else if (a == "--plot")
      plot = v;
    else
      fesd_bench::usage("unknown argument " + a);
  }
  if (points < 3) fesd_bench::usage("--points must be >= 3");

  const fesd::Pss model = fesd_bench::value_model();
  std::vector<Point> pts;
  for (int k = 0; k < points; ++k) {
    Point p;
    // x0 = -3 + 4 k / (points - 1), computed so that x0 = 0 is exact where it is on the grid
    p.x0 = (-3.0 * (points - 1) + 4.0 * k) / (points - 1);
    p.exact = fesd_bench::exact_value(p.x0);
    p.fesd = fesd_bench::simulated_value(model, p.x0, 1, fesd_bench::fig9_options(true));
    p.standard = fesd_bench::simulated_value(model, p.x0, 1, fesd_bench::fig9_options(false));
    std::fprintf(stderr, "\rx0 = %+.3f (%d of %d)", p.x0, k + 1, points);
    pts.push_back(p);
  }
  std::fprintf(stderr, "\n");

  fmt::print(
      "OCP (56): V(x0) = int_0^2 x^2 dt + (x(2) - 5/3)^2, x' in 2 - sign(x); Gauss-Legendre n_s = "
      "2, N_FE = 25, N_sim = 1 (every 4th of {} points)\n",
      points);
  fmt::print("{:>7} {:>11} {:>11} {:>11} {:>11} {:>11} {:>11} {:>11} {:>11}\n", "x0", "V exact",
             "V FESD", "V std", "V' exact", "V' FESD", "V' std", "V' err FESD", "V' err std");
  double err_V_fesd = 0, err_V_std = 0, err_dV_fesd = 0, err_dV_std = 0;
  int unavailable_fesd = 0, unavailable_std = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Point& p = pts[i];
    const double e_f = std::abs(p.fesd.dV - p.exact.dV), e_s = std::abs(p.standard.dV - p.exact.dV);
    err_V_fesd = std::max(err_V_fesd, std::abs(p.fesd.V - p.exact.V));
    err_V_std = std::max(err_V_std, std::abs(p.standard.V - p.exact.V));
    if (p.x0 != 0) {  // V' is one-sided at the kink x0 = 0
      if (std::isfinite(p.fesd.dV))
        err_dV_fesd = std::max(err_dV_fesd, e_f);
      else
        ++unavailable_fesd;
      if (std::isfinite(p.standard.dV))
        err_dV_std = std::max(err_dV_std, e_s);
      else
        ++unavailable_std;
    }
    if (i % 4 == 0)
      fmt::print(
          "{:>7.3f} {:>11.7f} {:>11.7f} {:>11.7f} {:>11.7f} {:>11.7f} {:>11.7f} {:>11.1e} "
          "{:>11.1e}\n",
          p.x0, p.exact.V, p.fesd.V, p.standard.V, p.exact.dV, p.fesd.dV, p.standard.dV, e_f, e_s);
  }
  const std::vector<double> min_fesd = local_minima(pts, true), min_std = local_minima(pts, false);
  fmt::print("max |V - V exact|:   FESD {:.1e}, standard {:.1e}\n", err_V_fesd, err_V_std);
  fmt::print(
      "max |V' - V' exact| (x0 != 0): FESD {:.1e}, standard {:.1e} (not available: FESD {}, "
      "standard {})\n",
      err_dV_fesd, err_dV_std, unavailable_fesd, unavailable_std);
  fmt::print(
      "local minima of V on the grid: FESD {} [{}], standard {} [{}] (exact: one, x0* = "
      "{:.6f})\n",
      min_fesd.size(), fmt::join(min_fesd, ", "), min_std.size(), fmt::join(min_std, ", "),
      (9 - std::sqrt(417.0)) / 8);

  if (!csv.empty()) {
    std::ofstream f(csv);
    f << "x0,V_exact,V_fesd,V_standard,dV_exact,dV_fesd,dV_standard\n";
    for (const Point& p : pts)
      f << fmt::format("{:.6f},{:.15e},{:.15e},{:.15e},{:.15e},{:.15e},{:.15e}\n", p.x0, p.exact.V,
                       p.fesd.V, p.standard.V, p.exact.dV, p.fesd.dV, p.standard.dV);
  }
  if (!json_path.empty()) {
    nlohmann::json rows = nlohmann::json::array();
    for (const Point& p : pts)
      rows.push_back({{"x0", p.x0},
                      {"V_exact", p.exact.V},
                      {"V_fesd", num(p.fesd.V)},
                      {"V_standard", num(p.standard.V)},
                      {"dV_exact", p.exact.dV},
                      {"dV_fesd", num(p.fesd.dV)},
                      {"dV_standard", num(p.standard.dV)}});
    std::ofstream(json_path) << nlohmann::json{{"scheme", "gauss_legendre"},
                                               {"n_s", 2},
                                               {"N_FE", 25},
                                               {"N_sim", 1},
                                               {"max_error_V_fesd", err_V_fesd},
                                               {"max_error_V_standard", err_V_std},
                                               {"max_error_dV_fesd", err_dV_fesd},
                                               {"max_error_dV_standard", err_dV_std},
                                               {"local_minima_fesd", min_fesd},
                                               {"local_minima_standard", min_std},
                                               {"points", rows}}
                                    .dump(2)
                             << "\n";
  }
  if (!plot.empty()) {  // V (left) and V' (right): exact lines, FESD and standard points
    const std::string data = plot + ".dat";
    {
      std::ofstream os(data);
      os << "# x0 V_exact V_fesd V_standard dV_exact dV_fesd dV_standard\n";
      for (const Point& p : pts)
        os << fmt::format("{:.6f} {:.10e} {:.10e} {:.10e} {:.10e} {:.10e} {:.10e}\n", p.x0,
                          p.exact.V, p.fesd.V, p.standard.V, p.exact.dV, p.fesd.dV, p.standard.dV);
    }
    const std::string script = fmt::format(
        "set terminal pngcairo size 1200,480\nset output '{0}'\nset multiplot layout 1,2 title "
        "'OCP (56), Gauss-Legendre n_s = 2, N_FE = 25: FESD vs the standard method' noenhanced\n"
        "set grid\nset xlabel 'x0'\nset key top center noenhanced\nset ylabel 'V(x0)'\n"
        "plot '{1}' using 1:2 with lines lw 2 lc rgb 'black' title 'exact', "
        "'{1}' using 1:4 with linespoints pt 6 lc rgb 'red' title 'standard', "
        "'{1}' using 1:3 with points pt 7 ps 0.6 lc rgb 'blue' title 'FESD'\n"
        "set ylabel \"V'(x0)\"\n"
        "plot '{1}' using 1:5 with lines lw 2 lc rgb 'black' title 'exact', "
        "'{1}' using 1:7 with linespoints pt 6 lc rgb 'red' title 'standard', "
        "'{1}' using 1:6 with points pt 7 ps 0.6 lc rgb 'blue' title 'FESD'\n"
        "unset multiplot\n",
        plot, data);
    const std::string sp = plot + ".gp";
    std::ofstream(sp) << script;
    if (std::system(fmt::format("gnuplot '{}'", sp).c_str()) != 0)
      std::fprintf(stderr, "fig9_value_function: gnuplot failed (data in %s)\n", data.c_str());
  }
  return 0;
}
