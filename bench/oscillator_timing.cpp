// bench/oscillator_timing.cpp: where the time of an FESD simulation goes, on the oscillator (47)
// of papers/fesd-filippov.txt, and the rows of /work/shared/PEERS.md next to nosnoc_py's numbers.
//
// (a) Radau IIA n_s = 3, N_FE = 2, N_sim = 100, repeated R times: total wall time, time per
//     integration step, NLPs and IPOPT iterations per step, and the split into derivative
//     evaluation (fesd's own code), IPOPT + MUMPS (without the evaluations) and setup; median and
//     minimum over the repetitions.
// (b) The PEERS.md table: Radau IIA n_s = 2, 3, 4 x N_sim = 10, 20, 40, 80 with the error in x(T),
//     the error in t_s and the wall time, beside nosnoc_py's figures.
//
// Options as in the peer figures: IPOPT tol = complementarity_tol = sigma_N = 1e-12.
//
//   oscillator_timing [--part a|b|both] [--repeat R] [--N-a 100] [--stages 2,3,4]
//                     [--N 10,20,40,80] [--comp-tol X] [--sigma-N X] [--csv FILE] [--json FILE]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <fesd/error.hpp>
#include <fesd/integrator.hpp>
#include <fesd/options.hpp>

#include "bench_args.hpp"
#include "oscillator_model.hpp"

namespace {

using fesd_bench::parse_double;
using fesd_bench::parse_int;
using fesd_bench::parse_list;
using fesd_bench::usage;

/// nosnoc_py (commit 0c3f3bb, CasADi 3.6.3, IPOPT 3.11.9 + MUMPS) on a 2-core machine, from
/// /work/shared/PEERS.md, "Oscillator (47), FESD simulation, Radau IIA, N_FE = 2, T = pi/2".
/// NaN = not given there.
struct PeerRow {
  int n_s;
  int N_sim;
  double error_x;
  double error_t_s;
  double wall_s;
  const char* note;
};
constexpr double kNA = std::numeric_limits<double>::quiet_NaN();
constexpr PeerRow kNosnocPy[] = {
    {2, 10, 2.2e-1, kNA, 1.0, ""},
    {2, 20, 3.1e-2, kNA, 2.1, ""},
    {2, 40, 3.3e-3, 1.4e-4, 4.1, ""},
    {2, 80, 4.5e-4, kNA, 8.1, ""},
    {3, 10, 3.9e-4, kNA, 1.2, ""},
    {3, 20, 1.7e-5, kNA, 2.4, ""},
    {3, 40, 3.8e-7, 1.6e-8, 4.8, ""},
    {3, 80, 1.7e-8, kNA, 8.8, ""},
    {4, 10, 2.7e-7, kNA, 1.3, ""},
    {4, 20, 4.3e-9, kNA, 2.4, ""},
    {4, 40, 1.7e-12, 7.7e-14, 4.9, ""},
    {4, 80, 1.6e-2, kNA, 10.9, "failed (Infeasible_Problem_Detected)"},
};

const PeerRow* peer(int n_s, int N_sim) {
  for (const PeerRow& r : kNosnocPy)
    if (r.n_s == n_s && r.N_sim == N_sim) return &r;
  return nullptr;
}

struct Measurement {
  int n_s = 0;
  int N_sim = 0;
  int rep = 0;
  fesd::Status status = fesd::Status::NotRun;
  std::string message;
  fesd_bench::OscillatorErrors err;
  fesd::Summary summary;
  int steps = 0;
};

struct Config {
  bool part_a = true, part_b = true;
  int repeat = 3;
  int N_a = 100;
  std::vector<int> stages{2, 3, 4};
  std::vector<int> N{10, 20, 40, 80};
  double comp_tol = 1e-12, sigma_N = 1e-12;
  fesd::StepSolver step_solver = fesd::IntegratorOptions{}.step_solver;  // the library's default
  std::string csv, json;
};

Config parse_args(int argc, char** argv) {
  Config c;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(a + ": missing value");
      return argv[++i];
    };
    if (a == "--part") {
      const std::string p = value();
      if (p != "a" && p != "b" && p != "both") usage("--part " + p + ": expected a, b or both");
      c.part_a = p != "b";
      c.part_b = p != "a";
    } else if (a == "--repeat") {
      c.repeat = parse_int(a, value());
    } else if (a == "--N-a") {
      c.N_a = parse_int(a, value());
    } else if (a == "--stages") {
      c.stages = parse_list(a, value());
    } else if (a == "--N") {
      c.N = parse_list(a, value());
    } else if (a == "--comp-tol") {
      c.comp_tol = parse_double(a, value());
    } else if (a == "--step-solver") {
      c.step_solver = fesd_bench::parse_step_solver(a, value());
    } else if (a == "--sigma-N") {
      c.sigma_N = parse_double(a, value());
    } else if (a == "--csv") {
      c.csv = value();
    } else if (a == "--json") {
      c.json = value();
    } else if (a == "-h" || a == "--help") {
      usage("FESD timing on the oscillator (47) and the PEERS.md rows", 0);
    } else {
      usage("unknown argument " + a);
    }
  }
  return c;
}

