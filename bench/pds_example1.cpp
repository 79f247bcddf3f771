// The slope table of Example 1 of papers/fesd-pds.txt (issue 16, item 3a; docs/pds.md): the
// error ||x(T) - (-1, 0)|| of FESD and of the standard RK method (6) against h = T / N_FE, Radau
// IIA, (a) one interval over [0, T] with N_FE elements, (b) N_sim steps of 2 elements each; with
// least-squares slopes of log(error) over log(h) through the errors above the round-off floor
// 1e3 eps |x(T)|, printed with the range and number of points used (see fit() below).
//
//   pds_example1 [--ns 2,3,4] [--nfe 10,20,40,80,140,200,400] [--nsim 5,10,20,40,70,100,200]
//                [--scheme radau_iia|lobatto_iiic] [--method fesd|standard]
//                [--M 1e6]
//
// An empty list skips its table: --nsim '' runs (a) only, --nfe '' (b) only.
//
// (Lobatto IIIC: n_s >= 2, expected order 2 n_s - 2.)
// Prints one row per run (error, contact and leaving time errors for FESD, NLPs, IPOPT iterations,
// wall time) and the slopes.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pds_example1_model.hpp"
#include "slope_fit.hpp"

namespace {

std::vector<int> parse_list(const char* s) {
  std::vector<int> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(item, &used);
    } catch (const std::exception&) {
    }
    if (used == 0 || used != item.size())
      throw std::invalid_argument("'" + item + "' in '" + s + "' is not an integer");
    out.push_back(v);
  }
  return out;
}

// Least-squares fit of log(err) over log(h) through the runs that solved with err above the
// round-off floor 1e3 * eps * |x(T)| (= 2.2e-13 here; below it the error is round-off, not
// discretization error). Reports the slope, its standard error from the residuals ("+-"), the
// slopes of the coarser and the finer half of the points (pre-asymptotic vs. asymptotic), and the
// range.
struct Fit {
  fesd_bench::SlopeFit ls;
  int below_floor = 0, failed = 0, count_min = 0, count_max = 0;
};

Fit fit(const std::vector<int>& counts, const std::vector<double>& h, const std::vector<double>& e,
        double floor) {
  Fit f;
  std::vector<std::pair<double, double>> h_e;
  for (std::size_t i = 0; i < h.size(); ++i) {
    if (!std::isfinite(e[i])) {
      ++f.failed;
      continue;
    }
    if (!(e[i] > floor)) {
      ++f.below_floor;
      continue;
    }
    if (h_e.empty()) f.count_min = counts[i];
    f.count_max = counts[i];
    h_e.emplace_back(h[i], e[i]);
  }
  f.ls = fesd_bench::fit_log_log(h_e, /*halves_from=*/6);
  return f;
}

void print_fit(const char* name, const Fit& f, const std::string& expected, bool per_step) {
  std::printf("     %-8s slope %.2f +- %.2f (%s), %s %d..%d, %d points used", name, f.ls.slope,
              f.ls.se, expected.c_str(), per_step ? "N_sim" : "N_FE", f.count_min, f.count_max,
              f.ls.points);
  if (f.below_floor) std::printf(", %d below round-off", f.below_floor);
  if (f.failed) std::printf(", %d failed", f.failed);
  if (std::isfinite(f.ls.coarse))
    std::printf("; coarser half %.2f, finer half %.2f", f.ls.coarse, f.ls.fine);
  std::printf("\n");
}

fesd::RkScheme g_scheme = fesd::RkScheme::RadauIIA;
fesd::PdsOptions g_pds;
fesd::HomotopyOptions g_homotopy;
double g_gamma_h = -1, g_rho_h = -1;
bool g_rows = false;
int g_print_level = 0;
std::vector<std::pair<std::string, std::string>> g_ipopt;

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
  o.homotopy = g_homotopy;
  if (g_gamma_h > 0) o.discretization.gamma_h = g_gamma_h;
  if (g_rho_h > 0) o.discretization.rho_h = g_rho_h;
  o.nlp.print_level = g_print_level;
  o.nlp.extra = g_ipopt;
  Run r;
  const auto t0 = std::chrono::steady_clock::now();
  const auto res = fesd::integrate(pds_example1::model(), pds_example1::x0(), pds_example1::kT,
                                   N_sim, o, {}, {}, g_pds);
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.ok = res.status == fesd::Status::Success;
  r.nlps = res.summary.homotopy_steps;
  r.iters = res.summary.nlp_iterations;
  if (g_rows)
    for (const auto& step : res.homotopy)
      for (const auto& row : step)
        std::printf("       NLP %2d sigma %8.1e comp %8.1e obj %10.3e inf_pr %8.1e it %4d %s%s\n",
                    row.k, row.sigma, row.comp_residual, row.objective, row.inf_pr,
                    row.nlp_iterations, row.nlp_status.c_str(),
                    row.active_set_fixed ? " (active set fixed)" : "");
  if (!r.ok) return r;
  r.err = (res.x_final() - pds_example1::x_T()).norm();
  for (const auto& s : res.switches) {
    if (s.before.empty() && !s.after.empty()) r.contact = std::abs(s.t - pds_example1::kContact);
    if (!s.before.empty() && s.after.empty()) r.leave = std::abs(s.t - pds_example1::kLeave);
  }
  return r;
}

