// A dense symmetric-indefinite KKT solver behind the MA27 calling convention, so that IPOPT
// 3.11's linear-solver loader (option linear_solver = ma27, library "libhsl.so") uses it.
//
// Why: for the small NLPs of the FESD integrator (a few hundred KKT rows), MUMPS spends most of an
// IPOPT iteration in fixed per-call overhead (docs/benchmarks.md). A dense Bunch-Kaufman LDL'
// factorization (LAPACK dsytrf) of a 100 x 100 matrix costs a few microseconds.
//
// Storage: everything lives in the arrays IPOPT owns and passes back on every call, so there is no
// global state. A = [input values (NZ) | dense factor (N*N) | scaling (N)], IW = [pivots (N) | NZ].
// Only for small N: the required LA is NZ + N^2 + N (IPOPT multiplies it by la_init_factor).
#include "nlp/kkt/dense_ldl.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

extern "C" {
void dsytrf_(const char* uplo, const int* n, double* a, const int* lda, int* ipiv, double* work,
             const int* lwork, int* info);
}

namespace fesd::kkt {
namespace {
constexpr int kInfo = 20;
// A pivot below this fraction of the largest entry counts as zero: the matrix is reported
// singular (MA27's IFLAG = 3), and IPOPT regularizes.
constexpr double kSingularRel = 1e-14;
}  // namespace

void dense_analyse(const int* n, const int* nz, int* ikeep, int* nsteps, int* iflag, int* info,
                   double* ops) {
  std::fill_n(info, kInfo, 0);
  std::fill_n(ikeep, 3 * (*n), 0);
  *nsteps = 1;
  *iflag = 0;
  *ops = static_cast<double>(*n) * (*n) * (*n) / 3.0;
  info[4] = *nz + (*n) * (*n) + *n;  // NRLNEC: required LA (values, factor, scaling)
  info[5] = 2 * (*n) + 1;            // NIRNEC: required LIW
}

void dense_factor(const int* n_in, const int* nz_in, const int* irn, const int* icn, double* a,
                  const int* la, int* iw, const int* liw, int* maxfrt, int* info) {
  const int n = *n_in, nz = *nz_in;
  std::fill_n(info, kInfo, 0);
  *maxfrt = 1;
  if (*la < nz + n * n + n) {
    info[0] = -4;
    info[1] = nz + n * n + n;
    return;
  }
  if (*liw < 2 * n + 1) {
    info[0] = -3;
    info[1] = 2 * n + 1;
    return;
  }
  iw[n] = nz;          // ma27cd_ finds the factor behind the input values
  double* F = a + nz;  // column-major n x n, lower triangle used
  std::fill_n(F, static_cast<std::size_t>(n) * n, 0.0);
  double amax = 0.0;
  for (int e = 0; e < nz; ++e) {
    int i = irn[e] - 1, j = icn[e] - 1;
    if (i < j) std::swap(i, j);
    F[static_cast<std::size_t>(j) * n + i] += a[e];
  }
  // Symmetric equilibration S A S (three Ruiz sweeps on the lower triangle): inertia is kept by
  // congruence, and the singularity test below becomes scale-free (barrier terms reach 1e12).
  double* scale = F + static_cast<std::size_t>(n) * n;
  std::fill_n(scale, n, 1.0);
  std::vector<double> rmax(static_cast<std::size_t>(n));
  for (int sweep = 0; sweep < 3; ++sweep) {
    std::fill(rmax.begin(), rmax.end(), 0.0);
    for (int j = 0; j < n; ++j)
      for (int i = j; i < n; ++i) {
        const double v = std::abs(F[static_cast<std::size_t>(j) * n + i]);
        rmax[i] = std::max(rmax[i], v);
        rmax[j] = std::max(rmax[j], v);
      }
    for (int i = 0; i < n; ++i) rmax[i] = rmax[i] > 0 ? 1.0 / std::sqrt(rmax[i]) : 1.0;
    for (int j = 0; j < n; ++j)
      for (int i = j; i < n; ++i) F[static_cast<std::size_t>(j) * n + i] *= rmax[i] * rmax[j];
    for (int i = 0; i < n; ++i) scale[i] *= rmax[i];
  }
  for (int j = 0; j < n; ++j)
    for (int i = j; i < n; ++i)
      amax = std::max(amax, std::abs(F[static_cast<std::size_t>(j) * n + i]));
  int lwork = -1, lapack_info = 0;
  double wsize = 0;
  dsytrf_("L", &n, F, &n, iw, &wsize, &lwork, &lapack_info);
  lwork = std::max(1, static_cast<int>(wsize));
  std::vector<double> work(static_cast<std::size_t>(lwork));
  dsytrf_("L", &n, F, &n, iw, work.data(), &lwork, &lapack_info);
  if (lapack_info < 0) {
    info[0] = -1;
    return;
  }
  // Inertia from the block-diagonal D: a 2x2 block always has one negative eigenvalue when its
  // determinant is negative, two of the sign of its diagonal otherwise.
  const double tiny = kSingularRel * std::max(amax, 1e-300);
  int neg = 0, rank = 0;
  bool singular = lapack_info > 0;
  for (int k = 0; k < n;) {
    const double d11 = F[static_cast<std::size_t>(k) * n + k];
    if (iw[k] > 0) {
      if (std::abs(d11) <= tiny)
        singular = true;
      else
        ++rank;
      if (d11 < 0) ++neg;
      k += 1;
    } else {
      const double d21 = F[static_cast<std::size_t>(k) * n + k + 1];
      const double d22 = F[static_cast<std::size_t>(k + 1) * n + k + 1];
      const double det = d11 * d22 - d21 * d21;
      if (std::abs(det) <= tiny * tiny)
        singular = true;
      else
        rank += 2;
      if (det < 0)
        neg += 1;
      else if (d11 + d22 < 0)
        neg += 2;
      k += 2;
    }
  }
  info[14] = neg;
  if (singular) {
    info[0] = 3;
    info[1] = rank;
  }
}

namespace {
/// Solves (L D L') x = b in place for dsytrf's lower factor F (column-major, leading dimension n)
/// and pivots ipiv: the steps of LAPACK's dsytrs with UPLO = 'L', as plain loops. On Debian's
/// reference BLAS, dsytrs' per-column dgemv/dger calls dominated IPOPT's back-solves.
void ldlt_solve(int n, const double* F, const int* ipiv, double* b) {
  auto L = [&](int i, int j) { return F[static_cast<std::size_t>(j) * n + i]; };
  // Forward: solve L D y = P b.
  for (int k = 0; k < n;) {
    if (ipiv[k] > 0) {
      const int kp = ipiv[k] - 1;
      std::swap(b[k], b[kp]);
      const double bk = b[k];
      const double* col = F + static_cast<std::size_t>(k) * n;
      for (int i = k + 1; i < n; ++i) b[i] -= col[i] * bk;
      b[k] /= L(k, k);
      k += 1;
    } else {
      const int kp = -ipiv[k] - 1;
      std::swap(b[k + 1], b[kp]);
      const double b0 = b[k], b1 = b[k + 1];
      const double* c0 = F + static_cast<std::size_t>(k) * n;
      const double* c1 = F + static_cast<std::size_t>(k + 1) * n;
      for (int i = k + 2; i < n; ++i) b[i] -= c0[i] * b0 + c1[i] * b1;
      const double d21 = L(k + 1, k);
      const double d11 = L(k, k) / d21, d22 = L(k + 1, k + 1) / d21;
      const double denom = d11 * d22 - 1.0;
      const double y0 = b0 / d21, y1 = b1 / d21;
      b[k] = (d22 * y0 - y1) / denom;
      b[k + 1] = (d11 * y1 - y0) / denom;
      k += 2;
    }
  }
  // Backward: solve L' P' x = y.
  for (int k = n - 1; k >= 0;) {
    const double* col = F + static_cast<std::size_t>(k) * n;
    double s = 0.0;
    for (int i = k + 1; i < n; ++i) s += col[i] * b[i];
    b[k] -= s;
    if (ipiv[k] > 0) {
      std::swap(b[k], b[ipiv[k] - 1]);
      k -= 1;
    } else {
      const double* prev = F + static_cast<std::size_t>(k - 1) * n;
      double t = 0.0;
      for (int i = k + 1; i < n; ++i) t += prev[i] * b[i];
      b[k - 1] -= t;
      std::swap(b[k], b[-ipiv[k] - 1]);
      k -= 2;
    }
  }
}
}  // namespace

void dense_solve(const int* n_in, double* a, int* iw, double* rhs) {
  const int n = *n_in;
  // The factor sits behind the NZ input values; recover NZ from the layout IW = [pivots | NZ].
  const int nz = iw[n];
  const double* scale = a + nz + static_cast<std::size_t>(n) * n;
  for (int i = 0; i < n; ++i) rhs[i] *= scale[i];  // (S A S) y = S b, x = S y
  ldlt_solve(n, a + nz, iw, rhs);
  for (int i = 0; i < n; ++i) rhs[i] *= scale[i];
}

}  // namespace fesd::kkt
