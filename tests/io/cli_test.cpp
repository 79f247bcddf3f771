// tests/io/cli_test.cpp: the `fesd` program (FESD_CLI) run as a child process: exit codes, the
// one-line error messages, and the outputs of a short real simulation.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/temp_dir.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kOscillator = FESD_SOURCE_DIR "/examples/oscillator.toml";
const std::string kSensitivity = FESD_SOURCE_DIR "/examples/ocp_sensitivity.toml";
const std::string kSlidingOcp = FESD_SOURCE_DIR "/examples/ocp_sliding_mode.toml";

using fesd::testing::TempDir;

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char ch : s) {
    if (ch == '\'') {
      out += "'\\''";
    } else {
      out += ch;
    }
  }
  return out + "'";
}

struct CliRun {
  int code = -1;
  std::string out, err;
  int err_lines() const { return static_cast<int>(std::count(err.begin(), err.end(), '\n')); }
};

// Runs FESD_CLI with `args`, capturing stdout and stderr.
CliRun run_cli(const std::vector<std::string>& args) {
  TempDir dir;
  std::string cmd = shell_quote(FESD_CLI);
  for (const std::string& a : args) {
    cmd += ' ';
    cmd += shell_quote(a);
  }
  cmd += " >";
  cmd += shell_quote(dir.file("out"));
  cmd += " 2>";
  cmd += shell_quote(dir.file("err"));
  cmd += " </dev/null";
  const int status = std::system(cmd.c_str());
  CliRun r;
  r.code = status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(dir.file("out"));
  r.err = read_file(dir.file("err"));
  return r;
}

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

TEST(Cli, NoArgumentsPrintsHelpAndExits2) {
  const CliRun r = run_cli({});
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(contains(r.out, "simulate")) << r.out;
  EXPECT_TRUE(contains(r.err, "fesd: error: ")) << r.err;
  EXPECT_EQ(r.err_lines(), 1) << r.err;
}

TEST(Cli, HelpAndVersionExit0) {
  const CliRun help = run_cli({"--help"});
  EXPECT_EQ(help.code, 0) << help.err;
  EXPECT_TRUE(contains(help.out, "check")) << help.out;
  const CliRun sim_help = run_cli({"simulate", "--help"});
  EXPECT_EQ(sim_help.code, 0) << sim_help.err;
  EXPECT_TRUE(contains(sim_help.out, "--N_FE")) << sim_help.out;
  const CliRun version = run_cli({"--version"});
  EXPECT_EQ(version.code, 0) << version.err;
  EXPECT_TRUE(contains(version.out, "fesd ")) << version.out;
}

TEST(Cli, UnknownCommandExits2) {
  const CliRun r = run_cli({"frobnicate", "x.toml"});
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(contains(r.err, "fesd: error: ")) << r.err;
  EXPECT_TRUE(contains(r.err, "frobnicate")) << r.err;
  EXPECT_EQ(r.err_lines(), 1) << r.err;
}

TEST(Cli, UnknownOptionExits2) {
  const CliRun r = run_cli({"simulate", kOscillator, "--no_such_option", "1"});
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(contains(r.err, "--no_such_option")) << r.err;
  EXPECT_EQ(r.err_lines(), 1) << r.err;
}

// A misspelt option gets the nearest valid one, as docs/problem-files.md promises; both the
// "--KEY VALUE" and the "--KEY=VALUE" form, for every command.
TEST(Cli, MisspeltOptionSuggestsTheNearest) {
  for (const char* cmd : {"simulate", "check"}) {
    for (const auto& args : {std::vector<std::string>{"--n_S", "3"}, {"--n_S=3"}}) {
      std::vector<std::string> argv{cmd, kOscillator};
      argv.insert(argv.end(), args.begin(), args.end());
      const CliRun r = run_cli(argv);
      EXPECT_EQ(r.code, 2) << cmd;
      EXPECT_TRUE(contains(r.err, "unknown option 'n_S' (did you mean 'n_s'?)")) << r.err;
      EXPECT_EQ(r.err_lines(), 1) << r.err;
    }
  }
  const CliRun no_value = run_cli({"simulate", kOscillator, "--n_S"});
  EXPECT_EQ(no_value.code, 2);
  EXPECT_TRUE(contains(no_value.err, "'--n_S' needs a value")) << no_value.err;
  const CliRun stray = run_cli({"simulate", kOscillator, "stray"});
  EXPECT_EQ(stray.code, 2);
  EXPECT_TRUE(contains(stray.err, "unexpected argument 'stray'")) << stray.err;
}

TEST(Cli, MissingFileExits2WithThePath) {
  const std::string path = "/nonexistent/dir/problem.toml";
  for (const char* command : {"simulate", "check"}) {
    const CliRun r = run_cli({command, path});
    EXPECT_EQ(r.code, 2) << command;
    EXPECT_TRUE(contains(r.err, "fesd: error: ")) << r.err;
    EXPECT_TRUE(contains(r.err, path)) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
  }
}

TEST(Cli, CheckExample) {
  ASSERT_TRUE(fs::exists(kOscillator)) << kOscillator << " is missing";
  const CliRun r = run_cli({"check", kOscillator});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "oscillator")) << r.out;
  EXPECT_TRUE(contains(r.out, "n_x = 2")) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
}