Measurement measure(int n_s, int N_sim, int rep, const Config& cfg) {
  fesd::IntegratorOptions opt;
  opt.discretization.rk_scheme = fesd::RkScheme::RadauIIA;
  opt.discretization.n_s = n_s;
  opt.discretization.N_FE = 2;
  opt.discretization.use_fesd = true;
  opt.homotopy.complementarity_tol = cfg.comp_tol;
  opt.homotopy.sigma_N = cfg.sigma_N;
  opt.step_solver = cfg.step_solver;
  opt.nlp.tol = 1e-12;
  static const fesd::Pss model = fesd_bench::oscillator_model();
  Measurement m;
  m.n_s = n_s;
  m.N_sim = N_sim;
  m.rep = rep;
  try {
    const fesd::IntegratorResult r =
        fesd::integrate(model, fesd_bench::oscillator_x0(), fesd_bench::kOscillatorT, N_sim, opt);
    m.status = r.status;
    m.message = r.message;
    m.err = fesd_bench::oscillator_errors(r);
    m.summary = r.summary;
    m.steps = static_cast<int>(r.homotopy.size());
  } catch (const fesd::Error& e) {
    m.message = e.what();
  }
  std::fprintf(
      stderr,
      "  Radau IIA n_s=%d N_sim=%-3d rep %d: E=%.2e  |t_s-1|=%s  %6.2f s  NLPs %d  iter %d  "
      "%s\n",
      n_s, N_sim, rep + 1, m.err.x_T, m.err.t_s ? fmt::format("{:.2e}", *m.err.t_s).c_str() : "-",
      m.summary.wall_s, m.summary.homotopy_steps, m.summary.nlp_iterations,
      m.status == fesd::Status::Success ? "ok" : m.message.c_str());
  return m;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string sci(double v) {
  return std::isnan(v) ? std::string("-") : fmt::format("{:.1e}", v);
}

nlohmann::json to_json(const Measurement& m, const char* part) {
  return {{"part", part},
          {"n_s", m.n_s},
          {"N_sim", m.N_sim},
          {"rep", m.rep},
          {"status", std::string(fesd::to_string(m.status))},
          {"error_x", m.err.x_T},
          {"error_t_s", m.err.t_s ? nlohmann::json(*m.err.t_s) : nlohmann::json(nullptr)},
          {"n_switches", m.err.n_switches},
          {"wall_s", m.summary.wall_s},
          {"derivative_s", m.summary.derivative_s},
          {"solver_s", m.summary.solver_s},
          {"setup_s", m.summary.setup_s},
          {"nlps", m.summary.homotopy_steps},
          {"ipopt_iterations", m.summary.nlp_iterations},
          {"steps", m.steps}};
}

}  // namespace

void fesd_bench::usage(const std::string& why, int exit_code) {
  std::fprintf(
      stderr,
      "oscillator_timing: %s\n"
      "usage: oscillator_timing [--part a|b|both] [--repeat R] [--N-a N] [--stages 2,3,4]\n"
      "                         [--N 10,20,40,80] [--comp-tol X] [--sigma-N X]\n"
      "                         [--step-solver active_set|homotopy]\n"
      "                         [--csv FILE] [--json FILE]\n",
      why.c_str());
  std::exit(exit_code);
}

