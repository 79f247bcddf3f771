// bench/fig8_accuracy.cpp: Fig. 8 of papers/fesd-filippov.txt (Sect. 4.4) as tables.
//
// The nonsmooth oscillator (47) is simulated over [0, pi/2] with N_sim integration steps of
// N_FE = 2 finite elements each, by the standard time-stepping method (use_fesd = false) and by
// FESD, for Radau IIA n_s = 1..4, Gauss-Legendre 1..3, Lobatto IIIC 2..4 and explicit RK 1..4.
// For every run it records E(T) = ||x(T) - x_exact|| and the switching-time error |t_s - 1|, and
// per method it fits the slope of log E against log h (h = T / N_sim) by least squares. FESD:
// through the points with 1e-10 < E < 1e-1; below 1e-10 is round-off (the NLPs are solved to
// 1e-12), above 1e-1 is pre-asymptotic. Standard method: through all points with E > 1e-10. Its
// errors scatter between ~1e-2 and ~1 at every h (they depend on where t_s = 1 falls inside an
// element), so an upper cut would keep only the lucky points and bias the slope.
//
//   fig8_accuracy [--quick] [--methods radau_iia:3,gauss_legendre] [--N 8,16,32] [--N-low 64,128]
//                 [--mode both|fesd|std] [--comp-tol 1e-12] [--sigma-N 1e-13] [--ipopt-tol 1e-12]
//                 [--stage-sign auto|all|boundary] [--dcs-mode stewart|step]
//                 [--csv FILE] [--json FILE]
//
// A method is `scheme:n_s` or just `scheme` (all n_s of Fig. 8); scheme names as in problem files.
// Methods of order >= 3 run at --N (default 8, 11, ..., 64); methods of order 1 and 2, whose error
// constants are large on this problem, at --N-low (default 64, 128, ..., 1024; = --N if only --N
// is given). `--dcs-mode step` runs the Heaviside step form (nosnoc's Step mode, as in its
// oscillator/integration_order_experiment_oscillator.py) instead of Stewart's.
// One progress line per run goes to stderr; the tables go to stdout.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <fesd/error.hpp>
#include <fesd/integrator.hpp>
#include <fesd/options.hpp>
#include <fesd/tableau.hpp>

#include "bench_args.hpp"
#include "oscillator_model.hpp"
#include "slope_fit.hpp"