// Issue 13, 5: check prints the model it understood, region by region: the row of S and the row
// of F, so that a transposed F (nosnoc's layout) stands out.
TEST(Cli, CheckPrintsTheRegionsOfTheOscillator) {
  const CliRun r = run_cli({"check", kOscillator});
  EXPECT_EQ(r.code, 0) << r.err;
  for (const char* line : {
           "  p           omega = 6.28319\n",
           "  fesd        gamma_h = 1, rho_h = 1, stage_lambda_sign = auto, pin_sliding_exits = "
           "1\n",
           "\nmodel as read (region i: row i of S and of F)\n"
           "  c[0]        x1^2 + x2^2 - 1\n"
           "  region 0    c[0] < 0:  x1' = x1 + omega*x2,  x2' = -omega*x1 + x2\n"
           "  region 1    c[0] > 0:  x1' = x1 - omega*x2,  x2' = omega*x1 + x2\n"
           "  hint        F has one row per region (F[i] = the 2 components of region i's field); "
           "nosnoc's F has\n"
           "              one column per region. With n_x = 2 = the number of regions, a "
           "transposed F passes\n"
           "              every check: compare the fields above with the sign patterns.\n"
           "check: '",
       }) {
    EXPECT_TRUE(contains(r.out, line)) << "missing:\n" << line << "\nin:\n" << r.out;
  }
}

TEST(Cli, CheckPrintsSubsystemsControlsAndIndicatorFunctions) {
  TempDir dir;
  const std::string file = dir.file("two.toml");
  std::ofstream(file) << R"([model]
x = ["x1", "x2", "x3"]
u = ["w"]
p = { a = 0.5 }
x0 = [1, -2, 0]
[[model.subsystem]]
c = ["x1", "x2 - a"]
S = [[1, 1], [-1, 1], [-1, -1]]
F = [["-1", "0", "w"], ["1", "0", "0"], ["2", "0", "a*x3"]]
[[model.subsystem]]
g = ["-x2", "x2", "0"]
F = [["0", "-1", "0"], ["0", "1", "0"], ["0", "0", "0"]]
[simulation]
T_sim = 2
u = [0.25]
)";
  const CliRun r = run_cli({"check", file});
  EXPECT_EQ(r.code, 0) << r.err;
  const std::string expected =
      "model as read (region i: row i of S and of F)\n"
      "  controls    w\n"
      "  subsystem 0 regions 0..2, 2 switching functions\n"
      "  c[0]        x1\n"
      "  c[1]        x2 - a\n"
      "  region 0    c[0] > 0, c[1] > 0:  x1' = -1,  x2' = 0,  x3' = w\n"
      "  region 1    c[0] < 0, c[1] > 0:  x1' = 1,  x2' = 0,  x3' = 0\n"
      "  region 2    c[0] < 0, c[1] < 0:  x1' = 2,  x2' = 0,  x3' = a*x3\n"
      "  subsystem 1 regions 3..5, 3 indicator functions\n"
      "  g[0]        -x2\n"
      "  g[1]        x2\n"
      "  g[2]        0\n"
      "  region 3    g[0] smallest:  x1' = 0,  x2' = -1,  x3' = 0\n"
      "  region 4    g[1] smallest:  x1' = 0,  x2' = 1,  x3' = 0\n"
      "  region 5    g[2] smallest:  x1' = 0,  x2' = 0,  x3' = 0\n"
      "  dynamics    x' = the sum of one active region's field per subsystem (21a), e.g. f_0 + "
      "f_3 in\n"
      "              regions 0 and 3\n"
      "  hint        F has one row per region (F[i] = the 3 components of region i's field); "
      "nosnoc's F has\n"
      "              one column per region. With n_x = 3 = the number of regions of a subsystem, "
      "a\n"
      "              transposed F passes every check: compare the fields above with the sign "
      "patterns.\n"
      "check: '";
  EXPECT_TRUE(contains(r.out, expected)) << "expected:\n" << expected << "\nin:\n" << r.out;
  EXPECT_TRUE(contains(r.out, "  u           w = 0.25\n")) << r.out;
}

TEST(Cli, CheckShowsTheClockState) {
  const CliRun r = run_cli({"check", FESD_SOURCE_DIR "/examples/leaving_sliding.toml"});
  EXPECT_EQ(r.code, 0) << r.err;
  const std::string expected =
      "  clock       t' = 1 (the time t, appended to the states)\n"
      "  c[0]        x\n"
      "  region 0    c[0] < 0:  x' = 1 + t,  t' = 1\n"
      "  region 1    c[0] > 0:  x' = -1 + t,  t' = 1\n"
      "check: '";
  EXPECT_TRUE(contains(r.out, expected)) << "expected:\n" << expected << "\nin:\n" << r.out;
  EXPECT_FALSE(contains(r.out, "hint")) << r.out;  // one state of the user's, two regions
}

TEST(CliSolve, CheckPrintsTheOcpCostsAndNoHintWithoutAmbiguity) {
  const CliRun r = run_cli({"check", kSensitivity});
  EXPECT_EQ(r.code, 0) << r.err;
  const std::string expected =
      "  c[0]        x\n"
      "  region 0    c[0] > 0:  x' = 1\n"
      "  region 1    c[0] < 0:  x' = 3\n"
      "\ncosts and constraints as read\n"
      "  f_q         x^2\n"
      "  f_q_T       (x - 5/3)^2\n"
      "check: '";
  EXPECT_TRUE(contains(r.out, expected)) << "expected:\n" << expected << "\nin:\n" << r.out;
  EXPECT_FALSE(contains(r.out, "hint")) << r.out;  // one state: F cannot be transposed
}

