// tests/io/problem_file_test.cpp: problem files (docs/problem-files.md) and the paper's examples.
//
// Every example in examples/ loads with the dimensions, names and options written in it, and its
// parsed functions evaluate to hand-computed values: g = -S c (13) for c-form models, the region
// vector fields f_i as printed in the paper. No integration happens here.
#include <cmath>
#include <numbers>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <fesd/ad.hpp>
#include <fesd/error.hpp>
#include <fesd/problem_file.hpp>

namespace fesd {
namespace {

constexpr double kOmega = 2.0 * std::numbers::pi;
// Expressions are evaluated by the same floating-point operations a hand computation does, up to
// association order: a few ulps.
constexpr double kTol = 1e-14;

SimulationProblem load_example(const std::string& name) {
  return load_simulation_problem(std::string(FESD_SOURCE_DIR) + "/examples/" + name);
}

std::vector<double> eval_c(const Pss& m, const Eigen::VectorXd& x, const Eigen::VectorXd& p) {
  std::vector<double> c(static_cast<std::size_t>(m.n_c()));
  m.functions().c(x.data(), p.data(), c.data());
  return c;
}

std::vector<double> eval_g_direct(const Pss& m, const Eigen::VectorXd& x,
                                  const Eigen::VectorXd& p) {
  std::vector<double> g(static_cast<std::size_t>(m.n_g()));
  m.functions().g(x.data(), p.data(), g.data());
  return g;
}

Eigen::VectorXd eval_f(const Pss& m, int region, const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                       const Eigen::VectorXd& p) {
  Eigen::VectorXd f(m.n_x());
  m.functions().f(region, x.data(), u.data(), p.data(), f.data());
  return f;
}

/// g = -S c for a single c-form subsystem, eq. (13).
Eigen::VectorXd g_of_c(const Pss& m, const std::vector<double>& c) {
  const Eigen::Map<const Eigen::VectorXd> cv(c.data(), static_cast<Eigen::Index>(c.size()));
  return -m.S(0) * cv;
}

std::string fmt_name(int i) {
  return "\"q" + std::to_string(i) + "\"";
}

/// Input i of n for every scalar type: a variable with gradient e_i (and, for Hyper, the second
/// direction e_1, i.e. q2).
template <class T>
T make_input(double v, int i, int n) {
  if constexpr (std::is_same_v<T, double>) {
    return v;
  } else if constexpr (std::is_same_v<T, ad::Pattern>) {
    return ad::Pattern::variable(v, i);
  } else if constexpr (std::is_same_v<T, ad::Jet<128>>) {
    return ad::Jet<128>::variable(v, i, n);
  } else {
    return T(ad::Jet<128>::variable(v, i, n), ad::Jet<128>(i == 1 ? 1.0 : 0.0));
  }
}

void expect_vector_near(const Eigen::VectorXd& got, const std::vector<double>& want) {
  ASSERT_EQ(got.size(), static_cast<Eigen::Index>(want.size()));
  for (std::size_t i = 0; i < want.size(); ++i)
    EXPECT_NEAR(got[static_cast<Eigen::Index>(i)], want[i], kTol) << "component " << i;
}

// ---- the paper's examples -------------------------------------------------------------------

TEST(ProblemFileExamples, OscillatorAsPrinted) {
  const SimulationProblem q = load_example("oscillator.toml");
  EXPECT_EQ(q.name, "oscillator");
  EXPECT_FALSE(q.description.empty());
  const Pss& m = q.model;
  EXPECT_EQ(m.n_x(), 2);
  EXPECT_EQ(m.n_u(), 0);
  EXPECT_EQ(m.n_p(), 1);
  EXPECT_EQ(m.n_sys(), 1);
  EXPECT_EQ(m.n_c(), 1);
  EXPECT_EQ(m.n_g(), 0);
  EXPECT_EQ(m.n_theta(), 2);
  EXPECT_EQ(m.state_names, (std::vector<std::string>{"x1", "x2"}));
  EXPECT_EQ(m.parameter_names, (std::vector<std::string>{"omega"}));
  EXPECT_TRUE(m.control_names.empty());
  ASSERT_EQ(m.S(0).rows(), 2);
  EXPECT_EQ(m.S(0)(0, 0), -1.0);  // region 0: c < 0, inside the circle (A1)
  EXPECT_EQ(m.S(0)(1, 0), 1.0);   // region 1: c > 0, outside (A2)
  ASSERT_EQ(q.p.size(), 1);
  EXPECT_EQ(q.p[0], kOmega);
  EXPECT_EQ(m.p_default, q.p);
  expect_vector_near(q.x0, {std::exp(-1.0), 0.0});
  EXPECT_EQ(q.T_sim, std::numbers::pi / 2);
  EXPECT_EQ(q.N_sim, 100);
  EXPECT_FALSE(q.has_clock);
  EXPECT_EQ(q.u.size(), 0);
  const DiscretizationOptions& d = q.options.discretization;
  EXPECT_EQ(d.rk_scheme, RkScheme::RadauIIA);
  EXPECT_EQ(d.n_s, 3);
  EXPECT_EQ(d.N_FE, 2);
  EXPECT_TRUE(d.use_fesd);
  EXPECT_TRUE(validate(q.options).empty());

  // c, g = -S c = (c, -c) as in the paper (Sect. 4.4), and f_i = A_i x.
  const Eigen::Vector2d x(0.5, -2.0);
  const Eigen::VectorXd u;
  const std::vector<double> c = eval_c(m, x, q.p);
  ASSERT_EQ(c.size(), 1U);
  EXPECT_NEAR(c[0], 0.25 + 4.0 - 1.0, kTol);
  expect_vector_near(g_of_c(m, c), {3.25, -3.25});
  expect_vector_near(eval_f(m, 0, x, u, q.p), {0.5 + kOmega * -2.0, -kOmega * 0.5 - 2.0});
  expect_vector_near(eval_f(m, 1, x, u, q.p), {0.5 - kOmega * -2.0, kOmega * 0.5 - 2.0});
}

TEST(ProblemFileExamples, OscillatorDerivativesAreExact) {
  // The same functions with a Jet: the Jacobian of f_0 is A1, of f_1 is A2, of c is 2 x^T.
  const SimulationProblem q = load_example("oscillator.toml");
  using J = ad::Jet<8>;
  const J x[2] = {J::variable(0.5, 0, 2), J::variable(-2.0, 1, 2)};
  const J p[1] = {J(kOmega)};
  J f[2];
  q.model.functions().f(0, x, nullptr, p, f);
  EXPECT_NEAR(f[0].d(0), 1.0, kTol);
  EXPECT_NEAR(f[0].d(1), kOmega, kTol);
  EXPECT_NEAR(f[1].d(0), -kOmega, kTol);
  EXPECT_NEAR(f[1].d(1), 1.0, kTol);
  J c[1];
  q.model.functions().c(x, p, c);
  EXPECT_NEAR(c[0].d(0), 1.0, kTol);
  EXPECT_NEAR(c[0].d(1), -4.0, kTol);
}

struct SignExample {
  const char* file;
  double x0, T_sim;
  double f_negative, f_positive;  // the vector field for x < 0 (region 0) and x > 0 (region 1)
};

class ScalarExamples : public ::testing::TestWithParam<SignExample> {};

TEST_P(ScalarExamples, LoadAsWritten) {
  const SignExample& e = GetParam();
  const SimulationProblem q = load_example(e.file);
  const Pss& m = q.model;
  EXPECT_EQ(m.n_x(), 1);
  EXPECT_EQ(m.n_theta(), 2);
  EXPECT_EQ(m.state_names, std::vector<std::string>{"x"});
  EXPECT_FALSE(q.has_clock);
  expect_vector_near(q.x0, {e.x0});
  EXPECT_EQ(q.T_sim, e.T_sim);
  EXPECT_EQ(q.N_sim, 10);
  EXPECT_EQ(q.options.discretization.rk_scheme, RkScheme::RadauIIA);
  EXPECT_EQ(q.options.discretization.n_s, 2);
  EXPECT_TRUE(validate(q.options).empty());

  // c(x) = x, S = [[-1], [1]], g = -S c = (x, -x) (Example 2 of the paper).
  const Eigen::VectorXd p, u;
  for (double xv : {-0.7, 0.4}) {
    const Eigen::VectorXd x = Eigen::VectorXd::Constant(1, xv);
    const std::vector<double> c = eval_c(m, x, p);
    ASSERT_EQ(c.size(), 1U);
    EXPECT_EQ(c[0], xv);
    expect_vector_near(g_of_c(m, c), {xv, -xv});
    expect_vector_near(eval_f(m, 0, x, u, p), {e.f_negative});
    expect_vector_near(eval_f(m, 1, x, u, p), {e.f_positive});
  }
}

INSTANTIATE_TEST_SUITE_P(
    Example3, ScalarExamples,
    ::testing::Values(SignExample{"crossing.toml", -1.0, 2.0, 3.0, 1.0},      // 2 - sign(x)
                      SignExample{"sliding.toml", 0.5, 1.0, 1.0, -1.0},       // -sign(x)
                      SignExample{"spontaneous.toml", 0.0, 1.0, -1.0, 1.0}),  // sign(x)
    [](const ::testing::TestParamInfo<SignExample>& param_info) {
      std::string n = param_info.param.file;
      return n.substr(0, n.find('.'));
    });

TEST(ProblemFileExamples, LeavingSlidingAppendsClock) {
  const SimulationProblem q = load_example("leaving_sliding.toml");
  const Pss& m = q.model;
  EXPECT_TRUE(q.has_clock);
  EXPECT_EQ(m.n_x(), 2);
  EXPECT_EQ(m.state_names, (std::vector<std::string>{"x", "t"}));
  expect_vector_near(q.x0, {0.0, 0.0});
  EXPECT_EQ(q.T_sim, 2.0);
  // x' in -sign(x) + t, t' = 1 in both regions; c reads only x.
  const Eigen::Vector2d x(0.3, 0.7);
  const Eigen::VectorXd p, u;
  EXPECT_EQ(eval_c(m, x, p), std::vector<double>{0.3});
  expect_vector_near(eval_f(m, 0, x, u, p), {1.0 + 0.7, 1.0});
  expect_vector_near(eval_f(m, 1, x, u, p), {-1.0 + 0.7, 1.0});
}

// ---- format features ------------------------------------------------------------------------

constexpr const char* kMinimal = R"toml(
[model]
x = ["x"]
c = ["x"]
F = [["-1"], ["1"]]
x0 = [0.25]
[simulation]
T_sim = 1
)toml";

TEST(ProblemFile, DefaultsWhenTablesAreAbsent) {
  const SimulationProblem q = parse_simulation_problem(kMinimal, "dir/minimal.toml");
  EXPECT_EQ(q.name, "minimal");  // the file stem
  EXPECT_EQ(q.source, "dir/minimal.toml");
  EXPECT_TRUE(q.description.empty());
  EXPECT_EQ(q.N_sim, 0);      // chosen by simulate() for tol_sim
  EXPECT_EQ(q.tol_sim, 0.0);  // the default kDefaultTolSim applies
  EXPECT_EQ(q.N_sim_max, 1000);
  EXPECT_EQ(q.T_sim, 1.0);
  EXPECT_EQ(q.u.size(), 0);
  EXPECT_EQ(q.p.size(), 0);
  EXPECT_FALSE(q.has_clock);
  // The default sign matrix for n_c = 1: [[1], [-1]] (fesd::all_sign_rows).
  EXPECT_EQ(q.model.S(0), all_sign_rows(1));

  const IntegratorOptions def;
  const IntegratorOptions& o = q.options;
  EXPECT_EQ(o.discretization.rk_scheme, def.discretization.rk_scheme);
  EXPECT_EQ(o.discretization.n_s, def.discretization.n_s);
  EXPECT_EQ(o.discretization.N_FE, def.discretization.N_FE);
  EXPECT_EQ(o.discretization.use_fesd, def.discretization.use_fesd);
  EXPECT_EQ(o.discretization.cross_comp, def.discretization.cross_comp);
  EXPECT_EQ(o.discretization.step_eq, def.discretization.step_eq);
  EXPECT_EQ(o.discretization.gamma_h, def.discretization.gamma_h);
  EXPECT_EQ(o.discretization.rho_h, def.discretization.rho_h);
  EXPECT_EQ(o.discretization.pin_sliding_exits, def.discretization.pin_sliding_exits);
  EXPECT_EQ(o.homotopy.sigma_0, def.homotopy.sigma_0);
  EXPECT_EQ(o.homotopy.homotopy_update_slope, def.homotopy.homotopy_update_slope);
  EXPECT_EQ(o.homotopy.sigma_N, def.homotopy.sigma_N);
  EXPECT_EQ(o.homotopy.complementarity_tol, def.homotopy.complementarity_tol);
  EXPECT_EQ(o.homotopy.max_homotopy_steps, def.homotopy.max_homotopy_steps);
  EXPECT_EQ(o.nlp.tol, def.nlp.tol);
  EXPECT_EQ(o.nlp.acceptable_tol, def.nlp.acceptable_tol);
  EXPECT_EQ(o.nlp.max_iter, def.nlp.max_iter);
  EXPECT_EQ(o.nlp.print_level, def.nlp.print_level);
  EXPECT_TRUE(o.nlp.extra.empty());
}

TEST(ProblemFile, EveryOptionKeyIsRead) {
  const SimulationProblem q = parse_simulation_problem(R"toml(
name = "all options"
description = "every key"
[model]
x = ["x"]
g = ["x", "-x"]
F = [[3], [1.5]]     # numbers are expressions too
x0 = [-1]            # integers are numbers
[simulation]
T_sim = 2
N_sim = 7
t0 = 3.5
[discretization]
rk_scheme = "GAUSS_LEGENDRE"   # nosnoc's spelling
n_s = 4
N_finite_elements = 5
use_fesd = false
cross_comp_mode = "neighbor"
step_equilibration = "eta_tanh"
gamma_h = 0.5
rho_h = 10
pin_sliding_exits = false
[homotopy]
sigma_0 = 2.0
homotopy_update_slope = 0.2
sigma_N = 1e-10
complementarity_tol = 1e-8
N_homotopy = 9
[ipopt]
tol = 1e-10
acceptable_tol = 1e-5
max_iter = 77
print_level = 5
mu_strategy = "monotone"
bound_push = 1e-9
warm_start_init_point = true
max_soc = 2
)toml",
                                                       "all.toml");
  EXPECT_EQ(q.name, "all options");
  EXPECT_EQ(q.description, "every key");
  EXPECT_EQ(q.model.n_g(), 2);
  EXPECT_EQ(q.model.n_c(), 0);
  EXPECT_EQ(q.T_sim, 2.0);
  EXPECT_EQ(q.N_sim, 7);
  EXPECT_FALSE(q.has_clock);  // t0 only matters with a clock
  expect_vector_near(q.x0, {-1.0});
  const DiscretizationOptions& d = q.options.discretization;
  EXPECT_EQ(d.rk_scheme, RkScheme::GaussLegendre);
  EXPECT_EQ(d.n_s, 4);
  EXPECT_EQ(d.N_FE, 5);
  EXPECT_FALSE(d.use_fesd);
  EXPECT_EQ(d.cross_comp, CrossComp::Neighbor);
  EXPECT_EQ(d.step_eq, StepEq::EtaTanh);
  EXPECT_EQ(d.gamma_h, 0.5);
  EXPECT_EQ(d.rho_h, 10.0);
  EXPECT_FALSE(d.pin_sliding_exits);
  const HomotopyOptions& h = q.options.homotopy;
  EXPECT_EQ(h.sigma_0, 2.0);
  EXPECT_EQ(h.homotopy_update_slope, 0.2);
  EXPECT_EQ(h.sigma_N, 1e-10);
  EXPECT_EQ(h.complementarity_tol, 1e-8);
  EXPECT_EQ(h.max_homotopy_steps, 9);
  const NlpOptions& n = q.options.nlp;
  EXPECT_EQ(n.tol, 1e-10);
  EXPECT_EQ(n.acceptable_tol, 1e-5);
  EXPECT_EQ(n.max_iter, 77);
  EXPECT_EQ(n.print_level, 5);
  // Other IPOPT options pass through as strings, in the order written.
  using Extra = std::vector<std::pair<std::string, std::string>>;
  EXPECT_EQ(n.extra, (Extra{{"mu_strategy", "monotone"},
                            {"bound_push", "1e-09"},
                            {"warm_start_init_point", "yes"},
                            {"max_soc", "2"}}));

