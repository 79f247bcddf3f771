// Problem files of projected dynamical systems ([model] kind = "projected", docs/pds.md):
// simulation files, optimal control files and the program on both.
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "../../bench/pds_example1_model.hpp"
#include "fesd/error.hpp"
#include "fesd/ocp.hpp"
#include "fesd/pds_problem_file.hpp"
#include "fesd/problem_file.hpp"
#include "io/plot_parts.hpp"
#include "support/temp_dir.hpp"

namespace {

const std::string kExample1 = R"(
name = "ex1"
[model]
kind = "projected"
x = ["x1", "x2"]
p = { a = 1.0 }
f = ["x2", "-x1"]
constraints = ["x2 + a"]
x0 = [1.4142135623730951, 1.4142135623730951]
[simulation]
T_sim = 4.611844073359521
N_sim = 1
[discretization]
n_s = 3
N_finite_elements = 20
)";

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const std::size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

template <class E>
std::string error_of(const std::string& text) {
  try {
    const fesd::PdsSimulationProblem q = fesd::parse_pds_simulation_problem(text, "f.toml");
    fesd::simulate(q);
  } catch (const E& e) {
    return e.what();
  }
  return "(no exception)";
}

// Measured: 1.9e-7 (the C++ model gives the same, tests/pds/pds_example1_test.cpp).
TEST(PdsProblemFile, Example1) {
  const fesd::PdsSimulationProblem q = fesd::parse_pds_simulation_problem(kExample1, "f.toml");
  EXPECT_EQ(q.name, "ex1");
  EXPECT_EQ(q.model.n_c(), 1);
  EXPECT_EQ(q.options.discretization.N_FE, 20);
  const fesd::IntegratorResult r = fesd::simulate(q);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_LT((r.x_final() - pds_example1::x_T()).norm(), 6e-7);
  ASSERT_EQ(r.switches.size(), 2u);
  EXPECT_NEAR(r.switches[0].t, pds_example1::kContact, 8e-7);
  EXPECT_NEAR(r.switches[1].t, pds_example1::kLeave, 8e-7);
}

// [simulation] t0 (issue 16): the run starts at t0, every time of the result is offset by it
// (element boundaries, stage points, switches, the runs of the estimate) and x(T) is the same.
// Example 1 from t0 = 5: contact at 5 + 5 pi/12, leaving at 5 + 5 pi/12 + sqrt 3, x(T) = (-1, 0).
TEST(PdsProblemFile, StartTimeOffsetsEveryTime) {
  const std::string text = replace(kExample1, "N_sim = 1\n", "N_sim = 1\nt0 = 5\n");
  const fesd::PdsSimulationProblem q = fesd::parse_pds_simulation_problem(text, "f.toml");
  EXPECT_EQ(q.t0, 5.0);
  const fesd::IntegratorResult r = fesd::simulate(q);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_LT((r.x_final() - pds_example1::x_T()).norm(), 6e-7);
  EXPECT_EQ(r.t.front(), 5.0);
  EXPECT_NEAR(r.t.back(), 5.0 + pds_example1::kT, 1e-12);
  EXPECT_GE(r.t_stage.front(), 5.0);
  ASSERT_EQ(r.switches.size(), 2u);
  EXPECT_NEAR(r.switches[0].t, 5.0 + pds_example1::kContact, 8e-7);
  EXPECT_NEAR(r.switches[1].t, 5.0 + pds_example1::kLeave, 8e-7);
  ASSERT_FALSE(r.accuracy.runs.empty());
  for (const fesd::AccuracyRun& run : r.accuracy.runs) {
    ASSERT_EQ(run.switch_times.size(), 2u);
    EXPECT_NEAR(run.switch_times[0], 5.0 + pds_example1::kContact, 1e-5);
  }

  // The same run from t0 = 0 gives the same x(T) and the times 5 earlier.
  const fesd::IntegratorResult r0 =
      fesd::simulate(fesd::parse_pds_simulation_problem(kExample1, "f.toml"));
  ASSERT_EQ(r0.status, fesd::Status::Success) << r0.message;
  EXPECT_LT((r.x_final() - r0.x_final()).norm(), 1e-12);
  ASSERT_EQ(r.t.size(), r0.t.size());
  for (std::size_t n = 0; n < r.t.size(); ++n) EXPECT_NEAR(r.t[n], r0.t[n] + 5.0, 1e-12);

  // --t0 overrides it.
  fesd::PdsSimulationProblem o = q;
  fesd::apply_override(o, "t0", "-2.5");
  EXPECT_EQ(o.t0, -2.5);
  EXPECT_THROW(fesd::apply_override(o, "t0", "inf"), fesd::InvalidOption);
  EXPECT_EQ(o.t0, -2.5);
}