TEST(Cli, BadOverrideExits2NamingTheKey) {
  ASSERT_TRUE(fs::exists(kOscillator)) << kOscillator << " is missing";
  for (const char* command : {"simulate", "check"}) {
    const CliRun r = run_cli({command, kOscillator, "--n_s", "0"});
    EXPECT_EQ(r.code, 2) << command;
    EXPECT_TRUE(contains(r.err, "fesd: error: ")) << r.err;
    EXPECT_TRUE(contains(r.err, "n_s")) << r.err;
    EXPECT_EQ(r.err_lines(), 1) << r.err;
  }
  const CliRun scheme = run_cli({"check", kOscillator, "--rk_scheme", "runge_kutta_fehlberg"});
  EXPECT_EQ(scheme.code, 2);
  EXPECT_TRUE(contains(scheme.err, "rk_scheme")) << scheme.err;
  const CliRun ipopt = run_cli({"check", kOscillator, "--ipopt", "no_equals_sign"});
  EXPECT_EQ(ipopt.code, 2);
  EXPECT_TRUE(contains(ipopt.err, "--ipopt")) << ipopt.err;
}

TEST(Cli, OverridesAreApplied) {
  ASSERT_TRUE(fs::exists(kOscillator)) << kOscillator << " is missing";
  const CliRun r = run_cli({"check", kOscillator, "--N_FE", "3", "--n_s", "2", "--rk_scheme",
                            "gauss_legendre", "--N_sim", "7", "--ipopt", "mu_strategy=monotone"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "gauss_legendre, n_s = 2, N_FE = 3")) << r.out;
  EXPECT_TRUE(contains(r.out, "N_sim = 7")) << r.out;
  EXPECT_TRUE(contains(r.out, "mu_strategy = monotone")) << r.out;

  // Valid only together: N_FE = 1 needs use_fesd = 0, whatever the order on the command line.
  const CliRun both = run_cli({"check", kOscillator, "--N_FE", "1", "--use_fesd", "0"});
  EXPECT_EQ(both.code, 0) << both.err;
  EXPECT_TRUE(contains(both.out, "N_FE = 1, use_fesd = 0")) << both.out;
  const CliRun alone = run_cli({"check", kOscillator, "--N_FE", "1"});
  EXPECT_EQ(alone.code, 2);
  EXPECT_TRUE(contains(alone.err, "N_finite_elements")) << alone.err;
}

// docs/problem-files.md, "Overrides": --TABLE.KEY VALUE, --ipopt.NAME VALUE, --ipopt.NAME=VALUE,
// and every [simulation] key (u, t0 too).
TEST(Cli, QualifiedOverrideForms) {
  ASSERT_TRUE(fs::exists(kOscillator)) << kOscillator << " is missing";
  const CliRun r =
      run_cli({"check", kOscillator, "--discretization.n_s", "3", "--homotopy.sigma_0=0.5",
               "--ipopt.tol", "1e-10", "--ipopt.mu_strategy", "monotone", "--ipopt.bound_push=1e-9",
               "--discretization.N_FE", "4", "--t0", "0", "--u", ""});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "n_s = 3, N_FE = 4")) << r.out;
  EXPECT_TRUE(contains(r.out, "sigma_0 = 0.5")) << r.out;
  EXPECT_TRUE(contains(r.out, "tol = 1e-10")) << r.out;
  EXPECT_TRUE(contains(r.out, "mu_strategy = monotone, bound_push = 1e-9")) << r.out;
  const CliRun bad = run_cli({"check", kOscillator, "--homotopy.n_s", "3"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_TRUE(contains(bad.err, "--homotopy.n_s")) << bad.err;
  EXPECT_EQ(bad.err_lines(), 1) << bad.err;
}

TEST(Cli, HelpGroupsOverridesByTable) {
  const CliRun r = run_cli({"simulate", "--help"});
  EXPECT_EQ(r.code, 0) << r.err;
  for (const char* group : {"Overrides [simulation]", "Overrides [discretization]",
                            "Overrides [homotopy]", "Overrides [ipopt]"})
    EXPECT_TRUE(contains(r.out, group)) << group << "\n" << r.out;
  EXPECT_TRUE(contains(r.out, "--n_s INT")) << r.out;
  EXPECT_TRUE(contains(r.out, "1..9")) << r.out;
  EXPECT_TRUE(contains(r.out, "--ipopt.NAME VALUE")) << r.out;
  // [model] x0 and p (issue 13, 3), for every command; u and u_guess as lists.
  for (const char* command : {"simulate", "solve", "check"}) {
    const CliRun h = run_cli({command, "--help"});
    EXPECT_TRUE(contains(h.out, "Overrides [model]")) << command;
    EXPECT_TRUE(contains(h.out, "--x0 V1,V2,...")) << command;
    EXPECT_TRUE(contains(h.out, "--p NAME=VALUE")) << command;
  }
  EXPECT_TRUE(contains(r.out, "--u V1,V2,...")) << r.out;
  EXPECT_TRUE(contains(run_cli({"solve", "--help"}).out, "--u_guess V1,V2,..."));
}

// Parameters, x0, u and u_guess from the command line reach the problem (issue 13, 3): the
// header of `check` shows them; bad values are one-line errors naming the option.
TEST(Cli, ModelOverrides) {
  const CliRun r = run_cli({"check", kOscillator, "--p", "omega=3", "--x0", "-1,2", "--model.p",
                            "omega=4", "--p=omega=5"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "x0          [-1, 2]")) << r.out;
  EXPECT_TRUE(contains(r.out, "p           omega = 5")) << r.out;
  const CliRun ocp = run_cli({"check", kSlidingOcp, "--u_guess", "0.5,-0.5", "--x0=1,2,0,0"});
  EXPECT_EQ(ocp.code, 0) << ocp.err;
  EXPECT_TRUE(contains(ocp.out, "u guess     u1 = 0.5, u2 = -0.5")) << ocp.out;
  EXPECT_TRUE(contains(ocp.out, "x0          [1, 2, 0, 0]")) << ocp.out;
  for (const auto& [args, message] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--p", "omgea=3"}, "--p omgea=3: unknown parameter 'omgea' (did you mean 'omega'?)"},
           {{"--omega", "3"}, "('omega' is a parameter of model.p: write --p omega=3)"},
           {{"--x0", "1"},
            "--x0 = 1: wrong length (expected 2 numbers, one per state in model.x, "
            "got 1)"},
           {{"--T", "2"}, "--T = 2: unknown option 'T' (did you mean 'T_sim'?)"},
           {{"--u_guess", "0"}, "unknown option 'u_guess' (did you mean 'u'?)"}}) {
    std::vector<std::string> argv{"simulate", kOscillator};
    argv.insert(argv.end(), args.begin(), args.end());
    const CliRun bad = run_cli(argv);
    EXPECT_EQ(bad.code, 2) << bad.err;
    EXPECT_EQ(bad.err.rfind("fesd: error: " + args.front(), 0), 0U) << bad.err;
    EXPECT_TRUE(contains(bad.err, message)) << bad.err;
    EXPECT_EQ(bad.err_lines(), 1) << bad.err;
  }
}

