/* The fesd KKT module's own entry points besides MA27's (ma27id_, ma27ad_, ma27bd_, ma27cd_).
 * libfesd looks them up with dlsym; tests and benchmarks may call them directly. C linkage. */
#ifndef FESD_KKT_MODULE_H
#define FESD_KKT_MODULE_H

#ifdef __cplusplus
extern "C" {
#endif

/* Which factorization the next ma27ad_ calls on this thread choose; the choice is then recorded
 * in the arrays IPOPT owns (NSTEPS), so it holds for that matrix structure until the next
 * analysis. */
enum FesdKktMode {
  FESD_KKT_AUTO = 0,   /* dense for N <= FESD_KKT_DENSE_MAX, sparse LDL' above */
  FESD_KKT_DENSE = 1,  /* dense LAPACK LDL' at any size */
  FESD_KKT_SPARSE = 2  /* sparse multifrontal LDL' at any size */
};
#define FESD_KKT_DENSE_MAX 128

void fesd_kkt_request_mode(int mode);

/* How the sparse factorizations of this thread scale their matrices from now on: 0 (default)
 * from the previous factorization's scaling for matrices of at least 1000 rows (one Ruiz sweep),
 * 1 from the identity at every factorization (three sweeps; the scaling then depends on the
 * matrix alone). NlpOptions::kkt_scaling, docs/kkt-solver.md ("Choosing the scaling"). */
void fesd_kkt_request_scaling(int fresh);

/* Cumulative counters of this thread's ma27bd_ calls that ran the sparse factorization:
 * number of calls, thread CPU seconds in them, delayed pivots, re-orderings, the last matrix's
 * order and entries of the factor, and the per-thread scratch memory held after it (front
 * buffers, contribution blocks: everything outside IPOPT's arrays). */
struct FesdKktStats {
  long long factorizations;
  double factor_seconds;
  long long solves;
  double solve_seconds;
  long long delayed_pivots;
  long long refinement_steps;
  int last_n;
  long long last_factor_entries;
  long long reorderings;         /* orderings computed again within a structure (sparse_ldl.cpp) */
  long long reorderings_undone;  /* of them, undone: the factor was not smaller */
  long long scratch_bytes;       /* the thread's scratch memory after the last factorization */
  long long last_static_entries; /* the last factor's entries without delayed pivots */
  long long warm_scalings;       /* factorizations scaled from the previous one's scaling */
};
void fesd_kkt_stats(struct FesdKktStats* out);
void fesd_kkt_reset_stats(void);

/* For benchmarks: from now on keep a copy of every stride-th matrix the sparse factorization gets
 * on this thread, at most max_count of them (0 stops and frees them). */
void fesd_kkt_capture(int stride, int max_count);
int fesd_kkt_captured_count(void);
/* The i-th captured matrix: order, entries, 1-based triplets (IPOPT's lower triangle) and
 * values; the pointers stay valid until the next fesd_kkt_capture call. */
void fesd_kkt_captured(int i, int* n, int* nz, const int** irn, const int** icn,
                       const double** values);

#ifdef __cplusplus
}
#endif
#endif
