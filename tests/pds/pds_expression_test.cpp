// Projected dynamical systems from parsed expressions (model/expression_pds.hpp, the problem-file
// path) against the C++ template model and exact solutions.
#include <cmath>

#include <gtest/gtest.h>

#include "../../bench/pds_example1_model.hpp"
#include "fesd/error.hpp"
#include "fesd/pds.hpp"
#include "model/expression_pds.hpp"

namespace {

using fesd::expr::Expression;

// Symbols as the problem-file reader lays them out: states, the (unused) time slot, controls,
// parameters.
fesd::Pds expression_pds(const std::vector<std::string>& f, const std::vector<std::string>& c,
                         const std::vector<std::string>& p_names = {}) {
  std::vector<std::string> symbols{"x1", "x2", "t"};
  symbols.insert(symbols.end(), p_names.begin(), p_names.end());
  std::vector<Expression> fe, ce;
  for (const auto& s : f) fe.push_back(Expression::parse(s, symbols, "test f"));
  for (const auto& s : c) ce.push_back(Expression::parse(s, symbols, "test c"));
  fesd::ExpressionLayout layout{
      .n_x = 2, .n_x_slots = 3, .n_u = 0, .n_p = static_cast<int>(p_names.size())};
  return fesd::make_expression_pds(
      fesd::PdsDims{.n_x = 2, .n_p = layout.n_p, .n_c = static_cast<int>(c.size())}, layout,
      std::move(fe), std::move(ce));
}

fesd::IntegratorOptions options(int n_s, int N_FE) {
  fesd::IntegratorOptions o;
  o.discretization.n_s = n_s;
  o.discretization.N_FE = N_FE;
  return o;
}

TEST(PdsExpression, GradientOfTheConstraints) {
  const fesd::Pds m = expression_pds({"x2", "-x1"}, {"r^2 - x1^2 - x2^2", "x2 + 1"}, {"r"});
  const double x[2] = {1.0, 2.0}, p[1] = {2.0}, lambda[2] = {3.0, 0.5};
  double out[2];
  m.functions().grad_c_lambda(x, p, lambda, out);
  EXPECT_DOUBLE_EQ(out[0], 3.0 * -2.0);        // 3 * dc1/dx1
  EXPECT_DOUBLE_EQ(out[1], 3.0 * -4.0 + 0.5);  // 3 * dc1/dx2 + 0.5 * dc2/dx2
}

// Example 1 from expressions: the same discrete solution as the C++ model (n_s = 2, N_FE = 20).
TEST(PdsExpression, Example1SameAsTemplateModel) {
  const auto e = fesd::integrate(expression_pds({"x2", "-x1"}, {"x2 + 1"}), pds_example1::x0(),
                                 pds_example1::kT, 1, options(2, 20));
  const auto t = fesd::integrate(pds_example1::model(), pds_example1::x0(), pds_example1::kT, 1,
                                 options(2, 20));
  ASSERT_EQ(e.status, fesd::Status::Success) << e.message;
  ASSERT_EQ(t.status, fesd::Status::Success) << t.message;
  EXPECT_LT((e.x_final() - t.x_final()).norm(), 1e-10);
  EXPECT_LT((e.x_final() - pds_example1::x_T()).norm(), 1.2e-3);
}

// A curved boundary: C = unit disc, f = (1, 0), x0 = (0, -1). The state slides on the circle,
// x = (sin phi, -cos phi) with phi' = cos phi, phi(t) = 2 atan(tanh(t / 2)). Exercises the
// curvature of c in grad c(x) lambda and in the Hessian. Measured (n_s = 3, N_FE = 4, T = 1):
// 1.8e-7 (expressions and template model alike).
struct Disc {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = 1.0 - x[0] * x[0] - x[1] * x[1];
  }
  template <class T>
  void f(const T*, const T*, const T*, T* f) const {
    f[0] = T(1.0);
    f[1] = T(0.0);
  }
};

TEST(PdsExpression, SlidingOnACircle) {
  const double phi = 2 * std::atan(std::tanh(0.5));
  const Eigen::Vector2d exact(std::sin(phi), -std::cos(phi));
  const fesd::Pds from_expressions = expression_pds({"1", "0"}, {"1 - x1^2 - x2^2"});
  const fesd::Pds from_template = fesd::make_pds(Disc{}, fesd::PdsDims{.n_x = 2, .n_c = 1});
  for (const fesd::Pds* m : {&from_expressions, &from_template}) {
    const auto r = fesd::integrate(*m, Eigen::Vector2d(0.0, -1.0), 1.0, 1, options(3, 4));
    ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
    EXPECT_LT((r.x_final() - exact).norm(), 6e-7);
    EXPECT_TRUE(r.switches.empty());
  }
}

TEST(PdsExpression, ConstraintReadingAControlRejected) {
  std::vector<std::string> symbols{"x1", "t", "u1"};
  fesd::ExpressionLayout layout{.n_x = 1, .n_x_slots = 2, .n_u = 1, .n_p = 0};
  try {
    fesd::make_expression_pds(fesd::PdsDims{.n_x = 1, .n_u = 1, .n_c = 1}, layout,
                              {Expression::parse("u1", symbols, "f")},
                              {Expression::parse("x1 - u1", symbols, "c")});
    FAIL() << "no exception";
  } catch (const fesd::InvalidModel& e) {
    EXPECT_NE(std::string(e.what()).find("cannot depend on controls"), std::string::npos);
  }
}

}  // namespace