TEST(Cli, BadPlotExtensionExits2BeforeSolving) {
  ASSERT_TRUE(fs::exists(kOscillator)) << kOscillator << " is missing";
  TempDir dir;
  const CliRun r = run_cli({"simulate", kOscillator, "--plot", dir.file("x.pdf")});
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(contains(r.err, ".pdf")) << r.err;
  EXPECT_EQ(r.err_lines(), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("x.pdf")));
}

TEST(Cli, UnwritableOutputExits3) {
  // Output paths are checked before solving, so this needs no solve.
  ASSERT_TRUE(fs::exists(kOscillator)) << kOscillator << " is missing";
  const std::string path = "/nonexistent/dir/x.json";
  const CliRun r = run_cli({"simulate", kOscillator, "--json", path});
  EXPECT_EQ(r.code, 3);
  EXPECT_TRUE(contains(r.err, "fesd: error: ")) << r.err;
  EXPECT_TRUE(contains(r.err, path)) << r.err;
  EXPECT_EQ(r.err_lines(), 1) << r.err;
}

// REAL SOLVE: a short simulation of the oscillator (2 steps up to t = 0.1, well before its switch
// at t = 1), well under a second.
TEST(Cli, SimulateWritesRequestedOutputs) {
  ASSERT_TRUE(fs::exists(kOscillator)) << kOscillator << " is missing";
  TempDir dir;
  const std::string json = dir.file("r.json"), csv = dir.file("r.csv");
  const CliRun r = run_cli({"simulate", kOscillator, "--N_sim", "2", "--T_sim", "0.1", "--N_FE",
                            "2", "--json", json, "--csv", csv, "--quiet"});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_TRUE(r.err.empty()) << "--quiet prints nothing to stderr: " << r.err;
  EXPECT_TRUE(contains(r.out, json)) << r.out;
  EXPECT_TRUE(contains(r.out, csv)) << r.out;

  const nlohmann::json j = nlohmann::json::parse(read_file(json));
  EXPECT_EQ(j["status"], "success");
  EXPECT_EQ(j["t"].size(), 5u);
  EXPECT_DOUBLE_EQ(j["t"].back().get<double>(), 0.1);
  EXPECT_EQ(j["state_names"].get<std::vector<std::string>>(),
            (std::vector<std::string>{"x1", "x2"}));

  const std::string text = read_file(csv);
  EXPECT_EQ(text.substr(0, 9), "t,x1,x2\n0");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 6);  // header + 5 boundaries
}

// Issue 13, 2: the header and `fesd check` state how N_sim is chosen and the error estimated;
// simulate reports the estimate (progress: one line per run) and writes it to the JSON.
TEST(Cli, SimulateCarriesAnErrorEstimate) {
  ASSERT_TRUE(fs::exists(kOscillator)) << kOscillator << " is missing";
  const CliRun given = run_cli({"check", kOscillator});
  EXPECT_TRUE(contains(given.out,
                       "  simulation  T_sim = 1.5708, N_sim = 100 (step 0.015708); error "
                       "estimated from companion runs at N_sim = 50 and 25; fix_active_set = 1\n"))
      << given.out;
  const CliRun chosen = run_cli({"check", kOscillator, "--N_sim", "0"});
  EXPECT_TRUE(contains(chosen.out,
                       "N_sim chosen for tol_sim = 1e-06 (the default): runs from "
                       "N_sim = 10 up to 1000 (N_sim_max)"))
      << chosen.out;
  const CliRun target = run_cli({"check", kOscillator, "--tol_sim", "1e-8", "--N_sim_max", "500"});
  EXPECT_TRUE(contains(target.out,
                       "N_sim chosen for tol_sim = 1e-08: runs from N_sim = 100 up "
                       "to 500 (N_sim_max)"))
      << target.out;

  TempDir dir;
  const std::string json = dir.file("r.json");
  const CliRun r =
      run_cli({"simulate", kOscillator, "--N_sim", "2", "--T_sim", "0.1", "--json", json});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  for (const char* line : {"  run with N_sim = 2: success", "  run with N_sim = 4: success",
                           "  run with N_sim = 8: success"})
    EXPECT_TRUE(contains(r.err, line)) << r.err;
  EXPECT_TRUE(contains(r.err, "  run 3  step    8/8")) << r.err;  // steps numbered by run
  // Every step by Newton (the default step_solver): the progress says so, and the report has
  // the active-set line but no NLP or IPOPT lines.
  EXPECT_TRUE(contains(r.err, "Newton   2  (active set)       success")) << r.err;
  EXPECT_FALSE(contains(r.err, "NLPs ")) << r.err;
  EXPECT_TRUE(contains(r.out, "  active-set steps     2  (0 by the homotopy; ")) << r.out;
  EXPECT_FALSE(contains(r.out, "NLPs solved")) << r.out;
  EXPECT_FALSE(contains(r.out, "IPOPT")) << r.out;
  EXPECT_TRUE(contains(r.out, "  error estimate       ")) << r.out;
  EXPECT_TRUE(contains(r.out, "  runs                 N_sim = 2, 4, 8  (")) << r.out;
  const nlohmann::json j = nlohmann::json::parse(read_file(json));
  ASSERT_TRUE(j["error_estimate"].is_number()) << j["error_estimate"];
  EXPECT_GT(j["error_estimate"].get<double>(), 0.0);
  EXPECT_EQ(j["accuracy"]["N_sim"], 2);
  EXPECT_EQ(j["accuracy"]["runs"].size(), 3u);
  EXPECT_EQ(j["t"].size(), 5u);  // the result is the run asked for: 2 steps, 2 elements each
  EXPECT_EQ(j["step_path"], nlohmann::json::array({"active_set", "active_set"}));
}

