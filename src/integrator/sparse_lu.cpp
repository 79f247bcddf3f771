// See sparse_lu.hpp.
#include "integrator/sparse_lu.hpp"

#include <algorithm>
#include <cmath>

namespace fesd::integrator {

namespace {
/// A refactorization with the pivots of the one before is kept only if its pivot ratio stays
/// above this; below, the matrix is factored again with partial pivoting.
constexpr double kRefactorRcond = 1e-8;
/// Singular: the smallest pivot below this times the largest (the dense LU's rule before).
constexpr double kSingularRcond = 1e-14;
}  // namespace

SparseLu::SparseLu() {
  klu_defaults(&common_);
  common_.tol = 1.0;  // partial pivoting: always the largest entry of the column
}

SparseLu::~SparseLu() {
  free_numeric();
  if (symbolic_ != nullptr) klu_free_symbolic(&symbolic_, &common_);
}

void SparseLu::free_numeric() {
  if (numeric_ != nullptr) klu_free_numeric(&numeric_, &common_);
}

bool SparseLu::analyze(int n, std::vector<int> positions) {
  free_numeric();
  if (symbolic_ != nullptr) klu_free_symbolic(&symbolic_, &common_);
  n_ = n;
  std::sort(positions.begin(), positions.end());
  positions.erase(std::unique(positions.begin(), positions.end()), positions.end());
  pos_ = std::move(positions);  // column-major order: CSC with rows ascending
  Ap_.assign(static_cast<std::size_t>(n) + 1, 0);
  Ai_.resize(pos_.size());
  for (std::size_t k = 0; k < pos_.size(); ++k) {
    Ai_[k] = pos_[k] % n;
    ++Ap_[static_cast<std::size_t>(pos_[k] / n) + 1];
  }
  for (int j = 0; j < n; ++j) Ap_[j + 1] += Ap_[j];
  Ax_.resize(pos_.size());
  if (n == 0) return false;
  symbolic_ = klu_analyze(n, Ap_.data(), Ai_.data(), &common_);
  return symbolic_ != nullptr;
}

bool SparseLu::factor(const double* dense) {
  if (symbolic_ == nullptr) return false;
  for (std::size_t k = 0; k < pos_.size(); ++k) Ax_[k] = dense[pos_[k]];
  if (numeric_ != nullptr &&
      klu_refactor(Ap_.data(), Ai_.data(), Ax_.data(), symbolic_, numeric_, &common_) == 1 &&
      klu_rcond(symbolic_, numeric_, &common_) == 1 && common_.rcond > kRefactorRcond)
    return true;
  free_numeric();
  numeric_ = klu_factor(Ap_.data(), Ai_.data(), Ax_.data(), symbolic_, &common_);
  if (numeric_ == nullptr || common_.status != KLU_OK) return false;
  if (klu_rcond(symbolic_, numeric_, &common_) != 1) return false;
  return common_.rcond > kSingularRcond && std::isfinite(common_.rcond);
}

void SparseLu::solve(double* b) {
  klu_solve(symbolic_, numeric_, n_, 1, b, &common_);
}

}  // namespace fesd::integrator