  // g-form: g is returned as written; the numeric F entries are constant fields.
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(1, 0.3), p, u;
  const std::vector<double> g = eval_g_direct(q.model, x, p);
  ASSERT_EQ(g.size(), 2U);
  EXPECT_EQ(g[0], 0.3);
  EXPECT_EQ(g[1], -0.3);
  expect_vector_near(eval_f(q.model, 0, x, u, p), {3.0});
  expect_vector_near(eval_f(q.model, 1, x, u, p), {1.5});
}

TEST(ProblemFile, ControlsAndParametersInOrderWritten) {
  const SimulationProblem q = parse_simulation_problem(R"toml(
[model]
x = ["q", "v"]
u = ["force"]
p = { mu = 0.5, a = 2.0 }     # not alphabetical: order as written
c = ["v - a*q"]
F = [["v", "force - mu"], ["v", "force + mu"]]
x0 = [1, 0]
[simulation]
T_sim = 1
u = [0.25]
)toml",
                                                       "ctrl.toml");
  const Pss& m = q.model;
  EXPECT_EQ(m.control_names, std::vector<std::string>{"force"});
  EXPECT_EQ(m.parameter_names, (std::vector<std::string>{"mu", "a"}));
  expect_vector_near(q.p, {0.5, 2.0});
  expect_vector_near(q.u, {0.25});
  const Eigen::Vector2d x(1.0, 3.0);
  EXPECT_EQ(eval_c(m, x, q.p), std::vector<double>{3.0 - 2.0 * 1.0});
  expect_vector_near(eval_f(m, 0, x, q.u, q.p), {3.0, 0.25 - 0.5});
  expect_vector_near(eval_f(m, 1, x, q.u, q.p), {3.0, 0.25 + 0.5});
}

