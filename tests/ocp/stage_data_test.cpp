// Per-interval data of an OCP (issue "every nosnoc_py example", first slice): time-varying
// parameters (Ocp::p_stage, [ocp] p_time_var) and user initial guesses (Ocp::x_guess with
// initialization = external, Ocp::u_guess_stage), against problems with known answers
// (examples/ocp_time_varying_parameter.toml, examples/ocp_branch_by_guess.toml).
#include <cmath>
#include <functional>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <fesd/error.hpp>
#include <fesd/ocp.hpp>
#include <fesd/problem_file.hpp>

namespace fesd {
namespace {

OcpProblem example(const std::string& name) {
  return load_ocp_problem(std::string(FESD_SOURCE_DIR) + "/examples/" + name);
}

/// x at the grid point t (an element boundary of the result).
double x_at(const OcpResult& r, double t) {
  for (std::size_t n = 0; n < r.t.size(); ++n)
    if (std::abs(r.t[n] - t) < 1e-9) return r.x[n][0];
  ADD_FAILURE() << "no grid point at t = " << t;
  return NAN;
}

// x' in a_k - sign(x), x(0) = -1, a = (2, 0.5, 0.5): crossing at 1/3, x(1) = 2/3, x(2) = 1/6,
// sliding from 7/3, x(3) = 0. The solution is piecewise linear, so every RK scheme is exact once
// the switches are element boundaries: measured errors ~1e-15 (tolerance 1e-8).
void expect_time_varying_solution(const OcpResult& r) {
  ASSERT_EQ(r.status, Status::Success) << r.message;
  ASSERT_EQ(r.switches.size(), 2u);
  EXPECT_NEAR(r.switches[0].t, 1.0 / 3, 1e-8);
  EXPECT_EQ(r.switches[0].after, std::vector<int>{1});
  EXPECT_NEAR(r.switches[1].t, 7.0 / 3, 1e-8);
  EXPECT_EQ(r.switches[1].after, (std::vector<int>{0, 1}));  // sliding
  EXPECT_NEAR(x_at(r, 1), 2.0 / 3, 1e-8);
  EXPECT_NEAR(x_at(r, 2), 1.0 / 6, 1e-8);
  EXPECT_NEAR(x_at(r, 3), 0.0, 1e-8);
}

TEST(OcpStageData, TimeVaryingParameterFromTheFile) {
  const OcpProblem p = example("ocp_time_varying_parameter.toml");
  ASSERT_EQ(p.ocp.p_stage.size(), 3u);
  EXPECT_EQ(p.ocp.p_stage[0][0], 2.0);
  EXPECT_EQ(p.ocp.p_stage[2][0], 0.5);
  expect_time_varying_solution(solve(p.ocp, p.options));
}

TEST(OcpStageData, TimeVaryingParameterWithTheSimulationGuess) {
  // The initializing simulation runs interval by interval with each interval's parameters.
  OcpProblem p = example("ocp_time_varying_parameter.toml");
  p.options.initialization = OcpInitialization::Simulation;
  const OcpResult r = solve(p.ocp, p.options);
  expect_time_varying_solution(r);
  EXPECT_EQ(r.message.find("constant guess"), std::string::npos) << r.message;
}

TEST(OcpStageData, ParametersOfEveryIntervalMatter) {
  // a = 2 throughout (p_stage empty: [model] p): x' = 1 after the crossing, x(3) = 8/3.
  OcpProblem p = example("ocp_time_varying_parameter.toml");
  p.ocp.p_stage.clear();
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.x.back()[0], 8.0 / 3, 1e-8);
  ASSERT_EQ(r.switches.size(), 1u);
  EXPECT_NEAR(r.switches[0].t, 1.0 / 3, 1e-8);
}

// Example 3(d) as an OCP without control or cost: every solution is feasible; the state guess
// selects x(t) = t or x(t) = -t (measured: exact to 1e-16); the constant guess stays at x = 0.
TEST(OcpStageData, StateGuessSelectsTheBranch) {
  OcpProblem p = example("ocp_branch_by_guess.toml");
  EXPECT_EQ(p.options.initialization, OcpInitialization::External);  // implied by x_guess
  ASSERT_EQ(p.ocp.x_guess.size(), 3u);
  for (double sign : {1.0, -1.0}) {
    for (int k = 0; k < 3; ++k) p.ocp.x_guess[k][0] = sign * 0.5 * k;
    const OcpResult r = solve(p.ocp, p.options);
    ASSERT_EQ(r.status, Status::Success) << r.message;
    EXPECT_NEAR(r.x.back()[0], sign, 1e-8);
    EXPECT_NEAR(x_at(r, 0.5), 0.5 * sign, 1e-8);
  }
  p.options.initialization = OcpInitialization::Constant;
  p.ocp.x_guess.clear();
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.x.back()[0], 0.0, 1e-8);
}

TEST(OcpStageData, ControlGuessPerInterval) {
  // u_guess with one row per interval is read into Ocp::u_guess_stage (one vector per interval).
  const std::string text = R"(
[model]
x = ["x"]
u = ["u"]
c = ["x"]
S = [[-1], [1]]
F = [["u + 1"], ["u - 1"]]
x0 = [-1.0]
[ocp]
T = 2.0
N_stages = 2
lbu = [-5.0]
ubu = [5.0]
u_guess = [[1.0], [2.0]]
f_q = "u^2"
)";
  const OcpProblem p = parse_ocp_problem(text, "u_rows.toml");
  ASSERT_EQ(p.ocp.u_guess_stage.size(), 2u);
  EXPECT_EQ(p.ocp.u_guess_stage[1][0], 2.0);
  EXPECT_EQ(p.ocp.u_guess.size(), 0);
}

std::string error_of(const std::string& text) {
  try {
    parse_ocp_problem(text, "bad.toml");
  } catch (const Error& e) {
    return e.what();
  }
  return "<no exception>";
}

TEST(OcpStageData, BadInputNamesTheProblem) {
  const std::string head = R"(
[model]
x = ["x"]
p = { a = 2.0 }
c = ["x"]
S = [[-1], [1]]
F = [["a + 1"], ["a - 1"]]
x0 = [-1.0]
[ocp]
T = 3.0
N_stages = 3
)";
  struct Case {
    std::string extra, expected;
  };
  for (const Case& c : {
           Case{"p_time_var = { b = [1.0, 2.0, 3.0] }", "unknown parameter 'b'"},
           Case{"p_time_var = { a = [1.0, 2.0] }", "ocp.p_time_var.a"},
           Case{"p_time_var = { a = [1.0, nan, 2.0] }", "finite"},
           Case{"x_guess = [[0.0], [1.0]]", "2 rows, expected 4"},
           Case{"x_guess = [[0.0], [1.0], [2.0], [3.0, 4.0]]", "ocp.x_guess[3]"},
           Case{"x_guess = [[0.0], [1.0], [2.0], [3.0]]\ninitialization = \"simulation\"",
                "used only with initialization = external"},
           Case{"initialization = \"external\"", "needs x_guess"},
       }) {
    const std::string m = error_of(head + c.extra + "\n");
    EXPECT_NE(m.find(c.expected), std::string::npos) << c.extra << "\n -> " << m;
  }
}

}  // namespace
}  // namespace fesd