// The time t in f (issue 16): a clock state t' = 1 is appended as in piecewise smooth files, it
// starts at t0, and the result's times are absolute. x' = cos(t) on C = {x >= 0} from x(pi) = 0.5:
// x = 0.5 + sin t until contact at 7 pi/6, sliding on x = 0 while cos t < 0, leaving at 3 pi/2,
// then x = 1 + sin t: x(2 pi) = 1. Radau IIA n_s = 2, N_FE = 20, measured: |x(2 pi) - 1| =
// 1.8e-5, contact 3.9e-6 off, leaving < 1e-9 off.
TEST(PdsProblemFile, TimeInTheVectorFieldIsAClockFromT0) {
  const std::string text = R"toml(
[model]
kind = "projected"
x = ["x"]
f = ["cos(t)"]
constraints = ["x"]
x0 = [0.5]
[simulation]
T_sim = 3.141592653589793
t0 = 3.141592653589793
N_sim = 1
error_estimate = false
[discretization]
n_s = 2
N_finite_elements = 20
)toml";
  const double pi = 3.141592653589793;
  fesd::PdsSimulationProblem q = fesd::parse_pds_simulation_problem(text, "f.toml");
  EXPECT_TRUE(q.has_clock);
  ASSERT_EQ(q.model.n_x(), 2);
  EXPECT_EQ(q.model.state_names.back(), "t");
  EXPECT_EQ(q.x0[1], pi);
  const fesd::IntegratorResult r = fesd::simulate(q);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_NEAR(r.x_final()[0], 1.0, 6e-5);
  EXPECT_NEAR(r.x_final()[1], 2 * pi, 1e-9);  // the clock
  EXPECT_EQ(r.t.front(), pi);
  EXPECT_NEAR(r.t.back(), 2 * pi, 1e-12);
  for (std::size_t n = 0; n < r.t.size(); ++n) EXPECT_NEAR(r.x[n][1], r.t[n], 1e-9);
  ASSERT_EQ(r.switches.size(), 2u);
  EXPECT_NEAR(r.switches[0].t, 7 * pi / 6, 1.2e-5);
  EXPECT_NEAR(r.switches[1].t, 1.5 * pi, 1e-6);

  // --x0 sets the states of model.x (the clock keeps t0), --t0 the start time and the clock.
  fesd::apply_override(q, "x0", "0.25");
  EXPECT_EQ(q.x0[0], 0.25);
  EXPECT_EQ(q.x0[1], pi);
  fesd::apply_override(q, "t0", "1.5");
  EXPECT_EQ(q.t0, 1.5);
  EXPECT_EQ(q.x0[1], 1.5);
  EXPECT_THROW(fesd::apply_override(q, "x0", "0.25,1"), fesd::InvalidOption);
}