TEST(ProblemFile, StateNamedTIsNotAClock) {
  const SimulationProblem q = parse_simulation_problem(R"toml(
[model]
x = ["x", "t"]
c = ["x - t"]
F = [["-1", "2"], ["1", "2"]]
x0 = [0, 0]
[simulation]
T_sim = 1
)toml",
                                                       "t_state.toml");
  EXPECT_FALSE(q.has_clock);
  EXPECT_EQ(q.model.n_x(), 2);
  const Eigen::Vector2d x(0.5, 2.0);
  const Eigen::VectorXd p;
  EXPECT_EQ(eval_c(q.model, x, p), std::vector<double>{-1.5});
}

TEST(ProblemFile, ClockStartsAtT0AndTimeMayEnterSwitchingFunctions) {
  const SimulationProblem q = parse_simulation_problem(R"toml(
[model]
x = ["x"]
c = ["x - sin(t)"]
F = [["0"], ["1"]]
x0 = [0.5]
[simulation]
T_sim = 1
t0 = 2.5
)toml",
                                                       "clock.toml");
  EXPECT_TRUE(q.has_clock);
  expect_vector_near(q.x0, {0.5, 2.5});
  const Eigen::Vector2d x(0.5, 1.0);
  const Eigen::VectorXd p, u;
  EXPECT_NEAR(eval_c(q.model, x, p)[0], 0.5 - std::sin(1.0), kTol);
  expect_vector_near(eval_f(q.model, 0, x, u, p), {0.0, 1.0});
}

