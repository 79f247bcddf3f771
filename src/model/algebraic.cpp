// src/model/algebraic.cpp: z(x, u, p) from g_z = 0 by Newton, derivatives by chord steps in AD
// arithmetic (see algebraic.hpp).
#include "model/algebraic.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "fesd/ad.hpp"
#include "fesd/error.hpp"

namespace fesd {

AlgebraicEquations::AlgebraicEquations(int n_base, std::vector<expr::Expression> g_z,
                                       Eigen::VectorXd z0)
    : n_base_(n_base), g_z_(std::move(g_z)), z0_(std::move(z0)) {
  if (z0_.size() != static_cast<Eigen::Index>(g_z_.size()))
    throw InternalError("internal: algebraic equations: z0 and g_z differ in length");
}

void AlgebraicEquations::residual(const double* s, Eigen::VectorXd& g) const {
  g.resize(n_z());
  for (int i = 0; i < n_z(); ++i) g[i] = g_z_[static_cast<std::size_t>(i)].evaluate<double>(s);
}

void AlgebraicEquations::jacobian(const double* s, Eigen::MatrixXd& J) const {
  // Forward AD, 8 columns of dg_z/dz per pass.
  using J8 = ad::Jet<8>;
  const int n = n_base_ + n_z();
  J.resize(n_z(), n_z());
  std::vector<J8> in(static_cast<std::size_t>(n));
  for (int c0 = 0; c0 < n_z(); c0 += 8) {
    const int dirs = std::min(8, n_z() - c0);
    for (int a = 0; a < n; ++a) in[static_cast<std::size_t>(a)] = J8(s[a]);
    for (int d = 0; d < dirs; ++d)
      in[static_cast<std::size_t>(n_base_ + c0 + d)] = J8::variable(s[n_base_ + c0 + d], d, dirs);
    for (int i = 0; i < n_z(); ++i) {
      const J8 gi = g_z_[static_cast<std::size_t>(i)].evaluate<J8>(in.data());
      for (int d = 0; d < dirs; ++d) J(i, c0 + d) = gi.d(d);
    }
  }
}

bool AlgebraicEquations::newton(std::vector<double>& s, Eigen::MatrixXd& J) const {
  const int nz = n_z();
  double* z = s.data() + n_base_;
  for (int i = 0; i < nz; ++i) z[i] = z0_[i];
  Eigen::VectorXd g, g_new, dz;
  Eigen::VectorXd z_old(nz);
  residual(s.data(), g);
  for (int it = 0; it < kMaxIterations; ++it) {
    if (!g.allFinite()) return false;
    jacobian(s.data(), J);
    if (!J.allFinite()) return false;
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(J);
    if (!lu.isInvertible()) return false;
    dz = lu.solve(-g);
    if (!dz.allFinite()) return false;
    for (int i = 0; i < nz; ++i) z_old[i] = z[i];
    const double scale = 1.0 + z_old.lpNorm<Eigen::Infinity>();
    if (dz.lpNorm<Eigen::Infinity>() <= kStepTol * scale) {  // converged: a last full step
      for (int i = 0; i < nz; ++i) z[i] = z_old[i] + dz[i];
      residual(s.data(), g);
      jacobian(s.data(), J);
      return g.allFinite() && J.allFinite() && g.lpNorm<Eigen::Infinity>() <= kResidualTol * scale;
    }
    // Backtracking on |g_z|_2: full steps near the root.
    const double r0 = g.norm();
    double step = 1.0;
    for (;;) {
      for (int i = 0; i < nz; ++i) z[i] = z_old[i] + step * dz[i];
      residual(s.data(), g_new);
      if (g_new.allFinite() && g_new.norm() <= (1.0 - 1e-4 * step) * r0) break;
      step *= 0.5;
      if (step < 1e-10) {
        // No decrease: the root is reached to round-off if the residual is tiny.
        for (int i = 0; i < nz; ++i) z[i] = z_old[i];
        jacobian(s.data(), J);
        return g.lpNorm<Eigen::Infinity>() <= kResidualTol * scale;
      }
    }
    g = g_new;
  }
  return false;
}

template <class T>
void AlgebraicEquations::solve(T* symbols) const {
  const int nz = n_z();
  if (nz == 0) return;
  std::vector<double> s(static_cast<std::size_t>(n_base_ + nz));
  for (int a = 0; a < n_base_; ++a) s[static_cast<std::size_t>(a)] = ad::value_of(symbols[a]);
  Eigen::MatrixXd J;
  if (!newton(s, J)) {
    for (int i = 0; i < nz; ++i) symbols[n_base_ + i] = T(std::numeric_limits<double>::quiet_NaN());
    return;
  }
  for (int i = 0; i < nz; ++i) symbols[n_base_ + i] = T(s[static_cast<std::size_t>(n_base_ + i)]);
  if constexpr (!std::is_same_v<T, double>) {
    // Chord steps in T: the derivatives of z by the implicit function theorem (algebraic.hpp).
    const Eigen::MatrixXd Jinv = Eigen::FullPivLU<Eigen::MatrixXd>(J).inverse();
    std::vector<T> g(static_cast<std::size_t>(nz), T(0.0));
    for (int k = 0; k < 3; ++k) {
      for (int i = 0; i < nz; ++i)
        g[static_cast<std::size_t>(i)] = g_z_[static_cast<std::size_t>(i)].evaluate<T>(symbols);
      for (int i = 0; i < nz; ++i) {
        T zi = symbols[n_base_ + i];
        for (int j = 0; j < nz; ++j)
          if (Jinv(i, j) != 0.0) zi = zi - Jinv(i, j) * g[static_cast<std::size_t>(j)];
        symbols[n_base_ + i] = zi;
      }
    }
  }
}

#define FESD_INSTANTIATE_ALGEBRAIC(T) template void AlgebraicEquations::solve<T>(T*) const;
FESD_FOR_EACH_SCALAR(FESD_INSTANTIATE_ALGEBRAIC)
#undef FESD_INSTANTIATE_ALGEBRAIC

}  // namespace fesd
