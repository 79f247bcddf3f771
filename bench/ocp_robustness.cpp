// bench/ocp_robustness.cpp: does optimal control find the true optimum? (issue 14, items 1-2)
//
// Table "schemes": the sensitivity OCP (56) of papers/fesd-filippov.txt (Sect. 4.5) with the
// default OcpOptions except the RK scheme, N_FE and the initialization, from 30 initial guesses
// of x0 spread over [-3, 3]: how many reach the minimizer x0* = (9 - sqrt(417)) / 8 within 1e-6.
// For Radau IIA n_s = 1 and Lobatto IIIC n_s = 2 the quadrature of the cost is not exact, so the
// discrete minimizer differs from x0*: there the reference is the discrete minimizer, found by a
// brute-force scan over every allocation of the elements to the two segments before and after
// the switch (n1 = 1 .. N_FE - 1 elements before it; ocp_detail::solve_allocation), printed with
// its distance to x0*.
//
// Table "methods": the same count per MPCC method, step-equilibration mode and initialization at
// the paper's grid (Gauss-Legendre n_s = 2, N_FE = 25).
//
//   ocp_robustness [--table schemes|methods] [--guesses 30] [--csv FILE] [--json FILE]
//                  [--only SUBSTRING]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <fesd/error.hpp>
#include <fesd/ocp.hpp>

#include "bench_args.hpp"
#include "ocp/allocation.hpp"
#include "sensitivity_ocp.hpp"

namespace fesd_bench {
void usage(const std::string& why, int exit_code) {
  std::fprintf(stderr,
               "ocp_robustness: %s\n"
               "usage: ocp_robustness [--table schemes|methods] [--guesses N] [--only TEXT]\n"
               "                      [--csv FILE] [--json FILE]\n",
               why.c_str());
  std::exit(exit_code);
}
}  // namespace fesd_bench