// [simulation] t0 is the start time (docs/problem-files.md, "Results": every time is absolute),
// as in projected files: the clock (if any) starts at t0 and the result's times are offset by it.
// Example 3(c) from t0 = 0.5: x' in -sign(x) + t slides on x = 0 until t = 1, then
// x = (t - 1)^2 / 2, x(2.5) = 1.125; without a clock (x' = -1 from 0.25, then sliding on x = 0) the
// times start at t0 too.
TEST(ProblemFile, StartTimeIsAbsoluteWithAndWithoutClock) {
  SimulationProblem q = load_example("leaving_sliding.toml");
  apply_override(q, "t0", "0.5");
  apply_override(q, "error_estimate", "false");
  EXPECT_EQ(q.t0, 0.5);
  EXPECT_EQ(q.x0[1], 0.5);
  const IntegratorResult r = simulate(q);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_EQ(r.t.front(), 0.5);
  EXPECT_NEAR(r.t.back(), 2.5, 1e-12);
  EXPECT_NEAR(r.x_final()[0], 1.125, 1e-9);
  for (std::size_t n = 0; n < r.t.size(); ++n) EXPECT_NEAR(r.x[n][1], r.t[n], 1e-9);
  ASSERT_EQ(r.switches.size(), 1u);
  EXPECT_NEAR(r.switches[0].t, 1.0, 1e-9);

  SimulationProblem m = parse_simulation_problem(
      std::string(kMinimal) + "N_sim = 2\nerror_estimate = false\nt0 = 3\n", "t0.toml");
  EXPECT_FALSE(m.has_clock);
  EXPECT_EQ(m.t0, 3.0);
  const IntegratorResult rm = simulate(m);
  ASSERT_EQ(rm.status, Status::Success) << rm.message;
  EXPECT_EQ(rm.t.front(), 3.0);
  EXPECT_NEAR(rm.t.back(), 4.0, 1e-12);
  EXPECT_NEAR(rm.x_final()[0], 0.0, 1e-9);  // x' = -1 from 0.25, sliding on x = 0 from 3.25
}

