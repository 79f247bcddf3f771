// bench/active_set_step.cpp: the two step solvers side by side (issue 15 item 3, first number;
// docs/active-set.md, docs/benchmarks.md "Active-set step solver").
//
// The oscillator (47) of papers/fesd-filippov.txt, Radau IIA n_s = 3, N_FE = 2, T = pi/2,
// Example 3(a) (x' in 2 - sign(x), x0 = -1, T = 1.9), and the sliding modes of the second slice:
// Example 3(b) (x' in -sign(x), x0 = 0.47, T = 1: enters sliding at t = 0.47, x(T) = 0) and
// Example 3(c) (x' in -sign(x) + t, x0 = 0, T = 1.9: leaves at t = 1, x(T) = 0.9^2 / 2; the time as
// a second state), and the Cartesian product of docs/problem-files.md (x1' in -sign(x1), x2' in
// -sign(x2) from (1, -2), T = 3: sliding entries at t = 1 and 2, co-dimension 2 after, x(T) = 0),
// integrated with step_solver = homotopy and
// step_solver = active_set in one process: per path the median over R repetitions of the time of
// integrate() (in-process wall time and this process's CPU time), per step, the Newton iterations
// and the IPOPT iterations per step, the steps each path solved, the error of x(T) against the
// exact value and of the switch times (the largest).
//
// Built with Debian's libsundials-dev present (optional), a second table puts the oscillator on
// the active-set path beside CVODE with root finding (bench/cvode/), both timed in-process over
// repeated runs: CVODE's rtol is scanned and the largest one whose error is <= --cvode-error
// (4e-7) is the comparison; fesd's row is the oscillator of the first table (N_sim = --N).
//
//   active_set_step [--N 40] [--repeat R] [--repeat-active RA] [--cvode-error E] [--csv FILE]
//                   [--json FILE]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <fesd/integrator.hpp>
#include <fesd/options.hpp>
#include <fesd/stepper.hpp>

#include "bench_args.hpp"
#include "bench_timing.hpp"
#include "oscillator_model.hpp"
#include "sensitivity_ocp.hpp"
#ifdef FESD_BENCH_CVODE
#include "cvode/cvode_oscillator.hpp"
#endif

namespace fesd_bench {
[[noreturn]] void usage(const std::string& why, int exit_code) {
  std::fprintf(stderr,
               "active_set_step: %s\nusage: active_set_step [--N 40] [--repeat R] "
               "[--repeat-active RA] [--cvode-error E] [--csv FILE] [--json FILE]\n",
               why.c_str());
  std::exit(exit_code);
}
}  // namespace fesd_bench

namespace {

using fesd_bench::cpu_now;
using fesd_bench::median;

/// Example 3(b): x' in -sign(x) (region 0: x > 0, x' = -1; region 1: x < 0, x' = 1).
struct SlidingModel {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int region, const T*, const T*, const T*, T* f) const {
    f[0] = T(region == 0 ? -1.0 : 1.0);
  }
};

/// Example 3(c): x' in -sign(x) + t, with the time t = x[1] as a state (t' = 1).
struct LeavingModel {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int region, const T* x, const T*, const T*, T* f) const {
    f[0] = (region == 0 ? -1.0 : 1.0) + x[1];
    f[1] = T(1.0);
  }
};

/// The Cartesian product of docs/problem-files.md: x1' in -sign(x1), x2' in -sign(x2), two
/// subsystems (regions 0, 1: x1 > 0, < 0; 2, 3: x2 > 0, < 0). From (1, -2): x1 reaches 0 at t = 1
/// and slides, x2 at t = 2 (co-dimension 2 from then on), x(3) = 0.
struct ProductModel {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
    c[1] = x[1];
  }
  template <class T>
  void f(int region, const T*, const T*, const T*, T* f) const {
    f[0] = T(region == 0 ? -1.0 : region == 1 ? 1.0 : 0.0);
    f[1] = T(region == 2 ? -1.0 : region == 3 ? 1.0 : 0.0);
  }
};

