// Path complementarity pairs that read the DCS algebraic variables of the RK stages (g_path_comp
// with theta_i, alpha_j, ...; OcpData::n_g_rk_comp, OcpFunctions::g_rk_comp), against an OCP whose
// optimum is derived by hand (docs/problem-files.md, "g_path_comp reading theta"):
//
//   min int_0^1.5 u^2 dt,  x' = 1, y' = u in both regions of c = x,  x(0) = -0.75, y(0) = 1,
//   0 <= y perp theta_1 >= 0 at every RK stage point,  N_stages = 3 (intervals of 0.5).
//
// x(t) = t - 0.75 whatever the control: the switch from region 2 (c < 0) to region 1 (c > 0,
// theta_1 = 1) is at t = 0.75, inside the second control interval. After it the pair forces y = 0
// at every stage point. The second interval's control u_2 is constant, and its element after the
// switch has two stage points with t in (0.75, 1] (Radau IIA, n_s = 2): y = 0 at both gives u_2 = 0
// and y(0.75) = 0, hence y(0.5) = 0; on the third interval u_3 = 0. The cheapest control that
// empties y on [0, 0.5] is u_1 = -2: J* = 0.5 * 2^2 = 2. Without the pair u = 0 and J = 0, so the
// pair is active. The tolerances (1e-6) come from the relaxation (complementarity_tol 1e-9 on
// products with y ~ 1e-9); measured errors 1e-8.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <fesd/error.hpp>
#include <fesd/ocp.hpp>
#include <fesd/problem_file.hpp>

namespace fesd {
namespace {

constexpr double kJStar = 2.0;

std::string file_text(const std::string& pair, const std::string& extra = "") {
  return R"(
[model]
x = ["x", "y"]
u = ["u"]
c = ["x"]
F = [["1", "u"],
     ["1", "u"]]
x0 = [-0.75, 1.0]
[ocp]
T = 1.5
N_stages = 3
f_q = "u^2"
)" + (pair.empty() ? std::string() : "g_path_comp = [" + pair + "]\n") +
         R"(
[discretization]
n_s = 2
N_finite_elements = 2
)" + extra;
}

/// The derived optimum: u = (-2, 0, 0), J = 2, the switch at 0.75, y = 0 at every stage point
/// after it, the complementarity residual within the tolerance.
void expect_known_optimum(const OcpResult& r, double tol) {
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.objective, kJStar, 1e-6);
  ASSERT_EQ(r.u.size(), 3u);
  EXPECT_NEAR(r.u[0][0], -2.0, 1e-6);
  EXPECT_NEAR(r.u[1][0], 0.0, 1e-6);
  EXPECT_NEAR(r.u[2][0], 0.0, 1e-6);
  ASSERT_EQ(r.switches.size(), 1u);
  EXPECT_NEAR(r.switches[0].t, 0.75, 1e-6);
  for (std::size_t i = 0; i < r.t_stage.size(); ++i) {
    if (r.t_stage[i] > 0.75 + 1e-6) {
      EXPECT_NEAR(r.x_stage[i][1], 0.0, 1e-6) << r.t_stage[i];
    }
  }
  EXPECT_NEAR(r.x_final()[1], 0.0, 1e-6);
  EXPECT_LE(r.comp_residual, tol);
}

TEST(PathCompTheta, StewartThetaPairReachesTheDerivedOptimum) {
  const OcpProblem p = parse_ocp_problem(file_text(R"(["y", "theta_1"])"), "theta_pair.toml");
  EXPECT_EQ(p.ocp.n_g_path_comp, 0);  // the pair reads theta: a stage pair
  EXPECT_EQ(p.ocp.n_g_rk_comp, 1);
  ASSERT_TRUE(p.ocp.functions);
  EXPECT_EQ(p.ocp.functions->g_rk_comp_inputs(), std::vector<int>{0});  // theta_1
  expect_known_optimum(solve(p.ocp, p.options), p.options.homotopy.complementarity_tol);
}

// The pair is what makes the optimum: without it u = 0 costs nothing.
TEST(PathCompTheta, WithoutThePairTheOptimumIsZero) {
  const OcpProblem p = parse_ocp_problem(file_text(""), "no_pair.toml");
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.objective, 0.0, 1e-8);
}

// The Heaviside step form: theta_1 is theta(alpha) = alpha_1 there, and a pair on alpha_1 itself
// is the same constraint. Both reach the same optimum.
TEST(PathCompTheta, StepFormThetaAndAlphaPairs) {
  for (const std::string pair : {R"(["y", "theta_1"])", R"(["y", "alpha_1"])"}) {
    const OcpProblem p =
        parse_ocp_problem(file_text(pair, "dcs_mode = \"step\"\n"), "theta_pair_step.toml");
    EXPECT_EQ(p.ocp.n_g_rk_comp, 1) << pair;
    SCOPED_TRACE(pair);
    expect_known_optimum(solve(p.ocp, p.options), p.options.homotopy.complementarity_tol);
  }
}

// A pair of x only stays a path pair at the element boundaries next to a stage pair.
TEST(PathCompTheta, MixedPairsAreSplit) {
  const OcpProblem p =
      parse_ocp_problem(file_text(R"(["y", "theta_1"], ["u + 5", "0.001 + x^2"])"), "mixed.toml");
  EXPECT_EQ(p.ocp.n_g_path_comp, 1);
  EXPECT_EQ(p.ocp.n_g_rk_comp, 1);
}

// The library API: OcpFunctions::g_rk_comp with y in the RkAlgebraic layout (theta_1 = y[0]).
struct ThetaPair {
  template <class T>
  T f_q(const T*, const T* u, const T*) const {
    return u[0] * u[0];
  }
  template <class T>
  void g_rk_comp(const T* x, const T*, const T*, const T* y, T* out) const {
    out[0] = x[1];
    out[1] = y[0];
  }
};

TEST(PathCompTheta, LibraryFunctionsReadTheStageVector) {
  const OcpProblem p = parse_ocp_problem(file_text(""), "no_pair.toml");
  Ocp ocp = p.ocp;
  ocp.functions = make_ocp_functions(ThetaPair{});
  ocp.n_g_rk_comp = 1;
  const RkAlgebraic layout{ocp.model.n_theta(), ocp.model.n_c()};
  EXPECT_EQ(layout.size(), 2 * 2 + 3 * 1);
  EXPECT_EQ(layout.name(0), "theta_1");
  EXPECT_EQ(layout.name(3), "lambda_2");
  EXPECT_EQ(layout.name(4), "alpha_1");
  EXPECT_EQ(layout.name(5), "lambda_n_1");
  EXPECT_EQ(layout.name(6), "lambda_p_1");
  expect_known_optimum(solve(ocp, p.options), p.options.homotopy.complementarity_tol);
}

// Reading a step-form variable in Stewart's form (or Stewart's lambda in the step form) is an input
// error naming the symbol, also when the form comes from an override.
TEST(PathCompTheta, VariableOfTheOtherFormIsRefused) {
  try {
    parse_ocp_problem(file_text(R"(["y", "alpha_1"])"), "alpha_in_stewart.toml");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("alpha_1, which the Stewart form does not have"),
              std::string::npos)
        << e.what();
  }
  OcpProblem p =
      parse_ocp_problem(file_text(R"(["y", "lambda_1"])"), "lambda_pair.toml");  // Stewart: fine
  EXPECT_THROW(apply_override(p, "dcs_mode", "step"), Error);
}

}  // namespace
}  // namespace fesd