TEST(ProblemFile, CartesianProductOfTwoSubsystems) {
  // Sect. 2.3: x1' in -sign(x1), x2' in -sign(x2) as two independent subsystems; the second in
  // g-form. The clock's t' = 1 is carried by subsystem 0 only, so sum_k F^k theta^k has t' = 1.
  const SimulationProblem q = parse_simulation_problem(R"toml(
[model]
x = ["x1", "x2"]
x0 = [1, -2]

[[model.subsystem]]
c = ["x1"]
F = [["-1 + 0*t", "0"],   # c > 0 (default S row [1])
     ["1", "0"]]          # c < 0

[[model.subsystem]]
g = ["-x2", "x2"]
F = [["0", "-1"], ["0", "1"]]

[simulation]
T_sim = 3
)toml",
                                                       "product.toml");
  const Pss& m = q.model;
  EXPECT_EQ(m.n_sys(), 2);
  EXPECT_EQ(m.n_theta(), 4);
  EXPECT_EQ(m.region_offset(0), 0);
  EXPECT_EQ(m.region_offset(1), 2);
  EXPECT_EQ(m.n_c(), 1);
  EXPECT_EQ(m.n_g(), 2);
  EXPECT_EQ(m.dims().subsystems[0].n_c, 1);
  EXPECT_EQ(m.dims().subsystems[1].n_g, 2);
  EXPECT_EQ(m.S(1).size(), 0);
  EXPECT_TRUE(q.has_clock);
  EXPECT_EQ(m.n_x(), 3);
  expect_vector_near(q.x0, {1.0, -2.0, 0.0});

  const Eigen::Vector3d x(0.5, -0.25, 0.0);
  const Eigen::VectorXd p, u;
  EXPECT_EQ(eval_c(m, x, p), std::vector<double>{0.5});
  EXPECT_EQ(eval_g_direct(m, x, p), (std::vector<double>{0.25, -0.25}));
  expect_vector_near(eval_f(m, 0, x, u, p), {-1.0, 0.0, 1.0});
  expect_vector_near(eval_f(m, 1, x, u, p), {1.0, 0.0, 1.0});
  expect_vector_near(eval_f(m, 2, x, u, p), {0.0, -1.0, 0.0});
  expect_vector_near(eval_f(m, 3, x, u, p), {0.0, 1.0, 0.0});
}

