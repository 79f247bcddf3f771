// tests/model/algebraic_test.cpp: user algebraic variables z with g_z(x, u, p, z) = 0 (problem
// files' z, z0, g_z; model/algebraic.hpp, docs/problem-files.md "Algebraic variables z").
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "fesd/ad.hpp"
#include "fesd/integrator.hpp"
#include "fesd/ocp.hpp"
#include "fesd/problem_file.hpp"
#include "model/algebraic.hpp"

namespace {

using fesd::IntegratorResult;

IntegratorResult run(const std::string& text) {
  const fesd::SimulationProblem p = fesd::parse_simulation_problem(text, "algebraic.toml");
  return fesd::simulate(p);
}

void expect_same(const IntegratorResult& a, const IntegratorResult& b, double tol) {
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  ASSERT_EQ(a.x.size(), b.x.size());
  for (std::size_t i = 0; i < a.x.size(); ++i) {
    EXPECT_NEAR(a.t[i], b.t[i], tol) << i;
    EXPECT_NEAR((a.x[i] - b.x[i]).lpNorm<Eigen::Infinity>(), 0.0, tol) << i;
  }
  ASSERT_EQ(a.switch_times().size(), b.switch_times().size());
  for (std::size_t k = 0; k < a.switch_times().size(); ++k)
    EXPECT_NEAR(a.switch_times()[k], b.switch_times()[k], tol) << k;
}

// z = x - 1 is explicit: switching on c = z is switching on c = x - 1. x' = 3 - x below 1,
// 1 + x above, from x(0) = 0.
TEST(Algebraic, ExplicitZEqualsTheSubstitutedModel) {
  const std::string tail = R"(
F = [["1 + x"], ["3 - x"]]
x0 = [0.0]
[simulation]
T_sim = 2.0
N_sim = 4
[discretization]
n_s = 2
N_finite_elements = 3
)";
  const IntegratorResult sub = run("[model]\nx = [\"x\"]\nc = [\"x - 1\"]" + tail);
  const IntegratorResult alg = run(
      "[model]\nx = [\"x\"]\nz = [\"w\"]\nz0 = [0.0]\ng_z = [\"w - (x - 1)\"]\nc = [\"w\"]" + tail);
  expect_same(sub, alg, 1e-10);
  ASSERT_EQ(alg.z.size(), alg.x_stage.size());
  for (std::size_t i = 0; i < alg.z.size(); ++i)
    EXPECT_NEAR(alg.z[i][0], alg.x_stage[i][0] - 1.0, 1e-12) << i;
  // exact switch time: x = 3 - 3 e^-t reaches 1 at ln 1.5 (scheme accuracy with h = 1/6)
  ASSERT_EQ(alg.switch_times().size(), 1u);
  EXPECT_NEAR(alg.switch_times()[0], std::log(1.5), 1e-4);
}

double bisect(const auto& f, double lo, double hi) {
  for (int i = 0; i < 200; ++i) {
    const double m = 0.5 * (lo + hi);
    if (f(lo) * f(m) <= 0)
      hi = m;
    else
      lo = m;
  }
  return 0.5 * (lo + hi);
}

// An implicit z: w^3 + w = x - 1, switching on c = w (x = 1), x' = 2 + w^2 below, 1 + w above.
// Closed form: with x = 1 + w^3 + w, dt = (3 w^2 + 1) / (2 + w^2) dw below the switch, so the
// switch time is t_s = -3 w_0 + (5 / sqrt 2) atan(w_0 / sqrt 2) (w_0: the real root of
// w^3 + w + 1 = 0, x(0) = 0), and above it t - t_s = 3 w^2 / 2 - 3 w + 4 ln(1 + w). Also against
// the same model with z substituted by the hyperbolic formula of the cubic's root,
// w = 2/sqrt(3) sinh(asinh(3 sqrt(3) (x - 1) / 2) / 3).
TEST(Algebraic, ImplicitZAgainstClosedFormAndCardano) {
  const std::string tail = R"(
x0 = [0.0]
[simulation]
T_sim = 2.0
N_sim = 20
[discretization]
rk_scheme = "radau_iia"
n_s = 3
N_finite_elements = 2
)";
  const IntegratorResult alg = run(R"toml([model]
x = ["x"]
z = ["w"]
g_z = ["w^3 + w - (x - 1)"]
c = ["w"]
F = [["1 + w"], ["2 + w^2"]])toml" +
                                   tail);
  const std::string w = "(2/sqrt(3)*sinh(log(3*sqrt(3)/2*(x - 1) + sqrt(27/4*(x - 1)^2 + 1))/3))";
  const IntegratorResult sub = run("[model]\nx = [\"x\"]\nc = [\"" + w + "\"]\nF = [[\"1 + " + w +
                                   "\"], [\"2 + " + w + "^2\"]]" + tail);
  expect_same(sub, alg, 1e-10);

  const double w0 = bisect([](double v) { return v * v * v + v + 1; }, -2.0, 0.0);
  const double ts = -3 * w0 + 5 / std::sqrt(2.0) * std::atan(w0 / std::sqrt(2.0));
  const double wT = bisect(
      [&](double v) { return 1.5 * v * v - 3 * v + 4 * std::log(1 + v) - (2.0 - ts); }, 0.0, 5.0);
  ASSERT_EQ(alg.switch_times().size(), 1u);
  EXPECT_NEAR(alg.switch_times()[0], ts, 1e-8);                // measured 2.7e-9
  EXPECT_NEAR(alg.x_final()[0], 1 + wT * wT * wT + wT, 1e-8);  // measured 5.9e-9
  for (std::size_t i = 0; i < alg.z.size(); ++i) {
    const double z = alg.z[i][0];
    EXPECT_NEAR(z * z * z + z, alg.x_stage[i][0] - 1.0, 1e-12) << i;
  }
}