struct Case {
  std::string name;
  fesd::Pss model;
  Eigen::VectorXd x0, x_exact;
  double T = 0;
  std::vector<double> t_s;  // the exact switch times
  int n_s = 3;
};

struct Row {
  std::string problem, path;
  int N_sim = 0, repeats = 0;
  double wall_s = 0, cpu_s = 0;    // medians per run
  double path_s = 0, setup_s = 0;  // of the last run: time in the active-set path, setup
  double newton_per_step = 0, ipopt_per_step = 0, nlps_per_step = 0;
  int active_set_steps = 0, homotopy_steps = 0, tries = 0;
  double error_x = 0, error_t_s = 0;
};

Row measure(const Case& c, int N_sim, fesd::StepSolver solver, int repeats) {
  fesd::IntegratorOptions o;
  o.discretization.rk_scheme = fesd::RkScheme::RadauIIA;
  o.discretization.n_s = c.n_s;
  o.discretization.N_FE = 2;
  o.step_solver = solver;
  std::vector<double> wall, cpu;
  fesd::IntegratorResult r;
  for (int k = 0; k < repeats; ++k) {
    const double c0 = cpu_now();
    const auto t0 = std::chrono::steady_clock::now();
    r = fesd::integrate(c.model, c.x0, c.T, N_sim, o);
    wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    cpu.push_back(cpu_now() - c0);
  }
  Row row;
  row.problem = c.name;
  row.path = std::string(fesd::to_string(solver));
  row.N_sim = N_sim;
  row.repeats = repeats;
  row.wall_s = median(wall);
  row.cpu_s = median(cpu);
  const fesd::Summary& s = r.summary;
  row.path_s = s.active_set_s;
  row.setup_s = s.setup_s;
  row.newton_per_step = static_cast<double>(s.newton_iterations) / N_sim;
  row.ipopt_per_step = static_cast<double>(s.nlp_iterations) / N_sim;
  row.nlps_per_step = static_cast<double>(s.homotopy_steps) / N_sim;
  row.active_set_steps = s.active_set_path_steps;
  row.homotopy_steps = s.homotopy_path_steps;
  row.tries = s.active_set_tries;
  row.error_x = r.status == fesd::Status::Success ? (r.x_final() - c.x_exact).norm() : NAN;
  row.error_t_s = NAN;
  if (r.switches.size() == c.t_s.size()) {
    row.error_t_s = 0;
    for (std::size_t i = 0; i < c.t_s.size(); ++i)
      row.error_t_s = std::max(row.error_t_s, std::abs(r.switches[i].t - c.t_s[i]));
  }
  return row;
}

/// The stepping API on one case (include/fesd/stepper.hpp): a Stepper created once, then
/// `repeats` passes of N_sim step() calls from x0 (reset() between them; the first pass meets the
/// shapes and is not timed). Per step: the median and the largest CPU time over all timed steps.
struct StepperRow {
  double create_s = 0, first_pass_s = 0;
  double median_step_s = 0, p99_step_s = 0, max_step_s = 0, mean_step_s = 0;
  int N_sim = 0, repeats = 0, active_set_steps = 0, homotopy_steps = 0;
  double error_x = 0;
};

