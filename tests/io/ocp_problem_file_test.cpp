// tests/io/ocp_problem_file_test.cpp: optimal control problem files (docs/problem-files.md,
// "Optimal control problems") and the OCP examples.
//
// Each OCP example builds the same problem as its C++ version in bench/: the same sizes, bounds,
// options, and model and cost functions that evaluate to the same numbers and derivatives. Two
// real solves (the part that takes time): the sensitivity OCP (56) file reaches the exact x0*, and
// the sliding-mode OCP (61) file gives the C++ version's objective and x(T).
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <fesd/ad.hpp>
#include <fesd/error.hpp>
#include <fesd/ocp.hpp>
#include <fesd/problem_file.hpp>

#include "../../bench/sensitivity_ocp.hpp"
#include "../../bench/sliding_ocp.hpp"

namespace fesd {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

OcpProblem load_example(const std::string& name) {
  return load_ocp_problem(std::string(FESD_SOURCE_DIR) + "/examples/" + name);
}

std::string outcome_message(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "<no exception>";
}

// ---- comparing a file's problem with the C++ one ------------------------------------------------

void expect_same_vector(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (Eigen::Index i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]) << what << "[" << i << "]";
}

/// Bounds: an empty vector means "unbounded", the same as all -inf (lower) or +inf (upper).
void expect_same_bounds(const Eigen::VectorXd& a, const Eigen::VectorXd& b, Eigen::Index n,
                        double unbounded, const char* what) {
  const auto full = [&](const Eigen::VectorXd& v) {
    return v.size() == 0 ? Eigen::VectorXd::Constant(n, unbounded) : v;
  };
  expect_same_vector(full(a), full(b), what);
}

void expect_same_options(const OcpOptions& a, const OcpOptions& b) {
  const DiscretizationOptions &d = a.discretization, &e = b.discretization;
  EXPECT_EQ(d.rk_scheme, e.rk_scheme);
  EXPECT_EQ(d.n_s, e.n_s);
  EXPECT_EQ(d.N_FE, e.N_FE);
  EXPECT_EQ(d.use_fesd, e.use_fesd);
  EXPECT_EQ(d.cross_comp, e.cross_comp);
  EXPECT_EQ(d.step_eq, e.step_eq);
  EXPECT_EQ(d.stage_lambda_sign, e.stage_lambda_sign);
  EXPECT_EQ(d.gamma_h, e.gamma_h);
  EXPECT_EQ(d.rho_h, e.rho_h);
  EXPECT_EQ(d.pin_sliding_exits, e.pin_sliding_exits);
  EXPECT_EQ(a.homotopy.mpcc_mode, b.homotopy.mpcc_mode);
  EXPECT_EQ(a.homotopy.sigma_0, b.homotopy.sigma_0);
  EXPECT_EQ(a.homotopy.homotopy_update_slope, b.homotopy.homotopy_update_slope);
  EXPECT_EQ(a.homotopy.sigma_N, b.homotopy.sigma_N);
  EXPECT_EQ(a.homotopy.complementarity_tol, b.homotopy.complementarity_tol);
  EXPECT_EQ(a.homotopy.max_homotopy_steps, b.homotopy.max_homotopy_steps);
  EXPECT_EQ(a.nlp.tol, b.nlp.tol);
  EXPECT_EQ(a.nlp.acceptable_tol, b.nlp.acceptable_tol);
  EXPECT_EQ(a.nlp.max_iter, b.nlp.max_iter);
  EXPECT_EQ(a.nlp.print_level, b.nlp.print_level);
  EXPECT_EQ(a.nlp.extra, b.nlp.extra);
  EXPECT_EQ(a.initialization, b.initialization);
  EXPECT_EQ(a.constraints_at_stages, b.constraints_at_stages);
}