TEST(ProblemFile, SeveralSwitchingFunctionsUseAllSignRows) {
  const SimulationProblem q = parse_simulation_problem(R"toml(
[model]
x = ["a", "b"]
c = ["a", "b"]
F = [["1", "1"], ["1", "-1"], ["-1", "1"], ["-1", "-1"]]
x0 = [0.1, 0.2]
[simulation]
T_sim = 1
)toml",
                                                       "quad.toml");
  EXPECT_EQ(q.model.n_theta(), 4);
  EXPECT_EQ(q.model.S(0), all_sign_rows(2));
  const Eigen::Vector2d x(0.5, -3.0);
  const Eigen::VectorXd p;
  const std::vector<double> c = eval_c(q.model, x, p);
  // g = -S c with S rows (1,1), (1,-1), (-1,1), (-1,-1).
  expect_vector_near(g_of_c(q.model, c), {2.5, -3.5, 3.5, -2.5});
}

TEST(ProblemFile, ManyStatesEvaluateWithEveryScalarType) {
  // 12 states, 1 control, 2 parameters: more symbols than fit the evaluation's stack buffer for
  // the large AD types, so both buffer paths are used. f_0 = (q2, ..., q12, a*q1*q2 + u + b).
  std::string x = "x = [", f0 = "[", f1 = "[";
  for (int i = 1; i <= 12; ++i) {
    x += fmt_name(i) + (i < 12 ? ", " : "]");
    if (i < 12) {
      f0 += "\"q" + std::to_string(i + 1) + "\", ";
      f1 += "\"-q" + std::to_string(i + 1) + "\", ";
    }
  }
  f0 += "\"a*q1*q2 + u + b\"]";
  f1 += "\"0\"]";
  const std::string text = "[model]\n" + x + "\nu = [\"u\"]\np = { a = 2.0, b = 0.5 }\n" +
                           "c = [\"q1 - q12\"]\nF = [" + f0 + ", " + f1 + "]\n" +
                           "x0 = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]\n" +
                           "[simulation]\nT_sim = 1\nu = [0.25]\n";
  const SimulationProblem q = parse_simulation_problem(text, "many.toml");
  const Pss& m = q.model;
  ASSERT_EQ(m.n_x(), 12);

  const auto check = [&](auto tag) {
    using T = decltype(tag);
    std::vector<T> xs, fs(12), cs(1);
    for (int i = 0; i < 12; ++i) xs.push_back(make_input<T>(q.x0[i], i, 12));
    const std::vector<T> us{T(0.25)}, ps{T(2.0), T(0.5)};
    m.functions().f(0, xs.data(), us.data(), ps.data(), fs.data());
    m.functions().c(xs.data(), ps.data(), cs.data());
    for (int i = 0; i < 11; ++i) EXPECT_EQ(ad::value_of(fs[i]), q.x0[i + 1]) << i;
    EXPECT_EQ(ad::value_of(fs[11]), 2.0 * 1.0 * 2.0 + 0.25 + 0.5);
    EXPECT_EQ(ad::value_of(cs[0]), 1.0 - 12.0);
    return std::make_pair(fs, cs);
  };
  check(0.0);
  {
    const auto [fs, cs] = check(ad::Jet<128>());
    EXPECT_EQ(fs[11].d(0), 2.0 * 2.0);  // d(a q1 q2)/dq1 = a q2
    EXPECT_EQ(fs[11].d(1), 2.0 * 1.0);
    EXPECT_EQ(fs[11].d(2), 0.0);
    EXPECT_EQ(cs[0].d(0), 1.0);
    EXPECT_EQ(cs[0].d(11), -1.0);
  }
  {
    // Hyper: gradient plus the Hessian column of the direction seeded in d (here q2).
    const auto [fs, cs] = check(ad::Hyper<128>());
    EXPECT_EQ(fs[11].v.d(0), 4.0);
    EXPECT_EQ(fs[11].d.v, 2.0);     // directional derivative along q2: a q1
    EXPECT_EQ(fs[11].d.d(0), 2.0);  // d^2 f / dq2 dq1 = a
  }
  {
    const auto [fs, cs] = check(ad::Pattern());
    EXPECT_EQ(fs[11].dep, (std::vector<int>{0, 1}));
    EXPECT_EQ(fs[11].hess, (std::vector<std::pair<int, int>>{{1, 0}}));
    EXPECT_EQ(fs[3].dep, std::vector<int>{4});
    EXPECT_TRUE(fs[3].hess.empty());
  }
}

