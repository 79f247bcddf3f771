// src/model/algebraic.hpp: user algebraic variables z with algebraic equations g_z(x, u, p, z) = 0
// (nosnoc's z, z0, g_z; docs/problem-files.md, "Algebraic variables z").
//
// z is eliminated, not a variable of the NLP: wherever an expression of the model or of the OCP
// reads z (at every RK stage point, at the element boundaries where c is evaluated for cross
// complementarity, in the costs), z = z(x, u, p) is the solution of g_z = 0 there, found by
// Newton's method from the guess z0. The result is what the NLP with Z_{n,m} and the rows
// g_z(X_{n,m}, Z_{n,m}) = 0 computes at its solution, with derivatives by the implicit function
// theorem: for an AD scalar type T (first or second order), after Newton has converged in double to
// z*, three chord steps z <- z - J*^{-1} g_z(x, u, p, z) in T arithmetic (J* = dg_z/dz at z*,
// exact by forward AD) give z and its first and second derivatives exactly (the error after k
// steps is O(|dx|^{k+1})): exact derivatives, nothing differenced.
#pragma once
#include <vector>

#include <Eigen/Dense>

#include "model/expression.hpp"

namespace fesd {

class AlgebraicEquations {
 public:
  /// `g_z` (n_z expressions) read the symbol vector [base (n_base symbols), z (n_z)]; z0 is
  /// Newton's start (n_z entries).
  AlgebraicEquations(int n_base, std::vector<expr::Expression> g_z, Eigen::VectorXd z0);

  int n_z() const { return static_cast<int>(g_z_.size()); }
  int n_base() const { return n_base_; }
  const std::vector<expr::Expression>& g_z() const { return g_z_; }
  const Eigen::VectorXd& z0() const { return z0_; }

  /// `symbols` holds n_base + n_z entries; sets the last n_z to z(base). If Newton does not
  /// converge (no root near z0, singular dg_z/dz), z is NaN: the evaluation reports a
  /// non-finite value and the solver backtracks.
  template <class T>
  void solve(T* symbols) const;

  /// Newton's limits: at most kMaxIterations steps; converged when the step is at most
  /// kStepTol (1 + |z|_inf) and |g_z|_inf at most kResidualTol (1 + |z|_inf).
  static constexpr int kMaxIterations = 100;
  static constexpr double kStepTol = 1e-13;
  static constexpr double kResidualTol = 1e-9;

 private:
  /// Newton in double on s = [base, z] (z starts at z0); false if it fails. J: dg_z/dz at the end.
  bool newton(std::vector<double>& s, Eigen::MatrixXd& J) const;
  void residual(const double* s, Eigen::VectorXd& g) const;
  void jacobian(const double* s, Eigen::MatrixXd& J) const;

  int n_base_ = 0;
  std::vector<expr::Expression> g_z_;
  Eigen::VectorXd z0_;
};

}  // namespace fesd
