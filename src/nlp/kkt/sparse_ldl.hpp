// Sparse multifrontal LDL' with threshold 1x1 / 2x2 pivoting behind MA27's analyse / factorize /
// solve steps (kkt_module.cpp forwards MA27's arguments); see sparse_ldl.cpp.
#pragma once

#include "nlp/kkt/kkt_module.h"

namespace fesd::kkt {

/// MA27AD: AMD on the pattern to size LA and LIW; the ordering itself waits for the first values.
void sparse_analyse(int n, int nz, const int* irn, const int* icn, int* ikeep, int* info,
                    double* ops);
/// MA27BD: A = [values (NZ) | scaling (N) | factor], IW = [header | pattern | fronts].
/// may_warm_scale: matrices of at least kWarmMinRows rows may start from the scaling of the
/// previous factorization of the structure (false: three sweeps from the identity every time).
void sparse_factor(int n, int nz, const int* irn, const int* icn, double* a, int la, int* iw,
                   int liw, int* ikeep, int* maxfrt, double pivtol, bool may_warm_scale, int* info,
                   FesdKktStats* stats);
/// MA27CD: one solve with the factor of sparse_factor, iterative refinement on A's residual. W
/// has MAXFRT entries.
void sparse_solve(int n, const double* a, const int* iw, double* w, double* rhs,
                  FesdKktStats* stats);

}  // namespace fesd::kkt