namespace {

using fesd::RkScheme;
using fesd_bench::parse_double;
using fesd_bench::parse_int;
using fesd_bench::parse_list;
using fesd_bench::split;
using fesd_bench::usage;

constexpr double kFitLow = 1e-10;  // below: round-off of NLPs solved to tol = 1e-12
constexpr double kFitHigh = 1e-1;  // above: pre-asymptotic (h too large); FESD only
// First-order methods have error constants ~300 here (omega = 2 pi: explicit Euler's radius
// grows by sqrt((1 + h)^2 + omega^2 h^2) per step), so E < 0.1 needs N_sim > 5000: their window
// ends at 1 instead.
constexpr double kFitHighOrder1 = 1.0;
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Method {
  RkScheme scheme = RkScheme::RadauIIA;
  int n_s = 1;
  int order = 0;       // classical order for smooth ODEs
  std::vector<int> N;  // N_sim values run for this method
  std::string label;   // short column label, e.g. "Radau3"
  std::string name;    // e.g. "Radau IIA n_s=3"
};

Method make_method(RkScheme scheme, int n_s) {
  Method m;
  m.scheme = scheme;
  m.n_s = n_s;
  m.order = fesd::make_tableau(scheme, n_s).order;
  switch (scheme) {
    case RkScheme::RadauIIA:
      m.label = "Radau";
      m.name = "Radau IIA";
      break;
    case RkScheme::GaussLegendre:
      m.label = "Gauss";
      m.name = "Gauss-Legendre";
      break;
    case RkScheme::LobattoIIIA:
      m.label = "LobA";
      m.name = "Lobatto IIIA";
      break;
    case RkScheme::LobattoIIIC:
      m.label = "LobC";
      m.name = "Lobatto IIIC";
      break;
    case RkScheme::ExplicitRK:
      m.label = "ERK";
      m.name = "explicit RK";
      break;
  }
  m.label += std::to_string(n_s);
  m.name += fmt::format(" n_s={}", n_s);
  return m;
}

/// The n_s values Fig. 8 shows for a scheme.
std::vector<int> fig8_stages(RkScheme s) {
  switch (s) {
    case RkScheme::RadauIIA:
      return {1, 2, 3, 4};
    case RkScheme::GaussLegendre:
      return {1, 2, 3};
    case RkScheme::LobattoIIIA:
    case RkScheme::LobattoIIIC:
      return {2, 3, 4};
    case RkScheme::ExplicitRK:
      return {1, 2, 3, 4};
  }
  return {};
}

struct Run {
  const Method* method = nullptr;
  bool fesd = false;
  int N_sim = 0;
  double h = 0;
  fesd_bench::OscillatorErrors err;
  fesd::Status status = fesd::Status::NotRun;
  std::string message;
  double wall_s = 0;
  int nlps = 0;
  int iterations = 0;
  double max_comp = 0;
  bool ok() const { return status == fesd::Status::Success; }
};

/// The least-squares slope (slope_fit.hpp) of log y against log h through the points with
/// kFitLow < y < high, h decreasing (the order of the table: the local slopes go along it).
fesd_bench::SlopeFit fit_slope(const std::vector<std::pair<double, double>>& h_y, double high) {
  std::vector<std::pair<double, double>> pts;
  for (const auto& [h, y] : h_y)
    if (std::isfinite(y) && y > kFitLow && y < high) pts.emplace_back(h, y);
  std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  return fesd_bench::fit_log_log(pts);
}

std::string fmt_opt(const std::optional<double>& v, const char* spec = "{:.2f}") {
  return v ? fmt::format(fmt::runtime(spec), *v) : std::string("-");
}

struct Config {
  std::vector<Method> methods;
  std::vector<int> N;      // N_sim for methods of order >= 3
  std::vector<int> N_low;  // N_sim for methods of order 1 and 2 (larger error constants)
  bool run_std = true, run_fesd = true;
  double comp_tol = 1e-12, sigma_N = 1e-13, ipopt_tol = 1e-12;
  fesd::StageLambdaSign stage_sign = fesd::StageLambdaSign::Auto;
  fesd::StepSolver step_solver = fesd::IntegratorOptions{}.step_solver;  // the library's default
  fesd::DcsMode dcs_mode = fesd::DcsMode::Stewart;
  std::string csv, json;
  bool quick = false;
};

Config parse_args(int argc, char** argv) {
  Config cfg;
  std::string methods_arg, N_arg, N_low_arg;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(a + ": missing value");
      return argv[++i];
    };
    if (a == "--quick") {
      cfg.quick = true;
    } else if (a == "--methods") {
      methods_arg = value();
    } else if (a == "--N") {
      N_arg = value();
    } else if (a == "--N-low") {
      N_low_arg = value();
    } else if (a == "--mode") {
      const std::string m = value();
      if (m == "both") {
        cfg.run_std = cfg.run_fesd = true;
      } else if (m == "fesd") {
        cfg.run_std = false;
      } else if (m == "std") {
        cfg.run_fesd = false;
      } else {
        usage("--mode " + m + ": expected both, fesd or std");
      }
    } else if (a == "--stage-sign") {
      const std::string v = value();
      if (!fesd::parse(v, cfg.stage_sign))
        usage("--stage-sign " + v + ": expected all, boundary or auto");
    } else if (a == "--dcs-mode") {
      const std::string v = value();
      if (!fesd::parse(v, cfg.dcs_mode)) usage("--dcs-mode " + v + ": expected stewart or step");
    } else if (a == "--comp-tol") {
      cfg.comp_tol = parse_double(a, value());
    } else if (a == "--step-solver") {
      cfg.step_solver = fesd_bench::parse_step_solver(a, value());
    } else if (a == "--sigma-N") {
      cfg.sigma_N = parse_double(a, value());
    } else if (a == "--ipopt-tol") {
      cfg.ipopt_tol = parse_double(a, value());
    } else if (a == "--csv") {
      cfg.csv = value();
    } else if (a == "--json") {
      cfg.json = value();
    } else if (a == "-h" || a == "--help") {
      usage("Fig. 8 of the FESD paper: E(T) and t_s error vs h on the oscillator (47)", 0);
    } else {
      usage("unknown argument " + a);
    }
  }
  if (N_arg.empty()) {
    cfg.N = cfg.quick ? std::vector<int>{8, 16, 32} : std::vector<int>{8, 11, 16, 23, 32, 45, 64};
  } else {
    cfg.N = parse_list("--N", N_arg);
  }
  if (!N_low_arg.empty())
    cfg.N_low = parse_list("--N-low", N_low_arg);
  else if (!N_arg.empty() || cfg.quick)
    cfg.N_low = cfg.N;
  else
    cfg.N_low = {64, 128, 256, 512, 1024};
  for (auto* v : {&cfg.N, &cfg.N_low}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }

  if (methods_arg.empty())
    methods_arg = cfg.quick
                      ? "radau_iia:2,radau_iia:3,gauss_legendre:2,lobatto_iiic:3,explicit_rk:4"
                      : "radau_iia,gauss_legendre,lobatto_iiic,explicit_rk";
  for (const std::string& item : split(methods_arg, ',')) {
    const auto colon = item.find(':');
    const std::string name = item.substr(0, colon);
    RkScheme scheme{};
    if (!fesd::parse(name, scheme)) usage("unknown scheme " + name);
    std::vector<int> stages;
    if (colon == std::string::npos)
      stages = fig8_stages(scheme);
    else
      stages.push_back(parse_int("--methods", item.substr(colon + 1)));
    for (int n_s : stages) {
      try {
        cfg.methods.push_back(make_method(scheme, n_s));
        cfg.methods.back().N = cfg.methods.back().order <= 2 ? cfg.N_low : cfg.N;
      } catch (const fesd::Error& e) {
        usage(item + ": " + e.what());
      }
    }
  }
  return cfg;
}

