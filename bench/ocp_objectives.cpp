// bench/ocp_objectives.cpp: which MPCC method and step equilibration find the optimum of the
// paper's and nosnoc_py's OCPs? (issue 14, item 2)
//
// For the sliding-mode OCP (61) (examples/ocp_sliding_mode.toml), nosnoc_py's cart pole with
// friction (examples/nosnoc/cart_pole_with_friction.toml) and its motor with friction
// (examples/nosnoc/motor_with_friction.toml): each file solved as written except mpcc_mode and
// step_equilibration, one row per pair, against a reference: the same file on a grid with
// --fine times as many finite elements per control interval (default 4), its best objective over
// the step-equilibration modes of --ref-modes (default: every mode, scholtes_ineq). Columns:
// status, objective, its relative difference to the reference, collapsed elements (h_n <= 1e-6 of
// the nominal h), switches still held by the grid, IPOPT iterations, wall time.
//
//   ocp_objectives [--only PROBLEM,...] [--methods MODE,...] [--modes MODE,...] [--fine K]
//                  [--csv FILE] [--json FILE]
//
// PROBLEM: sliding, cartpole, motor. The program writes a file only for --csv and --json.
#include <algorithm>
#include <chrono>
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
#include <fesd/problem_file.hpp>

#include "bench_args.hpp"

namespace fesd_bench {
void usage(const std::string& why, int exit_code) {
  std::fprintf(stderr,
               "ocp_objectives: %s\n"
               "usage: ocp_objectives [--only sliding,cartpole,motor] [--methods MODE,...]\n"
               "                      [--modes MODE,...] [--fine K] [--csv FILE] [--json FILE]\n",
               why.c_str());
  std::exit(exit_code);
}
}  // namespace fesd_bench

