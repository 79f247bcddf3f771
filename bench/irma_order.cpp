// bench/irma_order.cpp: nosnoc_py's integration order experiment on the IRMA gene network
// (examples/Acary2014/irma_integration_order_experiment.py; row 11 of docs/nosnoc-examples.md).
//
// examples/nosnoc/irma.toml (the Heaviside step form with f_alpha, N_FE = 3, heuristic_mean) is
// simulated over [0, T] (T = 100, as the script's TSIM) with N_sim steps, by FESD and by the
// standard method (use_fesd = false), for Radau IIA and Gauss-Legendre with n_s stages, at the
// script's tolerance comp_tol = sigma_N = 1e-12. The error is its measure, max_i |x_i(T) -
// x_ref,i(T)|; the reference is not a fine numerical run as in the script but the exact solution
// (bench/gene_network_exact.hpp: x is piecewise exponential between threshold crossings, which
// are located in closed form; two crossings on [0, 100], at t = 25.54 and 39.19). Per method the
// slope of log E against log h (h = T / N_sim) is fitted by least squares through the points with
// E > --fit-low (default 1e-8: FESD's errors level off at about 1e-9, the resolution of the NLPs)
// and h <= --h-max (default 40: one or two steps over [0, 100] are pre-asymptotic here).
//
//   irma_order [--methods radau_iia:1,radau_iia:2,gauss_legendre] [--N 1,3,9,18,50,100,300]
//              [--mode both|fesd|std] [--T 100] [--comp-tol 1e-12] [--fit-low 1e-8]
//              [--h-max 40] [--quick]
//
// A method is `scheme:n_s` or just `scheme` (n_s = 1..4 as the script's NS_VALUES). Defaults:
// Radau IIA 1..4 and the script's N_sim values 1, 3, 9, 18, 50, 100, 300; --quick: Radau IIA 1..3
// at N_sim = 3, 9, 18, 50. One progress line per run goes to stderr, the tables to stdout.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include <fesd/error.hpp>
#include <fesd/integrator.hpp>
#include <fesd/problem_file.hpp>
#include <fesd/tableau.hpp>

#include "bench_args.hpp"
#include "gene_network_exact.hpp"
#include "slope_fit.hpp"

namespace {

using fesd::RkScheme;
using fesd_bench::parse_double;
using fesd_bench::parse_int;
using fesd_bench::parse_list;
using fesd_bench::split;
using fesd_bench::usage;

struct Method {
  RkScheme scheme = RkScheme::RadauIIA;
  int n_s = 1;
  int order = 0;
  std::string label;
};

struct Run {
  bool ok = false;
  double error = 0;    // max_i |x_i(T) - x_exact,i(T)|
  double t_error = 0;  // max |t_s - t_s,exact| if the switch count matches
  int switches = 0;
  double wall_s = 0;
  std::string message;
};

struct Config {
  std::vector<Method> methods;
  std::vector<int> N{1, 3, 9, 18, 50, 100, 300};
  bool run_std = true, run_fesd = true;
  double T = 100, comp_tol = 1e-12, h_max = 40;
  double fit_low = 1e-8;  // below: the NLPs' resolution (FESD reaches ~1e-9 and stays there)
};

Config parse_args(int argc, char** argv) {
  Config cfg;
  std::string methods_arg = "radau_iia";
  bool quick = false, N_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(a + ": missing value");
      return argv[++i];
    };
    if (a == "--quick") {
      quick = true;
    } else if (a == "--methods") {
      methods_arg = value();
    } else if (a == "--N") {
      cfg.N = parse_list(a, value());
      N_given = true;
    } else if (a == "--mode") {
      const std::string m = value();
      cfg.run_std = m == "both" || m == "std";
      cfg.run_fesd = m == "both" || m == "fesd";
      if (!cfg.run_std && !cfg.run_fesd) usage("--mode " + m + ": expected both, fesd or std");
    } else if (a == "--T") {
      cfg.T = parse_double(a, value());
    } else if (a == "--comp-tol") {
      cfg.comp_tol = parse_double(a, value());
    } else if (a == "--fit-low") {
      cfg.fit_low = parse_double(a, value());
    } else if (a == "--h-max") {
      cfg.h_max = parse_double(a, value());
    } else if (a == "-h" || a == "--help") {
      usage("nosnoc_py's integration order experiment on the IRMA gene network", 0);
    } else {
      usage("unknown argument " + a);
    }
  }
  if (quick) {
    if (methods_arg == "radau_iia") methods_arg = "radau_iia:1,radau_iia:2,radau_iia:3";
    if (!N_given) cfg.N = {3, 9, 18, 50};
  }
  std::sort(cfg.N.begin(), cfg.N.end());
  cfg.N.erase(std::unique(cfg.N.begin(), cfg.N.end()), cfg.N.end());
  for (const std::string& item : split(methods_arg, ',')) {
    const auto colon = item.find(':');
    RkScheme scheme{};
    if (!fesd::parse(item.substr(0, colon), scheme)) usage("unknown scheme " + item);
    std::vector<int> stages{1, 2, 3, 4};
    if (colon != std::string::npos) stages = {parse_int("--methods", item.substr(colon + 1))};
    for (int n_s : stages) {
      Method m;
      m.scheme = scheme;
      m.n_s = n_s;
      try {
        m.order = fesd::make_tableau(scheme, n_s).order;
      } catch (const fesd::Error& e) {
        usage(item + ": " + e.what());
      }
      m.label = fmt::format("{}{}",
                            scheme == RkScheme::RadauIIA        ? "Radau"
                            : scheme == RkScheme::GaussLegendre ? "Gauss"
                                                                : fesd::to_string(scheme),
                            n_s);
      cfg.methods.push_back(m);
    }
  }
  return cfg;
}

