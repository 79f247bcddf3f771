// Dense LDL' (LAPACK dsytrf) behind MA27's analyse / factorize / solve steps, for small KKT
// matrices. The arguments are MA27's (kkt_module.cpp forwards them); see dense_ldl.cpp.
#pragma once

namespace fesd::kkt {

void dense_analyse(const int* n, const int* nz, int* ikeep, int* nsteps, int* iflag, int* info,
                   double* ops);
void dense_factor(const int* n, const int* nz, const int* irn, const int* icn, double* a,
                  const int* la, int* iw, const int* liw, int* maxfrt, int* info);
void dense_solve(const int* n, double* a, int* iw, double* rhs);

}  // namespace fesd::kkt