// [simulation] tol_sim (issue 16): N_sim chosen by step doubling as for piecewise smooth files.
// Example 1 with Radau IIA n_s = 2 (order 3), N_FE = 10, from N_sim = 1: measured runs N_sim =
// 1, 2, 8, 19, estimate 5.3e-7, true error 5.4e-7. Asserted: the error <= tol_sim = 1e-6 and the
// estimate within a factor 3 of it.
TEST(PdsProblemFile, TolSimMeetsTheExactSolution) {
  std::string text = replace(kExample1, "N_sim = 1\n", "N_sim = 1\ntol_sim = 1e-6\n");
  text = replace(text, "n_s = 3\nN_finite_elements = 20", "n_s = 2\nN_finite_elements = 10");
  const fesd::PdsSimulationProblem q = fesd::parse_pds_simulation_problem(text, "f.toml");
  EXPECT_EQ(q.tol_sim, 1e-6);
  const fesd::IntegratorResult r = fesd::simulate(q);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  const double error = (r.x_final() - pds_example1::x_T()).norm();
  EXPECT_LE(error, 1e-6);
  EXPECT_TRUE(r.accuracy.met);
  EXPECT_EQ(r.accuracy.order, 3);
  EXPECT_LE(r.accuracy.error_estimate, 1e-6);
  EXPECT_GE(r.accuracy.error_estimate, error / 3) << error;
  EXPECT_LE(r.accuracy.error_estimate, 3 * error) << error;
  EXPECT_GE(r.accuracy.runs.size(), 3u);
  EXPECT_GT(r.accuracy.N_sim, 2);
  ASSERT_EQ(r.switches.size(), 2u);
  EXPECT_NEAR(r.switches[1].t, pds_example1::kLeave, 1e-5);
}

TEST(PdsProblemFile, MixingTheKindsRejected) {
  const std::string m = error_of<fesd::ProblemFileError>(
      replace(kExample1, "constraints = [\"x2 + a\"]", "constraints = [\"x2 + a\"]\nc = [\"x1\"]"));
  EXPECT_NE(m.find("f.toml:"), std::string::npos) << m;
  EXPECT_NE(m.find("model.c"), std::string::npos) << m;
  EXPECT_NE(m.find("cannot be mixed"), std::string::npos) << m;
}

TEST(PdsProblemFile, BadInputOneLineEach) {
  EXPECT_NE(error_of<fesd::ProblemFileError>(replace(kExample1, "f = [", "fx = ["))
                .find("unknown key 'fx'"),
            std::string::npos);
  EXPECT_NE(
      error_of<fesd::ProblemFileError>(replace(kExample1, "f = [\"x2\", \"-x1\"]", "f = [\"x2\"]"))
          .find("model.f: wrong length"),
      std::string::npos);
  EXPECT_NE(error_of<fesd::Error>(replace(kExample1, "N_sim = 1\n", "N_sim = -1\n")).find("N_sim"),
            std::string::npos);
  EXPECT_NE(error_of<fesd::Error>(replace(kExample1, "N_sim = 1\n", "N_sim = 1\ntol_sim = -1\n"))
                .find("tol_sim"),
            std::string::npos);
  EXPECT_NE(
      error_of<fesd::Error>(replace(kExample1, "N_sim = 1\n", "N_sim = 1\nt0 = nan\n")).find("t0"),
      std::string::npos);
  EXPECT_NE(error_of<fesd::ProblemFileError>(
                replace(kExample1, "x0 = [1.4142135623730951, ", "x0 = [nan, "))
                .find("must be finite"),
            std::string::npos);
  EXPECT_NE(error_of<fesd::ProblemFileError>(
                replace(kExample1, "constraints = [\"x2 + a\"]", "constraints = []"))
                .find("model.constraints: empty"),
            std::string::npos);
  EXPECT_NE(
      error_of<fesd::ExpressionError>(replace(kExample1, "\"x2 + a\"", "\"x2 + b\"")).find("b"),
      std::string::npos);
  // x0 outside C: the integrator's check, one line.
  const std::string outside = error_of<fesd::InvalidModel>(
      replace(kExample1, "x0 = [1.4142135623730951, 1.4142135623730951]", "x0 = [0.0, -2.0]"));
  EXPECT_NE(outside.find("x0 lies outside C"), std::string::npos) << outside;
  EXPECT_EQ(outside.find('\n'), std::string::npos) << outside;
  EXPECT_NE(error_of<fesd::InvalidOption>(replace(kExample1, "n_s = 3",
                                                  "n_s = 3\nrk_scheme = "
                                                  "\"gauss_legendre\""))
                .find("radau_iia"),
            std::string::npos);
}

}  // namespace