Run run_one(const Method& m, bool use_fesd, int N_sim, const Config& cfg) {
  fesd::IntegratorOptions opt;
  opt.discretization.rk_scheme = m.scheme;
  opt.discretization.n_s = m.n_s;
  opt.discretization.N_FE = 2;  // as in the paper
  opt.discretization.use_fesd = use_fesd;
  opt.discretization.stage_lambda_sign = cfg.stage_sign;
  opt.discretization.dcs_mode = cfg.dcs_mode;
  opt.homotopy.complementarity_tol = cfg.comp_tol;
  opt.homotopy.sigma_N = cfg.sigma_N;
  opt.step_solver = cfg.step_solver;
  opt.nlp.tol = cfg.ipopt_tol;
  Run r;
  r.method = &m;
  r.fesd = use_fesd;
  r.N_sim = N_sim;
  r.h = fesd_bench::kOscillatorT / N_sim;
  static const fesd::Pss model = fesd_bench::oscillator_model();
  try {
    const fesd::IntegratorResult res =
        fesd::integrate(model, fesd_bench::oscillator_x0(), fesd_bench::kOscillatorT, N_sim, opt);
    r.status = res.status;
    r.message = res.message;
    r.err = fesd_bench::oscillator_errors(res);
    r.wall_s = res.summary.wall_s;
    r.nlps = res.summary.homotopy_steps;
    r.iterations = res.summary.nlp_iterations;
    r.max_comp = res.summary.max_comp_residual;
  } catch (const fesd::Error& e) {
    r.status = fesd::Status::NotRun;
    r.message = e.what();
  }
  return r;
}

