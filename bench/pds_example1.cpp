// The slope table of Example 1 of papers/fesd-pds.txt (issue 16, item 3a; docs/pds.md): the
// error ||x(T) - (-1, 0)|| of FESD and of the standard RK method (6) against h = T / N_FE, Radau
// IIA, (a) one interval over [0, T] with N_FE elements, (b) N_sim steps of 2 elements each; with
// least-squares slopes of log(error) over log(h) through the errors above 1e-10 (round-off and
// the complementarity_tol 1e-9 of the homotopy lie below).
//
//   pds_example1 [--ns 2,3,4] [--nfe 10,20,40,80,140,200,400] [--nsim 5,10,20,40,70,100,200]
//                [--scheme radau_iia|lobatto_iiic]
//
// (Lobatto IIIC: n_s >= 2, expected order 2 n_s - 2.)
// Prints one row per run (error, contact and leaving time errors for FESD, NLPs, IPOPT iterations,
// wall time) and the slopes.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "pds_example1_model.hpp"

namespace {

std::vector<int> parse_list(const char* s) {
  std::vector<int> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(std::stoi(item));
  return out;
}

double slope(const std::vector<double>& h, const std::vector<double>& e) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    if (!(e[i] > 1e-10) || !std::isfinite(e[i])) continue;
    const double x = std::log(h[i]), y = std::log(e[i]);
    sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
  }
  if (n < 2) return NAN;
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

fesd::RkScheme g_scheme = fesd::RkScheme::RadauIIA;

struct Run {
  double err = NAN, contact = NAN, leave = NAN, wall = 0;
  int nlps = 0, iters = 0;
  bool ok = false;
};

Run run(int n_s, int N_FE, int N_sim, bool fesd) {
  fesd::IntegratorOptions o;
  o.discretization.rk_scheme = g_scheme;
  o.discretization.n_s = n_s;
  o.discretization.N_FE = N_FE;
  o.discretization.use_fesd = fesd;
  Run r;
  const auto t0 = std::chrono::steady_clock::now();
  const auto res =
      fesd::integrate(pds_example1::model(), pds_example1::x0(), pds_example1::kT, N_sim, o);
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.ok = res.status == fesd::Status::Success;
  r.nlps = res.summary.homotopy_steps;
  r.iters = res.summary.nlp_iterations;
  if (!r.ok) return r;
  r.err = (res.x_final() - pds_example1::x_T()).norm();
  for (const auto& s : res.switches) {
    if (s.before.empty() && !s.after.empty()) r.contact = std::abs(s.t - pds_example1::kContact);
    if (!s.before.empty() && s.after.empty()) r.leave = std::abs(s.t - pds_example1::kLeave);
  }
  return r;
}

void table(const char* title, const std::vector<int>& n_s_list, const std::vector<int>& counts,
           bool per_step) {
  std::printf("\n%s\n", title);
  std::printf("%4s %6s %10s | %10s %9s %9s %5s %6s %7s | %10s %5s %6s %7s\n", "n_s",
              per_step ? "N_sim" : "N_FE", "h", "FESD err", "t_c err", "t_l err", "NLPs", "iters",
              "s", "std err", "NLPs", "iters", "s");
  for (int n_s : n_s_list) {
    std::vector<double> hs, ef, es;
    for (int count : counts) {
      const int N_FE = per_step ? 2 : count, N_sim = per_step ? count : 1;
      const double h = pds_example1::kT / (N_FE * N_sim);
      const Run f = run(n_s, N_FE, N_sim, true);
      const Run s = run(n_s, N_FE, N_sim, false);
      std::printf("%4d %6d %10.3e | %10.3e %9.2e %9.2e %5d %6d %7.2f | %10.3e %5d %6d %7.2f%s\n",
                  n_s, count, h, f.err, f.contact, f.leave, f.nlps, f.iters, f.wall, s.err, s.nlps,
                  s.iters, s.wall, f.ok && s.ok ? "" : "  (failed run: err nan)");
      hs.push_back(h);
      ef.push_back(f.err);
      es.push_back(s.err);
      std::fflush(stdout);
    }
    const int order = g_scheme == fesd::RkScheme::LobattoIIIC ? 2 * n_s - 2 : 2 * n_s - 1;
    std::printf("     n_s = %d: slope FESD %.2f (order %d), standard %.2f\n", n_s, slope(hs, ef),
                order, slope(hs, es));
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> n_s_list{1, 2, 3, 4}, nfe{10, 20, 40, 80, 140, 200, 400},
      nsim{5, 10, 20, 40, 70, 100, 200};
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--ns"))
      n_s_list = parse_list(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--nfe"))
      nfe = parse_list(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--nsim"))
      nsim = parse_list(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--scheme") && !std::strcmp(argv[i + 1], "lobatto_iiic"))
      g_scheme = fesd::RkScheme::LobattoIIIC;
    else if (!std::strcmp(argv[i], "--scheme") && !std::strcmp(argv[i + 1], "radau_iia"))
      g_scheme = fesd::RkScheme::RadauIIA;
    else {
      std::fprintf(stderr, "unknown argument %s\n", argv[i]);
      return 2;
    }
  }
  std::printf("Example 1 of papers/fesd-pds.txt, %s, error ||x(T) - (-1, 0)||\n",
              g_scheme == fesd::RkScheme::LobattoIIIC ? "Lobatto IIIC" : "Radau IIA");
  if (!nfe.empty()) table("(a) one interval [0, T], N_FE elements", n_s_list, nfe, false);
  if (!nsim.empty()) table("(b) N_sim steps of N_FE = 2 elements", n_s_list, nsim, true);
  return 0;
}