bool g_fesd = true, g_standard = true;

void table(const char* title, const std::vector<int>& n_s_list, const std::vector<int>& counts,
           bool per_step) {
  std::printf("\n%s\n", title);
  std::printf("%4s %6s %10s | %10s %9s %9s %5s %6s %7s | %10s %5s %6s %7s\n", "n_s",
              per_step ? "N_sim" : "N_FE", "h", "FESD err", "t_c err", "t_l err", "NLPs", "iters",
              "s", "std err", "NLPs", "iters", "s");
  const double floor = 1e3 * std::numeric_limits<double>::epsilon() * pds_example1::x_T().norm();
  for (int n_s : n_s_list) {
    std::vector<double> hs, ef, es;
    for (int count : counts) {
      const int N_FE = per_step ? 2 : count, N_sim = per_step ? count : 1;
      const double h = pds_example1::kT / (N_FE * N_sim);
      const Run f = g_fesd ? run(n_s, N_FE, N_sim, true) : Run{};
      const Run s = g_standard ? run(n_s, N_FE, N_sim, false) : Run{};
      const bool failed = (g_fesd && !f.ok) || (g_standard && !s.ok);
      std::printf("%4d %6d %10.3e | %10.3e %9.2e %9.2e %5d %6d %7.2f | %10.3e %5d %6d %7.2f%s\n",
                  n_s, count, h, f.err, f.contact, f.leave, f.nlps, f.iters, f.wall, s.err, s.nlps,
                  s.iters, s.wall, failed ? "  (failed run: err nan)" : "");
      hs.push_back(h);
      ef.push_back(f.err);
      es.push_back(s.err);
      std::fflush(stdout);
    }
    const int order = g_scheme == fesd::RkScheme::LobattoIIIC ? 2 * n_s - 2 : 2 * n_s - 1;
    std::printf("     n_s = %d, fit through err > %.1e (1e3 eps |x(T)|):\n", n_s, floor);
    if (g_fesd)
      print_fit("FESD", fit(counts, hs, ef, floor), "expected " + std::to_string(order), per_step);
    if (g_standard)
      print_fit("standard", fit(counts, hs, es, floor),
                "paper's Fig. 2: between 1 and 2 (min(2, order) at most)", per_step);
  }
}

}  // namespace

int run_main(int argc, char** argv) {
  std::vector<int> n_s_list{1, 2, 3, 4}, nfe{10, 20, 40, 80, 140, 200, 400},
      nsim{5, 10, 20, 40, 70, 100, 200};
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--ns"))
      n_s_list = parse_list(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--nfe"))
      nfe = parse_list(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--nsim"))
      nsim = parse_list(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--M"))
      g_pds.M = std::stod(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--intermediate_tol"))
      g_homotopy.intermediate_tol = std::stod(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--ipopt") && std::strchr(argv[i + 1], '=')) {
      const std::string kv = argv[i + 1];
      g_ipopt.emplace_back(kv.substr(0, kv.find('=')), kv.substr(kv.find('=') + 1));
    } else if (!std::strcmp(argv[i], "--gamma_h")) {
      g_gamma_h = std::stod(argv[i + 1]);
    } else if (!std::strcmp(argv[i], "--rho_h")) {
      g_rho_h = std::stod(argv[i + 1]);
    } else if (!std::strcmp(argv[i], "--rows"))
      g_rows = std::stoi(argv[i + 1]) != 0;
    else if (!std::strcmp(argv[i], "--print_level"))
      g_print_level = std::stoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--method") && !std::strcmp(argv[i + 1], "fesd"))
      g_standard = false;
    else if (!std::strcmp(argv[i], "--method") && !std::strcmp(argv[i + 1], "standard"))
      g_fesd = false;
    else if (!std::strcmp(argv[i], "--scheme") && !std::strcmp(argv[i + 1], "lobatto_iiic"))
      g_scheme = fesd::RkScheme::LobattoIIIC;
    else if (!std::strcmp(argv[i], "--scheme") && !std::strcmp(argv[i + 1], "radau_iia"))
      g_scheme = fesd::RkScheme::RadauIIA;
    else {
      std::fprintf(stderr, "unknown argument %s\n", argv[i]);
      return 2;
    }
  }
  for (const auto* list : {&n_s_list, &nfe, &nsim})
    for (int v : *list)
      if (v < 1) {
        std::fprintf(stderr,
                     "pds_example1: --ns, --nfe and --nsim take values >= 1 (got %d; an empty "
                     "list, e.g. --nsim '', skips that table)\n",
                     v);
        return 2;
      }
  std::printf("Example 1 of papers/fesd-pds.txt, %s, error ||x(T) - (-1, 0)||\n",
              g_scheme == fesd::RkScheme::LobattoIIIC ? "Lobatto IIIC" : "Radau IIA");
  if (!nfe.empty()) table("(a) one interval [0, T], N_FE elements", n_s_list, nfe, false);
  if (!nsim.empty()) table("(b) N_sim steps of N_FE = 2 elements", n_s_list, nsim, true);
  return 0;
}

int main(int argc, char** argv) {
  try {
    return run_main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pds_example1: %s\n", e.what());
    return 2;
  }
}