/// Table cell for an error: value, "-" if absent, "FAIL" if the run did not finish. A '*' marks a
/// run that detected a number of switches other than one.
std::string cell(const Run& r, bool t_s) {
  if (!r.ok()) return "FAIL";
  if (t_s) {
    if (!r.err.t_s) return "-";
    return fmt::format("{:.1e}{}", *r.err.t_s, r.err.n_switches == 1 ? "" : "*");
  }
  return fmt::format("{:.1e}", r.err.x_T);
}

}  // namespace

void fesd_bench::usage(const std::string& why, int exit_code) {
  std::fprintf(
      stderr,
      "fig8_accuracy: %s\n"
      "usage: fig8_accuracy [--quick] [--methods scheme[:n_s],...] [--N n1,...] [--N-low n1,...]\n"
      "                     [--mode both|fesd|std] [--comp-tol X] [--sigma-N X]\n"
      "                     [--stage-sign auto|all|boundary] [--dcs-mode stewart|step]\n"
      "                     [--ipopt-tol X] [--step-solver active_set|homotopy]\n"
      "                     [--csv FILE] [--json FILE]\n"
      "schemes: radau_iia gauss_legendre lobatto_iiia lobatto_iiic explicit_rk\n",
      why.c_str());
  std::exit(exit_code);
}