namespace {

struct Config {
  std::string name;
  fesd::OcpOptions options;
  bool exact_quadrature = true;  // the scheme's quadrature integrates (56)'s cost exactly
};

struct Run {
  double guess = 0, x0 = NAN, objective = NAN, wall_s = 0;
  int iterations = 0;
  std::string status;
  std::size_t warnings = 0;
};

std::vector<Config> scheme_configs() {
  struct Scheme {
    fesd::RkScheme scheme;
    int n_s;
    bool exact;
  };
  const Scheme schemes[] = {
      {fesd::RkScheme::RadauIIA, 1, false},     {fesd::RkScheme::RadauIIA, 2, true},
      {fesd::RkScheme::RadauIIA, 3, true},      {fesd::RkScheme::GaussLegendre, 2, true},
      {fesd::RkScheme::GaussLegendre, 3, true}, {fesd::RkScheme::LobattoIIIC, 2, false},
      {fesd::RkScheme::LobattoIIIC, 3, true}};
  std::vector<Config> out;
  for (const Scheme& s : schemes)
    for (int n_fe : {10, 25})
      for (auto init : {fesd::OcpInitialization::Constant, fesd::OcpInitialization::Simulation}) {
        Config c;
        c.options.discretization.rk_scheme = s.scheme;
        c.options.discretization.n_s = s.n_s;
        c.options.discretization.N_FE = n_fe;
        c.options.initialization = init;
        c.exact_quadrature = s.exact;
        c.name = fmt::format("{} {} N_FE {} {}", fesd::to_string(s.scheme), s.n_s, n_fe,
                             fesd::to_string(init));
        out.push_back(c);
      }
  return out;
}

std::vector<Config> method_configs() {
  using fesd::MpccMode;
  using fesd::StepEq;
  std::vector<Config> out;
  for (MpccMode m : {MpccMode::ScholtesIneq, MpccMode::ScholtesEq, MpccMode::FischerBurmeister,
                     MpccMode::L1Penalty, MpccMode::ElasticIneq, MpccMode::ElasticTwoSided})
    for (StepEq e : {StepEq::L2Relaxed, StepEq::HeuristicMean, StepEq::HeuristicDelta, StepEq::Eta,
                     StepEq::None})
      for (auto init : {fesd::OcpInitialization::Constant, fesd::OcpInitialization::Simulation}) {
        Config c;
        c.options.discretization.rk_scheme = fesd::RkScheme::GaussLegendre;
        c.options.discretization.n_s = 2;
        c.options.discretization.N_FE = 25;
        c.options.discretization.step_eq = e;
        c.options.homotopy.mpcc_mode = m;
        c.options.initialization = init;
        c.name =
            fmt::format("{} {} {}", fesd::to_string(m), fesd::to_string(e), fesd::to_string(init));
        out.push_back(c);
      }
  return out;
}

/// The minimizer of the discretized (56) for a scheme whose quadrature is not exact: the OCP
/// solved at each allocation of the N_FE elements to the segments before and after the switch
/// (n1 and N_FE - n1), from a guess with the switch (x0*), and the best of these.
struct Allocation {
  int n1 = 0;
  double x0 = NAN, objective = INFINITY;
};
Allocation discrete_minimizer(fesd::OcpOptions o) {
  o.initialization = fesd::OcpInitialization::Simulation;
  const int N = o.discretization.N_FE;
  Allocation best;
  for (int n1 = 1; n1 < N; ++n1) {
    const std::optional<fesd::OcpResult> r = fesd::ocp_detail::solve_allocation(
        fesd_bench::sensitivity_ocp(fesd_bench::kSensitivityX0Star), o, {n1, N - n1});
    if (r && r->status == fesd::Status::Success && r->objective < best.objective)
      best = {n1, r->x0()[0], r->objective};
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  int n_guesses = 30;
  std::string table = "schemes", only, csv, json_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) fesd_bench::usage(a + ": missing value");
      return argv[++i];
    };
    if (a == "--guesses") {
      n_guesses = fesd_bench::parse_int(a, value());
    } else if (a == "--table") {
      table = value();
      if (table != "schemes" && table != "methods")
        fesd_bench::usage("--table " + table + ": expected schemes or methods");
    } else if (a == "--only") {
      only = value();
    } else if (a == "--csv") {
      csv = value();
    } else if (a == "--json") {
      json_path = value();
    } else if (a == "-h" || a == "--help") {
      fesd_bench::usage("does the OCP (56) reach its minimizer from 30 guesses?", 0);
    } else {
      fesd_bench::usage("unknown argument " + a);
    }
  }
  const std::vector<double> guesses = fesd_bench::sensitivity_guesses(n_guesses);
  std::vector<Config> configs = table == "schemes" ? scheme_configs() : method_configs();
  if (!only.empty())
    std::erase_if(configs, [&](const Config& c) { return c.name.find(only) == std::string::npos; });

  const double x_star = fesd_bench::kSensitivityX0Star;
  fmt::print("OCP (56): min int_0^2 x^2 dt + (x(2) - 5/3)^2, x' in 2 - sign(x), x0 free\n");
  fmt::print("exact minimizer x0* = {:.13f}; {} guesses over [-3, 3]; table '{}'\n\n", x_star,
             guesses.size(), table);
  fmt::print("{:<46} {:>8} {:>9} {:>12} {:>8} {:>9} {:>7} {:>8}\n", "configuration", "success",
             "within", "max |err|", "warned", "ref-x0*", "it/run", "s/run");
  nlohmann::json jconf = nlohmann::json::array();
  std::map<std::string, Allocation> scanned;  // discrete minimizers by scheme and N_FE
  std::string csv_rows;
  for (const Config& c : configs) {
    std::vector<Run> runs;
    for (double g : guesses) {
      Run r;
      r.guess = g;
      try {
        const fesd::OcpResult res = fesd::solve(fesd_bench::sensitivity_ocp(g), c.options);
        r.x0 = res.x0()[0];
        r.objective = res.objective;
        r.wall_s = res.summary.wall_s;
        r.iterations = res.summary.nlp_iterations;
        r.status = std::string(fesd::to_string(res.status));
        r.warnings = res.summary.warnings.size();
      } catch (const fesd::Error& e) {
        r.status = std::string("error: ") + e.what();
      }
      runs.push_back(r);
    }
    // Reference: x0* where the quadrature is exact, else the discrete minimizer (scan).
    double ref = x_star;
    if (!c.exact_quadrature) {
      const fesd::DiscretizationOptions& d = c.options.discretization;
      const std::string key = fmt::format("{} {} {}", fesd::to_string(d.rk_scheme), d.n_s, d.N_FE);
      if (!scanned.contains(key)) scanned[key] = discrete_minimizer(c.options);
      const Allocation a = scanned[key];
      ref = a.x0;
      fmt::print(
          "  discrete minimizer (scan over the {} allocations): n1 = {}, x0 = {:.10f}, "
          "V = {:.10f}\n",
          c.options.discretization.N_FE - 1, a.n1, a.x0, a.objective);
    }
    int success = 0, within = 0, warned = 0, iters = 0;
    double worst = 0, wall = 0;
    for (const Run& r : runs) {
      wall += r.wall_s;
      iters += r.iterations;
      if (r.warnings > 0) ++warned;
      if (r.status != "success") continue;
      ++success;
      const double d = std::abs(r.x0 - ref);
      worst = std::max(worst, d);
      if (d <= 1e-6) ++within;
      csv_rows +=
          fmt::format("{},{:.17g},{:.17g},{:.3e},{:.17g},{},{},{},{:.4f}\n", c.name, r.guess, r.x0,
                      d, r.objective, r.status, r.warnings, r.iterations, r.wall_s);
    }
    const double n = static_cast<double>(runs.size());
    fmt::print("{:<46} {:>8} {:>9} {:>12.1e} {:>8} {:>9.1e} {:>7.1f} {:>8.3f}\n", c.name,
               fmt::format("{}/{}", success, runs.size()),
               fmt::format("{}/{}", within, runs.size()), worst, warned, std::abs(ref - x_star),
               iters / n, wall / n);
    std::fflush(stdout);
    for (const Run& r : runs)
      if (r.status != "success" || std::abs(r.x0 - ref) > 1e-6)
        std::fprintf(stderr, "  %s: guess %+.4f -> x0 %+.10f (%s, %zu warnings)\n", c.name.c_str(),
                     r.guess, r.x0, r.status.c_str(), r.warnings);
    nlohmann::json jr = nlohmann::json::array();
    for (const Run& r : runs)
      jr.push_back({{"guess", r.guess},
                    {"x0", r.x0},
                    {"objective", r.objective},
                    {"status", r.status},
                    {"warnings", r.warnings},
                    {"iterations", r.iterations},
                    {"wall_s", r.wall_s}});
    jconf.push_back({{"configuration", c.name},
                     {"reference_x0", ref},
                     {"success", success},
                     {"within_1e-6", within},
                     {"warned", warned},
                     {"max_error", worst},
                     {"iterations_per_run", iters / n},
                     {"wall_s_per_run", wall / n},
                     {"runs", jr}});
  }
  if (!csv.empty()) {
    std::ofstream os(csv);
    if (!os) fesd_bench::usage("cannot write " + csv, 1);
    os << "configuration,guess,x0,error,objective,status,warnings,iterations,wall_s\n" << csv_rows;
  }
  if (!json_path.empty()) {
    std::ofstream os(json_path);
    if (!os) fesd_bench::usage("cannot write " + json_path, 1);
    nlohmann::json j;
    j["problem"] = "sensitivity OCP (56)";
    j["table"] = table;
    j["x0_exact"] = x_star;
    j["configurations"] = jconf;
    os << j.dump(2) << "\n";
  }
  return 0;
}
