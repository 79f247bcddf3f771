// bench/fig13_ocp.cpp: Fig. 13 of papers/fesd-filippov.txt (Sect. 5.3) as a table.
//
// The sliding-mode OCP (61) is solved with N_stages = 6 for every RK method (Radau IIA,
// Gauss-Legendre, Lobatto IIIC, explicit RK), n_s = 1..4 and N_FE = 1..7 (FESD: 2..7), by the
// standard discretization and by FESD. Its optimal controls are then simulated with the FESD
// integrator at high accuracy (Radau IIA n_s = 4, --sim-steps steps of 2 elements per control
// interval), and E(T) = ||q_int(4) - q_final|| (REFERENCE.md: the position part) is set against
// the CPU time of the OCP solve.
//
//   fig13_ocp [--schemes radau_iia,gauss_legendre,lobatto_iiic,explicit_rk] [--stages 1,2,3,4]
//             [--N-FE 1,...,7] [--mode both|fesd|std] [--sim-steps 6] [--quick]
//             [--step-eq l2_relaxed|heuristic_mean|eta|none] [--comp-tol 1e-12]
//             [--intermediate-tol TOL]
//             [--mpcc-fesd MODE] [--mpcc-std MODE]   (mpcc_mode names, default scholtes_ineq)
//             [--csv FILE] [--json FILE] [--plot FILE.png|svg]
//   fig13_ocp --merge A.csv,B.csv [--csv FILE] [--json FILE] [--plot FILE]   (no solving: the
//             table, summary and plot of runs saved by --csv, later files replacing earlier runs)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <fesd/error.hpp>
#include <fesd/integrator.hpp>
#include <fesd/ocp.hpp>

#include "bench_args.hpp"
#include "sliding_ocp.hpp"

namespace fesd_bench {
void usage(const std::string& why, int exit_code) {
  std::fprintf(stderr,
               "fig13_ocp: %s\n"
               "usage: fig13_ocp [--schemes s1,s2] [--stages 1,2] [--N-FE 1,2,...] "
               "[--mode both|fesd|std] [--step-eq NAME]\n"
               "                 [--comp-tol TOL] [--intermediate-tol TOL] [--mpcc-fesd MODE] "
               "[--mpcc-std MODE]\n"
               "                 [--sim-steps N] [--quick] [--csv FILE] [--json FILE] "
               "[--plot FILE.png|svg]\n"
               "       fig13_ocp --merge A.csv,B.csv [--csv FILE] [--json FILE] [--plot FILE]\n",
               why.c_str());
  std::exit(exit_code);
}
}  // namespace fesd_bench