int main(int argc, char** argv) {
  const Config cfg = parse_args(argc, argv);
  std::vector<bool> modes;
  if (cfg.run_std) modes.push_back(false);
  if (cfg.run_fesd) modes.push_back(true);

  // runs[method][mode][N]
  std::vector<std::vector<std::vector<Run>>> runs(cfg.methods.size());
  std::size_t total = 0;
  std::vector<int> all_N;  // table rows: every N_sim any method ran
  for (const Method& m : cfg.methods) {
    total += modes.size() * m.N.size();
    all_N.insert(all_N.end(), m.N.begin(), m.N.end());
  }
  std::sort(all_N.begin(), all_N.end());
  all_N.erase(std::unique(all_N.begin(), all_N.end()), all_N.end());
  std::size_t done = 0;
  double total_wall = 0;
  for (std::size_t mi = 0; mi < cfg.methods.size(); ++mi) {
    for (bool f : modes) {
      runs[mi].emplace_back();
      for (int N : cfg.methods[mi].N) {
        const Run r = run_one(cfg.methods[mi], f, N, cfg);
        ++done;
        total_wall += r.wall_s;
        std::fprintf(stderr,
                     "[%3zu/%zu] %-20s %-4s N_sim=%-3d E=%.2e  |t_s-1|=%-9s sw=%d  NLPs %4d  "
                     "iter %5d  %7.2f s  %s\n",
                     done, total, cfg.methods[mi].name.c_str(), f ? "FESD" : "std", N, r.err.x_T,
                     fmt_opt(r.err.t_s, "{:.2e}").c_str(), r.err.n_switches, r.nlps, r.iterations,
                     r.wall_s,
                     r.ok() ? "ok" : (std::string(to_string(r.status)) + ": " + r.message).c_str());
        runs[mi].back().push_back(r);
      }
    }
  }

  fmt::print("Fig. 8: nonsmooth oscillator (47), T = pi/2, N_FE = 2, h = T/N_sim\n");
  fmt::print("IPOPT tol {:.0e}, complementarity_tol {:.0e}, sigma_N {:.0e}; FESD step_solver {}\n",
             cfg.ipopt_tol, cfg.comp_tol, cfg.sigma_N, fesd::to_string(cfg.step_solver));
  fmt::print(
      "FAIL = status not success; '-' = no switch detected; '*' = more than one switch detected\n");

  // ---- error tables: rows N_sim, columns methods ----
  for (std::size_t k = 0; k < modes.size(); ++k) {
    for (bool t_s : {false, true}) {
      fmt::print("\n{} {}\n", modes[k] ? "FESD" : "Standard",
                 t_s ? "|t_s - 1|" : "E(T) = ||x(T) - x_exact||");
      std::string head = fmt::format("{:>5} {:>8}", "N_sim", "h");
      for (const Method& m : cfg.methods) head += fmt::format(" {:>9}", m.label);
      fmt::print("{}\n", head);
      for (int N : all_N) {
        std::string line = fmt::format("{:>5} {:>8.4f}", N, fesd_bench::kOscillatorT / N);
        for (std::size_t mi = 0; mi < cfg.methods.size(); ++mi) {
          const auto& rs = runs[mi][k];
          auto it = std::find_if(rs.begin(), rs.end(), [&](const Run& r) { return r.N_sim == N; });
          line += fmt::format(" {:>9}", it == rs.end() ? std::string("") : cell(*it, t_s));
        }
        fmt::print("{}\n", line);
      }
    }
  }

  // ---- summary: fitted slopes ----
  nlohmann::json jsum = nlohmann::json::array();
  fmt::print(
      "\nSlopes of log E (and of log |t_s - 1|) against log h, least squares; (k) = points used."
      "\nFESD: {:.0e} < E < {:.0e} ({:.0e} for order 1); standard: all points with E > {:.0e} (its "
      "errors scatter)\n",
      kFitLow, kFitHigh, kFitHighOrder1, kFitLow);
  fmt::print("{:<22} {:>5} {:>10} {:>10} {:>9} {:>10} {:>10}  {:<26} {:>8}\n", "method", "order",
             "std", "FESD", "FESD-ord", "t_s FESD", "t_s std", "FESD local slopes", "wall s");
  for (std::size_t mi = 0; mi < cfg.methods.size(); ++mi) {
    const Method& m = cfg.methods[mi];
    std::optional<fesd_bench::SlopeFit> fx[2], ft[2];
    double wall = 0;
    int failures = 0;
    for (std::size_t k = 0; k < modes.size(); ++k) {
      std::vector<std::pair<double, double>> ex, et;
      for (const Run& r : runs[mi][k]) {
        wall += r.wall_s;
        if (!r.ok()) {
          ++failures;
          continue;
        }
        ex.emplace_back(r.h, r.err.x_T);
        if (r.err.t_s) et.emplace_back(r.h, *r.err.t_s);
      }
      const double high =  // see the top of this file
          modes[k] ? (m.order == 1 ? kFitHighOrder1 : kFitHigh) : kInf;
      fx[modes[k] ? 1 : 0] = fit_slope(ex, high);
      ft[modes[k] ? 1 : 0] = fit_slope(et, high);
    }
    auto slope = [](const std::optional<fesd_bench::SlopeFit>& f) {
      if (!f || f->points < 2) return std::string("-");
      return fmt::format("{:.2f} ({})", f->slope, f->points);
    };
    std::optional<double> diff;
    if (fx[1] && fx[1]->points >= 2) diff = fx[1]->slope - m.order;
    std::string local;
    if (fx[1])
      for (double s : fx[1]->local) local += fmt::format("{}{:.1f}", local.empty() ? "" : " ", s);
    fmt::print(
        "{:<22} {:>5} {:>10} {:>10} {:>9} {:>10} {:>10}  {:<26} {:>8.1f}{}\n", m.name, m.order,
        slope(fx[0]), slope(fx[1]), fmt_opt(diff, "{:+.2f}"), slope(ft[1]), slope(ft[0]),
        local.empty() ? "-" : local, wall,
        failures ? fmt::format("  ({} failed run{})", failures, failures == 1 ? "" : "s") : "");
    auto jfit = [](const std::optional<fesd_bench::SlopeFit>& f) -> nlohmann::json {
      if (!f) return nullptr;
      nlohmann::json j;
      j["slope"] = f->points >= 2 ? nlohmann::json(f->slope) : nlohmann::json(nullptr);
      j["points"] = f->points;
      j["local_slopes"] = f->local;
      return j;
    };
    jsum.push_back({{"method", m.name},
                    {"rk_scheme", std::string(fesd::to_string(m.scheme))},
                    {"n_s", m.n_s},
                    {"order", m.order},
                    {"std_error", jfit(fx[0])},
                    {"fesd_error", jfit(fx[1])},
                    {"std_t_s", jfit(ft[0])},
                    {"fesd_t_s", jfit(ft[1])},
                    {"failed_runs", failures},
                    {"wall_s", wall}});
  }
  fmt::print("\ntotal integration wall time {:.1f} s over {} runs\n", total_wall, total);

  // ---- files ----
  if (!cfg.csv.empty()) {
    std::ofstream os(cfg.csv);
    if (!os) {
      std::fprintf(stderr, "fig8_accuracy: cannot write %s\n", cfg.csv.c_str());
      return 1;
    }
    os << "method,rk_scheme,n_s,order,use_fesd,N_sim,h,error_x,error_t_s,n_switches,status,wall_s,"
          "nlps,ipopt_iterations,max_comp_residual\n";
    for (std::size_t mi = 0; mi < cfg.methods.size(); ++mi)
      for (const auto& mode_runs : runs[mi])
        for (const Run& r : mode_runs)
          os << fmt::format("{},{},{},{},{},{},{:.17g},{:.17g},{},{},{},{:.4f},{},{},{:.3e}\n",
                            r.method->name, fesd::to_string(r.method->scheme), r.method->n_s,
                            r.method->order, r.fesd ? 1 : 0, r.N_sim, r.h, r.err.x_T,
                            r.err.t_s ? fmt::format("{:.17g}", *r.err.t_s) : "", r.err.n_switches,
                            fesd::to_string(r.status), r.wall_s, r.nlps, r.iterations, r.max_comp);
  }
  if (!cfg.json.empty()) {
    nlohmann::json j;
    j["problem"] = "oscillator (47), T = pi/2, N_FE = 2";
    j["options"] = {{"ipopt_tol", cfg.ipopt_tol},
                    {"complementarity_tol", cfg.comp_tol},
                    {"sigma_N", cfg.sigma_N},
                    {"fit_window_fesd", {kFitLow, kFitHigh}},
                    {"fit_window_std", {kFitLow, nullptr}}};
    nlohmann::json jr = nlohmann::json::array();
    for (std::size_t mi = 0; mi < cfg.methods.size(); ++mi)
      for (const auto& mode_runs : runs[mi])
        for (const Run& r : mode_runs)
          jr.push_back(
              {{"method", r.method->name},
               {"use_fesd", r.fesd},
               {"N_sim", r.N_sim},
               {"h", r.h},
               {"error_x", r.ok() ? nlohmann::json(r.err.x_T) : nlohmann::json(nullptr)},
               {"error_t_s", r.err.t_s ? nlohmann::json(*r.err.t_s) : nlohmann::json(nullptr)},
               {"n_switches", r.err.n_switches},
               {"status", std::string(fesd::to_string(r.status))},
               {"message", r.message},
               {"wall_s", r.wall_s},
               {"nlps", r.nlps},
               {"ipopt_iterations", r.iterations},
               {"max_comp_residual", r.max_comp}});
    j["runs"] = jr;
    j["summary"] = jsum;
    std::ofstream os(cfg.json);
    if (!os) {
      std::fprintf(stderr, "fig8_accuracy: cannot write %s\n", cfg.json.c_str());
      return 1;
    }
    os << j.dump(2) << "\n";
  }
  return 0;
}