StepperRow measure_stepper(const Case& c, int N_sim, int repeats) {
  fesd::IntegratorOptions o;
  o.discretization.rk_scheme = fesd::RkScheme::RadauIIA;
  o.discretization.n_s = c.n_s;
  o.discretization.N_FE = 2;
  const Eigen::VectorXd none;  // u, p: zero controls, the model's p_default
  StepperRow row;
  row.N_sim = N_sim;
  row.repeats = repeats;
  double c0 = cpu_now();
  fesd::Stepper stepper(c.model, c.T / N_sim, o);
  row.create_s = cpu_now() - c0;
  Eigen::VectorXd x = c.x0;
  c0 = cpu_now();
  for (int k = 0; k < N_sim; ++k) stepper.step(x, none, none, x);
  row.first_pass_s = cpu_now() - c0;
  std::vector<double> per_step;
  per_step.reserve(static_cast<std::size_t>(N_sim) * static_cast<std::size_t>(repeats));
  for (int r = 0; r < repeats; ++r) {
    stepper.reset();
    x = c.x0;
    for (int k = 0; k < N_sim; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      stepper.step(x, none, none, x);
      per_step.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
  }
  row.error_x = stepper.status() == fesd::Status::Success ? (x - c.x_exact).norm() : NAN;
  row.active_set_steps = static_cast<int>(stepper.stats().active_set_steps);
  row.homotopy_steps = static_cast<int>(stepper.stats().homotopy_steps);
  double sum = 0;
  for (double t : per_step) sum += t;
  row.mean_step_s = sum / static_cast<double>(per_step.size());
  row.max_step_s = *std::max_element(per_step.begin(), per_step.end());
  row.median_step_s = median(per_step);
  std::sort(per_step.begin(), per_step.end());
  row.p99_step_s =
      per_step[static_cast<std::size_t>(0.99 * static_cast<double>(per_step.size() - 1))];
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  using fesd_bench::parse_int;
  int N_sim = 40, repeat = 3, repeat_active = 200;
  [[maybe_unused]] double cvode_error = 4e-7;  // read only with FESD_BENCH_CVODE
  std::string csv, json_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) fesd_bench::usage(a + ": missing value");
    const std::string v = argv[++i];
    if (a == "--N")
      N_sim = parse_int(a, v);
    else if (a == "--repeat")
      repeat = parse_int(a, v);
    else if (a == "--repeat-active")
      repeat_active = parse_int(a, v);
    else if (a == "--cvode-error")
      cvode_error = fesd_bench::parse_double(a, v);
    else if (a == "--csv")
      csv = v;
    else if (a == "--json")
      json_path = v;
    else
      fesd_bench::usage("unknown argument " + a);
  }

  std::vector<Case> cases;
  cases.push_back({"oscillator (47)",
                   fesd_bench::oscillator_model(),
                   fesd_bench::oscillator_x0(),
                   fesd_bench::oscillator_exact_xT(),
                   fesd_bench::kOscillatorT,
                   {fesd_bench::kOscillatorSwitch},
                   3});
  cases.push_back(
      {"Example 3(a)",
       fesd::make_pss(fesd_bench::SensitivityModel{},
                      fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}}),
       Eigen::VectorXd::Constant(1, -1.0),
       Eigen::VectorXd::Constant(1, 1.9 - 1.0 / 3.0),
       1.9,
       {1.0 / 3.0},
       3});

  const fesd::PssDims one_c{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}};
  cases.push_back({"Example 3(b)",
                   fesd::make_pss(SlidingModel{}, one_c),
                   Eigen::VectorXd::Constant(1, 0.47),
                   Eigen::VectorXd::Zero(1),
                   1.0,
                   {0.47},
                   3});
  cases.push_back(
      {"Example 3(c)",
       fesd::make_pss(LeavingModel{},
                      fesd::PssDims{.n_x = 2, .subsystems = {fesd::Subsystem::from_c(1)}}),
       Eigen::VectorXd::Zero(2),
       Eigen::Vector2d(0.5 * 0.9 * 0.9, 1.9),
       1.9,
       {1.0},
       3});
  cases.push_back(
      {"Cartesian prod.",
       fesd::make_pss(ProductModel{}, fesd::PssDims{.n_x = 2,
                                                    .subsystems = {fesd::Subsystem::from_c(1),
                                                                   fesd::Subsystem::from_c(1)}}),
       Eigen::Vector2d(1.0, -2.0),
       Eigen::VectorXd::Zero(2),
       3.0,
       {1.0, 2.0},
       3});

  std::vector<Row> rows;
  for (const Case& c : cases) {
    rows.push_back(measure(c, N_sim, fesd::StepSolver::Homotopy, repeat));
    rows.push_back(measure(c, N_sim, fesd::StepSolver::ActiveSet, repeat_active));
  }

  fmt::print("Radau IIA n_s = 3, N_FE = 2, N_sim = {}; medians over the repetitions (in-process)\n",
             N_sim);
  fmt::print(
      "{:<16} {:<11} {:>5} {:>10} {:>10} {:>10} {:>10} {:>9} {:>7} {:>7} {:>6} {:>9} {:>9} {:>9} "
      "{:>9}\n",
      "problem", "path", "reps", "wall ms", "cpu ms", "us/step", "path wall", "setup ms", "Newton",
      "IPOPT", "NLPs", "as/hom", "err x(T)", "err t_s", "speedup");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    const Row& base = rows[i - i % 2];
    fmt::print(
        "{:<16} {:<11} {:>5} {:>10.3f} {:>10.3f} {:>10.1f} {:>10.1f} {:>9.3f} {:>7.2f} {:>7.1f} "
        "{:>6.2f} {:>9} {:>9.1e} {:>9.1e} {:>8.0f}x\n",
        r.problem, r.path, r.repeats, 1e3 * r.wall_s, 1e3 * r.cpu_s, 1e6 * r.cpu_s / r.N_sim,
        1e6 * r.path_s / r.N_sim, 1e3 * r.setup_s, r.newton_per_step, r.ipopt_per_step,
        r.nlps_per_step, fmt::format("{}/{}", r.active_set_steps, r.homotopy_steps), r.error_x,
        r.error_t_s, base.cpu_s / r.cpu_s);
  }
  // The stepping API on the oscillator: time per step() (wall, steady_clock around each call).
  const StepperRow st = measure_stepper(cases[0], N_sim, repeat_active);
  fmt::print(
      "\nfesd::Stepper on the oscillator (47), N_sim = {} steps of h = T / N_sim, {} timed passes "
      "(the first pass, which meets the shapes, not timed)\n",
      N_sim, repeat_active);
  fmt::print("{:>12} {:>14} {:>12} {:>12} {:>12} {:>12} {:>9} {:>9}\n", "create ms",
             "first pass ms", "median us", "mean us", "p99 us", "max us", "as/hom", "err x(T)");
  fmt::print("{:>12.3f} {:>14.3f} {:>12.2f} {:>12.2f} {:>12.2f} {:>12.2f} {:>9} {:>9.1e}\n",
             1e3 * st.create_s, 1e3 * st.first_pass_s, 1e6 * st.median_step_s, 1e6 * st.mean_step_s,
             1e6 * st.p99_step_s, 1e6 * st.max_step_s,
             fmt::format("{}/{}", st.active_set_steps, st.homotopy_steps), st.error_x);
  const nlohmann::json stepper_json{{"problem", cases[0].name},
                                    {"N_sim", st.N_sim},
                                    {"repeats", st.repeats},
                                    {"create_s", st.create_s},
                                    {"first_pass_s", st.first_pass_s},
                                    {"median_step_s", st.median_step_s},
                                    {"mean_step_s", st.mean_step_s},
                                    {"p99_step_s", st.p99_step_s},
                                    {"max_step_s", st.max_step_s},
                                    {"active_set_steps", st.active_set_steps},
                                    {"homotopy_steps", st.homotopy_steps},
                                    {"error_x", st.error_x}};
  nlohmann::json cvode_json = nlohmann::json::array();
