// bench/sensitivity_h.cpp: the error of the sensitivity dx(T)/dx0 (IntegratorOptions::
// sensitivities, docs/sensitivities.md) against the step size, for FESD (Radau IIA, Gauss-Legendre;
// the active-set path) and the standard method (use_fesd = false, the homotopy path), on
// Example 3(a) (x' in 2 - sign(x), x0 = -1, T = 2: exact 1/3) and the oscillator (47) (exact
// e^(A2 (T - 1)) J e^(A1) with the jump matrix (24) J = [[1, 0], [2 omega, 1]]). Thm 19: FESD's
// error is O(h^q); the standard method's does not go to 0 (Sect. 2.4).
//
//   sensitivity_h [--N 8,16,32,64,128] [--path active_set|homotopy] [--csv FILE]
//
// --path: FESD's step solver (default active_set; homotopy: the sensitivity at the homotopy's
// final active set, docs/sensitivities.md).
//
// The error is the largest absolute entry of the difference (for Ex. 3(a) the one entry). One
// table to stdout; progress to stderr.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <fesd/integrator.hpp>
#include <fesd/options.hpp>

#include "bench_args.hpp"
#include "oscillator_model.hpp"
#include "sensitivity_ocp.hpp"

namespace fesd_bench {
[[noreturn]] void usage(const std::string& why, int exit_code) {
  std::fprintf(stderr,
               "sensitivity_h: %s\nusage: sensitivity_h [--N 8,16,32,64,128] [--path "
               "active_set|homotopy] [--csv FILE]\n",
               why.c_str());
  std::exit(exit_code);
}
}  // namespace fesd_bench

namespace {

using fesd::RkScheme;

struct Method {
  std::string name;
  RkScheme scheme;
  int n_s;
  bool fesd;
};

struct Problem {
  std::string name;
  fesd::Pss model;
  Eigen::VectorXd x0;
  double T;
  Eigen::MatrixXd exact;
};

/// e^(A t) for A = [[a, b], [-b, a]].
Eigen::Matrix2d exp_rotation(double a, double b, double t) {
  Eigen::Matrix2d e;
  e << std::cos(b * t), std::sin(b * t), -std::sin(b * t), std::cos(b * t);
  return std::exp(a * t) * e;
}

std::vector<Problem> problems() {
  std::vector<Problem> out;
  out.push_back(
      {"ex3a",
       fesd::make_pss(fesd_bench::SensitivityModel{},
                      fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}}),
       Eigen::VectorXd::Constant(1, -1.0), 2.0, Eigen::MatrixXd::Constant(1, 1, 1.0 / 3.0)});
  const double w = 2 * std::numbers::pi, T = fesd_bench::kOscillatorT;
  Eigen::Matrix2d J;
  J << 1, 0, 2 * w, 1;
  out.push_back({"oscillator", fesd_bench::oscillator_model(), fesd_bench::oscillator_x0(), T,
                 exp_rotation(1, -w, T - 1) * J * exp_rotation(1, w, 1)});
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> Ns{8, 16, 32, 64, 128};
  std::string csv;
  fesd::StepSolver fesd_path = fesd::StepSolver::ActiveSet;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) fesd_bench::usage("missing value after " + a);
    if (a == "--N")
      Ns = fesd_bench::parse_list(a, argv[++i]);
    else if (a == "--path") {
      const std::string v = argv[++i];
      if (v != "active_set" && v != "homotopy") fesd_bench::usage("--path: active_set or homotopy");
      fesd_path = v == "homotopy" ? fesd::StepSolver::Homotopy : fesd::StepSolver::ActiveSet;
    } else if (a == "--csv")
      csv = argv[++i];
    else
      fesd_bench::usage("unknown argument " + a);
  }
  const std::vector<Method> methods{{"fesd radau_iia 1", RkScheme::RadauIIA, 1, true},
                                    {"fesd radau_iia 2", RkScheme::RadauIIA, 2, true},
                                    {"fesd radau_iia 3", RkScheme::RadauIIA, 3, true},
                                    {"fesd gauss_legendre 2", RkScheme::GaussLegendre, 2, true},
                                    {"std radau_iia 2", RkScheme::RadauIIA, 2, false},
                                    {"std radau_iia 3", RkScheme::RadauIIA, 3, false}};
  std::string out = "problem,method,N_sim,h,error,available,value00\n";
  fmt::print("{:<11} {:<22} {:>6} {:>10} {:>12}  {}\n", "problem", "method", "N_sim", "h", "error",
             "dx(T)/dx0 [0,0]");
  for (const Problem& pb : problems())
    for (const Method& m : methods)
      for (int N : Ns) {
        fesd::IntegratorOptions o;
        o.discretization.rk_scheme = m.scheme;
        o.discretization.n_s = m.n_s;
        o.discretization.use_fesd = m.fesd;
        o.step_solver = m.fesd ? fesd_path : fesd::StepSolver::Homotopy;
        o.sensitivities = true;
        std::fprintf(stderr, "%s %s N_sim = %d\n", pb.name.c_str(), m.name.c_str(), N);
        const fesd::IntegratorResult r = fesd::integrate(pb.model, pb.x0, pb.T, N, o);
        const fesd::Sensitivities& s = r.sensitivities;
        const bool ok = r.status == fesd::Status::Success && s.available;
        const double err = ok ? (s.x0 - pb.exact).lpNorm<Eigen::Infinity>()
                              : std::numeric_limits<double>::quiet_NaN();
        const double v = ok ? s.x0(0, 0) : std::numeric_limits<double>::quiet_NaN();
        const double h = pb.T / N;
        fmt::print("{:<11} {:<22} {:>6} {:>10.4g} {:>12.3e}  {}\n", pb.name, m.name, N, h, err,
                   ok ? fmt::format("{:.10g}", v) : "n/a: " + s.message + " " + r.message);
        out += fmt::format("{},{},{},{:.17g},{:.17g},{},{:.17g}\n", pb.name, m.name, N, h, err,
                           ok ? 1 : 0, v);
      }
  if (!csv.empty()) {
    std::ofstream f(csv);
    f << out;
    if (!f) {
      std::fprintf(stderr, "sensitivity_h: cannot write %s\n", csv.c_str());
      return 1;
    }
  }
  return 0;
}
