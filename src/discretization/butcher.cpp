// src/discretization/butcher.cpp: Butcher tableaus (A, b, c) of eq. 25 of the FESD paper.
//
// The implicit schemes are computed, not tabulated, for n_s = 1..9 (Hairer & Wanner, Solving ODEs
// II, Sec. IV.5):
//  - nodes c: zeros of the shifted Legendre polynomial P_s(2t-1) (Gauss), of P_s - P_{s-1}
//    (Radau IIA, contains t = 1) and of P_s - P_{s-2} (Lobatto, contains t = 0 and t = 1);
//  - collocation methods (Gauss, Radau IIA, Lobatto IIIA): a_ij = int_0^{c_i} l_j(t) dt and
//    b_j = int_0^1 l_j(t) dt with the Lagrange polynomials l_j on the nodes c;
//  - Lobatto IIIC: a_i1 = b_1 and sum_j a_ij c_j^{k-1} = c_i^k / k for k = 1..s-1.
// All integrals are of polynomials of degree <= s-1 and are evaluated exactly (up to rounding) by
// Gauss-Legendre quadrature; no Vandermonde system is ever solved, so the result stays accurate to
// a few ulps for every supported n_s.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>
#include <fesd/error.hpp>
#include <fesd/tableau.hpp>

namespace fesd {
namespace {

constexpr int kMaxImplicitStages = 9;
constexpr int kMaxExplicitStages = 4;

// ---- Legendre polynomials ------------------------------------------------------------------

// Values P_0(x)..P_n(x) and derivatives P_0'(x)..P_n'(x) by Bonnet's recurrence
//   (k+1) P_{k+1} = (2k+1) x P_k - k P_{k-1},
//   (k+1) P'_{k+1} = (2k+1) (P_k + x P'_k) - k P'_{k-1}   (its derivative; no 1/(1-x^2)).
struct LegendreTable {
  std::vector<double> p, dp;
};

LegendreTable legendre_table(int n, double x) {
  LegendreTable t;
  t.p.assign(static_cast<std::size_t>(n) + 1, 0.0);
  t.dp.assign(static_cast<std::size_t>(n) + 1, 0.0);
  t.p[0] = 1.0;
  if (n >= 1) {
    t.p[1] = x;
    t.dp[1] = 1.0;
  }
  for (int k = 1; k < n; ++k) {
    const double kd = k;
    t.p[k + 1] = ((2.0 * kd + 1.0) * x * t.p[k] - kd * t.p[k - 1]) / (kd + 1.0);
    t.dp[k + 1] = ((2.0 * kd + 1.0) * (t.p[k] + x * t.dp[k]) - kd * t.dp[k - 1]) / (kd + 1.0);
  }
  return t;
}

// The node polynomial on [-1, 1]: f(x) = P_s(x) - P_{s-d}(x) for d = 1 (Radau) or 2 (Lobatto),
// f(x) = P_s(x) for d = 0 (Gauss). Returns f(x) and f'(x).
struct ValueAndSlope {
  double f, df;
};

ValueAndSlope node_polynomial(int s, int d, double x) {
  const LegendreTable t = legendre_table(s, x);
  if (d == 0) return {t.p[s], t.dp[s]};
  return {t.p[s] - t.p[s - d], t.dp[s] - t.dp[s - d]};
}

// ---- interior roots --------------------------------------------------------------------------

// Zeros of the Jacobi polynomial P_m^{(alpha, beta)} (weight (1-x)^alpha (1+x)^beta on [-1, 1]),
// ascending, as eigenvalues of the symmetric tridiagonal Jacobi matrix of the monic three-term
// recurrence (Golub-Welsch). With (alpha, beta) = (0, 0), (1, 0), (1, 1) these are the interior
// zeros of P_s, of P_s - P_{s-1} (m = s-1) and of P_s - P_{s-2} (m = s-2), respectively.
std::vector<double> jacobi_zeros(int m, double alpha, double beta) {
  if (m <= 0) return {};
  Eigen::VectorXd diag(m);
  Eigen::VectorXd sub(m - 1);  // off-diagonal; empty for m = 1
  for (int k = 0; k < m; ++k) {
    const double q = 2.0 * k + alpha + beta;  // 2k + alpha + beta
    // a_k = (beta^2 - alpha^2) / ((q)(q + 2)); zero when alpha == beta (also covers 0/0 at k = 0).
    diag(k) = (alpha == beta) ? 0.0 : (beta * beta - alpha * alpha) / (q * (q + 2.0));
  }
  for (int k = 1; k < m; ++k) {
    const double q = 2.0 * k + alpha + beta;
    // b_k^2 = 4 k (k + alpha) (k + beta) (k + alpha + beta) / (q^2 (q + 1) (q - 1)).
    const double num = 4.0 * k * (k + alpha) * (k + beta) * (k + alpha + beta);
    sub(k - 1) = std::sqrt(num / (q * q * (q + 1.0) * (q - 1.0)));
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig;
  eig.computeFromTridiagonal(diag, sub, Eigen::EigenvaluesOnly);
  std::vector<double> x(eig.eigenvalues().data(), eig.eigenvalues().data() + m);
  std::sort(x.begin(), x.end());
  return x;
}

// Newton polish of a simple zero x0 of the node polynomial f = P_s - P_{s-d}. The eigenvalue start
// is already accurate to a few ulps; a couple of Newton steps remove any residual bias.
double polish_root(int s, int d, double x0) {
  double x = x0;
  for (int it = 0; it < 8; ++it) {
    const ValueAndSlope v = node_polynomial(s, d, x);
    if (v.df == 0.0) break;
    const double dx = v.f / v.df;
    x -= dx;
    if (std::abs(dx) <= 1e-16) break;  // converged to rounding level
  }
  // From an accurate start Newton moves x by ~1e-16; guard against divergence anyway.
  return std::abs(x - x0) <= 1e-8 ? x : x0;
}

// Mirrors nodes on [0, 1] about 1/2 (exact symmetry c_i + c_{s+1-i} = 1 of Gauss and Lobatto).
void symmetrize(std::vector<double>& c) {
  const std::size_t s = c.size();
  for (std::size_t i = 0; i < s / 2; ++i) {
    const double lo = 0.5 * (c[i] + (1.0 - c[s - 1 - i]));
    c[i] = lo;
    c[s - 1 - i] = 1.0 - lo;
  }
  if (s % 2 == 1) c[s / 2] = 0.5;
}

// Nodes c_1 < ... < c_s on [0, 1] of the given implicit scheme (t = (1 + x) / 2).
std::vector<double> collocation_nodes(RkScheme scheme, int s) {
  int d = 0;  // node polynomial P_s - P_{s-d}
  double alpha = 0.0, beta = 0.0;
  int m = s;  // number of interior (free) zeros
  switch (scheme) {
    case RkScheme::GaussLegendre:
      break;
    case RkScheme::RadauIIA:
      d = 1, alpha = 1.0, m = s - 1;
      break;
    default:  // Lobatto IIIA / IIIC
      d = 2, alpha = 1.0, beta = 1.0, m = s - 2;
      break;
  }
  std::vector<double> c;
  c.reserve(static_cast<std::size_t>(s));
  if (d == 2) c.push_back(0.0);
  for (double x : jacobi_zeros(m, alpha, beta)) c.push_back(0.5 * (1.0 + polish_root(s, d, x)));
  if (d >= 1) c.push_back(1.0);
  std::sort(c.begin(), c.end());
  if (scheme != RkScheme::RadauIIA) symmetrize(c);
  return c;
}

// ---- quadrature and Lagrange polynomials -----------------------------------------------------

// m-point Gauss-Legendre rule on [0, 1]: nodes tau_q and weights w_q (sum w_q = 1), exact for
// polynomials of degree <= 2m - 1. Weights w = 1 / ((1 - x^2) P_m'(x)^2) (half the [-1, 1] ones).
struct QuadratureRule {
  std::vector<double> tau, w;
};

QuadratureRule gauss_rule_01(int m) {
  QuadratureRule r;
  for (double x0 : jacobi_zeros(m, 0.0, 0.0)) {
    const double x = polish_root(m, 0, x0);
    const double dp = legendre_table(m, x).dp[m];
    r.tau.push_back(0.5 * (1.0 + x));
    r.w.push_back(1.0 / ((1.0 - x * x) * dp * dp));
  }
  return r;
}

// Lagrange polynomial l_j(t) = prod_{k != j} (t - nodes_k) / (nodes_j - nodes_k).
double lagrange(const std::vector<double>& nodes, std::size_t j, double t) {
  double l = 1.0;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (k != j) l *= (t - nodes[k]) / (nodes[j] - nodes[k]);
  }
  return l;
}

// int_0^upper l_j(t) dt = upper * sum_q w_q l_j(upper * tau_q) (exact: deg l_j <= 2m - 1).
double integrate_lagrange(const std::vector<double>& nodes, std::size_t j, double upper,
                          const QuadratureRule& rule) {
  double sum = 0.0;
  for (std::size_t q = 0; q < rule.tau.size(); ++q) {
    sum += rule.w[q] * lagrange(nodes, j, upper * rule.tau[q]);
  }
  return upper * sum;
}

// ---- tableaus --------------------------------------------------------------------------------

// Collocation tableau on nodes c: a_ij = int_0^{c_i} l_j, b_j = int_0^1 l_j.
void fill_collocation(const std::vector<double>& c, Tableau& t) {
  const int s = t.n_s;
  const QuadratureRule rule = gauss_rule_01(s);  // exact to degree 2s-1 >= s-1
  for (int j = 0; j < s; ++j) {
    const auto ju = static_cast<std::size_t>(j);
    t.b(j) = integrate_lagrange(c, ju, 1.0, rule);
    for (int i = 0; i < s; ++i) {
      t.A(i, j) = integrate_lagrange(c, ju, c[static_cast<std::size_t>(i)], rule);
    }
  }
}

// Lobatto IIIC (discontinuous collocation): a_i1 = b_1 and
// sum_j a_ij p(c_j) = int_0^{c_i} p for every polynomial p of degree <= s-2 (i.e. C(s-1)).
// Taking p = L_m, the Lagrange polynomial on the s-1 nodes c_2..c_s, gives directly
// a_im = int_0^{c_i} L_m(t) dt - b_1 L_m(c_1), m = 2..s, with c_1 = 0.
void fill_lobatto_iiic(const std::vector<double>& c, Tableau& t) {
  const int s = t.n_s;
  const QuadratureRule rule = gauss_rule_01(s);
  const std::vector<double> tail(c.begin() + 1, c.end());  // c_2..c_s
  const double b1 = t.b(0);
  for (int i = 0; i < s; ++i) {
    t.A(i, 0) = b1;
    for (int m = 1; m < s; ++m) {
      const auto mu = static_cast<std::size_t>(m - 1);
      t.A(i, m) = integrate_lagrange(tail, mu, c[static_cast<std::size_t>(i)], rule) -
                  b1 * lagrange(tail, mu, c[0]);
    }
  }
}

void fill_explicit(Tableau& t) {
  t.A.setZero();
  switch (t.n_s) {
    case 1:  // explicit Euler
      t.b << 1.0;
      t.c << 0.0;
      break;
    case 2:  // Heun (explicit trapezoidal rule)
      t.A(1, 0) = 1.0;
      t.b << 0.5, 0.5;
      t.c << 0.0, 1.0;
      break;
    case 3:  // Kutta's third-order method
      t.A(1, 0) = 0.5;
      t.A(2, 0) = -1.0;
      t.A(2, 1) = 2.0;
      t.b << 1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0;
      t.c << 0.0, 0.5, 1.0;
      break;
    default:  // classical fourth-order Runge-Kutta
      t.A(1, 0) = 0.5;
      t.A(2, 1) = 0.5;
      t.A(3, 2) = 1.0;
      t.b << 1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0;
      t.c << 0.0, 0.5, 0.5, 1.0;
      break;
  }
}

std::string range_error(RkScheme scheme, int n_s, const std::string& why) {
  return "n_s = " + std::to_string(n_s) + " is out of range for " + std::string(to_string(scheme)) +
         ": " + why;
}

void check_range(RkScheme scheme, int n_s) {
  switch (scheme) {
    case RkScheme::RadauIIA:
    case RkScheme::GaussLegendre:
      if (n_s < 1) throw InvalidOption(range_error(scheme, n_s, "need n_s >= 1"));
      break;
    case RkScheme::LobattoIIIA:
    case RkScheme::LobattoIIIC:
      if (n_s < 2) throw InvalidOption(range_error(scheme, n_s, "Lobatto methods need n_s >= 2"));
      break;
    case RkScheme::ExplicitRK:
      if (n_s < 1 || n_s > kMaxExplicitStages) {
        throw InvalidOption(range_error(
            scheme, n_s, "explicit RK needs n_s in 1..4 (Euler, Heun, Kutta 3, classical RK4)"));
      }
      return;
    default:
      throw InvalidOption("unknown Runge-Kutta scheme (enum value " +
                          std::to_string(static_cast<int>(scheme)) + ")");
  }
  if (n_s > kMaxImplicitStages) {
    throw InvalidOption(range_error(scheme, n_s, "implicit schemes are limited to n_s <= 9"));
  }
}

}  // namespace

std::string Tableau::name() const {
  std::string label;
  switch (scheme) {
    case RkScheme::RadauIIA:
      label = "Radau IIA";
      break;
    case RkScheme::GaussLegendre:
      label = "Gauss-Legendre";
      break;
    case RkScheme::LobattoIIIA:
      label = "Lobatto IIIA";
      break;
    case RkScheme::LobattoIIIC:
      label = "Lobatto IIIC";
      break;
    case RkScheme::ExplicitRK: {
      static constexpr const char* kExplicit[] = {"explicit Euler", "Heun", "Kutta 3",
                                                  "classical RK4"};
      label = (n_s >= 1 && n_s <= kMaxExplicitStages) ? kExplicit[n_s - 1] : "explicit RK";
      break;
    }
    default:
      label = "unknown scheme";
      break;
  }
  return label + " (n_s = " + std::to_string(n_s) + ", order " + std::to_string(order) + ")";
}

Tableau make_tableau(RkScheme scheme, int n_s) {
  check_range(scheme, n_s);
  Tableau t;
  t.scheme = scheme;
  t.n_s = n_s;
  t.A = Eigen::MatrixXd::Zero(n_s, n_s);
  t.b = Eigen::VectorXd::Zero(n_s);
  t.c = Eigen::VectorXd::Zero(n_s);

  switch (scheme) {
    case RkScheme::ExplicitRK:
      fill_explicit(t);
      t.order = n_s;
      break;
    case RkScheme::GaussLegendre:
    case RkScheme::RadauIIA:
    case RkScheme::LobattoIIIA:
    case RkScheme::LobattoIIIC: {
      const std::vector<double> c = collocation_nodes(scheme, n_s);
      t.c = Eigen::Map<const Eigen::VectorXd>(c.data(), n_s);
      fill_collocation(c, t);  // b (and A, overwritten below for IIIC)
      if (scheme == RkScheme::LobattoIIIC) fill_lobatto_iiic(c, t);
      // Stiff accuracy: for c_s = 1 the last row int_0^1 l_j (collocation) or the IIIC formula
      // equals b_j analytically; copy b so the identity holds bit for bit.
      if (scheme != RkScheme::GaussLegendre) t.A.row(n_s - 1) = t.b.transpose();
      t.order = scheme == RkScheme::GaussLegendre ? 2 * n_s
                : scheme == RkScheme::RadauIIA    ? 2 * n_s - 1
                                                  : 2 * n_s - 2;
      break;
    }
  }

  // Flags from the computed matrix, not from the scheme name.
  t.stiffly_accurate = (t.A.row(n_s - 1) - t.b.transpose()).cwiseAbs().maxCoeff() <= 1e-14;
  t.is_explicit = true;
  for (int i = 0; i < n_s && t.is_explicit; ++i) {
    for (int j = i; j < n_s; ++j) {
      if (t.A(i, j) != 0.0) {
        t.is_explicit = false;
        break;
      }
    }
  }
  return t;
}

}  // namespace fesd
