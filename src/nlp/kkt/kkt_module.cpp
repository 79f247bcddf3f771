// fesd's KKT module: MA27's calling convention (ma27id_, ma27ad_, ma27bd_, ma27cd_) in front of
// two factorizations, so that IPOPT 3.11's loader (linear_solver = ma27, library "libhsl.so",
// this module's SONAME) uses them:
//  - dense LAPACK LDL' (dense_ldl.cpp) for small matrices, bit-for-bit the solver fesd used before
//    the sparse one existed;
//  - sparse multifrontal LDL' (sparse_ldl.cpp) for the rest.
// The choice is made per matrix structure in ma27ad_ (the thread's requested mode, or by size) and
// recorded in NSTEPS, which IPOPT keeps and passes to ma27bd_ and ma27cd_: several IPOPT solves,
// dense and sparse, may be alive at once. Everything else lives in IPOPT's arrays.
#include "nlp/kkt/kkt_module.h"

#include <algorithm>
#include <vector>

#include "nlp/kkt/dense_ldl.hpp"
#include "nlp/kkt/sparse_ldl.hpp"

#define FESD_KKT_EXPORT extern "C" __attribute__((visibility("default")))

namespace {
// NSTEPS values that mark the factorization of a structure. The dense solver always wrote 1.
constexpr int kStepsDense = 1;
constexpr int kStepsSparse = 2;

thread_local int requested_mode = FESD_KKT_AUTO;
thread_local bool fresh_scaling = false;
thread_local FesdKktStats stats{};

/// Matrices kept for benchmarks (fesd_kkt_capture).
struct Captured {
  int n = 0;
  std::vector<int> irn, icn;
  std::vector<double> values;
};
struct Capture {
  int stride = 0, max_count = 0;
  long long seen = 0;
  std::vector<Captured> matrices;
};
thread_local Capture capture;

void maybe_capture(int n, int nz, const int* irn, const int* icn, const double* a) {
  if (capture.stride <= 0 || static_cast<int>(capture.matrices.size()) >= capture.max_count) return;
  if (capture.seen++ % capture.stride != 0) return;
  capture.matrices.push_back(Captured{n, std::vector<int>(irn, irn + nz),
                                      std::vector<int>(icn, icn + nz),
                                      std::vector<double>(a, a + nz)});
}
}  // namespace

FESD_KKT_EXPORT void fesd_kkt_capture(int stride, int max_count) {
  capture = Capture{stride, max_count, 0, {}};
}

FESD_KKT_EXPORT int fesd_kkt_captured_count(void) {
  return static_cast<int>(capture.matrices.size());
}

FESD_KKT_EXPORT void fesd_kkt_captured(int i, int* n, int* nz, const int** irn, const int** icn,
                                       const double** values) {
  const Captured& c = capture.matrices.at(static_cast<std::size_t>(i));
  *n = c.n;
  *nz = static_cast<int>(c.values.size());
  *irn = c.irn.data();
  *icn = c.icn.data();
  *values = c.values.data();
}

FESD_KKT_EXPORT void fesd_kkt_request_mode(int mode) {
  requested_mode = mode;
}

FESD_KKT_EXPORT void fesd_kkt_request_scaling(int fresh) {
  fresh_scaling = fresh != 0;
}

FESD_KKT_EXPORT void fesd_kkt_stats(FesdKktStats* out) {
  *out = stats;
}

FESD_KKT_EXPORT void fesd_kkt_reset_stats(void) {
  stats = FesdKktStats{};
}

FESD_KKT_EXPORT void ma27id_(int* icntl, double* cntl) {
  std::fill_n(icntl, 30, 0);
  std::fill_n(cntl, 5, 0.0);
  cntl[0] = 0.1;
}

FESD_KKT_EXPORT void ma27ad_(const int* n, const int* nz, const int* irn, const int* icn, int*,
                             const int*, int* ikeep, int*, int* nsteps, int* iflag, int*, double*,
                             int* info, double* ops) {
  const bool dense = requested_mode == FESD_KKT_DENSE ||
                     (requested_mode == FESD_KKT_AUTO && *n <= FESD_KKT_DENSE_MAX);
  if (dense) {
    fesd::kkt::dense_analyse(n, nz, ikeep, nsteps, iflag, info, ops);
    return;
  }
  fesd::kkt::sparse_analyse(*n, *nz, irn, icn, ikeep, info, ops);
  *nsteps = kStepsSparse;
  *iflag = info[0];
}

FESD_KKT_EXPORT void ma27bd_(const int* n, const int* nz, const int* irn, const int* icn, double* a,
                             const int* la, int* iw, const int* liw, int* ikeep, int* nsteps,
                             int* maxfrt, int*, int*, double* cntl, int* info) {
  if (*nsteps == kStepsSparse) maybe_capture(*n, *nz, irn, icn, a);
  if (*nsteps == kStepsSparse)
    fesd::kkt::sparse_factor(*n, *nz, irn, icn, a, *la, iw, *liw, ikeep, maxfrt, cntl[0],
                             !fresh_scaling, info, &stats);
  else
    fesd::kkt::dense_factor(n, nz, irn, icn, a, la, iw, liw, maxfrt, info);
}

FESD_KKT_EXPORT void ma27cd_(const int* n, double* a, const int*, int* iw, const int*, double* w,
                             const int*, double* rhs, int*, const int* nsteps, int*, double*) {
  if (*nsteps == kStepsSparse)
    fesd::kkt::sparse_solve(*n, a, iw, w, rhs, &stats);
  else
    fesd::kkt::dense_solve(n, a, iw, rhs);
}
