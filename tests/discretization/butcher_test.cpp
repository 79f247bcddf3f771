// tests/discretization/butcher_test.cpp: Butcher tableaus (eq. 25 of the FESD paper).
//
// The implicit tableaus are checked through the simplifying assumptions (Butcher 1964; Hairer &
// Wanner, Solving ODEs II, Sec. IV.5):
//   B(p): sum_i b_i c_i^{k-1} = 1/k,                          k = 1..p,
//   C(q): sum_j a_ij c_j^{k-1} = c_i^k / k          (all i),   k = 1..q,
//   D(r): sum_i b_i c_i^{k-1} a_ij = b_j (1 - c_j^k) / k (all j), k = 1..r.
// Butcher's theorem: B(p), C(q), D(r) with p <= q + r + 1 and p <= 2q + 2 imply order p. The
// expected (q, r) are Gauss (s, s), Radau IIA (s, s-1), Lobatto IIIA (s, s-2), Lobatto IIIC
// (s-1, s-1), so passing B, C and D below proves the claimed order; the quadrature (b, c) having
// order exactly p (B(p+1) fails) shows the order is not understated either. The explicit methods
// are checked against the eight rooted-tree conditions up to order 4.
#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <fesd/error.hpp>
#include <fesd/tableau.hpp>

namespace fesd {
namespace {

using Case = std::tuple<RkScheme, int>;

// Tolerance on the (absolute) residual of an order condition. Measured residuals (GCC 12, x86-64)
// are <= 5e-16 for every n_s <= 9, because butcher.cpp never solves a Vandermonde system: nodes are
// eigenvalues of a Jacobi matrix polished by Newton, and a_ij, b_j are Gauss-quadrature integrals
// of Lagrange polynomials. 1e-13 for n_s <= 5 is a wide margin. For n_s >= 6 we allow 1e-12: the
// conditions there sum more terms and high powers c^{k-1} (k up to 2 n_s = 18), results may differ
// with FMA contraction or another libm, and a construction through monomial (Vandermonde) systems,
// whose condition number grows from ~8e2 at n_s = 5 to ~9e5 at n_s = 9, would legitimately lose
// digits there. 1e-12 is still far below what a wrong coefficient produces (>= 1e-4) and 20x below
// the smallest quadrature error of order p+1 checked in QuadratureOrderB (2.2e-11, Gauss n_s = 9).
double tolerance(int n_s) {
  return n_s <= 5 ? 1e-13 : 1e-12;
}

// |sum_i b_i c_i^{k-1} - 1/k| (condition B, one k).
double b_residual(const Tableau& t, int k) {
  double sum = 0.0;
  for (int i = 0; i < t.n_s; ++i) sum += t.b(i) * std::pow(t.c(i), k - 1);
  return std::abs(sum - 1.0 / k);
}

// max_i |sum_j a_ij c_j^{k-1} - c_i^k / k| (condition C, one k).
double c_residual(const Tableau& t, int k) {
  double worst = 0.0;
  for (int i = 0; i < t.n_s; ++i) {
    double sum = 0.0;
    for (int j = 0; j < t.n_s; ++j) sum += t.A(i, j) * std::pow(t.c(j), k - 1);
    worst = std::max(worst, std::abs(sum - std::pow(t.c(i), k) / k));
  }
  return worst;
}

// max_j |sum_i b_i c_i^{k-1} a_ij - b_j (1 - c_j^k) / k| (condition D, one k).
double d_residual(const Tableau& t, int k) {
  double worst = 0.0;
  for (int j = 0; j < t.n_s; ++j) {
    double sum = 0.0;
    for (int i = 0; i < t.n_s; ++i) sum += t.b(i) * std::pow(t.c(i), k - 1) * t.A(i, j);
    worst = std::max(worst, std::abs(sum - t.b(j) * (1.0 - std::pow(t.c(j), k)) / k));
  }
  return worst;
}

// The (C, D) indices q and r that each implicit scheme satisfies (see the header comment).
int expected_q(RkScheme scheme, int s) {
  return scheme == RkScheme::LobattoIIIC ? s - 1 : s;
}
int expected_r(RkScheme scheme, int s) {
  switch (scheme) {
    case RkScheme::GaussLegendre:
      return s;
    case RkScheme::RadauIIA:
    case RkScheme::LobattoIIIC:
      return s - 1;
    default:  // Lobatto IIIA
      return s - 2;
  }
}

int expected_order(RkScheme scheme, int s) {
  switch (scheme) {
    case RkScheme::RadauIIA:
      return 2 * s - 1;
    case RkScheme::GaussLegendre:
      return 2 * s;
    case RkScheme::LobattoIIIA:
    case RkScheme::LobattoIIIC:
      return 2 * s - 2;
    default:
      return s;
  }
}

bool is_radau_or_lobatto(RkScheme s) {
  return s == RkScheme::RadauIIA || s == RkScheme::LobattoIIIA || s == RkScheme::LobattoIIIC;
}
bool is_lobatto(RkScheme s) {
  return s == RkScheme::LobattoIIIA || s == RkScheme::LobattoIIIC;
}

std::vector<Case> implicit_cases() {
  std::vector<Case> cases;
  for (int s = 1; s <= 9; ++s) cases.emplace_back(RkScheme::RadauIIA, s);
  for (int s = 1; s <= 9; ++s) cases.emplace_back(RkScheme::GaussLegendre, s);
  for (int s = 2; s <= 9; ++s) cases.emplace_back(RkScheme::LobattoIIIA, s);
  for (int s = 2; s <= 9; ++s) cases.emplace_back(RkScheme::LobattoIIIC, s);
  return cases;
}

std::vector<Case> explicit_cases() {
  std::vector<Case> cases;
  for (int s = 1; s <= 4; ++s) cases.emplace_back(RkScheme::ExplicitRK, s);
  return cases;
}

std::vector<Case> all_cases() {
  std::vector<Case> cases = implicit_cases();
  for (const Case& c : explicit_cases()) cases.push_back(c);
  return cases;
}

class TableauTest : public ::testing::TestWithParam<Case> {
 protected:
  RkScheme scheme() const { return std::get<0>(GetParam()); }
  int n_s() const { return std::get<1>(GetParam()); }
};
class ImplicitTableauTest : public TableauTest {};  // Gauss, Radau IIA, Lobatto IIIA/IIIC
class ExplicitTableauTest : public TableauTest {};  // Euler, Heun, Kutta 3, RK4

TEST_P(TableauTest, ShapeAndMetadata) {
  const Tableau t = make_tableau(scheme(), n_s());
  EXPECT_EQ(t.scheme, scheme());
  EXPECT_EQ(t.n_s, n_s());
  ASSERT_EQ(t.A.rows(), n_s());
  ASSERT_EQ(t.A.cols(), n_s());
  ASSERT_EQ(t.b.size(), n_s());
  ASSERT_EQ(t.c.size(), n_s());
  EXPECT_TRUE(t.A.allFinite() && t.b.allFinite() && t.c.allFinite());
  EXPECT_EQ(t.order, expected_order(scheme(), n_s()));
  const std::string name = t.name();
  EXPECT_NE(
      name.find("(n_s = " + std::to_string(n_s()) + ", order " + std::to_string(t.order) + ")"),
      std::string::npos)
      << name;
}

TEST_P(TableauTest, NodesAscendingInUnitInterval) {
  const Tableau t = make_tableau(scheme(), n_s());
  for (int i = 0; i < n_s(); ++i) {
    EXPECT_GE(t.c(i), 0.0);
    EXPECT_LE(t.c(i), 1.0);
    if (i == 0) continue;
    // Distinct for the implicit schemes; RK4 repeats c = 1/2.
    if (scheme() != RkScheme::ExplicitRK) {
      EXPECT_LT(t.c(i - 1), t.c(i)) << "i = " << i;
    } else {
      EXPECT_LE(t.c(i - 1), t.c(i)) << "i = " << i;
    }
  }
  // Radau IIA and Lobatto contain the right end point, Lobatto also the left one. They are set,
  // not computed, so they are exact.
  if (is_radau_or_lobatto(scheme())) {
    EXPECT_EQ(t.c(n_s() - 1), 1.0);
  }
  if (is_lobatto(scheme())) {
    EXPECT_EQ(t.c(0), 0.0);
  }
  // Gauss and Lobatto nodes are symmetric about 1/2.
  if (scheme() == RkScheme::GaussLegendre || is_lobatto(scheme())) {
    for (int i = 0; i < n_s(); ++i) {
      EXPECT_NEAR(t.c(i) + t.c(n_s() - 1 - i), 1.0, 1e-15) << "i = " << i;
    }
  }
}

TEST_P(TableauTest, Flags) {
  const Tableau t = make_tableau(scheme(), n_s());
  EXPECT_EQ(t.stiffly_accurate, is_radau_or_lobatto(scheme()));
  EXPECT_EQ(t.is_explicit, scheme() == RkScheme::ExplicitRK);
  if (t.stiffly_accurate) {
    // Last row of A equals b: x_{n+1} is the last stage value.
    EXPECT_LE((t.A.row(n_s() - 1) - t.b.transpose()).cwiseAbs().maxCoeff(), 1e-14);
  }
  if (t.is_explicit) {
    for (int i = 0; i < n_s(); ++i) {
      for (int j = i; j < n_s(); ++j) EXPECT_EQ(t.A(i, j), 0.0) << i << "," << j;
    }
  }
}

// Row sums: sum_j a_ij = c_i (C(1); every tableau used here satisfies it).
TEST_P(TableauTest, RowSumsEqualNodes) {
  const Tableau t = make_tableau(scheme(), n_s());
  EXPECT_LE((t.A.rowwise().sum() - t.c).cwiseAbs().maxCoeff(), tolerance(n_s()));
}

// B(p) with p = the claimed order: b, c is a quadrature rule of order p.
TEST_P(TableauTest, QuadratureOrderB) {
  const Tableau t = make_tableau(scheme(), n_s());
  const double tol = tolerance(n_s());
  for (int k = 1; k <= t.order; ++k) EXPECT_LE(b_residual(t, k), tol) << "B, k = " << k;
  // Sharpness for the implicit schemes: Gauss, Radau and Lobatto quadrature has order exactly p,
  // so B(p+1) fails. Its residual is the quadrature error for t^p, which shrinks fast with n_s
  // (2.2e-11 for Gauss n_s = 9, the smallest here), hence the threshold of 10 x tolerance.
  // (Kutta's 3-stage method uses Simpson's rule, of order 4 > 3, so explicit RK is skipped.)
  if (scheme() != RkScheme::ExplicitRK) {
    EXPECT_GT(b_residual(t, t.order + 1), 10.0 * tol);
  }
}

// C(q): q = n_s for the collocation methods, n_s - 1 for Lobatto IIIC.
TEST_P(ImplicitTableauTest, StageOrderC) {
  const Tableau t = make_tableau(scheme(), n_s());
  const double tol = tolerance(n_s());
  for (int k = 1; k <= expected_q(scheme(), n_s()); ++k) {
    EXPECT_LE(c_residual(t, k), tol) << "C, k = " << k;
  }
}

// D(r): together with B and C this proves the claimed order (Butcher's theorem).
TEST_P(ImplicitTableauTest, ConditionD) {
  const Tableau t = make_tableau(scheme(), n_s());
  const int q = expected_q(scheme(), n_s());
  const int r = expected_r(scheme(), n_s());
  ASSERT_LE(t.order, q + r + 1);
  ASSERT_LE(t.order, 2 * q + 2);
  const double tol = tolerance(n_s());
  for (int k = 1; k <= r; ++k) EXPECT_LE(d_residual(t, k), tol) << "D, k = " << k;
}

// Rooted-tree order conditions for orders 1..4 (Hairer, Norsett & Wanner I, Table II.2.2), and
// failure of the tall tree of order s+1 (b^T A^{s-1} c = 0 for every explicit s-stage method).
TEST_P(ExplicitTableauTest, RootedTreeConditions) {
  const Tableau t = make_tableau(scheme(), n_s());
  const Eigen::VectorXd& b = t.b;
  const Eigen::VectorXd& c = t.c;
  const Eigen::MatrixXd& A = t.A;
  const Eigen::VectorXd e = Eigen::VectorXd::Ones(n_s());
  const Eigen::VectorXd c2 = c.cwiseProduct(c);
  const Eigen::VectorXd ac = A * c;
  struct Condition {
    int order;
    const char* tree;
    double value, exact;
  };
  const std::vector<Condition> conditions = {
      {1, "b^T e", b.dot(e), 1.0},
      {2, "b^T c", b.dot(c), 1.0 / 2.0},
      {3, "b^T c^2", b.dot(c2), 1.0 / 3.0},
      {3, "b^T A c", b.dot(ac), 1.0 / 6.0},
      {4, "b^T c^3", b.dot(c2.cwiseProduct(c)), 1.0 / 4.0},
      {4, "b^T (c .* A c)", b.dot(c.cwiseProduct(ac)), 1.0 / 8.0},
      {4, "b^T A c^2", b.dot(A * c2), 1.0 / 12.0},
      {4, "b^T A A c", b.dot(A * ac), 1.0 / 24.0},
  };
  for (const Condition& cond : conditions) {
    if (cond.order <= n_s()) {
      EXPECT_NEAR(cond.value, cond.exact, 1e-15) << cond.tree;
    }
  }
  // Tall tree of order s+1: b^T A^{s-1} c should be 1/(s+1)!, but is 0 for explicit methods.
  Eigen::VectorXd v = c;
  double factorial = 2.0;
  for (int k = 1; k < n_s(); ++k) {
    v = A * v;
    factorial *= k + 2;
  }
  EXPECT_EQ(b.dot(v), 0.0);
  EXPECT_GT(std::abs(b.dot(v) - 1.0 / factorial), 1e-4);
}

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  return std::string(to_string(std::get<0>(info.param))) + "_" +
         std::to_string(std::get<1>(info.param));
}

INSTANTIATE_TEST_SUITE_P(AllSchemes, TableauTest, ::testing::ValuesIn(all_cases()), case_name);
INSTANTIATE_TEST_SUITE_P(Implicit, ImplicitTableauTest, ::testing::ValuesIn(implicit_cases()),
                         case_name);
INSTANTIATE_TEST_SUITE_P(Explicit, ExplicitTableauTest, ::testing::ValuesIn(explicit_cases()),
                         case_name);

// ---- known values (Hairer & Wanner II, Tables IV.5.1-5.4, 5.6, 5.9, 5.11)
// ------------------------

void expect_matrix_near(const Eigen::MatrixXd& actual, const Eigen::MatrixXd& expected,
                        double tol) {
  ASSERT_EQ(actual.rows(), expected.rows());
  ASSERT_EQ(actual.cols(), expected.cols());
  EXPECT_LE((actual - expected).cwiseAbs().maxCoeff(), tol) << "actual:\n"
                                                            << actual << "\nexpected:\n"
                                                            << expected;
}

TEST(TableauKnownValues, RadauIIATwoStages) {
  const Tableau t = make_tableau(RkScheme::RadauIIA, 2);
  expect_matrix_near(t.c, Eigen::Vector2d(1.0 / 3.0, 1.0), 1e-15);
  expect_matrix_near(t.b, Eigen::Vector2d(3.0 / 4.0, 1.0 / 4.0), 1e-15);
  Eigen::Matrix2d A;
  A << 5.0 / 12.0, -1.0 / 12.0, 3.0 / 4.0, 1.0 / 4.0;
  expect_matrix_near(t.A, A, 1e-15);
  EXPECT_EQ(t.name(), "Radau IIA (n_s = 2, order 3)");
}

TEST(TableauKnownValues, RadauIIAOneStageIsImplicitEuler) {
  const Tableau t = make_tableau(RkScheme::RadauIIA, 1);
  EXPECT_EQ(t.A(0, 0), 1.0);
  EXPECT_EQ(t.b(0), 1.0);
  EXPECT_EQ(t.c(0), 1.0);
}

TEST(TableauKnownValues, RadauIIAThreeStages) {
  const double r6 = std::sqrt(6.0);
  const Tableau t = make_tableau(RkScheme::RadauIIA, 3);
  expect_matrix_near(t.c, Eigen::Vector3d((4.0 - r6) / 10.0, (4.0 + r6) / 10.0, 1.0), 1e-15);
  expect_matrix_near(t.b, Eigen::Vector3d((16.0 - r6) / 36.0, (16.0 + r6) / 36.0, 1.0 / 9.0),
                     1e-15);
  Eigen::Matrix3d A;
  A << (88.0 - 7.0 * r6) / 360.0, (296.0 - 169.0 * r6) / 1800.0, (-2.0 + 3.0 * r6) / 225.0,
      (296.0 + 169.0 * r6) / 1800.0, (88.0 + 7.0 * r6) / 360.0, (-2.0 - 3.0 * r6) / 225.0,
      (16.0 - r6) / 36.0, (16.0 + r6) / 36.0, 1.0 / 9.0;
  expect_matrix_near(t.A, A, 1e-15);
  EXPECT_EQ(t.name(), "Radau IIA (n_s = 3, order 5)");
}

TEST(TableauKnownValues, GaussOneStageIsImplicitMidpoint) {
  const Tableau t = make_tableau(RkScheme::GaussLegendre, 1);
  EXPECT_EQ(t.c(0), 0.5);
  EXPECT_NEAR(t.A(0, 0), 0.5, 1e-16);
  EXPECT_NEAR(t.b(0), 1.0, 1e-16);
}

TEST(TableauKnownValues, GaussTwoStages) {
  const double r3 = std::sqrt(3.0);
  const Tableau t = make_tableau(RkScheme::GaussLegendre, 2);
  expect_matrix_near(t.c, Eigen::Vector2d(0.5 - r3 / 6.0, 0.5 + r3 / 6.0), 1e-15);
  expect_matrix_near(t.b, Eigen::Vector2d(0.5, 0.5), 1e-15);
  Eigen::Matrix2d A;
  A << 0.25, 0.25 - r3 / 6.0, 0.25 + r3 / 6.0, 0.25;
  expect_matrix_near(t.A, A, 1e-15);
  EXPECT_EQ(t.name(), "Gauss-Legendre (n_s = 2, order 4)");
}

TEST(TableauKnownValues, GaussThreeStages) {
  const double r15 = std::sqrt(15.0);
  const Tableau t = make_tableau(RkScheme::GaussLegendre, 3);
  expect_matrix_near(t.c, Eigen::Vector3d(0.5 - r15 / 10.0, 0.5, 0.5 + r15 / 10.0), 1e-15);
  expect_matrix_near(t.b, Eigen::Vector3d(5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0), 1e-15);
  Eigen::Matrix3d A;
  A << 5.0 / 36.0, 2.0 / 9.0 - r15 / 15.0, 5.0 / 36.0 - r15 / 30.0,  //
      5.0 / 36.0 + r15 / 24.0, 2.0 / 9.0, 5.0 / 36.0 - r15 / 24.0,   //
      5.0 / 36.0 + r15 / 30.0, 2.0 / 9.0 + r15 / 15.0, 5.0 / 36.0;
  expect_matrix_near(t.A, A, 1e-15);
}

TEST(TableauKnownValues, LobattoIIIATwoAndThreeStages) {
  const Tableau t2 = make_tableau(RkScheme::LobattoIIIA, 2);  // trapezoidal rule
  Eigen::Matrix2d A2;
  A2 << 0.0, 0.0, 0.5, 0.5;
  expect_matrix_near(t2.A, A2, 1e-15);
  expect_matrix_near(t2.b, Eigen::Vector2d(0.5, 0.5), 1e-15);
  expect_matrix_near(t2.c, Eigen::Vector2d(0.0, 1.0), 0.0);

  const Tableau t3 = make_tableau(RkScheme::LobattoIIIA, 3);
  Eigen::Matrix3d A3;
  A3 << 0.0, 0.0, 0.0,                     //
      5.0 / 24.0, 1.0 / 3.0, -1.0 / 24.0,  //
      1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0;
  expect_matrix_near(t3.A, A3, 1e-15);
  expect_matrix_near(t3.b, Eigen::Vector3d(1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0), 1e-15);
  expect_matrix_near(t3.c, Eigen::Vector3d(0.0, 0.5, 1.0), 0.0);
  EXPECT_EQ(t3.name(), "Lobatto IIIA (n_s = 3, order 4)");
}

TEST(TableauKnownValues, LobattoIIICTwoAndThreeStages) {
  const Tableau t2 = make_tableau(RkScheme::LobattoIIIC, 2);
  Eigen::Matrix2d A2;
  A2 << 0.5, -0.5, 0.5, 0.5;
  expect_matrix_near(t2.A, A2, 1e-15);
  expect_matrix_near(t2.b, Eigen::Vector2d(0.5, 0.5), 1e-15);

  const Tableau t3 = make_tableau(RkScheme::LobattoIIIC, 3);
  Eigen::Matrix3d A3;
  A3 << 1.0 / 6.0, -1.0 / 3.0, 1.0 / 6.0,  //
      1.0 / 6.0, 5.0 / 12.0, -1.0 / 12.0,  //
      1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0;
  expect_matrix_near(t3.A, A3, 1e-15);
  EXPECT_EQ(t3.name(), "Lobatto IIIC (n_s = 3, order 4)");
}

TEST(TableauKnownValues, ExplicitMethods) {
  const Tableau euler = make_tableau(RkScheme::ExplicitRK, 1);
  EXPECT_EQ(euler.A(0, 0), 0.0);
  EXPECT_EQ(euler.b(0), 1.0);
  EXPECT_EQ(euler.c(0), 0.0);

  const Tableau heun = make_tableau(RkScheme::ExplicitRK, 2);
  EXPECT_EQ(heun.A(1, 0), 1.0);
  expect_matrix_near(heun.b, Eigen::Vector2d(0.5, 0.5), 0.0);
  expect_matrix_near(heun.c, Eigen::Vector2d(0.0, 1.0), 0.0);

  const Tableau kutta = make_tableau(RkScheme::ExplicitRK, 3);
  Eigen::Matrix3d A3;
  A3 << 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, -1.0, 2.0, 0.0;
  expect_matrix_near(kutta.A, A3, 0.0);
  expect_matrix_near(kutta.b, Eigen::Vector3d(1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0), 0.0);
  expect_matrix_near(kutta.c, Eigen::Vector3d(0.0, 0.5, 1.0), 0.0);

  const Tableau rk4 = make_tableau(RkScheme::ExplicitRK, 4);
  Eigen::Matrix4d A4 = Eigen::Matrix4d::Zero();
  A4(1, 0) = 0.5;
  A4(2, 1) = 0.5;
  A4(3, 2) = 1.0;
  expect_matrix_near(rk4.A, A4, 0.0);
  expect_matrix_near(rk4.b, Eigen::Vector4d(1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0), 0.0);
  expect_matrix_near(rk4.c, Eigen::Vector4d(0.0, 0.5, 0.5, 1.0), 0.0);
  EXPECT_NE(rk4.name().find("(n_s = 4, order 4)"), std::string::npos) << rk4.name();
}

// ---- out-of-range n_s
// ----------------------------------------------------------------------------

class TableauRangeTest : public ::testing::TestWithParam<Case> {};

TEST_P(TableauRangeTest, ThrowsInvalidOptionNamingScheme) {
  const auto [scheme, n_s] = GetParam();
  try {
    (void)make_tableau(scheme, n_s);
    FAIL() << "no exception for n_s = " << n_s;
  } catch (const InvalidOption& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(std::string(to_string(scheme))), std::string::npos) << msg;
    EXPECT_NE(msg.find("n_s = " + std::to_string(n_s)), std::string::npos) << msg;
  }
}

