// bench/derivative_cost.cpp: what exact derivatives cost. Builds the FESD NLP of one integration
// step (or of N_ctrl intervals chained, the size of the paper's OCP) and times the evaluations
// IPOPT asks for, per call: constraints, Jacobian, Hessian of the Lagrangian. Prints sizes,
// nonzeros, median and min time over repeats.
// Usage: derivative_cost [--json FILE] [--repeats R] [--only NAME] [--column-passes]
//   --repeats R        calls per evaluation (200; a few under callgrind, whose instruction counts
//                      are the stable measure on a shared machine)
//   --only NAME        only the problems whose name contains NAME
//   --column-passes    the Hessian as before the planned passes: one pass per column, every input
//                      carried (BlockNlp::use_column_hessian_passes), for before/after figures
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "discretization/fesd_interval.hpp"
#include "fesd/model.hpp"
#include "mpcc/relaxation.hpp"
#include "oscillator_model.hpp"

namespace {

struct SlidingOcp {  // the dynamics of (61): q' = -sign(c(q)) + v, v' = u, two subsystems
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0] + 0.15 * x[1] * x[1];
    c[1] = -0.05 * x[0] * x[0] * x[0] + x[1];
  }
  template <class T>
  void f(int r, const T* x, const T* u, const T*, T* f) const {
    const int k = r / 2;                       // subsystem
    const double s = r % 2 == 0 ? 1.0 : -1.0;  // sign of c_k in this region
    for (int i = 0; i < 4; ++i) f[i] = T(0.0);
    f[k] = -s + x[2 + k];
    f[2 + k] = u[k];
  }
};

template <class Fn>
std::pair<double, double> time_it(int repeats, Fn&& fn) {
  std::vector<double> t;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return {t[t.size() / 2], t.front()};
}

struct Settings {
  int repeats = 200;
  bool column_passes = false;  // the Hessian as before the planned passes (the reference plan)
  std::string only;            // measure only the problems whose name contains this
};

nlohmann::json measure(const char* name, const fesd::Pss& model, int n_s, int N_FE, int N_ctrl,
                       const Settings& set) {
  if (std::string(name).find(set.only) == std::string::npos) return nullptr;
  const int R = set.repeats;
  fesd::DiscretizationOptions d;
  d.n_s = n_s;
  d.N_FE = N_FE;
  d.step_eq = fesd::StepEq::Eta;
  const fesd::Tableau tab = fesd::make_tableau(d.rk_scheme, n_s);
  fesd::nlp::BlockNlp nlp;
  auto vars = [&](int n) {
    std::vector<int> v;
    const int first = nlp.add_variables(n, -1e20, 1e20, 0.0);
    for (int i = 0; i < n; ++i) v.push_back(first + i);
    return v;
  };
  std::vector<fesd::discretization::FesdInterval> intervals;
  intervals.reserve(N_ctrl);
  fesd::discretization::IntervalInputs in;
  in.s0 = vars(model.n_x());
  in.lambda_start = vars(model.n_theta());
  in.mu_start = vars(model.n_sys());
  in.p = vars(model.n_p());
  in.T = 4.0 / N_ctrl;
  for (int k = 0; k < N_ctrl; ++k) {
    in.q = vars(model.n_u());
    intervals.emplace_back(model, tab, d);
    auto& iv = intervals.back();
    iv.build(nlp, in);
    fesd::mpcc::add_scholtes_rows(nlp, iv.groups());
    for (int i = 0; i < model.n_x(); ++i) in.s0[i] = iv.x(N_FE, i);
    for (int r = 0; r < model.n_theta(); ++r) in.lambda_start[r] = iv.lambda_end(N_FE - 1, r);
    for (int j = 0; j < model.n_sys(); ++j) in.mu_start[j] = iv.mu_end(N_FE - 1, j);
  }
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(0.1, 1.0);
  for (double& v : nlp.x_init) v = U(rng);
  const auto t_fin = time_it(1, [&] { nlp.finalize(); });
  if (set.column_passes) nlp.use_column_hessian_passes();
  std::vector<double> lambda(nlp.num_constraints());
  for (double& v : lambda) v = U(rng) - 0.5;
  std::vector<double> g(nlp.num_constraints()), jac(nlp.jac_nnz()), hess(nlp.hess_nnz());
  const auto tg = time_it(R, [&] { nlp.eval_g(nlp.x_init.data(), g.data()); });
  const auto tj = time_it(R, [&] { nlp.eval_jac_g(nlp.x_init.data(), jac.data()); });
  const auto th =
      time_it(R, [&] { nlp.eval_h(nlp.x_init.data(), 1.0, lambda.data(), hess.data()); });
  std::printf("%-28s %6d %6d %8d %8d %10.1f %10.1f %10.1f %10.1f\n", name, nlp.num_variables(),
              nlp.num_constraints(), nlp.jac_nnz(), nlp.hess_nnz(), 1e6 * tg.first, 1e6 * tj.first,
              1e6 * th.first, 1e6 * t_fin.first);
  return {{"problem", name},
          {"n", nlp.num_variables()},
          {"m", nlp.num_constraints()},
          {"jac_nnz", nlp.jac_nnz()},
          {"hess_nnz", nlp.hess_nnz()},
          {"eval_g_us", 1e6 * tg.first},
          {"eval_jac_us", 1e6 * tj.first},
          {"eval_h_us", 1e6 * th.first},
          {"finalize_us", 1e6 * t_fin.first}};
}

}  // namespace

int main(int argc, char** argv) {
  std::string json_path;
  Settings set;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--column-passes") set.column_passes = true;
    if (i + 1 == argc) continue;
    if (a == "--json") json_path = argv[i + 1];
    if (a == "--repeats") set.repeats = std::max(1, std::stoi(argv[i + 1]));
    if (a == "--only") set.only = argv[i + 1];
  }
  const fesd::Pss osc = fesd_bench::oscillator_model();  // eq. (47)
  const fesd::Pss ocp = fesd::make_pss(
      SlidingOcp{},
      fesd::PssDims{.n_x = 4,
                    .n_u = 2,
                    .subsystems = {fesd::Subsystem::from_c(1, Eigen::MatrixXd{{1}, {-1}}),
                                   fesd::Subsystem::from_c(1, Eigen::MatrixXd{{1}, {-1}})}});
  // The second subsystem's c is c[1]: c() fills both subsystems' switching functions in order.
  std::printf("%-28s %6s %6s %8s %8s %10s %10s %10s %10s\n", "problem (median)", "n", "m",
              "jac_nnz", "hess_nnz", "g [us]", "jac [us]", "hess [us]", "setup [us]");
  nlohmann::json rows = nlohmann::json::array();
  auto add = [&](nlohmann::json row) {
    if (!row.is_null()) rows.push_back(std::move(row));
  };
  add(measure("oscillator step n_s=3 N_FE=2", osc, 3, 2, 1, set));
  add(measure("oscillator step n_s=4 N_FE=2", osc, 4, 2, 1, set));
  add(measure("OCP (61) n_s=2 N_FE=6 N=6", ocp, 2, 6, 6, set));
  add(measure("OCP (61) n_s=4 N_FE=6 N=6", ocp, 4, 6, 6, set));
  if (!json_path.empty()) std::ofstream(json_path) << rows.dump(2) << "\n";
  return 0;
}