/// Evaluates model and OCP functions of both problems at random points with a Jet (values and
/// first derivatives with respect to x and u): they must agree to rounding.
void expect_same_functions(const Ocp& a, const Ocp& b, int n_g_terminal) {
  using J = ad::Jet<8>;
  const Pss &ma = a.model, &mb = b.model;
  const int n_x = ma.n_x(), n_u = ma.n_u(), n_v = n_x + n_u;
  ASSERT_LE(n_v, 8);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> dist(-3.0, 3.0);
  const auto same = [&](const J& p, const J& q, const std::string& what) {
    EXPECT_NEAR(p.v, q.v, 1e-14 * (1 + std::abs(q.v))) << what;
    for (int i = 0; i < n_v; ++i)
      EXPECT_NEAR(p.d(i), q.d(i), 1e-14 * (1 + std::abs(q.d(i)))) << what << " d/dw" << i;
  };
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<J> x, u, p;
    for (int i = 0; i < n_x; ++i) x.push_back(J::variable(dist(rng), i, n_v));
    for (int i = 0; i < n_u; ++i) u.push_back(J::variable(dist(rng), n_x + i, n_v));
    for (int i = 0; i < ma.n_p(); ++i) p.push_back(J(a.p[i]));
    std::vector<J> ca(ma.n_c()), cb(mb.n_c()), fa(n_x), fb(n_x);
    ma.functions().c(x.data(), p.data(), ca.data());
    mb.functions().c(x.data(), p.data(), cb.data());
    for (int i = 0; i < ma.n_c(); ++i) same(ca[i], cb[i], "c[" + std::to_string(i) + "]");
    for (int r = 0; r < ma.n_theta(); ++r) {
      ma.functions().f(r, x.data(), u.data(), p.data(), fa.data());
      mb.functions().f(r, x.data(), u.data(), p.data(), fb.data());
      for (int i = 0; i < n_x; ++i)
        same(fa[i], fb[i], "f_" + std::to_string(r) + "[" + std::to_string(i) + "]");
    }
    const OcpFunctions &oa = *a.functions, &ob = *b.functions;
    EXPECT_EQ(oa.has_f_q(), ob.has_f_q());
    EXPECT_EQ(oa.has_f_q_T(), ob.has_f_q_T());
    same(oa.f_q(x.data(), u.data(), p.data()), ob.f_q(x.data(), u.data(), p.data()), "f_q");
    same(oa.f_q_T(x.data(), p.data()), ob.f_q_T(x.data(), p.data()), "f_q_T");
    std::vector<J> ga(n_g_terminal), gb(n_g_terminal);
    oa.g_terminal(x.data(), p.data(), ga.data());
    ob.g_terminal(x.data(), p.data(), gb.data());
    for (int i = 0; i < n_g_terminal; ++i) same(ga[i], gb[i], "g_terminal");
  }
}

void expect_same_problem(const OcpProblem& file, const Ocp& cpp, const OcpOptions& cpp_options) {
  const Ocp& o = file.ocp;
  ASSERT_EQ(o.model.n_x(), cpp.model.n_x());
  ASSERT_EQ(o.model.n_u(), cpp.model.n_u());
  ASSERT_EQ(o.model.n_p(), cpp.model.n_p());
  ASSERT_EQ(o.model.n_sys(), cpp.model.n_sys());
  ASSERT_EQ(o.model.n_theta(), cpp.model.n_theta());
  ASSERT_EQ(o.model.n_c(), cpp.model.n_c());
  for (int k = 0; k < o.model.n_sys(); ++k) EXPECT_EQ(o.model.S(k), cpp.model.S(k)) << k;
  EXPECT_FALSE(file.has_clock);
  EXPECT_EQ(o.T, cpp.T);
  EXPECT_EQ(o.N_stages, cpp.N_stages);
  EXPECT_EQ(o.N_FE, cpp.N_FE);
  const Eigen::Index n_x = cpp.model.n_x(), n_u = cpp.model.n_u();
  expect_same_vector(o.x0, cpp.x0, "x0");
  EXPECT_EQ(o.lbx0.size() > 0, cpp.lbx0.size() > 0) << "x0 free in one, fixed in the other";
  if (cpp.lbx0.size() > 0) {
    expect_same_bounds(o.lbx0, cpp.lbx0, n_x, -kInf, "lbx0");
    expect_same_bounds(o.ubx0, cpp.ubx0, n_x, kInf, "ubx0");
  }
  expect_same_bounds(o.lbx, cpp.lbx, n_x, -kInf, "lbx");
  expect_same_bounds(o.ubx, cpp.ubx, n_x, kInf, "ubx");
  expect_same_bounds(o.lbu, cpp.lbu, n_u, -kInf, "lbu");
  expect_same_bounds(o.ubu, cpp.ubu, n_u, kInf, "ubu");
  expect_same_bounds(o.u_guess, cpp.u_guess, n_u, 0.0, "u_guess");
  EXPECT_EQ(o.n_g_path, cpp.n_g_path);
  EXPECT_EQ(o.n_g_terminal, cpp.n_g_terminal);
  expect_same_bounds(o.lbg_terminal, cpp.lbg_terminal, cpp.n_g_terminal, -kInf, "lbg_terminal");
  expect_same_bounds(o.ubg_terminal, cpp.ubg_terminal, cpp.n_g_terminal, kInf, "ubg_terminal");
  EXPECT_EQ(o.terminal_constraint, cpp.terminal_constraint);
  if (cpp.terminal_constraint == TerminalConstraint::L1) {
    EXPECT_EQ(o.rho_terminal, cpp.rho_terminal);
  }
  expect_same_options(file.options, cpp_options);
  expect_same_functions(o, cpp, cpp.n_g_terminal);
}