#ifdef FESD_BENCH_CVODE
  {
    // rows[1]: the oscillator on the active-set path. Its stepping time: integrate() less setup.
    const Row& as = rows[1];
    const double fesd_steps_s = as.cpu_s - as.setup_s;
    fmt::print(
        "\nOscillator (47) against CVODE with root finding (in-process CPU time, medians of {} "
        "runs; CVODE atol = rtol / 100, Adams + fixed point and BDF + dense Newton with the exact "
        "Jacobian)\n",
        repeat_active);
    fmt::print("{:<34} {:>9} {:>9} {:>9} {:>9} {:>8} {:>10}\n", "", "err x(T)", "err t_s",
               "solve ms", "setup ms", "steps", "fesd/this");
    fmt::print("{:<34} {:>9.1e} {:>9.1e} {:>9.4f} {:>9.4f} {:>8} {:>10}\n",
               fmt::format("fesd active_set, N_sim = {}", as.N_sim), as.error_x, as.error_t_s,
               1e3 * fesd_steps_s, 1e3 * as.setup_s, as.N_sim, "");
    for (bool bdf : {false, true}) {
      bool chosen = false;
      for (double rtol : {1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11}) {
        const fesd_bench::CvodeRun c =
            fesd_bench::cvode_oscillator(rtol, rtol / 100, bdf, repeat_active);
        const bool pick = !chosen && c.ok && c.error_x <= cvode_error;
        chosen = chosen || pick;
        fmt::print("{:<34} {:>9.1e} {:>9.1e} {:>9.4f} {:>9.4f} {:>8} {:>9.1f}x{}\n",
                   fmt::format("CVODE {} rtol = {:.0e}", bdf ? "BDF  " : "Adams", rtol), c.error_x,
                   c.error_t_s, 1e3 * c.solve_s, 1e3 * c.setup_s, c.steps, fesd_steps_s / c.solve_s,
                   pick ? "  <- equal error" : "");
        cvode_json.push_back({{"method", bdf ? "bdf" : "adams"},
                              {"rtol", rtol},
                              {"atol", c.atol},
                              {"ok", c.ok},
                              {"error_x", c.error_x},
                              {"error_t_s", c.error_t_s},
                              {"solve_s", c.solve_s},
                              {"setup_s", c.setup_s},
                              {"steps", c.steps},
                              {"rhs_evals", c.rhs_evals},
                              {"root_evals", c.root_evals},
                              {"equal_error_pick", pick},
                              {"fesd_steps_s", fesd_steps_s},
                              {"fesd_over_cvode", fesd_steps_s / c.solve_s}});
      }
    }
  }