// REAL SOLVE: one IPOPT iteration per NLP cannot converge: exit 1, and the outputs are written.
TEST(Cli, NumericalFailureExits1AndStillWrites) {
  ASSERT_TRUE(fs::exists(kOscillator)) << kOscillator << " is missing";
  TempDir dir;
  const std::string json = dir.file("failed.json");
  const CliRun r = run_cli({"simulate", kOscillator, "--N_sim", "2", "--T_sim", "0.1", "--max_iter",
                            "1", "--step_solver", "homotopy", "--json", json, "--quiet"});
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_EQ(r.err_lines(), 1) << r.err;
  EXPECT_TRUE(contains(r.err, "fesd: error: ")) << r.err;
  ASSERT_TRUE(fs::exists(json));
  const nlohmann::json j = nlohmann::json::parse(read_file(json));
  EXPECT_NE(j["status"], "success");
  // The failed step's residual is reported (was 0: only solved steps counted).
  ASSERT_TRUE(j["stats"]["max_comp_residual"].is_number());
  EXPECT_GT(j["stats"]["max_comp_residual"].get<double>(), 0.0);
}

// REAL SOLVE (one short step), run in an empty working directory.
TEST(Cli, NothingWrittenUnlessAsked) {
  ASSERT_TRUE(fs::exists(kOscillator)) << kOscillator << " is missing";
  TempDir dir;
  const std::string cmd = "cd " + shell_quote(dir.file("")) + " && " + shell_quote(FESD_CLI) +
                          " simulate " + shell_quote(kOscillator) +
                          " --N_sim 1 --T_sim 0.05 >/dev/null 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(fs::is_empty(dir.file("")));
}

// ---- fesd solve: optimal control problem files
// ---------------------------------------------------

TEST(CliSolve, HelpListsTheOcpOverrides) {
  const CliRun r = run_cli({"solve", "--help"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "--N_stages")) << r.out;
  EXPECT_TRUE(contains(r.out, "--initialization")) << r.out;
  EXPECT_TRUE(contains(r.out, "--N_FE")) << r.out;
  EXPECT_FALSE(contains(r.out, "--T_sim")) << r.out;
}

TEST(CliSolve, CheckAcceptsOcpFiles) {
  ASSERT_TRUE(fs::exists(kSensitivity)) << kSensitivity << " is missing";
  const CliRun r = run_cli({"check", kSensitivity, "--N_stages", "2", "--N_FE", "5"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "sensitivity_ocp")) << r.out;
  EXPECT_TRUE(contains(r.out, "T = 2, N_stages = 2")) << r.out;
  EXPECT_TRUE(contains(r.out, "N_FE = 5")) << r.out;
  EXPECT_TRUE(contains(r.out, "step_equilibration = l2_relaxed")) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
  // A simulation key does not apply to an OCP file.
  const CliRun wrong = run_cli({"check", kSensitivity, "--T_sim", "1"});
  EXPECT_EQ(wrong.code, 2);
  EXPECT_TRUE(contains(wrong.err, "unknown option 'T_sim'")) << wrong.err;
  EXPECT_EQ(wrong.err_lines(), 1) << wrong.err;
}

TEST(CliSolve, WrongKindOfFileExits2) {
  const CliRun sim = run_cli({"simulate", kSensitivity});
  EXPECT_EQ(sim.code, 2);
  EXPECT_TRUE(contains(sim.err, "fesd solve")) << sim.err;
  EXPECT_EQ(sim.err_lines(), 1) << sim.err;
  const CliRun ocp = run_cli({"solve", kOscillator});
  EXPECT_EQ(ocp.code, 2);
  EXPECT_TRUE(contains(ocp.err, "fesd simulate")) << ocp.err;
  EXPECT_EQ(ocp.err_lines(), 1) << ocp.err;
  const CliRun bad = run_cli({"solve", kSensitivity, "--T", "-1"});
  EXPECT_EQ(bad.code, 2);
  EXPECT_TRUE(contains(bad.err, "--T = -1: must be > 0")) << bad.err;
  EXPECT_EQ(bad.err_lines(), 1) << bad.err;
}