// ---- overrides --------------------------------------------------------------------------------

TEST(ProblemFileOverride, SetsEveryKindOfKey) {
  SimulationProblem q = load_example("oscillator.toml");
  apply_override(q, "n_s", "4");
  apply_override(q, "rk_scheme", "gauss_legendre");
  apply_override(q, "use_fesd", "0");
  apply_override(q, "N_FE", "3");
  apply_override(q, "N_sim", "40");
  apply_override(q, "T_sim", "0.5");
  apply_override(q, "sigma_0", "0.01");
  apply_override(q, "cross_comp_mode", "sparse");
  apply_override(q, "step_equilibration", "none");
  apply_override(q, "print_level", "3");
  apply_override(q, "homotopy.N_homotopy", "12");
  apply_override(q, "ipopt.mu_strategy", "monotone");
  const DiscretizationOptions& d = q.options.discretization;
  EXPECT_EQ(d.n_s, 4);
  EXPECT_EQ(d.rk_scheme, RkScheme::GaussLegendre);
  EXPECT_FALSE(d.use_fesd);
  EXPECT_EQ(d.N_FE, 3);
  EXPECT_EQ(d.cross_comp, CrossComp::Sparse);
  EXPECT_EQ(d.step_eq, StepEq::None);
  EXPECT_EQ(q.N_sim, 40);
  EXPECT_EQ(q.T_sim, 0.5);
  EXPECT_EQ(q.options.homotopy.sigma_0, 0.01);
  EXPECT_EQ(q.options.homotopy.max_homotopy_steps, 12);
  EXPECT_EQ(q.options.nlp.print_level, 3);
  ASSERT_EQ(q.options.nlp.extra.size(), 1U);
  EXPECT_EQ(q.options.nlp.extra[0].first, "mu_strategy");
  EXPECT_EQ(q.options.nlp.extra[0].second, "monotone");

  apply_override(q, "use_fesd", "true");
  apply_override(q, "discretization.N_finite_elements", "4");
  apply_override(q, "ipopt.mu_strategy", "adaptive");  // replaces, does not append
  EXPECT_TRUE(q.options.discretization.use_fesd);
  EXPECT_EQ(q.options.discretization.N_FE, 4);
  ASSERT_EQ(q.options.nlp.extra.size(), 1U);
  EXPECT_EQ(q.options.nlp.extra[0].second, "adaptive");
}