// The derivatives of z(x) through AD types: dz/dx = 1 / (3 z^2 + 1),
// d2z/dx2 = -6 z (dz/dx)^3 for z^3 + z = x.
TEST(Algebraic, ExactFirstAndSecondDerivatives) {
  const fesd::expr::Expression g = fesd::expr::Expression::parse("z^3 + z - x", {"x", "z"}, "test");
  const fesd::AlgebraicEquations eq(1, {g}, Eigen::VectorXd::Zero(1));
  for (double x : {-3.0, -0.5, 0.0, 0.7, 10.0}) {
    double s[2] = {x, 0.0};
    eq.solve<double>(s);
    const double z = s[1], dz = 1 / (3 * z * z + 1), d2z = -6 * z * dz * dz * dz;
    EXPECT_NEAR(z * z * z + z, x, 1e-12 * (1 + std::abs(x)));
    using H = fesd::ad::Hyper<8>;
    H h[2] = {H(fesd::ad::Jet<8>::variable(x, 0, 1), fesd::ad::Jet<8>::variable(1.0, 0, 1)),
              H(0.0)};
    h[1].d = fesd::ad::Jet<8>(0.0);
    // direction: d = e_0 with no gradient of its own
    h[0].d = fesd::ad::Jet<8>(1.0);
    eq.solve<H>(h);
    EXPECT_NEAR(h[1].v.v, z, 1e-14 * (1 + std::abs(z))) << x;
    EXPECT_NEAR(h[1].v.d(0), dz, 1e-13) << x;
    EXPECT_NEAR(h[1].d.v, dz, 1e-13) << x;
    EXPECT_NEAR(h[1].d.d(0), d2z, 1e-12) << x;
  }
}

// The simple car switching on z = v - 15 (examples/nosnoc/simple_car_algebraic.toml) solves the
// same OCP as c = v - 15 written out.
TEST(Algebraic, SimpleCarOnZEqualsTheSubstitutedFile) {
  const std::string path =
      std::string(FESD_SOURCE_DIR) + "/examples/nosnoc/simple_car_algebraic.toml";
  const fesd::OcpProblem alg = fesd::load_ocp_problem(path);
  fesd::OcpProblem sub = alg;
  ASSERT_EQ(alg.ocp.model.n_z(), 1);
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* line : {"z = [\"z\"]\n", "z0 = [-15.0]\n", "g_z = [\"z - (v - 15)\"]\n"})
    text.erase(text.find(line), std::string(line).size());
  text.replace(text.find("c = [\"z\"]"), 9, "c = [\"v - 15\"]");
  sub = fesd::parse_ocp_problem(text, "simple_car_substituted.toml");
  ASSERT_EQ(sub.ocp.model.n_z(), 0);
  const fesd::OcpResult ra = fesd::solve(alg.ocp, alg.options);
  const fesd::OcpResult rs = fesd::solve(sub.ocp, sub.options);
  ASSERT_EQ(ra.status, fesd::Status::Success) << ra.message;
  ASSERT_EQ(rs.status, fesd::Status::Success) << rs.message;
  EXPECT_NEAR(ra.objective, rs.objective, 1e-9);  // measured 5.892276 both
  ASSERT_EQ(ra.switches.size(), rs.switches.size());
  for (std::size_t k = 0; k < ra.switches.size(); ++k)
    EXPECT_NEAR(ra.switches[k].t, rs.switches[k].t, 1e-8) << k;
  ASSERT_EQ(ra.z.size(), ra.x_stage.size());
  for (std::size_t i = 0; i < ra.z.size(); ++i)
    EXPECT_NEAR(ra.z[i][0], ra.x_stage[i][1] - 15.0, 1e-12) << i;
}

}  // namespace