namespace {

using fesd::testing::TempDir;

struct CliRun {
  int code = -1;
  std::string out, err;
};

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

CliRun fesd_cli(const std::string& args, const std::string& command = "simulate") {
  TempDir dir;
  const std::string cmd = std::string("'") + FESD_CLI + "' " + command + " " + args + " >'" +
                          dir.file("out") + "' 2>'" + dir.file("err") + "' </dev/null";
  const int status = std::system(cmd.c_str());
  return {status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(dir.file("out")),
          slurp(dir.file("err"))};
}

// `fesd simulate examples/pds_example1.toml` end to end: the report, and the CSV of t and x.
TEST(PdsCli, SimulateExample1) {
  TempDir dir;
  const CliRun r = fesd_cli(std::string(FESD_SOURCE_DIR) + "/examples/pds_example1.toml --csv '" +
                            dir.file("x.csv") + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("projected dynamical system, n_x = 2, n_c = 1"), std::string::npos);
  EXPECT_NE(r.out.find("switches             2"), std::string::npos) << r.out;
  const std::string csv = slurp(dir.file("x.csv"));
  EXPECT_EQ(csv.rfind("t,x1,x2\n0,1.4142135623730951,1.4142135623730951\n", 0), 0u) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 22);  // header + 21 element boundaries
}