// ---- the examples
// ---------------------------------------------------------------------------------

TEST(OcpExamples, SlidingModeIsTheCppProblem) {
  expect_same_problem(load_example("ocp_sliding_mode.toml"), fesd_bench::sliding_ocp_paper(),
                      fesd_bench::sliding_options());
}

TEST(OcpExamples, SlidingModeNosnocIsTheCppProblem) {
  expect_same_problem(load_example("nosnoc/ocp_sliding_mode_nosnoc.toml"),
                      fesd_bench::sliding_ocp_nosnoc(), fesd_bench::sliding_options());
}

TEST(OcpExamples, SensitivityIsTheCppProblem) {
  const OcpProblem q = load_example("ocp_sensitivity.toml");
  expect_same_problem(q, fesd_bench::sensitivity_ocp(-2.0),
                      fesd_bench::sensitivity_options(true, true, MpccMode::ScholtesEq));
}

// REAL SOLVE (about 1 s): the file reaches the exact minimizer of (56) from the guess x0 = -2.
TEST(OcpExamples, SensitivitySolvesToTheExactMinimizer) {
  const OcpProblem q = load_example("ocp_sensitivity.toml");
  const OcpResult r = solve(q.ocp, q.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.x0()[0], fesd_bench::kSensitivityX0Star, 1e-6);
  EXPECT_NEAR(r.objective, fesd_bench::kSensitivityVStar, 1e-6);
}

// REAL SOLVES (two of about 4 s): the file and the C++ version of (61) give the same solution.
TEST(OcpExamples, SlidingModeSolvesLikeTheCppProblem) {
  const OcpProblem q = load_example("ocp_sliding_mode.toml");
  const OcpResult file = solve(q.ocp, q.options);
  const OcpResult cpp = solve(fesd_bench::sliding_ocp_paper(), fesd_bench::sliding_options());
  ASSERT_EQ(cpp.status, Status::Success) << cpp.message;
  ASSERT_EQ(file.status, Status::Success) << file.message;
  EXPECT_NEAR(file.objective, cpp.objective, 1e-6);
  ASSERT_EQ(file.x_final().size(), 4);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(file.x_final()[i], cpp.x_final()[i], 1e-6) << i;
  EXPECT_EQ(file.switches.size(), cpp.switches.size());
}

// ---- the format ---------------------------------------------------------------------------------

constexpr const char* kSmall = R"toml(
[model]
x = ["x1", "x2"]
u = ["u1"]
p = { a = 2.0 }
c = ["x1"]
F = [["u1", "x1"], ["-1", "a"]]
x0 = [0.5, 0.0]
[ocp]
T = 2.0
)toml";