TEST(ProblemFileOverride, ClockStartAndControls) {
  SimulationProblem q = load_example("leaving_sliding.toml");
  apply_override(q, "t0", "1.5");
  expect_vector_near(q.x0, {0.0, 1.5});

  SimulationProblem c = parse_simulation_problem(R"toml(
[model]
x = ["x"]
u = ["u1", "u2"]
c = ["x"]
F = [["u1"], ["u2"]]
x0 = [0]
[simulation]
T_sim = 1
)toml",
                                                 "u.toml");
  expect_vector_near(c.u, {0.0, 0.0});
  apply_override(c, "u", "0.5, -2");
  expect_vector_near(c.u, {0.5, -2.0});
}

// [model] x0 and p (issue 13, 3): the states of model.x only (a clock keeps t0), one parameter
// per override, stored as the problem's p and the model's p_default.
TEST(ProblemFileOverride, InitialStateAndParameters) {
  SimulationProblem q = load_example("leaving_sliding.toml");
  apply_override(q, "t0", "1.5");
  apply_override(q, "x0", "-0.25");
  expect_vector_near(q.x0, {-0.25, 1.5});
  apply_override(q, "model.x0", " 2 ");
  expect_vector_near(q.x0, {2.0, 1.5});

  SimulationProblem o = load_example("oscillator.toml");
  apply_override(o, "--x0", "1, -2");
  expect_vector_near(o.x0, {1.0, -2.0});
  apply_override(o, "p", "omega=3.5");
  expect_vector_near(o.p, {3.5});
  expect_vector_near(o.model.p_default, {3.5});
  apply_override(o, "model.p", " omega = -1e-3 ");
  expect_vector_near(o.p, {-1e-3});
}

}  // namespace
}  // namespace fesd