namespace {

struct Problem {
  std::string name, file;
};

struct Row {
  std::string problem, method, mode, status;
  double objective = NAN, rel = NAN, wall_s = 0;
  int collapsed = 0, held = 0, iterations = 0, switches = 0;
  bool reference = false;
};

Row run(const Problem& p, const std::string& method, const std::string& mode, int fine) {
  Row r;
  r.problem = p.name;
  r.method = method;
  r.mode = mode;
  try {
    fesd::OcpProblem q = fesd::load_ocp_problem(std::string(FESD_SOURCE_DIR) + "/" + p.file);
    const int n_fe = q.options.discretization.N_FE * fine;
    fesd::apply_override(q, "N_finite_elements", std::to_string(n_fe));
    fesd::apply_override(q, "mpcc_mode", method);
    fesd::apply_override(q, "step_equilibration", mode);
    const auto t0 = std::chrono::steady_clock::now();
    const fesd::OcpResult res = fesd::solve(q.ocp, q.options);
    r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.status = std::string(fesd::to_string(res.status));
    r.objective = res.objective;
    r.iterations = res.summary.nlp_iterations;
    r.held = res.summary.held_switches;
    r.switches = static_cast<int>(res.switches.size());
    const double h_nominal = q.ocp.T / q.ocp.N_stages / n_fe;
    for (double h : res.h)
      if (h <= 1e-6 * h_nominal) ++r.collapsed;
  } catch (const fesd::Error& e) {
    r.status = std::string("error: ") + e.what();
  }
  return r;
}

void print(const Row& r) {
  fmt::print("{:<9} {:<19} {:<16} {:<16} {:>16.9g} {:>10} {:>5} {:>5} {:>5} {:>7} {:>8.2f}\n",
             r.problem, r.method, r.mode, r.status.substr(0, 16), r.objective,
             std::isnan(r.rel) ? std::string("-") : fmt::format("{:.1e}", r.rel), r.collapsed,
             r.held, r.switches, r.iterations, r.wall_s);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<Problem> all = {{"sliding", "examples/ocp_sliding_mode.toml"},
                                    {"cartpole", "examples/nosnoc/cart_pole_with_friction.toml"},
                                    {"motor", "examples/nosnoc/motor_with_friction.toml"}};
  std::vector<std::string> only, methods = {"scholtes_ineq", "scholtes_eq", "fischer_burmeister",
                                            "ell_1_penalty", "elastic_ineq"};
  std::vector<std::string> modes = {"l2_relaxed", "heuristic_mean", "heuristic_delta", "eta",
                                    "none"};
  std::vector<std::string> ref_modes = modes;
  int fine = 4;
  std::string csv, json_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) fesd_bench::usage(a + ": missing value");
      return argv[++i];
    };
    if (a == "--only") {
      only = fesd_bench::split(value(), ',');
    } else if (a == "--methods") {
      methods = fesd_bench::split(value(), ',');
    } else if (a == "--modes") {
      modes = fesd_bench::split(value(), ',');
    } else if (a == "--ref-modes") {
      ref_modes = fesd_bench::split(value(), ',');
    } else if (a == "--fine") {
      fine = fesd_bench::parse_int(a, value());
    } else if (a == "--csv") {
      csv = value();
    } else if (a == "--json") {
      json_path = value();
    } else if (a == "-h" || a == "--help") {
      fesd_bench::usage("objectives of OCP (61), cart pole, motor per MPCC method", 0);
    } else {
      fesd_bench::usage("unknown argument " + a);
    }
  }
  std::vector<Problem> problems;
  for (const Problem& p : all)
    if (only.empty() || std::find(only.begin(), only.end(), p.name) != only.end())
      problems.push_back(p);
  for (const std::string& o : only)
    if (std::none_of(all.begin(), all.end(), [&](const Problem& p) { return p.name == o; }))
      fesd_bench::usage("--only " + o + ": expected sliding, cartpole or motor");

  fmt::print(
      "OCP objectives per MPCC method and step equilibration, each file's grid; reference: the "
      "best objective over {} at {}x the finite elements (scholtes_ineq)\n"
      "rel = (J - J_ref) / |J_ref|; coll: collapsed elements (h <= 1e-6 h_nominal); held: "
      "switches held by an h bound; sw: switches\n\n",
      fmt::join(ref_modes, ", "), fine);
  fmt::print("{:<9} {:<19} {:<16} {:<16} {:>16} {:>10} {:>5} {:>5} {:>5} {:>7} {:>8}\n", "problem",
             "mpcc_mode", "step_eq", "status", "objective", "rel", "coll", "held", "sw", "iter",
             "wall s");
  std::vector<Row> rows;
  for (const Problem& p : problems) {
    double ref = INFINITY;
    for (const std::string& m : ref_modes) {
      Row r = run(p, "scholtes_ineq", m, fine);
      r.reference = true;
      if (r.status == "success") ref = std::min(ref, r.objective);
      r.problem = p.name + "*";
      print(r);
      rows.push_back(r);
    }
    for (Row& r : rows)
      if (r.problem == p.name + "*") r.rel = (r.objective - ref) / std::abs(ref);
    for (const std::string& method : methods)
      for (const std::string& mode : modes) {
        Row r = run(p, method, mode, 1);
        r.rel = (r.objective - ref) / std::abs(ref);
        print(r);
        rows.push_back(r);
      }
    fmt::print("{:<9} reference J_ref = {:.9g} ({}x finite elements)\n\n", p.name, ref, fine);
  }

  if (!csv.empty()) {
    std::ofstream f(csv);
    f << "problem,reference,mpcc_mode,step_eq,status,objective,rel,collapsed,held,switches,"
         "iterations,wall_s\n";
    for (const Row& r : rows)
      f << fmt::format("{},{},{},{},{},{:.17g},{:.6e},{},{},{},{},{:.4f}\n", r.problem,
                       r.reference ? 1 : 0, r.method, r.mode, r.status, r.objective, r.rel,
                       r.collapsed, r.held, r.switches, r.iterations, r.wall_s);
  }
  if (!json_path.empty()) {
    nlohmann::json j = nlohmann::json::array();
    for (const Row& r : rows)
      j.push_back({{"problem", r.problem},
                   {"reference", r.reference},
                   {"mpcc_mode", r.method},
                   {"step_equilibration", r.mode},
                   {"status", r.status},
                   {"objective", r.objective},
                   {"relative_difference", r.rel},
                   {"collapsed_elements", r.collapsed},
                   {"held_switches", r.held},
                   {"switches", r.switches},
                   {"iterations", r.iterations},
                   {"wall_s", r.wall_s}});
    std::ofstream(json_path) << j.dump(2) << "\n";
  }
  return 0;
}