// --json as for piecewise smooth models: the contact and leaving events, lambda per stage.
TEST(PdsCli, SimulateExample1Json) {
  TempDir dir;
  const CliRun r = fesd_cli(std::string(FESD_SOURCE_DIR) + "/examples/pds_example1.toml --quiet " +
                            "--json '" + dir.file("r.json") + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string json = slurp(dir.file("r.json"));
  EXPECT_NE(json.find("\"switch_times\""), std::string::npos);
  EXPECT_NE(json.find("\"lambda\""), std::string::npos);
  EXPECT_NE(json.find("\"state_names\": [\"x1\",\"x2\"]"), std::string::npos)
      << json.substr(0, 400);
}

// --plot of a projected run: the program writes the picture; its script shades the contact phase,
// labels the contact and leaving switches and draws the boundary c = 0 in the phase portrait.
TEST(PdsCli, PlotOfExample1) {
  TempDir dir;
  const std::string file = std::string(FESD_SOURCE_DIR) + "/examples/pds_example1.toml";
  const std::string png = dir.file("pds.png");
  const CliRun r = fesd_cli(file + " --plot " + png);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(png, std::ios::binary);
  in.seekg(0, std::ios::end);
  EXPECT_GT(in.tellg(), 10000);

  const fesd::PdsSimulationProblem p = fesd::load_pds_simulation_problem(file);
  const fesd::IntegratorResult result = fesd::simulate(p);
  const std::string s = fesd::io_detail::plot_script(result, p.model, "out.png", "");
  for (const char* part : {"title 'contact'", "'c[0] = 0'", "{}->{0}", "{0}->{}", "phase portrait"})
    EXPECT_NE(s.find(part), std::string::npos) << part;
  EXPECT_EQ(s.find("'sliding'"), std::string::npos);
}

// Bad projected files through the program: exit 2 and one line naming the problem.
TEST(PdsCli, BadFilesExitTwoWithOneLine) {
  TempDir dir;
  const std::string file = dir.file("bad.toml");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {replace(kExample1, "f = [", "fx = ["), "unknown key 'fx'"},
      {replace(kExample1, "f = [\"x2\", \"-x1\"]", "f = [\"x2\"]"), "model.f: wrong length"},
      {replace(kExample1, "x0 = [1.4142135623730951, ", "x0 = [nan, "), "must be finite"},
      {replace(kExample1, "x0 = [1.4142135623730951, 1.4142135623730951]", "x0 = [0.0, -2.0]"),
       "outside C"},
      {replace(kExample1, "N_sim = 1", "N_sim = 1\nbogus = 2"), "unknown key 'bogus'"}};
  for (const auto& [text, what] : cases) {
    {
      std::ofstream f(file);
      f << text;
    }
    const CliRun r = fesd_cli("'" + file + "' --quiet");
    EXPECT_EQ(r.code, 2) << what;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

// Command-line overrides as for piecewise smooth files; unknown and unsupported keys: exit 2.
TEST(PdsCli, Overrides) {
  const std::string file = std::string(FESD_SOURCE_DIR) + "/examples/pds_example1.toml";
  const CliRun ok =
      fesd_cli(file + " --n_s 2 --N_FE 10 --x0 1.4142135623730951,1.4142135623730951");
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.out.find("n_s = 2, N_FE = 10"), std::string::npos) << ok.out;
  for (const std::string& extra :
       {std::string("--n_S 2"), std::string("--p a=2"), std::string("--tol_sim -1"),
        std::string("--x0 1,2,3"), std::string("--N_sim -1"), std::string("--t0 nan"),
        std::string("--t0 x")}) {
    const CliRun r = fesd_cli(file + " " + extra);
    EXPECT_EQ(r.code, 2) << extra << r.out;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << extra << ": " << r.err;
  }
}

// `fesd check` of projected files: the header and the model as read (constraints, f, the
// parameters after --p), exit 0; a bad file: exit 2 with one line.
TEST(PdsCli, CheckDescribesTheModel) {
  TempDir dir;
  const std::string file = dir.file("ex1.toml");
  {
    std::ofstream f(file);
    f << kExample1;
  }
  const CliRun r = fesd_cli("'" + file + "' --p a=2 --n_s 2", "check");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* part : {"projected dynamical system, n_x = 2, n_c = 1", "n_s = 2",
                           "parameters  a = 2", "c[0]        x2 + a >= 0",
                           "f           x1' = x2,  x2' = -x1", "is valid (nothing was solved)"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
  const CliRun ocp =
      fesd_cli(std::string(FESD_SOURCE_DIR) + "/examples/ocp_pds_discs.toml", "check");
  ASSERT_EQ(ocp.code, 0) << ocp.err;
  for (const char* part : {"optimal control of a projected dynamical system", "controls    u1, v1",
                           "c[1]        (x3 - x2)^2", "costs and constraints as read", "f_q_T"})
    EXPECT_NE(ocp.out.find(part), std::string::npos) << part << "\n" << ocp.out;
  for (const std::string& bad : {std::string("--p b=2"), std::string("--tol_sim -1")}) {
    const CliRun e = fesd_cli("'" + file + "' " + bad, "check");
    EXPECT_EQ(e.code, 2) << bad;
    EXPECT_EQ(std::count(e.err.begin(), e.err.end(), '\n'), 1) << bad << ": " << e.err;
  }
  {
    std::ofstream f(file);
    f << replace(kExample1, "f = [", "fx = [");
  }
  const CliRun e = fesd_cli("'" + file + "'", "check");
  EXPECT_EQ(e.code, 2);
  EXPECT_NE(e.err.find("unknown key 'fx'"), std::string::npos) << e.err;
}

// --p NAME=VALUE of a projected file: the parameter and the model's default (what plots and
// results use) change together.
TEST(PdsProblemFile, ParameterOverride) {
  fesd::PdsSimulationProblem p = fesd::parse_pds_simulation_problem(kExample1, "f.toml");
  fesd::apply_override(p, "p", "a=0.5");
  EXPECT_EQ(p.p[0], 0.5);
  EXPECT_EQ(p.model.p_default[0], 0.5);
  EXPECT_THROW(fesd::apply_override(p, "p", "b=1"), fesd::InvalidOption);
  // The contact is now at x2 = -0.5: with the wall closer the trajectory slides on it.
  const fesd::IntegratorResult r = fesd::simulate(p);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_FALSE(r.switches.empty());
  EXPECT_NEAR(r.x[r.switches[0].element + 1][1], -0.5, 1e-9);
}

}  // namespace

namespace {

// A projected file given to the piecewise smooth loader (`fesd check`): says what it is.
TEST(PdsProblemFile, PiecewiseSmoothLoaderNamesTheKind) {
  try {
    fesd::parse_simulation_problem(kExample1, "f.toml");
    FAIL() << "no exception";
  } catch (const fesd::ProblemFileError& e) {
    EXPECT_NE(std::string(e.what()).find("model.kind: a projected dynamical system"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace

// ---- optimal control files ([model] kind = "projected" with [ocp], docs/pds.md) ----------------

namespace {

// A point driven by u towards -1 and stopped by the wall C = {x >= 0}: it reaches the wall and
// stays in contact, the cost of u is what keeps it from arriving early.
const std::string kWall = R"(
name = "wall"
[model]
kind = "projected"
x = ["x"]
u = ["u"]
f = ["u"]
constraints = ["x"]
x0 = [1.0]
[ocp]
T = 2.0
N_stages = 4
f_q = "u^2"
f_q_T = "(x + 1)^2"
lbu = [-2]
ubu = [2]
[discretization]
n_s = 2
N_finite_elements = 2
)";

template <class E>
std::string ocp_error_of(const std::string& text) {
  try {
    const fesd::PdsOcpProblem q = fesd::parse_pds_ocp_problem(text, "f.toml");
    (void)fesd::solve(q.ocp, q.options);
  } catch (const E& e) {
    return e.what();
  }
  return "(no exception)";
}

TEST(PdsOcpProblemFile, Wall) {
  const fesd::PdsOcpProblem q = fesd::parse_pds_ocp_problem(kWall, "f.toml");
  EXPECT_EQ(q.name, "wall");
  EXPECT_EQ(q.ocp.N_stages, 4);
  const fesd::OcpResult r = fesd::solve(q.ocp, q.options);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_LE(r.comp_residual, 1e-9);
  for (const Eigen::VectorXd& x : r.x_stage) EXPECT_GE(x[0], -1e-9);
  // The optimum reaches the wall: x(T) = 0 (the terminal cost pulls past it).
  EXPECT_NEAR(r.x_final()[0], 0.0, 1e-6);
}

// initialization = simulation (docs/pds.md): the guess is a simulation of every control interval
// with u_guess = -1, which reaches the wall in the second interval (contact in the guess); the
// solution is the one of the constant guess.
TEST(PdsOcpProblemFile, WallFromSimulation) {
  fesd::PdsOcpProblem q = fesd::parse_pds_ocp_problem(kWall, "f.toml");
  const fesd::OcpResult constant = fesd::solve(q.ocp, q.options);
  fesd::apply_override(q, "initialization", "simulation");
  fesd::apply_override(q, "u_guess", "-1");
  const fesd::OcpResult r = fesd::solve(q.ocp, q.options);
  ASSERT_EQ(constant.status, fesd::Status::Success) << constant.message;
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  for (const std::string& w : r.summary.warnings)
    EXPECT_EQ(w.find("initialization"), std::string::npos) << w;
  EXPECT_LE(r.comp_residual, 1e-9);
  EXPECT_NEAR(r.objective, constant.objective, 1e-6);
  EXPECT_NEAR(r.x_final()[0], 0.0, 1e-6);
}

// examples/ocp_pds_discs.toml is the problem of bench/pds_discs_model.hpp (solved in
// tests/pds/pds_ocp_test.cpp).
TEST(PdsOcpProblemFile, DiscsExampleReads) {
  const fesd::PdsOcpProblem q =
      fesd::load_pds_ocp_problem(std::string(FESD_SOURCE_DIR) + "/examples/ocp_pds_discs.toml");
  EXPECT_EQ(q.ocp.model.n_x(), 6);
  EXPECT_EQ(q.ocp.model.n_u(), 4);
  EXPECT_EQ(q.ocp.model.n_c(), 2);
  EXPECT_EQ(q.ocp.N_stages, 20);
  EXPECT_EQ(q.options.discretization.N_FE, 3);
  EXPECT_EQ(q.options.discretization.n_s, 2);
  EXPECT_TRUE(q.options.constraints_at_stages);
  EXPECT_EQ(q.ocp.ubx[0], -2.5);
  EXPECT_EQ(q.ocp.lbx[2], 2.5);
  ASSERT_TRUE(q.ocp.functions && q.ocp.functions->has_f_q() && q.ocp.functions->has_f_q_T());
  Eigen::VectorXd x(6), p(0);
  x << -10, 0, 10, 0, 0, 10;  // x_T: the Mayer term is 0 there
  EXPECT_EQ(q.ocp.functions->f_q_T(x.data(), p.data()), 0.0);
}

TEST(PdsOcpProblemFile, BadInputOneLineEach) {
  auto has = [](const std::string& m, const std::string& what) {
    EXPECT_NE(m.find(what), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  };
  has(ocp_error_of<fesd::ProblemFileError>(replace(kWall, "f_q = ", "fq = ")), "unknown key 'fq'");
  has(ocp_error_of<fesd::ProblemFileError>(replace(kWall, "lbu = [-2]", "lbu = [-2, 1]")),
      "ocp.lbu: wrong length");
  has(ocp_error_of<fesd::ProblemFileError>(replace(kWall, "f_q = \"u^2\"", "f_q = \"u^2 + t\"")),
      "time t");
  has(ocp_error_of<fesd::ProblemFileError>(replace(kWall, "x0 = [1.0]", "x0 = [inf]")),
      "must be finite");
  has(ocp_error_of<fesd::Error>(replace(kWall, "x0 = [1.0]", "x0 = [-0.5]")), "x0 lies outside C");
  has(ocp_error_of<fesd::Error>(
          replace(kWall, "n_s = 2", "n_s = 2\nrk_scheme = \"gauss_legendre\"")),
      "gauss_legendre");
  has(ocp_error_of<fesd::ProblemFileError>(
          replace(kWall, "[ocp]", "[simulation]\nT_sim = 1\n[ocp]")),
      "simulation");
  // The other loaders name the kind.
  try {
    (void)fesd::parse_ocp_problem(kWall, "f.toml");
    FAIL() << "no exception";
  } catch (const fesd::ProblemFileError& e) {
    has(e.what(), "load_pds_ocp_problem");
  }
  try {
    (void)fesd::parse_pds_simulation_problem(kWall, "f.toml");
    FAIL() << "no exception";
  } catch (const fesd::ProblemFileError& e) {
    has(e.what(), "fesd solve");
  }
}

TEST(PdsCli, SolveWall) {
  TempDir dir;
  const std::string wall = dir.file("wall.toml"), csv_file = dir.file("x.csv"),
                    json_file = dir.file("r.json"), bad_file = dir.file("bad.toml");
  {
    std::ofstream f(wall);
    f << kWall;
  }
  const CliRun r =
      fesd_cli("'" + wall + "' --csv '" + csv_file + "' --json '" + json_file + "'", "solve");
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("optimal control of a projected dynamical system"), std::string::npos);
  EXPECT_NE(r.out.find("fesd optimal control: success"), std::string::npos) << r.out;
  const std::string csv = slurp(csv_file);
  EXPECT_EQ(csv.rfind("t,x,interval,u\n0,1,0,", 0), 0u) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 10);  // header + 9 element boundaries
  const std::string json = slurp(json_file);
  EXPECT_NE(json.find("\"objective\""), std::string::npos);
  EXPECT_NE(json.find("\"switches\""), std::string::npos);
  EXPECT_NE(json.find("\"control_names\": [\"u\"]"), std::string::npos);
  // An override: 8 control intervals of 2 elements.
  const CliRun more = fesd_cli("'" + wall + "' --N_stages 8 --csv '" + csv_file + "'", "solve");
  ASSERT_EQ(more.code, 0) << more.err;
  const std::string csv8 = slurp(csv_file);
  EXPECT_EQ(std::count(csv8.begin(), csv8.end(), '\n'), 18);  // header + 17 element boundaries
  // x0 outside C: bad input, one line, exit 2.
  {
    std::ofstream f(bad_file);
    f << replace(kWall, "x0 = [1.0]", "x0 = [-0.5]");
  }
  const CliRun bad = fesd_cli("'" + bad_file + "' --quiet", "solve");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("outside C"), std::string::npos) << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
}

}  // namespace