#else
  fmt::print("\n(no CVODE comparison: built without libsundials-dev)\n");
#endif
  if (!csv.empty()) {
    std::ofstream f(csv);
    f << "problem,path,N_sim,repeats,wall_s,cpu_s,cpu_s_per_step,newton_per_step,"
         "ipopt_per_step,nlps_per_step,active_set_steps,homotopy_steps,tries,error_x,error_t_s,"
         "path_s,setup_s\n";
    for (const Row& r : rows)
      f << fmt::format(
          "{},{},{},{},{:.6e},{:.6e},{:.6e},{:.3f},{:.3f},{:.3f},{},{},{},{:.3e},{:.3e},{:.6e},"
          "{:.6e}\n",
          r.problem, r.path, r.N_sim, r.repeats, r.wall_s, r.cpu_s, r.cpu_s / r.N_sim,
          r.newton_per_step, r.ipopt_per_step, r.nlps_per_step, r.active_set_steps,
          r.homotopy_steps, r.tries, r.error_x, r.error_t_s, r.path_s, r.setup_s);
  }
  if (!json_path.empty()) {
    nlohmann::json j = nlohmann::json::array();
    for (const Row& r : rows)
      j.push_back({{"problem", r.problem},
                   {"path", r.path},
                   {"N_sim", r.N_sim},
                   {"repeats", r.repeats},
                   {"wall_s", r.wall_s},
                   {"cpu_s", r.cpu_s},
                   {"cpu_s_per_step", r.cpu_s / r.N_sim},
                   {"newton_per_step", r.newton_per_step},
                   {"ipopt_per_step", r.ipopt_per_step},
                   {"nlps_per_step", r.nlps_per_step},
                   {"active_set_steps", r.active_set_steps},
                   {"homotopy_steps", r.homotopy_steps},
                   {"tries", r.tries},
                   {"error_x", r.error_x},
                   {"error_t_s", r.error_t_s},
                   {"path_s", r.path_s},
                   {"setup_s", r.setup_s}});
    std::ofstream(json_path)
        << nlohmann::json{{"rows", j}, {"cvode", cvode_json}, {"stepper", stepper_json}}.dump(2)
        << "\n";
  }
  return 0;
}
