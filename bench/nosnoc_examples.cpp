// bench/nosnoc_examples.cpp: nosnoc_py's examples side by side with fesd, as whole processes.
//
// For every row of the side-by-side table of /work/shared/NOSNOC-EXAMPLES.md (nosnoc_py at commit
// 0c3f3bb) this runs the fesd command-line program on the matching example file, `fesd simulate
// FILE -q` or `fesd solve FILE -q`, --repeat N times (default 3), one process at a time, and prints
// fesd's status and objective (OCPs) or final state (simulations), the median wall time from
// process start to exit, the median CPU time (user + system) of the process, nosnoc_py's measured
// process time from NOSNOC-EXAMPLES.md and the ratio nosnoc_py / fesd of the wall times. Then, for
// a like-for-like view of the solver alone, fesd's own wall time of the run it returns (the
// report's "wall time" line: the integration at the file's N_sim without the companion runs
// below, or the OCP solve; median over the repeats) beside nosnoc_py's solve time
// (NOSNOC-EXAMPLES.md, in brackets in its time column) and their ratio.
//
// The fesd processes write no files: stderr goes to /dev/null and stdout (the report, a few
// hundred bytes) is read through a pipe, for the status, objective, final state and the run's
// own wall time. This program writes a file only for --csv and --json.
// Note: `fesd simulate` with N_sim given also runs two companion integrations (about N_sim / 2
// and N_sim / 4 steps) to estimate its error, about 75 % more work than the one integration
// nosnoc_py's example makes; the simulation rows include that work.
//
//   nosnoc_examples [--repeat N] [--fesd PATH] [--examples DIR] [--only NAME,...] [--csv FILE]
//                   [--json FILE]
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench_args.hpp"
#include "bench_timing.hpp"

extern char** environ;

namespace fesd_bench {
void usage(const std::string& why, int exit_code) {
  std::fprintf(stderr,
               "nosnoc_examples: %s\n"
               "usage: nosnoc_examples [--repeat N] [--fesd PATH] [--examples DIR] "
               "[--only NAME,...] [--catalogue] [--csv FILE] [--json FILE]\n",
               why.c_str());
  std::exit(exit_code);
}
}  // namespace fesd_bench

namespace {

using fesd_bench::median;

namespace fs = std::filesystem;

// One row of NOSNOC-EXAMPLES.md's side-by-side table. nosnoc_s: nosnoc_py's process time (start
// to exit, Python start-up and building the problem included), nosnoc_solve_s its solve time, and
// nosnoc_result what nosnoc_py reached, all from the table's "time nos" and "final state or
// objective" columns (/work/shared/NOSNOC-EXAMPLES.md, "Side by side", measured with nosnoc_py
// 0c3f3bb on CasADi 3.6.3 and Debian's IPOPT 3.11.9 + MUMPS, one process at a time).
struct Case {
  std::string name;
  std::string command;  // simulate or solve
  std::string file;     // in the examples directory
  std::vector<std::string> overrides;
  double nosnoc_s;
  double nosnoc_solve_s;
  std::string nosnoc_result;
};

const std::vector<Case>& cases() {
  // simplest: nosnoc_py's simplest_example.py is Example 3(a), x' in 2 - sign(x) from x0 = -1,
  // over T = pi/4 in one step (N_FE = 2, HEURISTIC_DELTA): examples/crossing.toml with overrides.
  // sliding_ocp: PEERS.md's median of five alternating pairs gives 4.39 s for nosnoc_py (and
  // 2.82 s for fesd main 0d0c9fc); NOSNOC-EXAMPLES.md's single run 4.9 s is used here as for the
  // other rows.
  static const std::vector<Case> all = {
      {"simplest",
       "simulate",
       "crossing.toml",
       {"--T_sim", "0.7853981633974483", "--N_sim", "1", "--step_equilibration", "heuristic_delta"},
       0.87,
       0.12,
       "x(T) = T - 1/3 to 5.4e-10"},
      {"relay",
       "simulate",
       "nosnoc/relay_feedback.toml",
       {},
       17.6,
       16.8,
       "1 failed step, 28 switches"},
      {"friction_block", "simulate", "nosnoc/friction_block.toml", {}, 15.8, 15.1, "12 switches"},
      {"stick_slip",
       "simulate",
       "nosnoc/periodic_stick_slip.toml",
       {},
       58.6,
       57.8,
       "ends at t = 19.970"},
      {"temperature", "simulate", "nosnoc/temperature_control.toml", {}, 6.8, 5.9, "y(3) = 19.58"},
      {"motor", "solve", "nosnoc/motor_with_friction.toml", {}, 5.7, 4.7, "J = 0.83969"},
      {"cartpole", "solve", "nosnoc/cart_pole_with_friction.toml", {}, 6.4, 5.5, "J = 678.50"},
      {"sliding_mode_ocp",
       "solve",
       "nosnoc/ocp_sliding_mode_nosnoc.toml",
       {},
       4.9,
       4.0,
       "J = 5.594461"},
  };
  return all;
}

// --catalogue: every file of DIR/nosnoc/ (issue 17's catalogue of nosnoc_py's examples), `fesd
// simulate` for a file with a [simulation] table and `fesd solve` otherwise; no nosnoc_py times
// (NOSNOC-EXAMPLES.md measured only the side-by-side rows), its published values are in
// docs/nosnoc-examples.md.
std::vector<Case> catalogue_cases(const std::string& examples) {
  std::vector<Case> out;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(fs::path(examples) / "nosnoc", ec)) {
    if (e.path().extension() != ".toml") continue;
    std::ifstream is(e.path());
    std::stringstream text;
    text << is.rdbuf();
    const bool simulation = text.str().find("\n[simulation]") != std::string::npos;
    out.push_back({e.path().stem().string(),
                   simulation ? "simulate" : "solve",
                   "nosnoc/" + e.path().filename().string(),
                   {},
                   NAN,
                   NAN,
                   "-"});
  }
  if (ec) fesd_bench::usage(fmt::format("{}/nosnoc: {}", examples, ec.message()), 1);
  std::sort(out.begin(), out.end(), [](const Case& a, const Case& b) { return a.name < b.name; });
  return out;
}