// REAL SOLVE (about 1 s): the sensitivity OCP (56) as written, with every output.
TEST(CliSolve, SolvesAndWritesRequestedOutputs) {
  ASSERT_TRUE(fs::exists(kSensitivity)) << kSensitivity << " is missing";
  TempDir dir;
  const std::string json = dir.file("s.json"), csv = dir.file("s.csv");
  const CliRun r = run_cli({"solve", kSensitivity, "--json", json, "--csv", csv});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "fesd optimal control: success")) << r.out;
  EXPECT_TRUE(contains(r.out, json)) << r.out;
  EXPECT_TRUE(contains(r.err, "sigma")) << "progress lines on stderr: " << r.err;
  // The homotopy table appears once: as progress, not again in the report.
  EXPECT_TRUE(contains(r.err, "IPOPT status")) << r.err;
  EXPECT_FALSE(contains(r.out, "IPOPT status")) << r.out;

  const nlohmann::json j = nlohmann::json::parse(read_file(json));
  for (const char* key : {"status", "message", "objective", "t", "x", "t_ctrl", "u", "h",
                          "interval", "eta", "switch_times", "x0", "x_final", "homotopy", "stats"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["status"], "success");
  EXPECT_NEAR(j["x0"][0].get<double>(), (9.0 - std::sqrt(417.0)) / 8.0, 1e-6);
  EXPECT_EQ(j["t"].size(), 26u);  // N_FE = 25 elements
  EXPECT_EQ(j["stats"]["mpcc_mode"], "scholtes_eq");
  EXPECT_EQ(read_file(csv).substr(0, 15), "t,x,interval\n0,");
}

// REAL SOLVE (a coarser grid, well under a second), run in an empty working directory.
TEST(CliSolve, NothingWrittenUnlessAsked) {
  ASSERT_TRUE(fs::exists(kSensitivity)) << kSensitivity << " is missing";
  TempDir dir;
  const std::string cmd = "cd " + shell_quote(dir.file("")) + " && " + shell_quote(FESD_CLI) +
                          " solve " + shell_quote(kSensitivity) + " --N_FE 6 >/dev/null 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(fs::is_empty(dir.file("")));
}

// ---- robustness (issue 12, items 5 and 6) ----------------------------------------------------

const std::string kCrossing = FESD_SOURCE_DIR "/examples/crossing.toml";

/// Runs `command` with sh, returns its exit status (-1 if it did not exit normally).
int run_shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// REAL SOLVE (one short step, twice): an ipopt.opt in the working directory that would stop
// every NLP (max_iter 0) and write IPOPT's full output to a file is not read.
TEST(CliRobust, IpoptOptInTheWorkingDirectoryIsIgnored) {
  TempDir plain, with_opt;
  {
    std::ofstream opt(with_opt.file("ipopt.opt"));
    opt << "max_iter 0\nprint_level 12\noutput_file ipopt_out.txt\nfile_print_level 12\n";
  }
  auto simulate_in = [&](const TempDir& dir) {
    const std::string cmd = "cd " + shell_quote(dir.file("")) + " && " + shell_quote(FESD_CLI) +
                            " simulate " + shell_quote(kOscillator) +
                            " --N_sim 1 --T_sim 0.05 --quiet --json r.json >out.txt 2>err.txt";
    return run_shell(cmd);
  };
  ASSERT_EQ(simulate_in(plain), 0) << read_file(plain.file("err.txt"));
  ASSERT_EQ(simulate_in(with_opt), 0) << read_file(with_opt.file("err.txt"));
  const nlohmann::json a = nlohmann::json::parse(read_file(plain.file("r.json")));
  const nlohmann::json b = nlohmann::json::parse(read_file(with_opt.file("r.json")));
  EXPECT_EQ(a["x"], b["x"]);
  EXPECT_EQ(a["h"], b["h"]);
  EXPECT_FALSE(contains(read_file(with_opt.file("out.txt")), "Ipopt")) << "IPOPT printed";
  std::vector<std::string> entries = with_opt.entries();
  std::sort(entries.begin(), entries.end());
  EXPECT_EQ(entries, (std::vector<std::string>{"err.txt", "ipopt.opt", "out.txt", "r.json"}));
}

TEST(CliRobust, HelpListsEveryExitCode) {
  const CliRun r = run_cli({"--help"});
  EXPECT_EQ(r.code, 0) << r.err;
  for (const char* code :
       {"0 solved", "1 not converged", "2 bad input", "3 I/O failure", "4 internal error"})
    EXPECT_TRUE(contains(r.out, code)) << code << " in\n" << r.out;
}

TEST(CliRobust, FullStdoutIsAnIoError) {
  // Issue 12, 6(f): `fesd check FILE > /dev/full` exited 0.
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  TempDir dir;
  const int code = run_shell(shell_quote(FESD_CLI) + " check " + shell_quote(kCrossing) +
                             " >/dev/full 2>" + shell_quote(dir.file("err")));
  const std::string err = read_file(dir.file("err"));
  EXPECT_EQ(code, 3) << err;
  EXPECT_TRUE(
      contains(err, "fesd: error: cannot write to standard output: No space left on device"))
      << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

// REAL SOLVE (Example 3(a), 10 steps, well under a second).
TEST(CliRobust, ClosedStdoutStillWritesTheOutputs) {
  // Issue 12, 6(f): `fesd simulate ... | head -1` died of SIGPIPE before writing --json. Standard
  // output is a pipe whose reading end is closed before fesd starts, so every write fails with
  // EPIPE (with `| head -1` whether head had exited before fesd's last write was a race that the
  // active-set path, fast enough to write everything first, lost now and then).
  TempDir dir;
  const std::string json = dir.file("r.json"), csv = dir.file("r.csv"), err_file = dir.file("err");
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  close(fds[0]);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
  posix_spawn_file_actions_addclose(&actions, fds[1]);
  posix_spawn_file_actions_addopen(&actions, 2, err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  std::vector<std::string> args{FESD_CLI, "simulate", kCrossing, "--json", json, "--csv", csv};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, FESD_CLI, &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  ASSERT_EQ(spawned, 0);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  const std::string err = read_file(err_file);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status) << ": " << err;
  EXPECT_EQ(WEXITSTATUS(status), 3) << err;
  EXPECT_TRUE(contains(err, "fesd: error: cannot write to standard output: Broken pipe")) << err;
  ASSERT_TRUE(fs::exists(json));
  EXPECT_EQ(nlohmann::json::parse(read_file(json))["status"], "success");
  EXPECT_TRUE(fs::exists(csv));
}

TEST(CliRobust, ConstantToThePowerZeroChecks) {
  // Issue 12, 6(a): F = [["2^0"], ["-1"]] crashed every command with SIGSEGV.
  TempDir dir;
  const std::string file = dir.file("power_zero.toml");
  std::ofstream(file) << "[model]\nx = [\"x\"]\nc = [\"x\"]\nF = [[\"2^0\"], "
                         "[\"pow(1, 0) - 2^(1-1) - 1\"]]\nx0 = [0.5]\n[simulation]\nT_sim = 1\n";
  const CliRun r = run_cli({"check", file});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "is valid")) << r.out;
}