INSTANTIATE_TEST_SUITE_P(
    OutOfRange, TableauRangeTest,
    ::testing::Values(Case{RkScheme::RadauIIA, 0}, Case{RkScheme::RadauIIA, -1},
                      Case{RkScheme::RadauIIA, 10}, Case{RkScheme::GaussLegendre, 0},
                      Case{RkScheme::GaussLegendre, 10}, Case{RkScheme::LobattoIIIA, 1},
                      Case{RkScheme::LobattoIIIA, 0}, Case{RkScheme::LobattoIIIA, 10},
                      Case{RkScheme::LobattoIIIC, 1}, Case{RkScheme::LobattoIIIC, 10},
                      Case{RkScheme::ExplicitRK, 0}, Case{RkScheme::ExplicitRK, 5}),
    [](const ::testing::TestParamInfo<Case>& param_info) {
      const int n = std::get<1>(param_info.param);
      return std::string(to_string(std::get<0>(param_info.param))) + "_" + (n < 0 ? "minus" : "") +
             std::to_string(std::abs(n));
    });

TEST(TableauRange, ExactMessageAndBaseClass) {
  EXPECT_THROW((void)make_tableau(RkScheme::LobattoIIIC, 1), Error);
  try {
    (void)make_tableau(RkScheme::LobattoIIIC, 1);
  } catch (const InvalidOption& e) {
    EXPECT_STREQ(e.what(),
                 "n_s = 1 is out of range for lobatto_iiic: Lobatto methods need n_s >= 2");
  }
}

