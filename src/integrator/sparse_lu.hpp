// The sparse LU of the active-set path's square systems (docs/active-set.md, "Factorization"):
// SuiteSparse KLU (Debian libsuitesparse-dev), the pattern analysed once per shape, the values
// gathered from the dense Jacobian storage, numeric factorizations reused where the pivots allow.
#pragma once
#include <vector>

#include <klu.h>

namespace fesd::integrator {

class SparseLu {
 public:
  SparseLu();
  ~SparseLu();
  SparseLu(const SparseLu&) = delete;
  SparseLu& operator=(const SparseLu&) = delete;

  /// The pattern of an n x n matrix: `positions` are row + n * col of its structural nonzeros
  /// (any order, duplicates allowed). Forgets any factorization.
  bool analyze(int n, std::vector<int> positions);
  /// Factors the matrix whose entries are dense[position] (column-major n x n storage): with the
  /// pivot order of the factorization before where that stays well conditioned (KLU refactor),
  /// else with partial pivoting. False if singular: a factorization failed or the smallest
  /// pivot is below 1e-14 times the largest.
  bool factor(const double* dense);
  /// b <- A^-1 b (after a successful factor()).
  void solve(double* b);
  int size() const { return n_; }

 private:
  void free_numeric();
  klu_common common_{};
  klu_symbolic* symbolic_ = nullptr;
  klu_numeric* numeric_ = nullptr;
  int n_ = 0;
  std::vector<int> Ap_, Ai_, pos_;
  std::vector<double> Ax_;
};

}  // namespace fesd::integrator