struct Run {
  int exit_code = -1;  // the process's exit code, or -1 if it did not exit normally
  double wall_s = NAN;
  double cpu_s = NAN;  // user + system time of the process
  std::string out;     // its stdout, if captured
};

// Runs argv as a process: stdin and stderr from/to /dev/null, stdout to /dev/null or, with
// capture, into Run::out through a pipe. Times from just before posix_spawn to wait4's return.
Run run_process(const std::vector<std::string>& args, bool capture) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  int pipe_fd[2] = {-1, -1};
  if (capture && pipe(pipe_fd) != 0) fesd_bench::usage("pipe failed", 1);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  if (capture) {
    posix_spawn_file_actions_adddup2(&actions, pipe_fd[1], 1);
    posix_spawn_file_actions_addclose(&actions, pipe_fd[0]);
    posix_spawn_file_actions_addclose(&actions, pipe_fd[1]);
  } else {
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  }
  Run run;
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int err = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0)
    fesd_bench::usage(fmt::format("cannot start {}: {}", args[0], std::strerror(err)), 1);
  if (capture) {
    close(pipe_fd[1]);
    char buf[4096];
    for (;;) {
      const ssize_t n = read(pipe_fd[0], buf, sizeof buf);
      if (n > 0) {
        run.out.append(buf, static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        break;
      }
    }
    close(pipe_fd[0]);
  }
  int status = 0;
  struct rusage usage {};
  while (wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.cpu_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
              1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// The value after "  KEY" on its line of fesd's report ("  objective            0.85396"), or "".
std::string report_field(const std::string& report, const std::string& key) {
  std::istringstream is(report);
  for (std::string line; std::getline(is, line);) {
    const std::size_t first = line.find_first_not_of(' ');
    if (first == std::string::npos || line.compare(first, key.size(), key) != 0) continue;
    const std::size_t rest = line.find_first_not_of(' ', first + key.size());
    if (rest == first + key.size()) continue;  // a longer key that starts with this one
    return rest == std::string::npos ? "" : line.substr(rest);
  }
  return "";
}

// "[0.01, -1.2e-33, 0.01]" -> the numbers.
std::vector<double> parse_vector(std::string s) {
  std::vector<double> v;
  std::replace(s.begin(), s.end(), '[', ' ');
  std::replace(s.begin(), s.end(), ']', ' ');
  for (const std::string& item : fesd_bench::split(s, ','))
    v.push_back(std::strtod(item.c_str(), nullptr));
  return v;
}

struct Row {
  const Case* c = nullptr;
  std::string status;  // from the report, or "exit N" if there is none
  double objective = NAN;
  std::vector<double> x_final;
  std::string switches;
  std::vector<double> wall_s, cpu_s, run_s;  // run_s: the report's own "wall time"
  double median_wall = NAN, median_cpu = NAN, median_run = NAN;
};

std::string result_text(const Row& r) {
  if (!std::isnan(r.objective)) return fmt::format("J = {:.6g}", r.objective);
  std::string s;
  for (double x : r.x_final) s += fmt::format("{}{:.4g}", s.empty() ? "" : ", ", x);
  return "x(T) = (" + s + ")";
}

// The fesd program: --fesd PATH, or `fesd` next to this program or one directory up (build/bench/
// nosnoc_examples next to build/fesd).
std::string find_fesd(const std::string& given) {
  if (!given.empty()) return given;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec)
    for (const fs::path& dir : {self.parent_path(), self.parent_path().parent_path()})
      if (fs::exists(dir / "fesd")) return (dir / "fesd").string();
  fesd_bench::usage("cannot find the fesd program next to this one: give --fesd PATH");
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 3;
  std::string fesd_path, csv, json_path;
#ifdef FESD_SOURCE_DIR
  std::string examples = std::string(FESD_SOURCE_DIR) + "/examples";
#else
  std::string examples = "examples";
#endif
  std::vector<std::string> only;
  bool catalogue = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) fesd_bench::usage(a + ": missing value");
      return argv[++i];
    };
    if (a == "--repeat") {
      repeat = fesd_bench::parse_int(a, value());
    } else if (a == "--fesd") {
      fesd_path = value();
    } else if (a == "--examples") {
      examples = value();
    } else if (a == "--only") {
      only = fesd_bench::split(value(), ',');
    } else if (a == "--catalogue") {
      catalogue = true;
    } else if (a == "--csv") {
      csv = value();
    } else if (a == "--json") {
      json_path = value();
    } else if (a == "-h" || a == "--help") {
      fesd_bench::usage(
          "nosnoc_py's examples side by side with the fesd program (NOSNOC-EXAMPLES.md)", 0);
    } else {
      fesd_bench::usage("unknown argument " + a);
    }
  }
  const std::vector<Case> all = catalogue ? catalogue_cases(examples) : cases();
  for (const std::string& name : only) {
    if (std::none_of(all.begin(), all.end(), [&](const Case& c) { return name == c.name; }))
      fesd_bench::usage("--only " + name + ": no such case");
  }
  const std::string fesd = find_fesd(fesd_path);
  if (access(fesd.c_str(), X_OK) != 0) fesd_bench::usage(fesd + ": not an executable program");

  fmt::print(
      "fesd program: {}\nexamples:     {}\nmedian of {} run{} per case, one process at a time\n\n",
      fesd, examples, repeat, repeat == 1 ? "" : "s");
  fmt::print("{:<17} {:<8} {:>7} {:>7} {:>7} {:>6}   {:>7} {:>7} {:>6}   {:<40} {}\n", "", "fesd",
             "fesd", "fesd", "nos", "ratio", "fesd", "nos", "ratio", "fesd", "nosnoc_py");
  fmt::print("{:<17} {:<8} {:>7} {:>7} {:>7} {:>6}   {:>7} {:>7} {:>6}   {:<40} {}\n", "case",
             "status", "wall s", "cpu s", "wall s", "nos/fe", "run s", "solve s", "nos/fe",
             "result", "result");
  std::vector<Row> rows;
  for (const Case& c : all) {
    if (!only.empty() && std::find(only.begin(), only.end(), c.name) == only.end()) continue;
    Row row;
    row.c = &c;
    std::vector<std::string> args = {fesd, c.command, examples + "/" + c.file, "-q"};
    args.insert(args.end(), c.overrides.begin(), c.overrides.end());
    for (int k = 0; k < repeat; ++k) {
      const Run run = run_process(args, /*capture=*/true);
      row.wall_s.push_back(run.wall_s);
      row.cpu_s.push_back(run.cpu_s);
      const std::string run_s = report_field(run.out, "wall time");
      row.run_s.push_back(run_s.empty() ? NAN : std::strtod(run_s.c_str(), nullptr));
      if (k > 0) continue;
      const std::string status = report_field(run.out, "status");
      row.status = status.empty() ? fmt::format("exit {}", run.exit_code)
                                  : status.substr(0, status.find(' '));
      const std::string objective = report_field(run.out, "objective");
      if (!objective.empty()) row.objective = std::strtod(objective.c_str(), nullptr);
      std::string x = report_field(run.out, "x(T)");
      if (x.empty()) x = report_field(run.out, "final state");
      row.x_final = parse_vector(x);
      row.switches = report_field(run.out, "switches");
    }
    row.median_wall = median(row.wall_s);
    row.median_cpu = median(row.cpu_s);
    row.median_run = median(row.run_s);
    fmt::print(
        "{:<17} {:<8} {:>7.2f} {:>7.2f} {:>7.2f} {:>6.2f}   {:>7.2f} {:>7.2f} {:>6.2f}   {:<40} "
        "{}\n",
        c.name, row.status, row.median_wall, row.median_cpu, c.nosnoc_s,
        c.nosnoc_s / row.median_wall, row.median_run, c.nosnoc_solve_s,
        c.nosnoc_solve_s / row.median_run, result_text(row), c.nosnoc_result);
    std::fflush(stdout);
    rows.push_back(std::move(row));
  }
  fmt::print(
      "\nfesd wall s: median wall time of the whole fesd process (start to exit); cpu s: its user "
      "+ "
      "system time;\nnos wall s: nosnoc_py's process time in NOSNOC-EXAMPLES.md (one run). fesd "
      "run "
      "s: the wall time fesd reports\nfor the run it returns (simulations: the integration at "
      "N_sim "
      "without the two companion runs of the\nerror estimate, which the process time includes; "
      "OCPs: the solve); nos solve s: nosnoc_py's solve time.\nratio nos/fe > 1: fesd is "
      "faster.\n");

  if (!csv.empty()) {
    std::ofstream os(csv);
    if (!os) fesd_bench::usage("cannot write " + csv, 1);
    os << "case,command,file,status,objective,x_final,switches,fesd_wall_s,fesd_cpu_s,"
          "fesd_run_s,nosnoc_s,nosnoc_solve_s,ratio_wall,ratio_run\n";
    for (const Row& r : rows) {
      std::string x;
      for (double v : r.x_final) x += fmt::format("{}{:.17g}", x.empty() ? "" : " ", v);
      os << fmt::format("{},{},{},{},{:.17g},{},{},{:.4f},{:.4f},{:.4f},{},{},{:.4f},{:.4f}\n",
                        r.c->name, r.c->command, r.c->file, r.status, r.objective, x, r.switches,
                        r.median_wall, r.median_cpu, r.median_run, r.c->nosnoc_s,
                        r.c->nosnoc_solve_s, r.c->nosnoc_s / r.median_wall,
                        r.c->nosnoc_solve_s / r.median_run);
    }
  }
  if (!json_path.empty()) {
    nlohmann::json out = nlohmann::json::array();
    for (const Row& r : rows)
      out.push_back(
          {{"case", r.c->name},
           {"command", r.c->command},
           {"file", r.c->file},
           {"overrides", r.c->overrides},
           {"status", r.status},
           {"objective", std::isnan(r.objective) ? nlohmann::json() : nlohmann::json(r.objective)},
           {"x_final", r.x_final},
           {"switches", r.switches},
           {"fesd_wall_s", r.median_wall},
           {"fesd_wall_s_all", r.wall_s},
           {"fesd_cpu_s", r.median_cpu},
           {"fesd_cpu_s_all", r.cpu_s},
           {"fesd_run_s", r.median_run},
           {"fesd_run_s_all", r.run_s},
           {"nosnoc_s", r.c->nosnoc_s},
           {"nosnoc_solve_s", r.c->nosnoc_solve_s},
           {"nosnoc_result", r.c->nosnoc_result},
           {"ratio_nosnoc_over_fesd", r.c->nosnoc_s / r.median_wall},
           {"ratio_nosnoc_solve_over_fesd_run", r.c->nosnoc_solve_s / r.median_run}});
    std::ofstream os(json_path);
    if (!os) fesd_bench::usage("cannot write " + json_path, 1);
    os << out.dump(2) << "\n";
  }
  return 0;
}