int main(int argc, char** argv) {
  const Config cfg = parse_args(argc, argv);
  std::vector<std::pair<std::string, Measurement>> all;  // (part, measurement)
  nlohmann::json jout;
  jout["options"] = {{"rk_scheme", "radau_iia"},
                     {"N_FE", 2},
                     {"ipopt_tol", 1e-12},
                     {"complementarity_tol", cfg.comp_tol},
                     {"sigma_N", cfg.sigma_N}};
  fmt::print(
      "Oscillator (47), FESD, Radau IIA, N_FE = 2, T = pi/2; IPOPT tol 1e-12, "
      "complementarity_tol {:.0e}, sigma_N {:.0e}; step_solver {}\n",
      cfg.comp_tol, cfg.sigma_N, fesd::to_string(cfg.step_solver));

  // ---- (a) where the time goes ----
  if (cfg.part_a) {
    std::fprintf(stderr, "(a) n_s = 3, N_sim = %d, %d repetitions\n", cfg.N_a, cfg.repeat);
    std::vector<Measurement> ms;
    for (int rep = 0; rep < cfg.repeat; ++rep) {
      ms.push_back(measure(3, cfg.N_a, rep, cfg));
      all.emplace_back("a", ms.back());
    }
    // Each quantity over the repetitions: (median, min).
    auto stat = [&](auto get) {
      std::vector<double> v;
      for (const Measurement& m : ms) v.push_back(get(m));
      return std::pair{median(v), *std::min_element(v.begin(), v.end())};
    };
    const double steps = std::max(1, ms.front().steps);
    const auto wall = stat([](const Measurement& m) { return m.summary.wall_s; });
    const auto der = stat([](const Measurement& m) { return m.summary.derivative_s; });
    const auto sol = stat([](const Measurement& m) { return m.summary.solver_s; });
    const auto setup = stat([](const Measurement& m) { return m.summary.setup_s; });
    const auto other = stat([](const Measurement& m) {
      return m.summary.wall_s - m.summary.derivative_s - m.summary.solver_s - m.summary.setup_s;
    });
    const Measurement& m0 = ms.front();
    fmt::print(
        "\n(a) Radau IIA n_s = 3, N_sim = {}, {} repetitions (status {}, E = {:.2e}, "
        "|t_s - 1| = {})\n",
        cfg.N_a, cfg.repeat, fesd::to_string(m0.status), m0.err.x_T,
        m0.err.t_s ? fmt::format("{:.2e}", *m0.err.t_s) : "-");
    fmt::print("{:<34} {:>12} {:>12}\n", "", "median", "min");
    auto row = [&](const char* name, std::pair<double, double> v, double scale, const char* unit) {
      fmt::print("{:<34} {:>9.3f} {:<2} {:>9.3f} {:<2}\n", name, v.first * scale, unit,
                 v.second * scale, unit);
    };
    row("total wall time", wall, 1.0, "s");
    row("per integration step", wall, 1e3 / steps, "ms");
    row("  derivative evaluation", der, 1.0, "s");
    row("  IPOPT + MUMPS (w/o evaluations)", sol, 1.0, "s");
    row("  setup (NLP build)", setup, 1e3, "ms");
    row("  other (LP, guesses, results)", other, 1e3, "ms");
    const double busy = der.first + sol.first;
    fmt::print("{:<34} {:>9.1f} %  of derivative + IPOPT time\n", "derivative share",
               busy > 0 ? 100 * der.first / busy : 0.0);
    fmt::print("{:<34} {:>9.1f}\n", "NLPs per step", m0.summary.homotopy_steps / steps);
    fmt::print("{:<34} {:>9.1f}\n", "IPOPT iterations per step", m0.summary.nlp_iterations / steps);
    fmt::print("{:<34} {:>9.2f} ms\n", "wall per IPOPT iteration",
               1e3 * wall.first / std::max(1, m0.summary.nlp_iterations));
    jout["part_a"] = {{"N_sim", cfg.N_a},
                      {"repeat", cfg.repeat},
                      {"steps", steps},
                      {"wall_s", {{"median", wall.first}, {"min", wall.second}}},
                      {"derivative_s", {{"median", der.first}, {"min", der.second}}},
                      {"solver_s", {{"median", sol.first}, {"min", sol.second}}},
                      {"setup_s", {{"median", setup.first}, {"min", setup.second}}},
                      {"other_s", {{"median", other.first}, {"min", other.second}}},
                      {"nlps_per_step", m0.summary.homotopy_steps / steps},
                      {"iterations_per_step", m0.summary.nlp_iterations / steps}};
  }

  // ---- (b) the PEERS.md rows ----
  if (cfg.part_b) {
    std::fprintf(stderr, "(b) PEERS.md rows\n");
    std::vector<Measurement> ms;
    for (int n_s : cfg.stages)
      for (int N : cfg.N) {
        ms.push_back(measure(n_s, N, 0, cfg));
        all.emplace_back("b", ms.back());
      }
    fmt::print(
        "\n(b) PEERS.md rows: fesd vs nosnoc_py (PEERS.md: nosnoc_py 0c3f3bb, CasADi 3.6.3,\n"
        "    IPOPT 3.11.9 + MUMPS, 2-core machine, timings +-30 %)\n");
    fmt::print("{:>3} {:>5} | {:>9} {:>9} {:>7} {:>6} {:>6} {:<10} | {:>9} {:>9} {:>6}  {}\n",
               "n_s", "N_sim", "err x(T)", "err t_s", "wall s", "ms/st", "NLP/st", "status",
               "err x(T)", "err t_s", "wall s", "nosnoc_py note");
    for (const Measurement& m : ms) {
      const PeerRow* p = peer(m.n_s, m.N_sim);
      const double steps = std::max(1, m.steps);
      fmt::print(
          "{:>3} {:>5} | {:>9} {:>9} {:>7.2f} {:>6.1f} {:>6.1f} {:<10} | {:>9} {:>9} {:>6}  {}\n",
          m.n_s, m.N_sim, sci(m.err.x_T), m.err.t_s ? sci(*m.err.t_s) : "-", m.summary.wall_s,
          1e3 * m.summary.wall_s / steps, m.summary.homotopy_steps / steps,
          m.status == fesd::Status::Success ? "ok" : std::string(fesd::to_string(m.status)),
          p ? sci(p->error_x) : "-", p ? sci(p->error_t_s) : "-",
          p ? fmt::format("{:.1f}", p->wall_s) : "-", p ? p->note : "");
    }
    for (const Measurement& m : ms)
      if (m.status != fesd::Status::Success)
        fmt::print("fesd n_s = {}, N_sim = {}: {}\n", m.n_s, m.N_sim, m.message);
  }

  if (!cfg.csv.empty()) {
    std::ofstream os(cfg.csv);
    if (!os) {
      std::fprintf(stderr, "oscillator_timing: cannot write %s\n", cfg.csv.c_str());
      return 1;
    }
    os << "part,n_s,N_sim,rep,status,error_x,error_t_s,n_switches,wall_s,derivative_s,solver_s,"
          "setup_s,nlps,ipopt_iterations,steps\n";
    for (const auto& [part, m] : all)
      os << fmt::format("{},{},{},{},{},{:.17g},{},{},{:.4f},{:.4f},{:.4f},{:.4f},{},{},{}\n", part,
                        m.n_s, m.N_sim, m.rep, fesd::to_string(m.status), m.err.x_T,
                        m.err.t_s ? fmt::format("{:.17g}", *m.err.t_s) : "", m.err.n_switches,
                        m.summary.wall_s, m.summary.derivative_s, m.summary.solver_s,
                        m.summary.setup_s, m.summary.homotopy_steps, m.summary.nlp_iterations,
                        m.steps);
  }
  if (!cfg.json.empty()) {
    nlohmann::json runs = nlohmann::json::array();
    for (const auto& [part, m] : all) runs.push_back(to_json(m, part.c_str()));
    jout["runs"] = runs;
    nlohmann::json peers = nlohmann::json::array();
    for (const PeerRow& p : kNosnocPy)
      peers.push_back({{"n_s", p.n_s},
                       {"N_sim", p.N_sim},
                       {"error_x", p.error_x},
                       {"error_t_s", std::isnan(p.error_t_s) ? nlohmann::json(nullptr)
                                                             : nlohmann::json(p.error_t_s)},
                       {"wall_s", p.wall_s},
                       {"note", p.note}});
    jout["nosnoc_py"] = {{"source", "/work/shared/PEERS.md"}, {"rows", peers}};
    std::ofstream os(cfg.json);
    if (!os) {
      std::fprintf(stderr, "oscillator_timing: cannot write %s\n", cfg.json.c_str());
      return 1;
    }
    os << jout.dump(2) << "\n";
  }
  return 0;
}