Run run_one(const fesd::SimulationProblem& file, const Method& m, bool use_fesd, int N_sim,
            const Config& cfg, const fesd_bench::GeneSolution& exact) {
  fesd::IntegratorOptions opt = file.options;
  opt.discretization.rk_scheme = m.scheme;
  opt.discretization.n_s = m.n_s;
  opt.discretization.use_fesd = use_fesd;
  opt.homotopy.complementarity_tol = cfg.comp_tol;
  opt.homotopy.sigma_N = cfg.comp_tol;
  Run r;
  try {
    const fesd::IntegratorResult res =
        fesd::integrate(file.model, file.x0, cfg.T, N_sim, opt, file.u, file.p);
    r.wall_s = res.summary.wall_s;
    r.message = res.message;
    r.ok = res.status == fesd::Status::Success;
    if (r.ok) {
      for (int i = 0; i < res.x_final().size(); ++i)
        r.error = std::max(r.error, std::abs(res.x_final()[i] - exact.x_T[i]));
      r.switches = static_cast<int>(res.switches.size());
      if (res.switches.size() == exact.events.size())
        for (std::size_t k = 0; k < res.switches.size(); ++k)
          r.t_error = std::max(r.t_error, std::abs(res.switches[k].t - exact.events[k].t));
      else
        r.t_error = NAN;
    }
  } catch (const fesd::Error& e) {
    r.message = e.what();
  }
  return r;
}

/// The least-squares slope (slope_fit.hpp) of log E against log h through the points with
/// E > low, h <= h_max.
fesd_bench::SlopeFit fit_slope(const std::vector<std::pair<double, double>>& h_e, double low,
                               double h_max) {
  std::vector<std::pair<double, double>> pts;
  for (const auto& [h, e] : h_e)
    if (std::isfinite(e) && e > low && h <= h_max) pts.emplace_back(h, e);
  return fesd_bench::fit_log_log(pts);
}

}  // namespace

void fesd_bench::usage(const std::string& why, int exit_code) {
  std::fprintf(stderr,
               "irma_order: %s\n"
               "usage: irma_order [--quick] [--methods scheme[:n_s],...] [--N n1,...]\n"
               "                  [--mode both|fesd|std] [--T X] [--comp-tol X] [--fit-low X]\n"
               "                  [--h-max X]\n"
               "schemes: radau_iia gauss_legendre lobatto_iiia lobatto_iiic explicit_rk\n",
               why.c_str());
  std::exit(exit_code);
}