// ---- names
// ---------------------------------------------------------------------------------------

TEST(RkSchemeNames, RoundTripAndUpperCase) {
  const std::vector<std::pair<RkScheme, std::string>> names = {
      {RkScheme::RadauIIA, "RADAU_IIA"},       {RkScheme::GaussLegendre, "GAUSS_LEGENDRE"},
      {RkScheme::LobattoIIIA, "LOBATTO_IIIA"}, {RkScheme::LobattoIIIC, "LOBATTO_IIIC"},
      {RkScheme::ExplicitRK, "EXPLICIT_RK"},
  };
  for (const auto& [scheme, upper] : names) {
    RkScheme parsed = RkScheme::ExplicitRK;
    ASSERT_TRUE(parse(to_string(scheme), parsed)) << to_string(scheme);
    EXPECT_EQ(parsed, scheme);
    parsed = scheme == RkScheme::RadauIIA ? RkScheme::GaussLegendre : RkScheme::RadauIIA;
    ASSERT_TRUE(parse(upper, parsed)) << upper;
    EXPECT_EQ(parsed, scheme);
  }
  EXPECT_EQ(to_string(RkScheme::RadauIIA), "radau_iia");
  EXPECT_EQ(to_string(RkScheme::GaussLegendre), "gauss_legendre");
  EXPECT_EQ(to_string(RkScheme::LobattoIIIA), "lobatto_iiia");
  EXPECT_EQ(to_string(RkScheme::LobattoIIIC), "lobatto_iiic");
  EXPECT_EQ(to_string(RkScheme::ExplicitRK), "explicit_rk");
}

TEST(RkSchemeNames, UnknownNamesRejected) {
  for (const char* bad : {"", "radau", "Radau_IIA", "radau_iia ", " radau_iia", "gauss", "lobatto",
                          "lobatto_iiib", "LOBATTO_IIIB", "explicit", "rk4", "radau-iia"}) {
    RkScheme out = RkScheme::LobattoIIIC;
    EXPECT_FALSE(parse(bad, out)) << '"' << bad << '"';
    EXPECT_EQ(out, RkScheme::LobattoIIIC) << "out must be untouched for \"" << bad << '"';
  }
}

}  // namespace
}  // namespace fesd
