// include/fesd/tableau.hpp: Runge-Kutta Butcher tableaus used inside every finite element (eq. 25
// of the FESD paper).
//
// A tableau (A, b, c) with n_s stages defines the stage equations inside a finite element of length
// h: x_{n,i} = x_n + h * sum_j a_ij f(x_{n,j}), x_{n+1} = x_n + h * sum_j b_j f(x_{n,j}). The
// implicit schemes are computed for any n_s from the roots of (shifted) Legendre polynomials; only
// the four explicit methods are tables.
#pragma once
#include <string>
#include <string_view>

#include <Eigen/Dense>

namespace fesd {

/// Runge-Kutta family. The implicit ones are the collocation methods Gauss-Legendre, Radau IIA and
/// Lobatto IIIA, and the discontinuous-collocation method Lobatto IIIC.
enum class RkScheme { RadauIIA, GaussLegendre, LobattoIIIA, LobattoIIIC, ExplicitRK };

/// Problem-file name: "radau_iia", "gauss_legendre", "lobatto_iiia", "lobatto_iiic", "explicit_rk".
std::string_view to_string(RkScheme s);

/// Parses the problem-file name (exact match). Also accepts nosnoc's upper-case spellings
/// "RADAU_IIA", "GAUSS_LEGENDRE", "LOBATTO_IIIA", "LOBATTO_IIIC", "EXPLICIT_RK". Returns false (and
/// leaves `out` unchanged) if the name is unknown.
bool parse(std::string_view name, RkScheme& out);

/// Butcher tableau (A, b, c) with n_s stages.
struct Tableau {
  RkScheme scheme = RkScheme::RadauIIA;
  int n_s = 0;        // number of stages
  Eigen::MatrixXd A;  // n_s x n_s, entries a_ij
  Eigen::VectorXd b;  // n_s, weights b_j
  Eigen::VectorXd c;  // n_s, nodes c_i (ascending)
  // Classical order for smooth ODEs: Radau IIA 2 n_s - 1, Gauss 2 n_s, Lobatto IIIA/IIIC
  // 2 n_s - 2, explicit n_s.
  int order = 0;
  // Last row of A equals b (up to 1e-14; exactly for the schemes below): Radau IIA, Lobatto IIIA
  // and IIIC. Then c_{n_s} = 1 and the last stage value is the end-point value of the finite
  // element.
  bool stiffly_accurate = false;
  bool is_explicit = false;  // A strictly lower triangular
  std::string name() const;  // e.g. "Radau IIA (n_s = 3, order 5)"
};

/// Builds the tableau of `scheme` with n_s stages.
/// Throws fesd::InvalidOption (<fesd/error.hpp>) if n_s is out of range: Radau IIA and
/// Gauss-Legendre need n_s >= 1, Lobatto IIIA/IIIC n_s >= 2, implicit schemes n_s <= 9, explicit RK
/// n_s in 1..4 (Euler, Heun, Kutta's third-order method, classical RK4).
Tableau make_tableau(RkScheme scheme, int n_s);

}  // namespace fesd