int main(int argc, char** argv) {
  const Config cfg = parse_args(argc, argv);
  const fesd::SimulationProblem file =
      fesd::load_simulation_problem(std::string(FESD_SOURCE_DIR) + "/examples/nosnoc/irma.toml");
  const fesd_bench::GeneSolution exact =
      fesd_bench::exact_solution(fesd_bench::irma_network(), fesd_bench::irma_x0(), cfg.T);
  std::vector<bool> modes;
  if (cfg.run_fesd) modes.push_back(true);
  if (cfg.run_std) modes.push_back(false);

  // runs[method][mode][N]
  std::vector<std::vector<std::vector<Run>>> runs(cfg.methods.size());
  const std::size_t total = cfg.methods.size() * modes.size() * cfg.N.size();
  std::size_t done = 0;
  double wall = 0;
  for (std::size_t mi = 0; mi < cfg.methods.size(); ++mi)
    for (bool f : modes) {
      runs[mi].emplace_back();
      for (int N : cfg.N) {
        const Run r = run_one(file, cfg.methods[mi], f, N, cfg, exact);
        wall += r.wall_s;
        std::fprintf(stderr, "[%3zu/%zu] %-7s %-8s N_sim=%-4d E=%.2e  sw=%d  %7.2f s  %s\n", ++done,
                     total, cfg.methods[mi].label.c_str(), f ? "FESD" : "standard", N, r.error,
                     r.switches, r.wall_s, r.ok ? "ok" : r.message.c_str());
        runs[mi].back().push_back(r);
      }
    }

  fmt::print("IRMA (examples/nosnoc/irma.toml), T = {}, N_FE = 3, comp_tol = sigma_N = {:.0e}\n",
             cfg.T, cfg.comp_tol);
  fmt::print("E = max_i |x_i(T) - x_exact,i(T)|, exact: {} crossings (t = ", exact.events.size());
  for (std::size_t k = 0; k < exact.events.size(); ++k)
    fmt::print("{}{:.6f}", k ? ", " : "", exact.events[k].t);
  fmt::print("); FAIL = not success; '*' = a switch count other than the exact one\n");
  for (std::size_t k = 0; k < modes.size(); ++k) {
    fmt::print("\n{}\n{:>5} {:>9}", modes[k] ? "FESD" : "Standard (use_fesd = false)", "N_sim",
               "h");
    for (const Method& m : cfg.methods) fmt::print(" {:>9}", m.label);
    fmt::print("\n");
    for (std::size_t ni = 0; ni < cfg.N.size(); ++ni) {
      fmt::print("{:>5} {:>9.4g}", cfg.N[ni], cfg.T / cfg.N[ni]);
      for (std::size_t mi = 0; mi < cfg.methods.size(); ++mi) {
        const Run& r = runs[mi][k][ni];
        const bool count_ok = r.switches == static_cast<int>(exact.events.size());
        fmt::print(" {:>9}", r.ok ? fmt::format("{:.1e}{}", r.error, count_ok ? "" : "*") : "FAIL");
      }
      fmt::print("\n");
    }
  }
  fmt::print("\nSlopes of log E against log h (least squares, E > {:.0e}, h <= {}; (k) = points)\n",
             cfg.fit_low, cfg.h_max);
  fmt::print("{:<8} {:>5} {:>10} {:>10}\n", "method", "order", "FESD", "standard");
  for (std::size_t mi = 0; mi < cfg.methods.size(); ++mi) {
    std::string cols[2] = {"-", "-"};
    for (std::size_t k = 0; k < modes.size(); ++k) {
      std::vector<std::pair<double, double>> h_e;
      for (std::size_t ni = 0; ni < cfg.N.size(); ++ni)
        if (runs[mi][k][ni].ok) h_e.emplace_back(cfg.T / cfg.N[ni], runs[mi][k][ni].error);
      const fesd_bench::SlopeFit s = fit_slope(h_e, cfg.fit_low, cfg.h_max);
      if (s.points >= 2) cols[modes[k] ? 0 : 1] = fmt::format("{:.2f} ({})", s.slope, s.points);
    }
    fmt::print("{:<8} {:>5} {:>10} {:>10}\n", cfg.methods[mi].label, cfg.methods[mi].order, cols[0],
               cols[1]);
  }
  fmt::print("\ntotal integration wall time {:.1f} s over {} runs\n", wall, total);
  return 0;
}