TEST(OcpProblemFile, Defaults) {
  const OcpProblem q = parse_ocp_problem(kSmall, "dir/small.toml");
  EXPECT_EQ(q.name, "small");
  EXPECT_EQ(q.source, "dir/small.toml");
  EXPECT_FALSE(q.has_clock);
  EXPECT_EQ(q.ocp.T, 2.0);
  EXPECT_EQ(q.ocp.N_stages, 1);
  EXPECT_TRUE(q.ocp.N_FE.empty());
  EXPECT_EQ(q.ocp.lbx.size(), 0);
  EXPECT_EQ(q.ocp.lbu.size(), 0);
  EXPECT_EQ(q.ocp.lbx0.size(), 0);  // x0 fixed
  EXPECT_EQ(q.ocp.u_guess.size(), 0);
  EXPECT_EQ(q.ocp.n_g_path, 0);
  EXPECT_EQ(q.ocp.n_g_terminal, 0);
  EXPECT_EQ(q.ocp.terminal_constraint, TerminalConstraint::Hard);
  expect_same_vector(q.ocp.p, Eigen::VectorXd::Constant(1, 2.0), "p");
  ASSERT_NE(q.ocp.functions, nullptr);
  EXPECT_FALSE(q.ocp.functions->has_f_q());
  EXPECT_FALSE(q.ocp.functions->has_f_q_T());
  // The OCP defaults, not the integrator's: step equilibration l2_relaxed.
  expect_same_options(q.options, OcpOptions{});
  EXPECT_EQ(q.options.discretization.step_eq, StepEq::L2Relaxed);
}

TEST(OcpProblemFile, EveryKeyIsRead) {
  const std::string text = std::string(kSmall) + R"toml(
N_stages = 3
f_q = "u1^2 + a*x2^2"
f_q_T = "x1^2"
g_path = ["x1 + x2", "u1 - x1"]
lbg_path = [-1, -inf]
ubg_path = [1, 0.5]
g_terminal = ["x2"]
lbg_terminal = [0.25]
ubg_terminal = [0.75]
lbx = [-5, -inf]
ubx = [5, inf]
lbu = [-1]
ubu = [1]
u_guess = [0.5]
lbx0 = [0, -1]
ubx0 = [1, 1]
relax_terminal_constraint = "ell_1"
rho_terminal = 50
initialization = "simulation"
constraints_at_stages = true
[discretization]
N_finite_elements = [2, 3, 4]
step_equilibration = "heuristic_mean"
n_s = 3
[homotopy]
mpcc_mode = "fischer_burmeister"
[ipopt]
max_iter = 77
mu_strategy = "monotone"
)toml";
  const OcpProblem q = parse_ocp_problem(text, "all.toml");
  const Ocp& o = q.ocp;
  EXPECT_EQ(o.N_stages, 3);
  EXPECT_EQ(o.N_FE, (std::vector<int>{2, 3, 4}));
  EXPECT_EQ(o.n_g_path, 2);
  expect_same_vector(o.lbg_path, Eigen::Vector2d(-1, -kInf), "lbg_path");
  expect_same_vector(o.ubg_path, Eigen::Vector2d(1, 0.5), "ubg_path");
  EXPECT_EQ(o.n_g_terminal, 1);
  expect_same_vector(o.lbg_terminal, Eigen::VectorXd::Constant(1, 0.25), "lbg_terminal");
  expect_same_vector(o.ubg_terminal, Eigen::VectorXd::Constant(1, 0.75), "ubg_terminal");
  expect_same_vector(o.lbx, Eigen::Vector2d(-5, -kInf), "lbx");
  expect_same_vector(o.ubx, Eigen::Vector2d(5, kInf), "ubx");
  expect_same_vector(o.lbu, Eigen::VectorXd::Constant(1, -1), "lbu");
  expect_same_vector(o.ubu, Eigen::VectorXd::Constant(1, 1), "ubu");
  expect_same_vector(o.u_guess, Eigen::VectorXd::Constant(1, 0.5), "u_guess");
  expect_same_vector(o.lbx0, Eigen::Vector2d(0, -1), "lbx0");
  expect_same_vector(o.ubx0, Eigen::Vector2d(1, 1), "ubx0");
  EXPECT_EQ(o.terminal_constraint, TerminalConstraint::L1);
  EXPECT_EQ(o.rho_terminal, 50);
  EXPECT_EQ(q.options.initialization, OcpInitialization::Simulation);
  EXPECT_TRUE(q.options.constraints_at_stages);
  EXPECT_EQ(q.options.discretization.step_eq, StepEq::HeuristicMean);
  EXPECT_EQ(q.options.discretization.n_s, 3);
  EXPECT_EQ(q.options.homotopy.mpcc_mode, MpccMode::FischerBurmeister);
  EXPECT_EQ(q.options.nlp.max_iter, 77);
  EXPECT_EQ(q.options.nlp.extra,
            (std::vector<std::pair<std::string, std::string>>{{"mu_strategy", "monotone"}}));

  // The functions, at x = (1, 2), u = 0.5, p = a = 2.
  const OcpFunctions& f = *o.functions;
  const double x[2] = {1.0, 2.0}, u[1] = {0.5}, p[1] = {2.0};
  EXPECT_EQ(f.f_q(x, u, p), 0.25 + 2.0 * 4.0);
  EXPECT_EQ(f.f_q_T(x, p), 1.0);
  double g[2];
  f.g_path(x, u, p, g);
  EXPECT_EQ(g[0], 3.0);
  EXPECT_EQ(g[1], -0.5);
  f.g_terminal(x, p, g);
  EXPECT_EQ(g[0], 2.0);
}

