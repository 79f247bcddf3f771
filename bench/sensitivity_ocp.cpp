// bench/sensitivity_ocp.cpp: Fig. 9 (right) of papers/fesd-filippov.txt (Sect. 4.5) as a table.
//
// The sensitivity OCP (56) is solved from initial guesses x0 spread over [-3, 3] (the MPCC
// initialized by a simulation from that x0 on the same grid), with Gauss-Legendre n_s = 2 and
// N_FE = 25: FESD or the standard method, each with a fixed sigma = 1e-15 or with the homotopy
// sigma = 1 -> 1e-15 (factor 0.1), Scholtes relaxation theta lambda <= sigma; and FESD with the
// homotopy with the sparse pairs (28) instead of the default stage sums, and on theta lambda =
// sigma (scholtes_eq). Prints x0* per guess, the distance to the exact
// minimizer (9 - sqrt(417)) / 8, and per combination the worst distance, NLP iterations and
// time.
//
//   sensitivity_ocp [--guesses 30] [--csv FILE] [--json FILE]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <fesd/error.hpp>
#include <fesd/ocp.hpp>

#include "bench_args.hpp"
#include "sensitivity_ocp.hpp"

namespace fesd_bench {
void usage(const std::string& why, int exit_code) {
  std::fprintf(stderr,
               "sensitivity_ocp: %s\n"
               "usage: sensitivity_ocp [--guesses N] [--csv FILE] [--json FILE]\n",
               why.c_str());
  std::exit(exit_code);
}
}  // namespace fesd_bench

namespace {

struct Combo {
  const char* name;
  bool fesd, homotopy;
  fesd::MpccMode mode;
  fesd::CrossComp cross_comp = fesd::CrossComp::StageSum;  // the OCP default
};
constexpr Combo kCombos[] = {
    {"FESD fixed", true, false, fesd::MpccMode::ScholtesIneq},
    {"FESD homotopy", true, true, fesd::MpccMode::ScholtesIneq},
    {"FESD hom. sparse", true, true, fesd::MpccMode::ScholtesIneq, fesd::CrossComp::Sparse},
    {"FESD hom. eq", true, true, fesd::MpccMode::ScholtesEq},
    {"Std fixed", false, false, fesd::MpccMode::ScholtesIneq},
    {"Std homotopy", false, true, fesd::MpccMode::ScholtesIneq},
};

struct Run {
  double guess = 0, x0 = NAN, objective = NAN, wall_s = 0;
  int iterations = 0, nlps = 0;
  std::string status;
};

}  // namespace