// ---- the documented command lines (issue 13, 3) ----------------------------------------------
// Every command-line example in README.md and docs/problem-files.md, read from the docs
// themselves: the code spans `--...` and `fesd ...`, and README's shell blocks.

/// The code spans of a Markdown text (`a`, ``a``), whitespace runs as one space, "\|" as "|".
std::vector<std::string> code_spans(const std::string& text) {
  std::vector<std::string> spans;
  std::size_t i = 0;
  while ((i = text.find('`', i)) != std::string::npos) {
    std::size_t n = 0;
    while (i + n < text.size() && text[i + n] == '`') ++n;
    const std::string fence(n, '`');
    std::size_t end = text.find(fence, i + n);
    while (end != std::string::npos && end + n < text.size() && text[end + n] == '`')
      end = text.find(fence, end + n + 1);
    if (end == std::string::npos) break;
    std::string span;
    for (std::size_t k = i + n; k < end; ++k) {
      const char ch = text[k] == '\n' ? ' ' : text[k];
      if (ch == ' ' && (span.empty() || span.back() == ' ')) continue;
      if (ch == '|' && !span.empty() && span.back() == '\\') span.pop_back();
      span += ch;
    }
    while (!span.empty() && span.back() == ' ') span.pop_back();
    if (n < 3) spans.push_back(span);  // not a fenced block
    i = end + n;
  }
  return spans;
}

std::vector<std::string> words(const std::string& s) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < s.size()) {
    const std::size_t j = std::min(s.find(' ', i), s.size());
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j + 1;
  }
  return out;
}

/// Placeholders (`--KEY VALUE`, `fesd simulate FILE`) and elisions are forms, not examples.
bool is_template(const std::string& span) {
  for (const char* p : {"KEY", "VALUE", "NAME", "TABLE", "FILE", "OUT", "...", "V1"})
    if (contains(span, p)) return true;
  return false;
}

/// Checks one span of `doc`; returns "" or what is wrong.
std::string check_span(const std::string& span) {
  const std::vector<std::string> files{kOscillator, kSlidingOcp};
  if (span.rfind("fesd ", 0) == 0) {
    std::vector<std::string> args = words(span.substr(5));
    const bool has_option = std::any_of(args.begin(), args.end(),
                                        [](const std::string& w) { return w.rfind('-', 0) == 0; });
    if (!has_option || is_template(span)) return "";  // `fesd solve`: a name, not a command
    const CliRun r = run_cli(args);
    return r.code == 0 ? "" : "exit " + std::to_string(r.code) + ": " + r.err;
  }
  if (span.rfind("--", 0) != 0) return "";
  if (const std::size_t colon = span.find(": "); colon != std::string::npos) {
    // A message: run its head ("--n_s = 0", "--p omega=nan") and find its text in stderr, the
    // parts around "(...)" each.
    const std::string head = span.substr(2, colon - 2);
    const std::size_t eq = head.find(" = ");
    const std::size_t sp = head.find(' ');
    const std::vector<std::string> option =
        eq != std::string::npos
            ? std::vector<std::string>{"--" + head.substr(0, eq), head.substr(eq + 3)}
            : std::vector<std::string>{"--" + head.substr(0, sp), head.substr(sp + 1)};
    std::string errors;
    for (const std::string& file : files) {
      std::vector<std::string> args{"check", file};
      args.insert(args.end(), option.begin(), option.end());
      const CliRun r = run_cli(args);
      bool found = r.code == 2;
      for (std::size_t from = 0; found && from < span.size();) {
        const std::size_t to = std::min(span.find("(...)", from), span.size());
        found = contains(r.err, span.substr(from, to - from));
        from = to + 5;
      }
      if (found) return "";
      errors += r.err;
    }
    return "message not produced; got: " + errors;
  }
  if (is_template(span)) return "";
  if (span.find(' ') == std::string::npos && span.find('=') == std::string::npos) {
    // A key named in the text: an option of some command.
    for (const char* command : {"simulate", "solve"})
      if (contains(run_cli({command, "--help"}).out, span + " ")) return "";
    return "not in fesd simulate --help or fesd solve --help";
  }
  std::string errors;
  for (const std::string& file : files) {  // an example: valid for one of the example files
    std::vector<std::string> args{"check", file};
    for (const std::string& w : words(span)) args.push_back(w);
    const CliRun r = run_cli(args);
    if (r.code == 0) return "";
    errors += r.err;
  }
  return errors;
}