TEST(OcpProblemFile, ConstraintBoundDefaults) {
  // Without bounds: g_path <= 0 and g_terminal = 0 (nosnoc's convention); one bound alone leaves
  // the other side open.
  const OcpProblem none = parse_ocp_problem(
      std::string(kSmall) + "g_path = [\"x1\"]\ng_terminal = [\"x2\"]\n", "none.toml");
  expect_same_vector(none.ocp.lbg_path, Eigen::VectorXd::Constant(1, -kInf), "lbg_path");
  expect_same_vector(none.ocp.ubg_path, Eigen::VectorXd::Constant(1, 0.0), "ubg_path");
  expect_same_vector(none.ocp.lbg_terminal, Eigen::VectorXd::Constant(1, 0.0), "lbg_terminal");
  expect_same_vector(none.ocp.ubg_terminal, Eigen::VectorXd::Constant(1, 0.0), "ubg_terminal");
  const OcpProblem one = parse_ocp_problem(
      std::string(kSmall) +
          "g_path = [\"x1\"]\nlbg_path = [1]\ng_terminal = [\"x2\"]\nubg_terminal = [3]\n"
          "lbx0 = [0, 0]\n",
      "one.toml");
  expect_same_vector(one.ocp.ubg_path, Eigen::VectorXd::Constant(1, kInf), "ubg_path");
  expect_same_vector(one.ocp.lbg_terminal, Eigen::VectorXd::Constant(1, -kInf), "lbg_terminal");
  expect_same_vector(one.ocp.ubx0, Eigen::Vector2d(kInf, kInf), "ubx0");
}

TEST(OcpProblemFile, TimeInACostAddsTheClock) {
  // The model does not read t, the Lagrange term does: the clock state is appended all the same,
  // unbounded, starting (fixed) at 0.
  const OcpProblem q =
      parse_ocp_problem(std::string(kSmall) +
                            "f_q = \"t*x1\"\nlbx = [-1, -1]\nubx = [1, 1]\nlbx0 = [0, 0]\n"
                            "ubx0 = [1, 1]\n",
                        "clock.toml");
  EXPECT_TRUE(q.has_clock);
  ASSERT_EQ(q.ocp.model.n_x(), 3);
  EXPECT_EQ(q.ocp.model.state_names.back(), "t");
  expect_same_vector(q.ocp.x0, Eigen::Vector3d(0.5, 0, 0), "x0");
  expect_same_vector(q.ocp.lbx, Eigen::Vector3d(-1, -1, -kInf), "lbx");
  expect_same_vector(q.ocp.ubx, Eigen::Vector3d(1, 1, kInf), "ubx");
  expect_same_vector(q.ocp.lbx0, Eigen::Vector3d(0, 0, 0), "lbx0");
  expect_same_vector(q.ocp.ubx0, Eigen::Vector3d(1, 1, 0), "ubx0");
  const double x[3] = {2.0, 0.0, 0.75}, u[1] = {0.0}, p[1] = {2.0};
  EXPECT_EQ(q.ocp.functions->f_q(x, u, p), 0.75 * 2.0);
  double f[3];
  q.ocp.model.functions().f(0, x, u, p, f);
  EXPECT_EQ(f[2], 1.0);  // t' = 1
}