int main(int argc, char** argv) {
  int n_guesses = 30;
  std::string csv, json_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) fesd_bench::usage(a + ": missing value");
      return argv[++i];
    };
    if (a == "--guesses") {
      n_guesses = fesd_bench::parse_int(a, value());
    } else if (a == "--csv") {
      csv = value();
    } else if (a == "--json") {
      json_path = value();
    } else if (a == "-h" || a == "--help") {
      fesd_bench::usage("Fig. 9 (right) of the FESD paper: x0* of OCP (56) per initial guess", 0);
    } else {
      fesd_bench::usage("unknown argument " + a);
    }
  }
  const std::vector<double> guesses = fesd_bench::sensitivity_guesses(n_guesses);

  const double x_star = fesd_bench::kSensitivityX0Star;
  std::vector<std::vector<Run>> runs(std::size(kCombos));
  for (std::size_t c = 0; c < std::size(kCombos); ++c) {
    for (double g : guesses) {
      Run r;
      r.guess = g;
      try {
        const fesd::OcpResult res =
            fesd::solve(fesd_bench::sensitivity_ocp(g),
                        fesd_bench::sensitivity_options(kCombos[c].fesd, kCombos[c].homotopy,
                                                        kCombos[c].mode, kCombos[c].cross_comp));
        r.x0 = res.x0()[0];
        r.objective = res.objective;
        r.wall_s = res.summary.wall_s;
        r.iterations = res.summary.nlp_iterations;
        r.nlps = static_cast<int>(res.homotopy.size());
        r.status = std::string(fesd::to_string(res.status));
      } catch (const fesd::Error& e) {
        r.status = std::string("error: ") + e.what();
      }
      std::fprintf(stderr,
                   "%-14s guess %+7.4f  x0* %+.10f  |x0* - exact| %.1e  %3d it  %.2f s  %s\n",
                   kCombos[c].name, g, r.x0, std::abs(r.x0 - x_star), r.iterations, r.wall_s,
                   r.status.c_str());
      runs[c].push_back(r);
    }
  }

  fmt::print("Fig. 9 (right): OCP (56), Gauss-Legendre n_s = 2, N_FE = 25, T = 2\n");
  fmt::print("exact minimizer x0* = (9 - sqrt(417)) / 8 = {:.13f}, V* = {:.13f}\n", x_star,
             fesd_bench::kSensitivityVStar);
  fmt::print(
      "fixed: one NLP with sigma = 1e-15; homotopy: sigma = 1, 0.1, ..., 1e-15; 'eq': "
      "theta lambda = sigma\n\n");
  std::string head = fmt::format("{:>8}", "guess");
  for (const Combo& c : kCombos) head += fmt::format(" {:>16}", c.name);
  fmt::print("{}\n", head);
  for (std::size_t k = 0; k < guesses.size(); ++k) {
    std::string line = fmt::format("{:>+8.4f}", guesses[k]);
    for (std::size_t c = 0; c < std::size(kCombos); ++c) {
      const Run& r = runs[c][k];
      line += r.status == "success" ? fmt::format(" {:>+16.10f}", r.x0)
                                    : fmt::format(" {:>16}", "FAIL");
    }
    fmt::print("{}\n", line);
  }
  fmt::print("\n{:<14} {:>10} {:>14} {:>10} {:>10} {:>9} {:>9}\n", "method", "solved",
             "max |x0*-ex|", "within1e-6", "NLPs/run", "iter/run", "s/run");
  nlohmann::json jsum = nlohmann::json::array();
  for (std::size_t c = 0; c < std::size(kCombos); ++c) {
    int solved = 0, within = 0, nlps = 0, iters = 0;
    double worst = 0, wall = 0;
    for (const Run& r : runs[c]) {
      wall += r.wall_s;
      nlps += r.nlps;
      iters += r.iterations;
      if (r.status != "success") continue;
      ++solved;
      const double d = std::abs(r.x0 - x_star);
      worst = std::max(worst, d);
      if (d <= 1e-6) ++within;
    }
    const double n = static_cast<double>(runs[c].size());
    fmt::print("{:<16} {:>10} {:>14.1e} {:>10} {:>10.1f} {:>9.1f} {:>9.3f}\n", kCombos[c].name,
               fmt::format("{}/{}", solved, runs[c].size()), worst,
               fmt::format("{}/{}", within, runs[c].size()), nlps / n, iters / n, wall / n);
    jsum.push_back({{"method", kCombos[c].name},
                    {"solved", solved},
                    {"within_1e-6", within},
                    {"max_error", worst},
                    {"nlps_per_run", nlps / n},
                    {"iterations_per_run", iters / n},
                    {"wall_s_per_run", wall / n}});
  }

  if (!csv.empty()) {
    std::ofstream os(csv);
    if (!os) fesd_bench::usage("cannot write " + csv, 1);
    os << "method,guess,x0_star,error,objective,status,nlps,iterations,wall_s\n";
    for (std::size_t c = 0; c < std::size(kCombos); ++c)
      for (const Run& r : runs[c])
        os << fmt::format("{},{:.17g},{:.17g},{:.3e},{:.17g},{},{},{},{:.4f}\n", kCombos[c].name,
                          r.guess, r.x0, std::abs(r.x0 - x_star), r.objective, r.status, r.nlps,
                          r.iterations, r.wall_s);
  }
  if (!json_path.empty()) {
    std::ofstream os(json_path);
    if (!os) fesd_bench::usage("cannot write " + json_path, 1);
    nlohmann::json j;
    j["problem"] = "sensitivity OCP (56), Gauss-Legendre n_s = 2, N_FE = 25";
    j["x0_exact"] = x_star;
    j["summary"] = jsum;
    nlohmann::json jr = nlohmann::json::array();
    for (std::size_t c = 0; c < std::size(kCombos); ++c)
      for (const Run& r : runs[c])
        jr.push_back({{"method", kCombos[c].name},
                      {"guess", r.guess},
                      {"x0_star", r.x0},
                      {"objective", r.objective},
                      {"status", r.status},
                      {"iterations", r.iterations},
                      {"wall_s", r.wall_s}});
    j["runs"] = jr;
    os << j.dump(2) << "\n";
  }
  return 0;
}