TEST(CliDocs, EveryCommandLineSpanRunsAsDocumented) {
  int checked = 0;
  for (const char* doc : {"README.md", "docs/problem-files.md"}) {
    for (const std::string& span : code_spans(read_file(FESD_SOURCE_DIR "/" + std::string(doc)))) {
      if (span.rfind("--", 0) != 0 && span.rfind("fesd ", 0) != 0) continue;
      ++checked;
      EXPECT_EQ(check_span(span), "") << doc << ": `" << span << "`";
    }
  }
  EXPECT_GE(checked, 30);  // the parser found the spans
}

// REAL SOLVES (the README's commands, a few seconds each): run as written, from a scratch
// directory (the outputs land there).
TEST(CliDocs, ReadmeCommandsRun) {
  if (run_shell("command -v gnuplot >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "gnuplot is not installed (the README's commands write plots)";
  const std::string readme = read_file(FESD_SOURCE_DIR "/README.md");
  TempDir dir;
  int run = 0;
  std::size_t at = 0;
  while ((at = readme.find("./build/fesd ", at)) != std::string::npos) {
    const std::size_t end = readme.find('\n', at);
    std::string args = readme.substr(at + 13, end - at - 13);
    at = end;
    const std::string source = FESD_SOURCE_DIR "/";
    for (std::size_t k = 0; (k = args.find("examples/", k)) != std::string::npos;
         k += source.size() + 9)
      args.insert(k, source);
    const std::string cmd = "cd " + shell_quote(dir.file("")) + " && " + shell_quote(FESD_CLI) +
                            " " + args + " >out.txt 2>err.txt";
    EXPECT_EQ(run_shell(cmd), 0) << args << "\n" << read_file(dir.file("err.txt"));
    ++run;
  }
  EXPECT_EQ(run, 3);
}

// --sensitivities true (docs/sensitivities.md): Example 3(a), dx(T)/dx0 = 1/3 in the summary and
// in the JSON entry `sensitivities` (row-major nested arrays; no controls, no parameters).
TEST(Cli, SensitivitiesInSummaryAndJson) {
  ASSERT_TRUE(fs::exists(kCrossing)) << kCrossing << " is missing";
  TempDir dir;
  const std::string json = dir.file("r.json");
  const CliRun r = run_cli({"simulate", kCrossing, "--sensitivities", "true", "--error_estimate",
                            "false", "--step_solver", "active_set", "--json", json});
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "sensitivities        dx(T)/dx0 = [0.3333333333]")) << r.out;
  const nlohmann::json j = nlohmann::json::parse(read_file(json));
  ASSERT_TRUE(j.contains("sensitivities")) << j.dump();
  const nlohmann::json& s = j["sensitivities"];
  EXPECT_EQ(s["available"], true);
  ASSERT_EQ(s["x0"].size(), 1u);
  ASSERT_EQ(s["x0"][0].size(), 1u);
  EXPECT_NEAR(s["x0"][0][0].get<double>(), 1.0 / 3.0, 1e-9);
  EXPECT_EQ(s["u"].size(), 1u);
  EXPECT_TRUE(s["u"][0].empty());
  EXPECT_TRUE(s["p"][0].empty());

  // without the option: no entry
  const CliRun plain =
      run_cli({"simulate", kCrossing, "--error_estimate", "false", "--json", json});
  ASSERT_EQ(plain.code, 0) << plain.out << plain.err;
  EXPECT_FALSE(nlohmann::json::parse(read_file(json)).contains("sensitivities"));
  EXPECT_FALSE(contains(plain.out, "sensitivities")) << plain.out;
}

// REAL SOLVE (Example 3(a), 10 steps, well under a second, twice).
TEST(CliRobust, MissingKktModuleWarnsUnderAutoAndIsAnErrorWhenAsked) {
  // A broken install: libfesd.so without libfesd_kkt.so next to it. fesd used to run every KKT
  // system with MUMPS without a word (4-5x the time per IPOPT iteration on the hopper OCP).
  TempDir dir;
  const fs::path build_dir = fs::path(FESD_KKT_MODULE).parent_path();
  fs::copy_file(FESD_CLI, dir.file("fesd"));
  fs::copy_file(fs::canonical(build_dir / "libfesd.so.0"), dir.file("libfesd.so.0"));
  ASSERT_FALSE(fs::exists(dir.file("libfesd_kkt.so")));
  const auto run = [&](const std::string& kkt_solver) {
    const int code = run_shell(
        "LD_LIBRARY_PATH=" + shell_quote(dir.file("")) + " " + shell_quote(dir.file("fesd")) +
        " simulate " + shell_quote(kCrossing) + " --step_solver homotopy --kkt_solver " +
        kkt_solver + " >" + shell_quote(dir.file("out")) + " 2>" + shell_quote(dir.file("err")));
    return CliRun{code, read_file(dir.file("out")), read_file(dir.file("err"))};
  };
  const CliRun asked = run("sparse_ldl");
  EXPECT_EQ(asked.code, 2) << asked.out << asked.err;
  EXPECT_TRUE(contains(asked.err, "kkt_solver = sparse_ldl: fesd's KKT module is not available"))
      << asked.err;
  EXPECT_TRUE(contains(asked.err, "libfesd_kkt.so")) << asked.err;
  EXPECT_EQ(asked.err_lines(), 1) << asked.err;

  const CliRun fallback = run("auto");
  EXPECT_EQ(fallback.code, 0) << fallback.out << fallback.err;
  EXPECT_TRUE(contains(fallback.out, "kkt_solver = auto: fesd's KKT module is not available"))
      << fallback.out;
  EXPECT_TRUE(contains(fallback.out, "with MUMPS")) << fallback.out;
}

}  // namespace