TEST(OcpProblemFile, FunctionsEvaluateWithEveryScalarType) {
  const OcpProblem q = parse_ocp_problem(
      std::string(kSmall) + "f_q = \"a*x1*u1 + x2^2\"\ng_path = [\"x1*x2\"]\n", "types.toml");
  const OcpFunctions& f = *q.ocp.functions;
  {
    using J = ad::Jet<32>;
    const J x[2] = {J::variable(1.0, 0, 3), J::variable(3.0, 1, 3)};
    const J u[1] = {J::variable(0.5, 2, 3)};
    const J p[1] = {J(2.0)};
    const J v = f.f_q(x, u, p);
    EXPECT_EQ(v.v, 2.0 * 0.5 + 9.0);
    EXPECT_EQ(v.d(0), 2.0 * 0.5);  // a u1
    EXPECT_EQ(v.d(1), 6.0);        // 2 x2
    EXPECT_EQ(v.d(2), 2.0);        // a x1
  }
  {
    const ad::Pattern x[2] = {ad::Pattern::variable(1.0, 0), ad::Pattern::variable(3.0, 1)};
    const ad::Pattern u[1] = {ad::Pattern::variable(0.5, 2)};
    const ad::Pattern p[1] = {ad::Pattern(2.0)};
    const ad::Pattern v = f.f_q(x, u, p);
    EXPECT_EQ(v.dep, (std::vector<int>{0, 1, 2}));
    ad::Pattern g[1];
    f.g_path(x, u, p, g);
    EXPECT_EQ(g[0].dep, (std::vector<int>{0, 1}));
  }
}

TEST(OcpProblemFile, KindOfFile) {
  EXPECT_EQ(problem_file_kind(std::string(FESD_SOURCE_DIR) + "/examples/ocp_sensitivity.toml"),
            ProblemKind::Ocp);
  EXPECT_EQ(problem_file_kind(std::string(FESD_SOURCE_DIR) + "/examples/oscillator.toml"),
            ProblemKind::Simulation);
  EXPECT_THROW(problem_file_kind("/nonexistent/x.toml"), ProblemFileError);
}

// ---- overrides ----------------------------------------------------------------------------------

TEST(OcpProblemFileOverride, SetsOcpAndSolverKeys) {
  OcpProblem q = parse_ocp_problem(std::string(kSmall) + "g_terminal = [\"x1\"]\n", "o.toml");
  apply_override(q, "T", "3.5");
  apply_override(q, "ocp.N_stages", "4");
  apply_override(q, "initialization", "simulation");
  apply_override(q, "relax_terminal_constraint", "ell_1");
  apply_override(q, "rho_terminal", "20");
  apply_override(q, "constraints_at_stages", "1");
  apply_override(q, "n_s", "3");
  apply_override(q, "step_equilibration", "eta");
  apply_override(q, "mpcc_mode", "scholtes_eq");
  apply_override(q, "ipopt.mu_strategy", "monotone");
  EXPECT_EQ(q.ocp.T, 3.5);
  EXPECT_EQ(q.ocp.N_stages, 4);
  EXPECT_EQ(q.options.initialization, OcpInitialization::Simulation);
  EXPECT_EQ(q.ocp.terminal_constraint, TerminalConstraint::L1);
  EXPECT_EQ(q.ocp.rho_terminal, 20);
  EXPECT_TRUE(q.options.constraints_at_stages);
  EXPECT_EQ(q.options.discretization.n_s, 3);
  EXPECT_EQ(q.options.discretization.step_eq, StepEq::Eta);
  EXPECT_EQ(q.options.homotopy.mpcc_mode, MpccMode::ScholtesEq);
  EXPECT_EQ(q.options.nlp.extra,
            (std::vector<std::pair<std::string, std::string>>{{"mu_strategy", "monotone"}}));
}

TEST(OcpProblemFileOverride, NumberOfElementsReplacesAList) {
  OcpProblem q = parse_ocp_problem(
      std::string(kSmall) + "N_stages = 2\n[discretization]\nN_finite_elements = [3, 4]\n",
      "list.toml");
  EXPECT_EQ(q.ocp.N_FE, (std::vector<int>{3, 4}));
  // More control intervals than list entries: refused, nothing changed.
  EXPECT_NE(outcome_message([&] {
              apply_override(q, "N_stages", "3");
            }).find("--N_stages = 3: discretization.N_finite_elements = [3, 4]: wrong length"),
            std::string::npos);
  EXPECT_EQ(q.ocp.N_stages, 2);
  apply_override(q, "N_FE", "5");
  EXPECT_TRUE(q.ocp.N_FE.empty());
  EXPECT_EQ(q.options.discretization.N_FE, 5);
  apply_override(q, "N_stages", "3");
  EXPECT_EQ(q.ocp.N_stages, 3);
}