namespace {

struct Run {
  fesd::RkScheme scheme{};
  int n_s = 0, N_FE = 0;
  bool fesd = false;
  std::string status;
  double objective = NAN, cpu_s = 0, E = NAN;
  int iterations = 0, nlps = 0;
};

/// q(4) of a high-accuracy simulation of the piecewise constant controls u_k.
double simulate_error(const fesd::OcpResult& r, int sim_steps) {
  const fesd::Pss model = fesd_bench::sliding_model();
  fesd::IntegratorOptions io;
  io.discretization.rk_scheme = fesd::RkScheme::RadauIIA;
  io.discretization.n_s = 4;
  io.discretization.N_FE = 2;
  io.homotopy.complementarity_tol = 1e-12;
  io.homotopy.sigma_N = 1e-13;
  Eigen::VectorXd x = fesd_bench::sliding_ocp_paper().x0;
  const double T_k = 4.0 / static_cast<double>(r.u.size());
  for (const Eigen::VectorXd& u : r.u) {
    const fesd::IntegratorResult s = fesd::integrate(model, x, T_k, sim_steps, io, u);
    if (s.status != fesd::Status::Success) return NAN;
    x = s.x_final();
  }
  return (x.head<2>() - fesd_bench::sliding_q_final()).norm();
}

/// Runs from CSV files written by --csv (header rk_scheme,n_s,N_FE,use_fesd,E_T,cpu_s,
/// iterations,nlps,objective,status); a later file's run replaces an earlier one with the same
/// scheme, n_s, N_FE and method, so partial sweeps run in parallel can be put together.
std::vector<Run> read_runs(const std::vector<std::string>& files) {
  std::vector<Run> runs;
  for (const std::string& file : files) {
    std::ifstream is(file);
    if (!is) fesd_bench::usage("cannot read " + file, 1);
    std::string line;
    std::getline(is, line);  // header
    while (std::getline(is, line)) {
      const std::vector<std::string> f = fesd_bench::split(line, ',');
      Run r;
      try {
        if (f.size() != 10 || !fesd::parse(f[0], r.scheme)) throw std::invalid_argument(line);
        r.n_s = std::stoi(f[1]);
        r.N_FE = std::stoi(f[2]);
        r.fesd = f[3] == "1";
        r.E = std::stod(f[4]);  // "nan" for a failed reference simulation
        r.cpu_s = std::stod(f[5]);
        r.iterations = std::stoi(f[6]);
        r.nlps = std::stoi(f[7]);
        r.objective = std::stod(f[8]);
        r.status = f[9];
      } catch (const std::exception&) {
        fesd_bench::usage(file + ": not a fig13_ocp CSV line: " + line, 1);
      }
      auto same = [&](const Run& o) {
        return o.scheme == r.scheme && o.n_s == r.n_s && o.N_FE == r.N_FE && o.fesd == r.fesd;
      };
      if (auto it = std::find_if(runs.begin(), runs.end(), same); it != runs.end())
        *it = r;
      else
        runs.push_back(r);
    }
  }
  std::sort(runs.begin(), runs.end(), [](const Run& a, const Run& b) {
    return std::tie(a.scheme, a.n_s, a.fesd, a.N_FE) < std::tie(b.scheme, b.n_s, b.fesd, b.N_FE);
  });
  return runs;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<fesd::RkScheme> schemes{fesd::RkScheme::RadauIIA, fesd::RkScheme::GaussLegendre,
                                      fesd::RkScheme::LobattoIIIC, fesd::RkScheme::ExplicitRK};
  std::vector<int> stages{1, 2, 3, 4}, n_fe{1, 2, 3, 4, 5, 6, 7};
  bool run_std = true, run_fesd = true;
  int sim_steps = 6;
  fesd::StepEq step_eq = fesd::StepEq::L2Relaxed;
  // E(T) cannot fall below what the complementarity tolerance leaves of a sliding exit's place
  // (both factors vanish there): with 1e-9 FESD's E(T) stays at 2e-8 - 4e-8, with 1e-12 it
  // reaches 1e-11 (docs/benchmarks-ocp.md). REFERENCE.md's accuracy figures use 1e-12 too.
  double comp_tol = 1e-12;
  double intermediate_tol = fesd::OcpOptions{}.homotopy.intermediate_tol;
  fesd::MpccMode mpcc_fesd = fesd::OcpOptions{}.homotopy.mpcc_mode, mpcc_std = mpcc_fesd;
  std::string csv, json_path, plot;
  std::vector<std::string> merge;  // --merge: read runs from these CSVs instead of solving
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) fesd_bench::usage(a + ": missing value");
      return argv[++i];
    };
    if (a == "--schemes") {
      schemes.clear();
      for (const std::string& s : fesd_bench::split(value(), ',')) {
        fesd::RkScheme sc{};
        if (!fesd::parse(s, sc)) fesd_bench::usage("unknown scheme " + s);
        schemes.push_back(sc);
      }
    } else if (a == "--stages") {
      stages = fesd_bench::parse_list(a, value());
    } else if (a == "--N-FE") {
      n_fe = fesd_bench::parse_list(a, value());
    } else if (a == "--mode") {
      const std::string m = value();
      run_std = m != "fesd";
      run_fesd = m != "std";
      if (m != "both" && m != "fesd" && m != "std")
        fesd_bench::usage("--mode " + m + ": expected both, fesd or std");
    } else if (a == "--step-eq") {
      const std::string v = value();
      if (!fesd::parse(v, step_eq)) fesd_bench::usage("--step-eq " + v + ": unknown name");
    } else if (a == "--intermediate-tol") {  // 0 allowed: every NLP to tol
      const std::string v = value();
      intermediate_tol = v == "0" ? 0.0 : fesd_bench::parse_double(a, v);
    } else if (a == "--comp-tol") {
      comp_tol = fesd_bench::parse_double(a, value());
    } else if (a == "--mpcc-fesd" || a == "--mpcc-std") {
      const std::string v = value();
      if (!fesd::parse(v, a == "--mpcc-fesd" ? mpcc_fesd : mpcc_std))
        fesd_bench::usage(a + " " + v + ": unknown mpcc_mode");
    } else if (a == "--sim-steps") {
      sim_steps = fesd_bench::parse_int(a, value());
    } else if (a == "--quick") {
      schemes = {fesd::RkScheme::RadauIIA};
      stages = {2};
      n_fe = {2, 4};
    } else if (a == "--csv") {
      csv = value();
    } else if (a == "--json") {
      json_path = value();
    } else if (a == "--merge") {
      merge = fesd_bench::split(value(), ',');
    } else if (a == "--plot") {
      plot = value();
    } else if (a == "-h" || a == "--help") {
      fesd_bench::usage("Fig. 13 of the FESD paper: E(T) vs CPU time for OCP (61)", 0);
    } else {
      fesd_bench::usage("unknown argument " + a);
    }
  }

  const fesd::Ocp ocp = fesd_bench::sliding_ocp_paper();
  std::vector<Run> runs;
  if (!merge.empty()) {
    runs = read_runs(merge);
    schemes.clear();  // nothing to solve
  }
  for (fesd::RkScheme scheme : schemes)
    for (int n_s : stages) {
      try {
        (void)fesd::make_tableau(scheme, n_s);
      } catch (const fesd::Error&) {
        continue;  // e.g. Lobatto with n_s = 1
      }
      for (bool f : {false, true}) {
        if ((f && !run_fesd) || (!f && !run_std)) continue;
        for (int N : n_fe) {
          if (f && N < 2) continue;  // FESD needs two elements to move a switch
          Run run;
          run.scheme = scheme;
          run.n_s = n_s;
          run.N_FE = N;
          run.fesd = f;
          fesd::OcpOptions o = fesd_bench::sliding_options();
          // The OCP default, not nosnoc's heuristic_mean of sliding_options(): heuristic_mean
          // costs FESD two orders of E(T) here (Radau IIA n_s = 3, N_FE = 4: 7.4e-5 against
          // 1.0e-7 with l2_relaxed, 1.4e-6 with none; docs/benchmarks-ocp.md). The standard
          // method has fixed h_n and is not affected.
          o.discretization.step_eq = step_eq;
          o.discretization.rk_scheme = scheme;
          o.discretization.n_s = n_s;
          o.discretization.N_FE = N;
          o.discretization.use_fesd = f;
          o.homotopy.complementarity_tol = comp_tol;
          o.homotopy.intermediate_tol = intermediate_tol;
          o.homotopy.mpcc_mode = f ? mpcc_fesd : mpcc_std;
          try {
            // Process CPU time (not wall time): the sweep shares a 2-core machine.
            const std::clock_t c0 = std::clock();
            const fesd::OcpResult r = fesd::solve(ocp, o);
            run.cpu_s = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
            run.status = std::string(fesd::to_string(r.status));
            run.objective = r.objective;
            run.iterations = r.summary.nlp_iterations;
            run.nlps = static_cast<int>(r.homotopy.size());
            if (r.status == fesd::Status::Success) run.E = simulate_error(r, sim_steps);
          } catch (const fesd::Error& e) {
            run.status = std::string("error: ") + e.what();
          }
          std::fprintf(stderr, "%-15s n_s=%d N_FE=%d %-4s  E(T) %.2e  %6.2f s  %4d it  %s\n",
                       std::string(fesd::to_string(scheme)).c_str(), n_s, N, f ? "FESD" : "std",
                       run.E, run.cpu_s, run.iterations, run.status.c_str());
          runs.push_back(run);
        }
      }
    }

  if (merge.empty())
    fmt::print(
        "Fig. 13: OCP (61), N_stages = 6; E(T) = ||q_int(4) - q_final|| of a Radau IIA n_s = 4 "
        "simulation ({} steps per interval)\nstep equilibration {}, complementarity_tol {:.0e}, "
        "intermediate_tol {:g}, mpcc_mode {} (FESD) / {} (standard)\n\n",
        sim_steps, fesd::to_string(step_eq), comp_tol, intermediate_tol, fesd::to_string(mpcc_fesd),
        fesd::to_string(mpcc_std));
  else
    fmt::print("Fig. 13: OCP (61), N_stages = 6; runs read from {} (settings as run)\n\n",
               fmt::join(merge, ", "));
  // One row per (scheme, n_s, N_FE), standard and FESD side by side (objective and status in
  // the CSV / JSON files).
  fmt::print("{:<14} {:>3} {:>4} | {:>9} {:>6} {:>5} | {:>9} {:>6} {:>5}\n", "scheme", "n_s",
             "N_FE", "std E(T)", "CPU s", "iter", "FESD E(T)", "CPU s", "iter");
  auto cell = [&](const Run* r) {
    return r ? fmt::format("{:>9.2e} {:>6.2f} {:>5}", r->E, r->cpu_s, r->iterations)
             : fmt::format("{:>9} {:>6} {:>5}", "", "", "");
  };
  std::vector<std::tuple<fesd::RkScheme, int, int>> rows;
  for (const Run& r : runs)
    if (std::find(rows.begin(), rows.end(), std::tuple{r.scheme, r.n_s, r.N_FE}) == rows.end())
      rows.emplace_back(r.scheme, r.n_s, r.N_FE);
  for (const auto& [scheme, n_s, N] : rows) {
    const Run *s = nullptr, *f = nullptr;
    for (const Run& r : runs)
      if (r.scheme == scheme && r.n_s == n_s && r.N_FE == N) (r.fesd ? f : s) = &r;
    fmt::print("{:<14} {:>3} {:>4} | {} | {}\n", fesd::to_string(scheme), n_s, N, cell(s), cell(f));
  }

  // Summary: best E(T) per method family, and FESD vs standard at comparable CPU time.
  auto best = [&](bool f, double max_cpu) {
    double e = std::numeric_limits<double>::infinity();
    for (const Run& r : runs)
      if (r.fesd == f && std::isfinite(r.E) && r.cpu_s <= max_cpu) e = std::min(e, r.E);
    return e;
  };
  // orders = log10(standard / FESD); "-" where a method has no run within the budget.
  fmt::print("\nbest E(T) within a CPU budget (all schemes):\n{:>10} {:>12} {:>12} {:>8}\n",
             "budget s", "standard", "FESD", "orders");
  for (double budget : {1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 15.0, 20.0, 30.0, 1e9}) {
    const double s = best(false, budget), f = best(true, budget);
    const bool both = std::isfinite(s) && std::isfinite(f) && f > 0;
    fmt::print("{:>10} {:>12.2e} {:>12.2e} {:>8}\n",
               budget > 1e8 ? std::string("any") : fmt::format("{:.0f}", budget), s, f,
               both ? fmt::format("{:.2f}", std::log10(s / f)) : std::string("-"));
  }

  if (!csv.empty()) {
    std::ofstream os(csv);
    if (!os) fesd_bench::usage("cannot write " + csv, 1);
    os << "rk_scheme,n_s,N_FE,use_fesd,E_T,cpu_s,iterations,nlps,objective,status\n";
    for (const Run& r : runs)
      os << fmt::format("{},{},{},{},{:.6e},{:.4f},{},{},{:.12g},{}\n", fesd::to_string(r.scheme),
                        r.n_s, r.N_FE, r.fesd ? 1 : 0, r.E, r.cpu_s, r.iterations, r.nlps,
                        r.objective, r.status);
  }
  if (!json_path.empty()) {
    std::ofstream os(json_path);
    if (!os) fesd_bench::usage("cannot write " + json_path, 1);
    nlohmann::json j = nlohmann::json::array();
    for (const Run& r : runs)
      j.push_back({{"rk_scheme", std::string(fesd::to_string(r.scheme))},
                   {"n_s", r.n_s},
                   {"N_FE", r.N_FE},
                   {"use_fesd", r.fesd},
                   {"E_T", std::isfinite(r.E) ? nlohmann::json(r.E) : nlohmann::json(nullptr)},
                   {"cpu_s", r.cpu_s},
                   {"iterations", r.iterations},
                   {"objective", r.objective},
                   {"status", r.status}});
    os << j.dump(2) << "\n";
  }
  if (!plot.empty()) {  // E(T) against CPU time, one point set per scheme and method
    const std::string data = plot + ".dat";
    std::vector<fesd::RkScheme> plotted;  // the schemes of the runs, in order
    for (const Run& r : runs)
      if (std::find(plotted.begin(), plotted.end(), r.scheme) == plotted.end())
        plotted.push_back(r.scheme);
    std::ofstream os(data);
    // Columns: CPU s, E(T), marker size growing with n_s (as in the paper's figure).
    for (bool f : {false, true})
      for (fesd::RkScheme sc : plotted) {
        os << fmt::format("# {} {}\n", fesd::to_string(sc), f ? "FESD" : "standard");
        for (const Run& r : runs)
          if (r.scheme == sc && r.fesd == f && std::isfinite(r.E))
            os << fmt::format("{:.6g} {:.6e} {:.2f}\n", r.cpu_s, r.E, 0.5 + 0.35 * r.n_s);
        os << "\n\n";
      }
    os.close();
    const bool svg = plot.size() > 4 && plot.substr(plot.size() - 4) == ".svg";
    std::string script = fmt::format(
        "set terminal {} size 900,600\nset output '{}'\nset logscale xy\nset xlabel 'CPU time "
        "[s]'\nset ylabel 'E(T)'\nset format y '%.0e'\nset key outside right noenhanced\n"
        "set grid\nset title 'OCP (61): terminal error vs CPU time (marker size: n_s)' "
        "noenhanced\nplot ",
        svg ? "svg" : "pngcairo", plot);
    int idx = 0;
    for (bool f : {false, true})
      for (fesd::RkScheme sc : plotted)
        script += fmt::format(
            "{}'{}' index {} using 1:2:3 with points pt {} ps variable title "
            "'{} {}'",
            idx ? ", " : "", data, idx, f ? 7 : 6, fesd::to_string(sc), f ? "FESD" : "std"),
            ++idx;
    script += "\n";
    const std::string sp = plot + ".gp";
    std::ofstream(sp) << script;
    if (std::system(fmt::format("gnuplot '{}'", sp).c_str()) != 0)
      std::fprintf(stderr, "fig13_ocp: gnuplot failed (data in %s)\n", data.c_str());
  }
  return 0;
}