TEST(OcpProblemFileOverride, BadOverridesThrowAndChangeNothing) {
  OcpProblem q = parse_ocp_problem(kSmall, "bad.toml");
  const auto expect_message = [&](const char* key, const char* value, const std::string& part) {
    const std::string m = outcome_message([&] { apply_override(q, key, value); });
    EXPECT_NE(m.find(part), std::string::npos) << "message:  " << m << "\nexpected: " << part;
  };
  expect_message("T", "-1", "--T = -1: must be > 0");
  expect_message("T", "inf", "--T = inf: must be finite");
  expect_message("N_stage", "2",
                 "--N_stage = 2: unknown option 'N_stage' (did you mean 'N_stages'");
  expect_message("T_sim", "2", "--T_sim = 2: unknown option 'T_sim' (did you mean 'T'?)");
  expect_message("N_sim", "2", "--N_sim = 2: unknown option 'N_sim' (did you mean 'N_stages'?)");
  expect_message("u", "1", "--u = 1: unknown option 'u' (did you mean 'u_guess'?)");
  expect_message("lbx", "1",
                 "--lbx = 1: unknown option 'lbx' (expressions and bounds can only be "
                 "set in the file)");
  expect_message("u_guess", "1, 2",
                 "--u_guess = 1, 2: wrong length (expected 1 number, one per control in model.u, "
                 "got 2)");
  expect_message("u_guess", "nan", "--u_guess = nan: ocp.u_guess[0] = nan: must be finite");
  expect_message("x0", "1",
                 "--x0 = 1: wrong length (expected 2 numbers, one per state in "
                 "model.x, got 1)");
  expect_message("p", "zz=1", "--p zz=1: unknown parameter 'zz' (parameters in model.p: a)");
  expect_message("a", "1",
                 "--a = 1: unknown option 'a' ('a' is a parameter of model.p: write "
                 "--p a=1)");
  expect_message("initialization", "zero", "unknown name (expected one of constant, simulation");
  expect_message("relax_terminal_constraint", "ell_1", "there are no terminal constraints");
  expect_message("simulation.T_sim", "1", "--simulation.T_sim = 1: unknown table 'simulation'");
  expect_message("n_s", "0", "--n_s = 0: must be in 1..9 for radau_iia");
  const OcpProblem fresh = parse_ocp_problem(kSmall, "bad.toml");
  EXPECT_EQ(q.ocp.T, fresh.ocp.T);
  EXPECT_EQ(q.ocp.N_stages, fresh.ocp.N_stages);
  EXPECT_EQ(q.ocp.terminal_constraint, fresh.ocp.terminal_constraint);
  EXPECT_EQ(q.ocp.x0, fresh.ocp.x0);
  EXPECT_EQ(q.ocp.p, fresh.ocp.p);
  EXPECT_EQ(q.ocp.u_guess, fresh.ocp.u_guess);
  expect_same_options(q.options, fresh.options);
}

// [model] x0 and p, [ocp] u_guess (issue 13, 3), checked with the file's rules (bounds).
TEST(OcpProblemFileOverride, InitialStateParametersAndControlGuess) {
  OcpProblem q = parse_ocp_problem(std::string(kSmall) + "lbu = [-1]\nubu = [1]\n", "g.toml");
  apply_override(q, "x0", "1.5, -2");
  apply_override(q, "p", "a=-4");
  apply_override(q, "ocp.u_guess", "0.25");
  EXPECT_EQ(q.ocp.x0, (Eigen::VectorXd(2) << 1.5, -2.0).finished());
  EXPECT_EQ(q.ocp.p, (Eigen::VectorXd(1) << -4.0).finished());
  EXPECT_EQ(q.ocp.model.p_default, (Eigen::VectorXd(1) << -4.0).finished());
  EXPECT_EQ(q.ocp.u_guess, (Eigen::VectorXd(1) << 0.25).finished());
  const std::string m = outcome_message([&] { apply_override(q, "u_guess", "3"); });
  EXPECT_NE(m.find("--u_guess = 3: ocp.u_guess[0]: 3 is outside [lbu, ubu] = [-1, 1]"),
            std::string::npos)
      << m;
  EXPECT_EQ(q.ocp.u_guess, (Eigen::VectorXd(1) << 0.25).finished());
}

}  // namespace
}  // namespace fesd
