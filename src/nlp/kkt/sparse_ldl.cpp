// Sparse symmetric-indefinite LDL' for IPOPT's KKT matrices, behind MA27's three steps.
//
// Why: above ~128 rows MUMPS took ~80 % of an IPOPT iteration on OCP (61), mostly in per-call
// overhead and reference-BLAS kernels on small fronts (docs/kkt-solver.md).
//
// Method (docs/kkt-solver.md):
//  - Ordering, once per matrix structure, on the first matrix's values: every row whose diagonal
//    is zero (a constraint row of the KKT matrix) is matched to the neighbour with the largest
//    entry, the pair becomes one node, and AMD (SuiteSparse) orders the compressed graph; a pair is
//    eliminated as (its nonzero-diagonal row, then the zero-diagonal row). Plain AMD put constraint
//    rows before their variables and delayed a pivot on almost every constraint.
//  - Symmetric equilibration (three Ruiz sweeps, factors rounded to powers of two): inertia is
//    kept by congruence and the pivot tests become scale-free.
//  - Elimination tree (Liu), column counts, supernodes = chains of the tree, relaxed amalgamation
//    (kRelax); multifrontal factorization in tree order with dense fronts. Computed once per
//    structure and kept in IW while IPOPT keeps IW.
//  - In a front: threshold pivoting among the fully summed rows, 1x1 if |d| >= u * column max,
//    else a 2x2 with the largest fully summed entry of the column if |D^-1| bounds the growth by
//    1/u; u = IPOPT's ma27_pivtol (CNTL(1)). Pivots that fail move up to the parent front
//    (delayed pivots). A fully summed column that is zero to round-off (every entry <= tiny) is
//    eliminated at once as a zero pivot; columns still failing at a root are zero to round-off
//    too: either way the matrix is reported singular (MA27's IFLAG = 3) and IPOPT regularizes.
//  - Inertia: negative eigenvalues of D (1x1 by sign, 2x2 by determinant and trace), exact by
//    Sylvester's law.
//  - Solve: forward / diagonal / backward over the fronts, then iterative refinement on the
//    residual of the unscaled matrix until the normwise backward error is <= kBerrTarget.
//
// Storage: all state is in the arrays IPOPT owns. IKEEP = [ordering (N) | unused (N) | state
// (KeepSlot)], A = [values (NZ) | scaling (N) | per front its nf x nelim block of L with D on the
// diagonal and a 2x2 pivot's off-diagonal at L(k+1, k)], IW = [header | pattern (2 NZ) | symbolic
// analysis (Symbolic) | per front: nf, nelim, offset in A, nf indices, nelim pivot kinds, record
// start]. Per-thread scratch memory (Workspace: front buffers, the contribution stack) holds no
// state between calls.
#include "nlp/kkt/sparse_ldl.hpp"

#include <amd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "core/thread_clock.hpp"

namespace fesd::kkt {
namespace {

using Index = std::int64_t;

constexpr int kInfo = 20;
constexpr int kMagic = 0x46544b4b;  // IW[0]: the factor in IW/A is ours
constexpr int kHeader = 16;         // IW header length
// IKEEP[2N]: whether IKEEP[0..N) holds the value-based ordering yet (MA27AD has no values).
constexpr int kOrderingPending = 0;
constexpr int kOrderingReady = 1;
/// Largest number of columns merged into one supernode (a chain of the elimination tree).
constexpr int kMaxSupernodeCols = 48;
/// Relaxed amalgamation: a front merges into its parent's if together they have at most max_cols
/// columns and a fraction below max_zeros of the merged front's entries are explicit zeros.
struct Relax {
  double max_cols, max_zeros;
};
constexpr Relax kRelax[] = {{8, 1.0}, {16, 0.3}, {48, 0.05}};
/// A pivot (1x1) or a 2x2 pivot's determinant scale below this fraction of the scaled matrix's
/// largest entry counts as zero: kTinyRel below kLargeKktRows rows, kTinyRelLarge from there on.
/// Threshold pivoting (u) keeps the factor stable whatever this is; it only decides which columns
/// are "zero" and make the matrix singular (IFLAG = 3), upon which IPOPT regularizes. On
/// hysteresis_car_control_time_optimal_2d (KKT order 24081) 1e-14 reported nonsingular matrices
/// near mu = 1e-9..1e-11 singular: IPOPT took the Jacobian as degenerate, raised delta_x to
/// 1e7-1e19 and ended with Restoration_Failed; with 1e-20 it converges (docs/kkt-solver.md,
/// "Row 30"). The integrator's small NLPs need 1e-14: with 1e-16 or below four acceptance tests
/// of the temperature control, stick-slip and PDS examples miss their tolerances.
constexpr double kTinyRel = 1e-14;
constexpr double kTinyRelLarge = 1e-20;
constexpr int kLargeKktRows = 5000;
/// A diagonal below this fraction of its row's largest entry makes a row "zero-diagonal" for the
/// ordering's matching.
constexpr double kZeroDiagRel = 1e-10;
/// Re-ordering: from kLargeKktRows rows on, a factorization whose matrix has fewer zero-diagonal
/// rows than the one the ordering was computed on, by more than 1 / kReorderZeroDrop of them,
/// computes the ordering (matching and AMD) and the symbolic analysis again from its own values,
/// at most kMaxReorders times per structure (MA27AD). Only the first kReorderChecks
/// factorizations of a structure are checked: the count is a pass over the entries, ~10 % of a
/// factorization of OCP (61) at N_stages 24. IPOPT's first matrix of an NLP is often an
/// unperturbed one (delta_x = 0), where the variables without curvature or bounds have a zero
/// diagonal; matched to constraint rows, they gave an ordering with 1.7x the factor entries and
/// 2-4x the time per factorization for all the (perturbed) matrices after it on the hopper OCP
/// (docs/kkt-solver.md, "Hopper: orderings from unperturbed matrices").
/// The new ordering is kept only if its symbolic analysis has at most kReorderKeep times the
/// factor entries (static fronts, no delayed pivots) of the old one; otherwise the old ordering
/// (saved in IKEEP[N..2N)) comes back before anything is factorized and the structure is not
/// re-ordered again. Measured in docs/kkt-solver.md ("Hopper"): on the hopper the new ordering
/// has well under 0.8x the entries; on OCP (61) at N_stages 24 about the same entries and then
/// 1.5-2x the delayed pivots of the first ordering (+10 % time per factorization) when kept.
constexpr int kReorderZeroDrop = 20;
constexpr int kMaxReorders = 4;
constexpr int kReorderChecks = 10;
constexpr double kReorderKeep = 0.8;
/// Threshold pivoting: u = clamp(CNTL(1), kMinPivtol, kMaxPivtol).
constexpr double kMinPivtol = 1e-8;
constexpr double kMaxPivtol = 0.5;
/// Iterative refinement: at most this many correction solves, stopping once the normwise backward
/// error |b - A x| / (|A| |x| + |b|) (max-norms) is at most kBerrTarget. The componentwise error
/// asked for a correction in most solves on OCP (61), for rows whose |A||x| + |b| is itself
/// round-off, without changing IPOPT's iterates (IPOPT refines on the whole system anyway).
/// Ruiz sweeps of a factorization whose A still holds the previous factorization's scaling (same
/// structure) and that has at least kWarmMinRows rows: kWarmSweeps started from it (three from
/// the identity otherwise). The two sweeps saved are ~7 % of a factorization's CPU time on OCP
/// (61) at N_stages 12 and 24. Not below kWarmMinRows: on every size the warm start changed the
/// round-off, and on the integrator's small NLPs that made IPOPT's pinned re-solve fail in the
/// homotopy path's co-dimension-2 exit of the periodic stick-slip
/// (PeriodicStickSlipExit.BothContactsSlipWhenX1ReachesOne, sanitizer build; its KKT matrices
/// have at most 424 rows, so they keep the three sweeps from the identity, bit for bit).
/// kkt_scaling = fresh (fesd_kkt_request_scaling, may_warm_scale = false) scales every matrix from
/// the identity: the warm scaling drifts over hundreds of factorizations on some problems
/// (docs/kkt-solver.md, "Delayed-pivot cascades", "Choosing the scaling").
constexpr bool kReuseScaling = true;
constexpr int kWarmMinRows = 1000;
constexpr int kWarmSweeps = 1;
constexpr int kMaxRefine = 3;
constexpr double kBerrTarget = 1e-15;

// IW header slots.
enum Header {
  kHMagic = 0,
  kHN,
  kHNz,
  kHFronts,    // number of front records
  kHFirst,     // offset of the first front record
  kHEnd,       // end of the front records
  kHMaxFront,  // largest front
  kHSymbolic,  // offset of the symbolic analysis (layout: Symbolic)
  kHEntries,   // entries of the permuted lower triangle (duplicates kept)
  kHSupernodes,
  kHFrontRows,  // sum of the supernodes' front sizes without delayed pivots
  kHEdgeRows    // sum of the children's contribution rows without delayed pivots
};
// IKEEP[2N + 1 ..]: the symbolic analysis in IW is valid for this IW (address and length), so the
// next factorization reuses it. IPOPT keeps IW between factorizations unless it reallocates it,
// which changes LIW.
// IKEEP[2N + kKScaled ..]: A[NZ .. NZ + N) holds the previous factorization's scaling for this A
// (address and length), the start of the next one's (kWarmSweeps).
enum KeepSlot {
  kKOrdering = 0,
  kKSymbolic,
  kKLiw,
  kKAddrLo,
  kKAddrHi,
  kKSlots,
  kKScaled = kKSlots,
  kKLa,
  kKAAddrLo,
  kKAAddrHi,
  kKScaleSlots,
  kKOrderZeros = kKScaleSlots,  // zero-diagonal rows of the matrix the ordering was computed on
  kKReorders,                   // orderings computed again since MA27AD (kReorderZeroDrop)
  kKFactorizations,             // factorizations since MA27AD, counted up to kReorderChecks
  kKStaticEntries,              // factor entries of the symbolic analysis in IW (static fronts)
  kKCompare,                    // 1: the ordering is new, compare with kKStaticEntries
  kKOrderSlots
};

/// The structure-only part of the factorization, computed once per structure and kept in IW:
/// arrays of ints behind these pointers.
struct Symbolic {
  const int* iperm;     // n: position of each row in the elimination order
  const int* crow;      // entries: rows (permuted numbering) of the permuted lower triangle
  const int* qptr;      // ns + 1: each supernode's entries in the factorization's scaled values
                        //   (own columns in front order, each column's entries as in crow)
  const int* slot;      // nz: where triplet e goes in them (-1: out of range)
  const int* cols_ptr;  // ns + 1: each supernode's columns ...
  const int* cols;      //   ... in elimination order (permuted numbering)
  const int* sparent;   // ns: parent supernode, -1 at a root
  const int* cptr;      // ns + 1: each supernode's children ...
  const int* clist;     //   ... in increasing order
  // Each supernode's front as it is without delayed pivots (the static front), kept so that a
  // factorization builds no index lists: the rows, original numbering, own columns first
  // (elimination order), then the others ascending in elimination order ...
  const int* fptr;   // ns + 1
  const int* frows;  //   ... (the delayed pivots of a factorization go between the two parts);
  // entries (qptr order): the entry's offset in its static front, t ld0 + sp for own column t
  // and static position sp, ld0 = front_ld(static front size): one flat scatter per front.
  const int* aoff;
  const int* eptr;  // clist entries + 1: per child (clist order), the static front positions in
  const int* emap;  //   its parent of its contribution rows other than delayed pivots
  int ns = 0;
};

Index symbolic_length(int n, int nz, int entries, int ns, int front_rows, int edge_rows) {
  return static_cast<Index>(n) * 2 + entries + nz + 4 * static_cast<Index>(ns) + 3 + ns +
         (static_cast<Index>(ns) + 1 + front_rows) + entries + (static_cast<Index>(ns) + edge_rows);
}

Index symbolic_length(const int* iw) {
  return symbolic_length(iw[kHN], iw[kHNz], iw[kHEntries], iw[kHSupernodes], iw[kHFrontRows],
                         iw[kHEdgeRows]);
}

Symbolic symbolic_view(const int* iw) {
  const int n = iw[kHN], nz = iw[kHNz], entries = iw[kHEntries], ns = iw[kHSupernodes];
  Symbolic v;
  const int* q = iw + iw[kHSymbolic];
  v.iperm = q;
  q += n;
  v.crow = q;
  q += entries;
  v.qptr = q;
  q += ns + 1;
  v.slot = q;
  q += nz;
  v.cols_ptr = q;
  q += ns + 1;
  v.cols = q;
  q += n;
  v.sparent = q;
  q += ns;
  v.cptr = q;
  q += ns + 1;
  v.clist = q;
  q += iw[kHSupernodes] > 0 ? v.cptr[ns] : 0;
  v.fptr = q;
  q += ns + 1;
  v.frows = q;
  q += iw[kHFrontRows];
  v.aoff = q;
  q += entries;
  v.eptr = q;
  q += (ns > 0 ? v.cptr[ns] : 0) + 1;
  v.emap = q;
  v.ns = ns;
  return v;
}

/// Entries of L for the symbolic analysis in IW without delayed pivots: per supernode its static
/// front's rows times its columns.
Index static_factor_entries(const int* iw) {
  const Symbolic sym = symbolic_view(iw);
  Index entries = 0;
  for (int s = 0; s < sym.ns; ++s)
    entries +=
        static_cast<Index>(sym.fptr[s + 1] - sym.fptr[s]) * (sym.cols_ptr[s + 1] - sym.cols_ptr[s]);
  return entries;
}

bool valid(int n, int i, int j) {
  return i >= 0 && i < n && j >= 0 && j < n;
}

/// AMD on a symmetric pattern given as column lists (either triangle; duplicates allowed).
/// Returns false if AMD fails (then perm is the identity).
bool amd(int n, const std::vector<int>& colptr, const std::vector<int>& rows, int* perm,
         double* info_out = nullptr) {
  double control[AMD_CONTROL], info[AMD_INFO];
  amd_defaults(control);
  const int status = amd_order(n, colptr.data(), rows.data(), perm, control, info);
  if (info_out != nullptr) std::copy_n(info, AMD_INFO, info_out);
  if (status < AMD_OK) {
    for (int i = 0; i < n; ++i) perm[i] = i;
    return false;
  }
  return true;
}

/// Off-diagonal triplets (0-based) grouped by column, for AMD.
void pattern_columns(int n, int nz, const int* irn, const int* icn, const std::vector<int>& id,
                     int ncols, std::vector<int>& colptr, std::vector<int>& rows) {
  colptr.assign(static_cast<std::size_t>(ncols) + 1, 0);
  for (int e = 0; e < nz; ++e) {
    const int i = irn[e] - 1, j = icn[e] - 1;
    if (!valid(n, i, j) || id[i] == id[j]) continue;
    ++colptr[id[j] + 1];
  }
  for (int c = 0; c < ncols; ++c) colptr[c + 1] += colptr[c];
  rows.assign(static_cast<std::size_t>(colptr[ncols]), 0);
  std::vector<int> next(colptr.begin(), colptr.end() - 1);
  for (int e = 0; e < nz; ++e) {
    const int i = irn[e] - 1, j = icn[e] - 1;
    if (!valid(n, i, j) || id[i] == id[j]) continue;
    rows[next[id[j]]++] = id[i];
  }
}

/// Each row's diagonal (duplicates summed) and largest off-diagonal magnitude.
void diagonal_and_row_max(int n, int nz, const int* irn, const int* icn, const double* a,
                          std::vector<double>& diag, std::vector<double>& rowmax) {
  diag.assign(n, 0.0);
  rowmax.assign(n, 0.0);
  for (int e = 0; e < nz; ++e) {
    const int i = irn[e] - 1, j = icn[e] - 1;
    if (!valid(n, i, j)) continue;
    if (i == j) {
      diag[i] += a[e];
    } else {
      rowmax[i] = std::max(rowmax[i], std::abs(a[e]));
      rowmax[j] = std::max(rowmax[j], std::abs(a[e]));
    }
  }
}

/// A row whose diagonal is at most kZeroDiagRel of its largest off-diagonal entry: the rows the
/// ordering matches.
bool zero_diagonal(double diag, double rowmax) {
  return rowmax != 0.0 && std::abs(diag) <= kZeroDiagRel * rowmax;
}

/// Number of zero-diagonal rows; diag and rowmax are scratch.
int count_zero_diagonal(int n, int nz, const int* irn, const int* icn, const double* a,
                        std::vector<double>& diag, std::vector<double>& rowmax) {
  diagonal_and_row_max(n, nz, irn, icn, a, diag, rowmax);
  int zeros = 0;
  for (int i = 0; i < n; ++i)
    if (zero_diagonal(diag[i], rowmax[i])) ++zeros;
  return zeros;
}

/// The value-based ordering (see the file comment): zero-diagonal rows matched to a neighbour,
/// pairs compressed, AMD on the compressed graph, pairs expanded (nonzero-diagonal row first).
void compute_ordering(int n, int nz, const int* irn, const int* icn, const double* a, int* perm) {
  std::vector<double> diag, rowmax;
  diagonal_and_row_max(n, nz, irn, icn, a, diag, rowmax);
  std::vector<int> deg(static_cast<std::size_t>(n) + 1, 0);
  for (int e = 0; e < nz; ++e) {
    const int i = irn[e] - 1, j = icn[e] - 1;
    if (!valid(n, i, j) || i == j) continue;
    ++deg[i + 1];
    ++deg[j + 1];
  }
  for (int i = 0; i < n; ++i) deg[i + 1] += deg[i];
  std::vector<int> adj(static_cast<std::size_t>(deg[n]));
  std::vector<double> weight(adj.size());
  {
    std::vector<int> next(deg.begin(), deg.end() - 1);
    for (int e = 0; e < nz; ++e) {
      const int i = irn[e] - 1, j = icn[e] - 1;
      if (!valid(n, i, j) || i == j) continue;
      adj[next[i]] = j;
      weight[next[i]++] = std::abs(a[e]);
      adj[next[j]] = i;
      weight[next[j]++] = std::abs(a[e]);
    }
  }
  std::vector<int> mate(n, -1);
  for (int i = 0; i < n; ++i) {
    if (mate[i] >= 0 || !zero_diagonal(diag[i], rowmax[i])) continue;
    int best = -1;
    double best_w = 0.0;
    for (int p = deg[i]; p < deg[i + 1]; ++p)
      if (mate[adj[p]] < 0 && weight[p] > best_w) {
        best = adj[p];
        best_w = weight[p];
      }
    if (best >= 0) {
      mate[i] = best;
      mate[best] = i;
    }
  }
  // Compressed node c: first[c] is eliminated before second[c] (-1: a single row).
  std::vector<int> id(n), first, second;
  for (int i = 0; i < n; ++i) {
    if (mate[i] >= 0 && mate[i] < i) {
      id[i] = id[mate[i]];
      continue;
    }
    id[i] = static_cast<int>(first.size());
    if (mate[i] < 0) {
      first.push_back(i);
      second.push_back(-1);
    } else {
      // The zero-diagonal row goes second: the partner's pivot gives it a nonzero diagonal.
      const bool i_zero = zero_diagonal(diag[i], rowmax[i]);
      first.push_back(i_zero ? mate[i] : i);
      second.push_back(i_zero ? i : mate[i]);
    }
  }
  const int nc = static_cast<int>(first.size());
  std::vector<int> colptr, rows, cperm(nc);
  pattern_columns(n, nz, irn, icn, id, nc, colptr, rows);
  amd(nc, colptr, rows, cperm.data());
  int k = 0;
  for (int c : cperm) {
    perm[k++] = first[c];
    if (second[c] >= 0) perm[k++] = second[c];
  }
}

/// Makes v at least n long. Scratch vectors only grow: resizing one down and up again zero-filled
/// it every time (a memset per front for the contribution blocks).
template <class T>
void grow(std::vector<T>& v, std::size_t n) {
  if (v.size() < n) v.resize(n);
}

/// Rows of a front's column in storage: nf rounded up to a multiple of 4, so the vector kernels
/// need no remainder loops (the padding rows stay zero).
inline int front_ld(int nf) {
  return (nf + 3) & ~3;
}

/// Dense front, column-major nf x nf with leading dimension front_ld(nf), lower triangle used.
class Front {
 public:
  Front(double* f, int nf) : f_(f), nf_(nf), ld_(front_ld(nf)) {}
  double& at(int i, int j) { return f_[static_cast<std::size_t>(j) * ld_ + i]; }  // i >= j
  double sym(int i, int j) { return i >= j ? at(i, j) : at(j, i); }
  double* col(int j) { return f_ + static_cast<std::size_t>(j) * ld_; }

  /// Symmetric interchange of rows/columns a < b, including the rows of the eliminated columns.
  void swap(int a, int b, int* idx) {
    if (a == b) return;
    if (a > b) std::swap(a, b);
    for (int j = 0; j < a; ++j) std::swap(at(a, j), at(b, j));
    std::swap(at(a, a), at(b, b));
    for (int j = a + 1; j < b; ++j) std::swap(at(j, a), at(b, j));
    for (int i = b + 1; i < nf_; ++i) std::swap(at(i, a), at(i, b));
    std::swap(idx[a], idx[b]);
  }

 private:
  double* f_;
  int nf_, ld_;
};

// The kernels get an AVX2/FMA variant chosen at load time (the default build targets plain
// x86-64).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FESD_KKT_KERNEL __attribute__((target_clones("arch=x86-64-v3", "default")))
#define FESD_KKT_INLINE __attribute__((always_inline)) inline
#else
#define FESD_KKT_KERNEL
#define FESD_KKT_INLINE inline
#endif

/// Four doubles (two SSE registers in the default clone, one AVX register in the x86-64-v3 one).
/// Its helpers are always inlined, so GCC's note (-Wpsabi) that passing it by value changes the ABI
/// without AVX does not apply.
using Vec4 = double __attribute__((vector_size(32)));
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
FESD_KKT_INLINE Vec4 load4(const double* p) {
  Vec4 v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
FESD_KKT_INLINE void store4(double* p, Vec4 v) {
  __builtin_memcpy(p, &v, sizeof v);
}

/// Zeroes what the kernels read of a front: column j from row (j rounded down to a multiple of 4)
/// - 4 to the padded end (the kernels' vector loops start up to 7 rows above a diagonal). Half
/// the stores of a memset of the whole front. Kept a loop of stores (GCC's loop distribution would
/// make it a memset call per column).
FESD_KKT_KERNEL [[gnu::noinline, gnu::optimize("no-tree-loop-distribute-patterns")]] void
zero_front(double* f, int nf) {
  const int ld = front_ld(nf);
  const Vec4 zero = {};
  for (int j = 0; j < nf; ++j) {
    double* c = f + static_cast<std::size_t>(j) * ld;
#pragma GCC unroll 4
    for (int i = std::max(0, (j & ~3) - 4); i < ld; i += 4) store4(c + i, zero);
  }
}

/// C(:, j0 .. j0 + NB) -= L W for a front's contribution columns j0 .. j0 + NB: L = the front's
/// first k columns, W = (D L') (row t at w + t ldw). Rows four at a time, from j0 rounded down to
/// a multiple of 4 to the padded end of the column, with NB vector accumulators over all k pivots,
/// so each entry of C is loaded and stored once (the former kernel did an axpy per pivot and
/// column). Rows above a column's diagonal get updated too: the unused upper triangle.
template <int NB>
FESD_KKT_INLINE void contribution_block(int ld, int k, int j0, double* f, const double* w,
                                        int ldw) {
  const std::size_t lds = static_cast<std::size_t>(ld);
  int i = j0 & ~3;
  // Eight rows at a time (two vectors per column: each broadcast of W feeds two FMAs), then four.
  for (; i + 8 <= ld; i += 8) {
    Vec4 acc0[NB] = {}, acc1[NB] = {};
    for (int t = 0; t < k; ++t) {
      const Vec4 l0 = load4(f + t * lds + i), l1 = load4(f + t * lds + i + 4);
      const double* wt = w + static_cast<std::size_t>(t) * ldw;
      for (int c = 0; c < NB; ++c) {
        acc0[c] += l0 * wt[c];
        acc1[c] += l1 * wt[c];
      }
    }
    for (int c = 0; c < NB; ++c) {
      double* cj = f + (j0 + c) * lds + i;
      store4(cj, load4(cj) - acc0[c]);
      store4(cj + 4, load4(cj + 4) - acc1[c]);
    }
  }
  if (i < ld) {
    Vec4 acc[NB] = {};
    for (int t = 0; t < k; ++t) {
      const Vec4 l = load4(f + t * lds + i);
      const double* wt = w + static_cast<std::size_t>(t) * ldw;
      for (int c = 0; c < NB; ++c) acc[c] += l * wt[c];
    }
    for (int c = 0; c < NB; ++c) {
      double* cj = f + (j0 + c) * lds + i;
      store4(cj, load4(cj) - acc[c]);
    }
  }
}

/// Schur update of a front's contribution block (rows and columns >= nfs) with its k pivots:
/// C -= L21 D L21', as a matrix product in blocks of four columns.
FESD_KKT_KERNEL void update_contribution(int nf, int nfs, int k, double* f, const int* kind,
                                         std::vector<double>& wbuf) {
  const int m = nf - nfs, ld = front_ld(nf);
  const std::size_t lds = static_cast<std::size_t>(ld);
  // W = D L21' (k x m, by rows): row t is pivot t's column of L below the fully summed rows
  // times D.
  grow(wbuf, static_cast<std::size_t>(k) * m);
  double* w = wbuf.data();
  for (int t = 0; t < k;) {
    const double* lt = f + t * lds + nfs;
    double* wt = w + static_cast<std::size_t>(t) * m;
    if (kind[t] == 1) {
      const double d = f[t * lds + t];
      for (int c = 0; c < m; ++c) wt[c] = lt[c] * d;
      t += 1;
    } else {
      const double* lt1 = lt + lds;
      double* wt1 = wt + m;
      const double d11 = f[t * lds + t], d21 = f[t * lds + t + 1], d22 = f[(t + 1) * lds + t + 1];
      for (int c = 0; c < m; ++c) {
        wt[c] = lt[c] * d11 + lt1[c] * d21;
        wt1[c] = lt[c] * d21 + lt1[c] * d22;
      }
      t += 2;
    }
  }
  int j0 = nfs;
  for (; j0 + 4 <= nf; j0 += 4) contribution_block<4>(ld, k, j0, f, w + (j0 - nfs), m);
  for (; j0 < nf; ++j0) contribution_block<1>(ld, k, j0, f, w + (j0 - nfs), m);
}

/// sum_i x(i) y(i) over i = from .. to with four partial sums (vectorized; reassociated).
FESD_KKT_INLINE double dot(const double* x, const double* y, int from, int to) {
  Vec4 acc = {};
  int i = from;
  for (; i + 4 <= to; i += 4) acc += load4(x + i) * load4(y + i);
  double s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
  for (; i < to; ++i) s += x[i] * y[i];
  return s;
}

/// max |x(i)| over i = from .. to - 1, vectorized between multiples of 4 (a front column's rows
/// from `from` to its padded end, or any range). Maxima are exact, so the order of the comparisons
/// does not change the value.
FESD_KKT_INLINE double abs_max(const double* x, int from, int to) {
  using Bits = long long __attribute__((vector_size(32)));
  double m = 0.0;
  int i = from;
  for (; i < to && (i & 3) != 0; ++i) m = std::max(m, std::abs(x[i]));
  if (i + 4 <= to) {
    constexpr long long kMagnitude = 0x7fffffffffffffffLL;  // all bits but the sign
    const Bits magnitude = {kMagnitude, kMagnitude, kMagnitude, kMagnitude};
    Vec4 acc = {};
    for (; i + 4 <= to; i += 4) {
      const Vec4 v = reinterpret_cast<Vec4>(reinterpret_cast<Bits>(load4(x + i)) & magnitude);
      acc = acc > v ? acc : v;
    }
    m = std::max({m, acc[0], acc[1], acc[2], acc[3]});
  }
  for (; i < to; ++i) m = std::max(m, std::abs(x[i]));
  return m;
}

/// Row p of a front left of its diagonal, columns k .. p - 1 (strided), read once for the pivot
/// search: the largest |a_pi| and the first i with it (-1 if all are zero), and the largest of the
/// others (the 2x2 test's maximum without its partner q = that i).
struct RowMax {
  double max1 = 0.0, max2 = 0.0;
  int arg1 = -1;
};
FESD_KKT_INLINE RowMax row_max(const double* f, std::size_t lds, int p, int k) {
  RowMax r;
  const double* a = f + static_cast<std::size_t>(k) * lds + p;
  for (int i = k; i < p; ++i, a += lds) {
    const double v = std::abs(*a);
    if (v > r.max1) {
      r.max2 = r.max1;
      r.max1 = v;
      r.arg1 = i;
    } else {
      r.max2 = std::max(r.max2, v);
    }
  }
  return r;
}

/// w(i) = c(i), c(i) = c(i) / d for i = from .. ld (the padding rows stay zero), in vector
/// passes from `from` rounded down to a multiple of 4: the rows before `from` of w get c's (a
/// front column's diagonal and unused upper triangle), c keeps them (a lane mask). Vector divisions
/// round as scalar ones.
FESD_KKT_INLINE void copy_and_scale(double* w, double* c, double d, int from, int ld) {
  using Bits = long long __attribute__((vector_size(32)));
  const Vec4 dv = {d, d, d, d};
  int i = from & ~3;
  if (i < from) {
    const Vec4 x = load4(c + i);
    store4(w + i, x);
    const Bits lane = {i, i + 1, i + 2, i + 3};
    const Bits keep = lane < static_cast<long long>(from);
    store4(c + i, keep ? x : x / dv);
    i += 4;
  }
  for (; i < ld; i += 4) {
    const Vec4 x = load4(c + i);
    store4(w + i, x);
    store4(c + i, x / dv);
  }
}

struct PivotResult {
  int nelim = 0;
  int negative = 0;
  int zero = 0;  // zero pivots among the nelim (columns zero to round-off)
};

/// Rows i .. i + 4R of fully summed column j (cj), updated with the pending 1x1 pivots t = base ..
/// k - 1 in order: minus U_t L(j, t) (U_t = pivot t's column before the division by d, at u + t
/// ld), each entry loaded and stored once.
template <int R>
FESD_KKT_INLINE void pending_rows_1x1(double* cj, int i, int j, int base, int k, const double* f,
                                      const double* u, int ld) {
  const std::size_t lds = static_cast<std::size_t>(ld);
  Vec4 acc[R];
  for (int r = 0; r < R; ++r) acc[r] = load4(cj + i + 4 * r);
  const double* ut = u + base * lds + i;
  const double* st = f + base * lds + j;
  for (int t = base; t < k; ++t, ut += lds, st += lds)
    for (int r = 0; r < R; ++r) acc[r] = acc[r] - load4(ut + 4 * r) * *st;
  for (int r = 0; r < R; ++r) store4(cj + i + 4 * r, acc[r]);
}

/// Brings fully summed column j up to date with the pending pivots base .. k - 1, rows from j
/// rounded down to a multiple of 4 to the padded end, as the right-looking update pivot by pivot
/// did and with the same operations per entry in the same order (the same values bit for bit): a
/// 1x1 pivot t subtracts U_t L(j, t), a 2x2 pivot (t, t + 1) L_t U_t(j) + L_t+1 U_t+1(j) (its two
/// columns of L and of the copies before the multiplication by D^-1).
FESD_KKT_INLINE void apply_pending(double* f, int j, int base, int k, const double* u,
                                   const int* kind, int ld, bool all_one_by_one) {
  const std::size_t lds = static_cast<std::size_t>(ld);
  double* cj = f + j * lds;
  const int i0 = j & ~3;
  if (all_one_by_one) {
    int i = i0;
    for (; i + 16 <= ld; i += 16) pending_rows_1x1<4>(cj, i, j, base, k, f, u, ld);
    if (i + 8 <= ld) {
      pending_rows_1x1<2>(cj, i, j, base, k, f, u, ld);
      i += 8;
    }
    if (i < ld) pending_rows_1x1<1>(cj, i, j, base, k, f, u, ld);
    return;
  }
  for (int t = base; t < k;) {
    if (kind[t] == 1) {
      const double* ut = u + t * lds;
      const double st = f[t * lds + j];
      for (int i = i0; i < ld; i += 4) store4(cj + i, load4(cj + i) - load4(ut + i) * st);
      t += 1;
    } else {
      const double *c1 = f + t * lds, *c2 = c1 + lds;
      const double s1 = u[t * lds + j], s2 = u[(t + 1) * lds + j];
      for (int i = i0; i < ld; i += 4)
        store4(cj + i, load4(cj + i) - (load4(c1 + i) * s1 + load4(c2 + i) * s2));
      t += 2;
    }
  }
}

/// Partial LDL' of a front whose first nfs rows are fully summed: eliminates as many of them as
/// the threshold test allows, moving accepted pivots to the front (idx follows). On return the
/// first nelim columns hold L (D on the diagonal, a 2x2's off-diagonal at (k+1, k)), the trailing
/// (nf - nelim) block the Schur complement. kind[k]: 1 = 1x1, 2 = first of a 2x2, 0 = second.
/// Only the lower triangle of the front is read or kept.
FESD_KKT_KERNEL PivotResult partial_ldlt(int nf, int nfs, double* storage, int* idx, int* kind,
                                         double u, double tiny, std::vector<double>& w1,
                                         std::vector<double>& w2) {
  Front F(storage, nf);
  const int ld = front_ld(nf);
  const std::size_t lds = static_cast<std::size_t>(ld);
  PivotResult res;
  // w1: per pivot t, at t ld, its column(s) before the division by D (the pending updates).
  grow(w1, static_cast<std::size_t>(nfs + 1) * lds);
  double* ubuf = w1.data();
  // Left-looking over the fully summed columns: pivots base .. k - 1 are not yet applied to the
  // columns after k (all of them have pivots 0 .. base - 1); column k gets them before its pivot
  // test, the others when a test fails (the search and the swaps then see every column up to
  // date) or when they become column k. Per entry the same updates in the same order as
  // right-looking, once loaded and stored instead of once per pivot.
  int k = 0, base = 0, twos = 0;  // twos: 2x2 pivots among base .. k - 1
  // (Called directly: a lambda would be compiled for the default target, without the clone's
  // FMA, and round differently.)
  while (k < nfs) {
    int pivot_p = -1, pivot_q = -1;
    bool zero_pivot = false;
    if (base < k) apply_pending(storage, k, base, k, ubuf, kind, ld, twos == 0);
    // Column k's 1x1 test (the usual pivot); the search below repeats it after a failure, with
    // this maximum (no later column's update changes column k, and row k left of it is empty).
    const double colmax_k = abs_max(F.col(k), k + 1, ld);
    {
      const double akk = F.at(k, k);
      if (std::abs(akk) > tiny && std::abs(akk) >= u * colmax_k) pivot_p = k;
    }
    if (pivot_p < 0 && base < k) {
      for (int j = k + 1; j < nfs; ++j)
        apply_pending(storage, j, base, k, ubuf, kind, ld, twos == 0);
      base = k;
      twos = 0;
    }
    for (int p = k; p < nfs && pivot_p < 0; ++p) {
      // The column maximum first (column p vectorized, row p in one strided pass that also
      // serves the 2x2 search); the 2x2 partner only if the 1x1 test fails. Every maximum is
      // exact, so the pivots are those of one scalar loop over each row and column.
      const RowMax row = row_max(storage, lds, p, k);
      const double colmax = p == k ? colmax_k : abs_max(F.col(p), p + 1, ld);
      const double cmax = std::max(colmax, row.max1);
      const double app = F.at(p, p);
      if (std::abs(app) > tiny && std::abs(app) >= u * cmax) {
        pivot_p = p;
        break;
      }
      if (std::abs(app) <= tiny && cmax <= tiny) {
        // The whole column (the fully summed rows and the contribution rows) is zero to
        // round-off: no later pivot changes it (its entries in their columns are zero too), so
        // delaying it would only carry it, and the columns it makes fail, up to the root in
        // ever larger fronts (on the hopper OCP's singular KKT matrices: 5e5 delayed pivots,
        // fronts of 1800 rows, 3 s per factorization instead of 0.015 s). It is eliminated
        // here as a zero pivot (MA27's and MA57's treatment): the matrix is singular.
        pivot_p = p;
        zero_pivot = true;
        break;
      }
      // The partner q: the largest |a_pi| over the other fully summed rows, the first such i
      // (row p's if it holds the largest, else the first in column p that does).
      double qmax = row.max1;
      int q = row.arg1;
      const double* colp = F.col(p);
      if (const double m = abs_max(colp, p + 1, nfs); m > qmax) {
        qmax = m;
        q = p + 1;
        while (std::abs(colp[q]) != m) ++q;
      }
      if (q < 0 || qmax <= tiny) continue;
      // 2x2 candidate (p, q): column maxima outside the block, then |D^-1| [cp; cq] <= 1/u.
      const double aqq = F.at(q, q), apq = F.sym(p, q);
      const double det = app * aqq - apq * apq;
      if (std::abs(det) <= tiny * std::max({std::abs(app), std::abs(aqq), std::abs(apq)})) continue;
      // cp over rows k .. nf - 1 but p, q: row p without q (row.max2 if q is in it), column p
      // (without q if q is below p; the padding rows are zero).
      const double cp =
          q < p ? std::max(row.max2, colmax)
                : std::max({row.max1, abs_max(colp, p + 1, q), abs_max(colp, q + 1, ld)});
      // cq likewise: row q (strided, without p), then column q below q (without p).
      double cq = 0.0;
      for (int i = k; i < q; ++i)
        if (i != p) cq = std::max(cq, std::abs(F.at(q, i)));
      const double* colq = F.col(q);
      if (p > q)
        cq = std::max({cq, abs_max(colq, q + 1, p), abs_max(colq, p + 1, ld)});
      else
        cq = std::max(cq, abs_max(colq, q + 1, ld));
      const double bound = std::abs(det) / u;
      if (std::abs(aqq) * cp + std::abs(apq) * cq <= bound &&
          std::abs(apq) * cp + std::abs(app) * cq <= bound) {
        pivot_p = p;
        pivot_q = q;
      }
    }
    if (pivot_p < 0) break;  // the rest is delayed to the parent front
    if (pivot_q < 0) {
      F.swap(k, pivot_p, idx);
      if (zero_pivot) {
        // Entries <= tiny become 0 and D = 1: L's column and the pivot's updates are zero; the
        // factorization reports the matrix singular (the solve's value for this row is not used).
        std::fill(F.col(k) + k + 1, F.col(k) + ld, 0.0);
        F.at(k, k) = 1.0;
        ++res.zero;
      }
      const double d = F.at(k, k);
      if (d < 0) ++res.negative;
      double* wk = ubuf + k * lds;
      double* ck = F.col(k);
      // wk = column k below the pivot (padding rows: zero), column k = L = wk / d. Rows
      // (k + 1) & ~3 .. k of wk get column k's diagonal and upper triangle: the pending update
      // adds them only to the unused upper triangle. The fully summed columns get it later
      // (apply_pending), the contribution block one update at the end.
      copy_and_scale(wk, ck, d, k + 1, ld);
      kind[k] = 1;
      k += 1;
    } else {
      F.swap(k, pivot_p, idx);
      int q = pivot_q == k ? pivot_p : pivot_q;
      F.swap(k + 1, q, idx);
      const double d11 = F.at(k, k), d21 = F.at(k + 1, k), d22 = F.at(k + 1, k + 1);
      const double det = d11 * d22 - d21 * d21;
      if (det < 0)
        res.negative += 1;
      else if (d11 + d22 < 0)
        res.negative += 2;
      // a1, a2 = the two columns below the pivot, columns k, k + 1 = L = [a1 a2] D^-1, in vector
      // passes from k + 2 rounded down to a multiple of 4 (padding rows included: zero); the
      // first block keeps rows k, k + 1 (D) and the rows above of the columns (a lane mask).
      double *a1 = ubuf + k * lds, *a2 = a1 + lds;
      double* c1 = F.col(k);
      double* c2 = F.col(k + 1);
      {
        using Bits = long long __attribute__((vector_size(32)));
        const Vec4 v11 = {d11, d11, d11, d11}, v21 = {d21, d21, d21, d21},
                   v22 = {d22, d22, d22, d22}, vdet = {det, det, det, det};
        const int i0 = (k + 2) & ~3;
        for (int i = i0; i < ld; i += 4) {
          const Vec4 x1 = load4(c1 + i), x2 = load4(c2 + i);
          store4(a1 + i, x1);
          store4(a2 + i, x2);
          Vec4 l1 = (v22 * x1 - v21 * x2) / vdet, l2 = (v11 * x2 - v21 * x1) / vdet;
          if (i == i0) {
            const Bits lane = {i, i + 1, i + 2, i + 3};
            const Bits keep = lane < static_cast<long long>(k + 2);
            l1 = keep ? x1 : l1;
            l2 = keep ? x2 : l2;
          }
          store4(c1 + i, l1);
          store4(c2 + i, l2);
        }
      }
      // The fully summed columns get it later (apply_pending: rows from j rounded down, c1, c2
      // hold D and the unused upper triangle there; padding rows are zero).
      kind[k] = 2;
      kind[k + 1] = 0;
      ++twos;
      k += 2;
    }
  }
  res.nelim = k;
  if (nf > nfs && k > 0) update_contribution(nf, nfs, k, storage, kind, w2);
  return res;
}

/// Contribution block a front passes to its parent: the lower triangle of its m rows, the first
/// ndelayed of them delayed pivots (their indices in idx), the others the static front's rows
/// below the fully summed ones (the parent's position map, Symbolic::emap, has them).
struct Contribution {
  std::vector<int> idx;  // the delayed pivots (original numbering)
  int ndelayed = 0;
  int m = 0;  // rows of the block
  /// Where the block is: packed (column-major lower triangle, m (m + 1) / 2 entries) at offset in
  /// the workspace's contribution stack, or, when the parent is the next front (offset < 0),
  /// in place in the front buffer it was computed in, at block with leading dimension ldb.
  Index offset = -1;
  const double* block = nullptr;
  int ldb = 0;
  /// Column 0 of the block. Each column is addressed by row (entries jb .. m - 1 of column jb
  /// are the block's); column jb + 1 starts ldb entries after column jb in place, m - 1 - jb
  /// packed: step() for column 0, then one less per column when packed().
  const double* first_column(const double* stack) const {
    return offset < 0 ? block : stack + offset;
  }
  bool packed() const { return offset >= 0; }
  std::ptrdiff_t step() const { return offset < 0 ? ldb : m - 1; }
};

/// Packed offset of column j of an m-row lower triangle (its entry (j, j)).
inline Index packed_column(Index m, Index j) {
  return j * m - j * (j - 1) / 2;
}

/// Scratch memory of the factorization, kept per thread between calls (it holds no state: every
/// call overwrites what it uses). Allocating it per call cost more than the factorization of a
/// ~3000-row KKT matrix: glibc returned the freed memory to the kernel and the next call paid
/// page faults again.
struct Workspace {
  std::vector<double> rmax, diag, cval, front[2], w1, w2;
  std::vector<int> fidx, kind, lp;
  std::vector<Contribution> cb;
  /// The contribution blocks not in place, one after the other in the order they were computed
  /// (stack_owner: their supernodes). A consumed block is popped once every block above it is
  /// consumed too; the supernodes come in tree order (children first), mostly a postorder, so the
  /// live blocks are the stack's top and the stack's length is their peak, about the factor of
  /// the largest subtree. (A pool of one vector per block, each grown to the largest block it had
  /// ever held, reached 2.1 GB for 6.5e6 factor entries on the hopper OCP at n_s = 5, and 16.9 GB
  /// before the out-of-memory killer stopped it: docs/kkt-solver.md, "Memory".)
  std::vector<double> stack;
  std::vector<int> stack_owner;
  /// Bytes held (capacities), for FesdKktStats::scratch_bytes.
  long long bytes() const {
    std::size_t b = 0;
    for (const auto* v : {&rmax, &diag, &cval, &front[0], &front[1], &w1, &w2, &stack})
      b += v->capacity() * sizeof(double);
    for (const auto* v : {&fidx, &kind, &lp, &stack_owner}) b += v->capacity() * sizeof(int);
    b += cb.capacity() * sizeof(Contribution);
    for (const Contribution& c : cb) b += c.idx.capacity() * sizeof(int);
    return static_cast<long long>(b);
  }
};
/// The thread's workspace, behind a call: with the thread_local used directly, GCC re-derived its
/// address (__tls_get_addr) inside the front loop, ~34000 calls per factorization on OCP (61).
[[gnu::noinline]] Workspace& thread_workspace() {
  thread_local Workspace ws;
  return ws;
}

/// Applies the factor to v in place: v <- S (L D L')^-1 S v.
FESD_KKT_KERNEL void apply_inverse(const double* __restrict a, const int* __restrict iw,
                                   double* __restrict v, double* __restrict w) {
  const int n = iw[kHN], nz = iw[kHNz];
  const double* scale = a + nz;
  for (int i = 0; i < n; ++i) v[i] *= scale[i];
  const int first = iw[kHFirst], end = iw[kHEnd];
  // Forward: L y = v and D z = y, front by front.
  for (int p = first; p < end;) {
    const int nf = iw[p], ne = iw[p + 1];
    const double* L = a + iw[p + 2];
    const int* idx = iw + p + 3;
    const int* kind = idx + nf;
    for (int i = 0; i < nf; ++i) w[i] = v[idx[i]];
    // The pivot block (triangular), then the rows below it, four columns at a time.
    for (int k = 0; k < ne;) {
      const double* lk = L + static_cast<std::size_t>(k) * nf;
      if (kind[k] == 1) {
        const double y = w[k];
        for (int i = k + 1; i < ne; ++i) w[i] -= lk[i] * y;
        k += 1;
      } else {
        const double* lk1 = lk + nf;
        const double y0 = w[k], y1 = w[k + 1];
        for (int i = k + 2; i < ne; ++i) w[i] -= lk[i] * y0 + lk1[i] * y1;
        k += 2;
      }
    }
    int c = 0;
    for (; c + 4 <= ne; c += 4) {
      const double* l0 = L + static_cast<std::size_t>(c) * nf;
      const double *l1 = l0 + nf, *l2 = l1 + nf, *l3 = l2 + nf;
      const double y0 = w[c], y1 = w[c + 1], y2 = w[c + 2], y3 = w[c + 3];
      for (int i = ne; i < nf; ++i) w[i] -= (l0[i] * y0 + l1[i] * y1) + (l2[i] * y2 + l3[i] * y3);
    }
    for (; c < ne; ++c) {
      const double* lc = L + static_cast<std::size_t>(c) * nf;
      const double y = w[c];
      for (int i = ne; i < nf; ++i) w[i] -= lc[i] * y;
    }
    for (int k = 0; k < ne;) {
      const double* lk = L + static_cast<std::size_t>(k) * nf;
      if (kind[k] == 1) {
        w[k] /= lk[k];
        k += 1;
      } else {
        const double d11 = lk[k], d21 = lk[k + 1], d22 = lk[nf + k + 1];
        const double det = d11 * d22 - d21 * d21;
        const double y0 = w[k], y1 = w[k + 1];
        w[k] = (d22 * y0 - d21 * y1) / det;
        w[k + 1] = (d11 * y1 - d21 * y0) / det;
        k += 2;
      }
    }
    for (int i = 0; i < nf; ++i) v[idx[i]] = w[i];
    p += 4 + nf + ne;
  }
  // Backward: L' x = z, fronts in reverse.
  for (int p = end; p > first;) {
    p = iw[p - 1];
    const int nf = iw[p], ne = iw[p + 1];
    const double* L = a + iw[p + 2];
    const int* idx = iw + p + 3;
    const int* kind = idx + nf;
    for (int i = 0; i < nf; ++i) w[i] = v[idx[i]];
    // The rows below the pivot block (dot products), then the pivot block (triangular).
    for (int k = 0; k < ne; ++k) w[k] -= dot(L + static_cast<std::size_t>(k) * nf, w, ne, nf);
    for (int k = ne - 1; k >= 0;) {
      if (kind[k] == 1) {
        const double* lk = L + static_cast<std::size_t>(k) * nf;
        double s = 0.0;
        for (int i = k + 1; i < ne; ++i) s += lk[i] * w[i];
        w[k] -= s;
        k -= 1;
      } else {  // kind[k] == 0: the second column of the 2x2 pivot (k - 1, k)
        const double* l0 = L + static_cast<std::size_t>(k - 1) * nf;
        const double* l1 = l0 + nf;
        double s0 = 0.0, s1 = 0.0;
        for (int i = k + 1; i < ne; ++i) {
          s0 += l0[i] * w[i];
          s1 += l1[i] * w[i];
        }
        w[k - 1] -= s0;
        w[k] -= s1;
        k -= 2;
      }
    }
    for (int i = 0; i < ne; ++i) v[idx[i]] = w[i];
  }
  for (int i = 0; i < n; ++i) v[i] *= scale[i];
}
#pragma GCC diagnostic pop

/// 2^-floor(e / 2) for v = m 2^e (1 <= m < 2): about 1 / sqrt(v), a power of two; 1 for zero,
/// subnormal, infinite or NaN v.
double inverse_sqrt_pow2(double v) {
  const auto bits = std::bit_cast<std::uint64_t>(v);
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  if (biased == 0 || biased == 0x7ff) return 1.0;
  const int e = biased - 1023;
  const int half = e >> 1;  // floor(e / 2): >> is arithmetic on negative ints (C++20)
  return std::bit_cast<double>(static_cast<std::uint64_t>(1023 - half) << 52);
}

}  // namespace

void sparse_analyse(int n, int nz, const int* irn, const int* icn, int* ikeep, int* info,
                    double* ops) {
  std::fill_n(info, kInfo, 0);
  for (int e = 0; e < nz; ++e)
    if (!valid(n, irn[e] - 1, icn[e] - 1)) info[0] = 1;  // MA27: out-of-range entries ignored
  std::vector<int> id(n);
  for (int i = 0; i < n; ++i) id[i] = i;
  std::vector<int> colptr, rows;
  pattern_columns(n, nz, irn, icn, id, n, colptr, rows);
  double amd_info[AMD_INFO] = {};
  std::fill_n(ikeep, 3 * static_cast<std::size_t>(n), 0);
  if (n > 0) amd(n, colptr, rows, ikeep, amd_info);
  if (n > 0) ikeep[2 * n] = kOrderingPending;
  const double lnz = n > 0 ? std::max(0.0, amd_info[AMD_LNZ]) : 0.0;
  *ops = n > 0 ? std::max(0.0, amd_info[AMD_NMULTSUBS_LDL]) : 0.0;
  // The relaxed supernodes store each front's pivot block square and pad chains: twice AMD's
  // count plus a margin; a factorization that needs more reports IFLAG = -4 and IPOPT grows A.
  const double la = nz + n + 2.0 * lnz + 20.0 * n + 1000.0;
  // IW: pattern, symbolic analysis with the static fronts (their rows and position maps), records.
  const double liw = kHeader + 3.0 * nz + 8.0 * n + 2.0 * lnz + 1000.0;
  const double cap = static_cast<double>(std::numeric_limits<int>::max() / 8);
  info[4] = static_cast<int>(std::min(la, cap));   // NRLNEC
  info[5] = static_cast<int>(std::min(liw, cap));  // NIRNEC
}

/// Builds the symbolic analysis for the ordering in ikeep and writes it to IW at iw_at (the
/// header gets its offset and sizes). Returns the IW length it needs; writes nothing if liw is
/// too short.
Index build_symbolic(int n, int nz, const int* irn, const int* icn, const int* perm, int* iw,
                     Index iw_at, Index liw) {
  std::vector<int> iperm(n);
  for (int k = 0; k < n; ++k) iperm[perm[k]] = k;
  // Entries by permuted column c = min, row r = max (lower triangle of P A P'); and by row for
  // the elimination tree.
  std::vector<int> colptr(static_cast<std::size_t>(n) + 1, 0), rowptr(colptr);
  for (int e = 0; e < nz; ++e) {
    const int i = irn[e] - 1, j = icn[e] - 1;
    if (!valid(n, i, j)) continue;
    const int r = std::max(iperm[i], iperm[j]), c = std::min(iperm[i], iperm[j]);
    ++colptr[c + 1];
    if (r != c) ++rowptr[r + 1];
  }
  for (int k = 0; k < n; ++k) {
    colptr[k + 1] += colptr[k];
    rowptr[k + 1] += rowptr[k];
  }
  std::vector<int> crow(static_cast<std::size_t>(colptr[n])), rcol(rowptr[n]), slot(nz, -1);
  {
    std::vector<int> cnext(colptr.begin(), colptr.end() - 1),
        rnext(rowptr.begin(), rowptr.end() - 1);
    for (int e = 0; e < nz; ++e) {
      const int i = irn[e] - 1, j = icn[e] - 1;
      if (!valid(n, i, j)) continue;
      const int r = std::max(iperm[i], iperm[j]), c = std::min(iperm[i], iperm[j]);
      slot[e] = cnext[c];
      crow[cnext[c]++] = r;
      if (r != c) rcol[rnext[r]++] = c;
    }
  }
  // Elimination tree (Liu's algorithm with path compression).
  std::vector<int> parent(n, -1), ancestor(n, -1), nchild(n, 0);
  for (int k = 0; k < n; ++k)
    for (int p = rowptr[k]; p < rowptr[k + 1]; ++p)
      for (int i = rcol[p]; i != -1 && i < k;) {
        const int next = ancestor[i];
        ancestor[i] = k;
        if (next == -1) parent[i] = k;
        i = next;
      }
  for (int k = 0; k < n; ++k)
    if (parent[k] >= 0) ++nchild[parent[k]];

  // Column counts of L by row subtrees (O(|L|)): the front sizes for the amalgamation.
  std::vector<int> colcount(n, 1), mark(n, -1);
  for (int k = 0; k < n; ++k) {
    mark[k] = k;
    for (int p = rowptr[k]; p < rowptr[k + 1]; ++p)
      for (int j = rcol[p]; mark[j] != k; j = parent[j]) {
        ++colcount[j];
        mark[j] = k;
      }
  }
  // Fundamental chains j -> j + 1 (j + 1's only child, same structure below), at most
  // kMaxSupernodeCols columns.
  std::vector<int> chain_start{0}, chain_of(n);
  for (int j = 1; j < n; ++j) {
    const bool chain = parent[j - 1] == j && nchild[j] == 1 && colcount[j - 1] == colcount[j] + 1 &&
                       j - chain_start.back() < kMaxSupernodeCols;
    if (!chain) chain_start.push_back(j);
  }
  const int nchains = static_cast<int>(chain_start.size());
  chain_start.push_back(n);
  for (int c = 0; c < nchains; ++c)
    for (int j = chain_start[c]; j < chain_start[c + 1]; ++j) chain_of[j] = c;
  // Relaxed amalgamation: a chain joins its parent's front when the explicit zeros this adds stay
  // a small fraction of the merged front (more zeros allowed for few columns). One or two columns
  // a front left the per-front work (assembly, index lists, the solve's gathers) dominant; merging
  // up to 16 columns regardless of zeros doubled |L| and the flops.
  std::vector<int> rep(nchains), ncols(nchains), below(nchains);
  std::vector<double> true_nnz(nchains, 0.0);
  for (int c = 0; c < nchains; ++c) {
    rep[c] = c;
    ncols[c] = chain_start[c + 1] - chain_start[c];
    below[c] = colcount[chain_start[c]] - ncols[c];
    for (int j = chain_start[c]; j < chain_start[c + 1]; ++j) true_nnz[c] += colcount[j];
  }
  const auto find = [&](int c) {
    while (rep[c] != c) c = rep[c] = rep[rep[c]];
    return c;
  };
  for (int c = 0; c < nchains; ++c) {
    const int last = chain_start[c + 1] - 1;
    if (parent[last] < 0) continue;
    const int p = find(chain_of[parent[last]]);
    const double k = ncols[c] + ncols[p];
    if (k > kMaxSupernodeCols) continue;
    const double stored = k * (k + 1) / 2 + k * below[p];
    const double zeros = 1.0 - (true_nnz[c] + true_nnz[p]) / stored;
    bool merge = false;
    for (const Relax& r : kRelax) merge = merge || (k <= r.max_cols && zeros < r.max_zeros);
    if (merge) {
      rep[c] = p;
      ncols[p] += ncols[c];
      true_nnz[p] += true_nnz[c];
    }
  }
  // Supernodes: the amalgamated chains, numbered by their last column (children first), each
  // with its columns in elimination order.
  std::vector<int> sn_id(nchains, -1);
  int ns = 0;
  for (int c = 0; c < nchains; ++c)
    if (find(c) == c) sn_id[c] = ns++;
  std::vector<int> sn_of(n), cols_ptr(static_cast<std::size_t>(ns) + 1, 0), cols(n);
  for (int j = 0; j < n; ++j) {
    sn_of[j] = sn_id[find(chain_of[j])];
    ++cols_ptr[sn_of[j] + 1];
  }
  for (int s = 0; s < ns; ++s) cols_ptr[s + 1] += cols_ptr[s];
  {
    std::vector<int> next(cols_ptr.begin(), cols_ptr.end() - 1);
    for (int j = 0; j < n; ++j) cols[next[sn_of[j]]++] = j;
  }
  std::vector<int> sparent(ns, -1), cptr(static_cast<std::size_t>(ns) + 1, 0), clist;
  for (int s = 0; s < ns; ++s) {
    const int last = cols[cols_ptr[s + 1] - 1];
    sparent[s] = parent[last] < 0 ? -1 : sn_of[parent[last]];
    if (sparent[s] >= 0) ++cptr[sparent[s] + 1];
  }
  for (int s = 0; s < ns; ++s) cptr[s + 1] += cptr[s];
  clist.resize(static_cast<std::size_t>(cptr[ns]));
  {
    std::vector<int> next(cptr.begin(), cptr.end() - 1);
    for (int s = 0; s < ns; ++s)
      if (sparent[s] >= 0) clist[next[sparent[s]]++] = s;
  }

  // Static fronts (no delayed pivots): rows, the original entries' positions and the children's
  // contribution rows' positions, so that a factorization neither builds index lists nor sorts.
  // Children before parents (a supernode's number is its last column's rank).
  const int entries = colptr[n];
  std::vector<int> fptr(static_cast<std::size_t>(ns) + 1, 0), frows, amap(entries),
      eptr(static_cast<std::size_t>(cptr[ns]) + 1, 0), emap;
  {
    std::vector<int> fpos(n, -1);
    for (int s = 0; s < ns; ++s) {
      const int start = static_cast<int>(frows.size());
      const auto add = [&](int g) {
        if (fpos[g] >= 0) return;
        fpos[g] = 0;
        frows.push_back(g);
      };
      const int nown = cols_ptr[s + 1] - cols_ptr[s];
      for (int t = 0; t < nown; ++t) add(cols[cols_ptr[s] + t]);
      for (int t = 0; t < nown; ++t) {
        const int c = cols[cols_ptr[s] + t];
        for (int p = colptr[c]; p < colptr[c + 1]; ++p) add(crow[p]);
      }
      for (int p = cptr[s]; p < cptr[s + 1]; ++p) {
        const int ch = clist[p];
        const int ch_own = cols_ptr[ch + 1] - cols_ptr[ch];
        for (int i = fptr[ch] + ch_own; i < fptr[ch + 1]; ++i) add(frows[i]);
      }
      std::sort(frows.begin() + start + nown, frows.end());
      const int end = static_cast<int>(frows.size());
      for (int i = start; i < end; ++i) fpos[frows[i]] = i - start;
      for (int t = 0; t < nown; ++t) {
        const int c = cols[cols_ptr[s] + t];
        for (int p = colptr[c]; p < colptr[c + 1]; ++p) amap[p] = fpos[crow[p]];
      }
      for (int p = cptr[s]; p < cptr[s + 1]; ++p) {
        const int ch = clist[p];
        const int ch_own = cols_ptr[ch + 1] - cols_ptr[ch];
        for (int i = fptr[ch] + ch_own; i < fptr[ch + 1]; ++i) emap.push_back(fpos[frows[i]]);
        eptr[p + 1] = static_cast<int>(emap.size());
      }
      for (int i = start; i < end; ++i) fpos[frows[i]] = -1;
      fptr[s + 1] = end;
    }
  }
  for (int& g : frows) g = perm[g];
  // The entries in front order (supernodes in order, own columns in front order: one flat
  // scatter per front in the factorization), with their offsets in the static front; the
  // triplets' slots follow. The same additions in the same order as column by column.
  std::vector<int> qptr(static_cast<std::size_t>(ns) + 1, 0), aoff(entries);
  {
    std::vector<int> qof(entries);
    int q = 0;
    for (int s = 0; s < ns; ++s) {
      qptr[s] = q;
      const int ld0 = front_ld(fptr[s + 1] - fptr[s]);
      for (int t = 0; t < cols_ptr[s + 1] - cols_ptr[s]; ++t) {
        const int c = cols[cols_ptr[s] + t];
        for (int p = colptr[c]; p < colptr[c + 1]; ++p) {
          qof[p] = q;
          aoff[q++] = t * ld0 + amap[p];
        }
      }
    }
    qptr[ns] = q;
    for (int& e : slot)
      if (e >= 0) e = qof[e];
  }

  const int front_rows = static_cast<int>(frows.size()), edge_rows = static_cast<int>(emap.size());
  const Index need = symbolic_length(n, nz, entries, ns, front_rows, edge_rows);
  if (iw_at + need > liw) return iw_at + need;
  iw[kHSymbolic] = static_cast<int>(iw_at);
  iw[kHEntries] = entries;
  iw[kHSupernodes] = ns;
  iw[kHFrontRows] = front_rows;
  iw[kHEdgeRows] = edge_rows;
  int* q = iw + iw_at;
  for (const std::vector<int>* v : {&iperm, &crow, &qptr, &slot, &cols_ptr, &cols, &sparent, &cptr,
                                    &clist, &fptr, &frows, &aoff, &eptr, &emap})
    q = std::copy(v->begin(), v->end(), q);
  return iw_at + need;
}

// With the kernels' AVX2 clone too (assembly, extend-add, scaling: -1.7 % instructions per
// factorization at N_stages 12). Its floating-point code has no product feeding a sum (products
// of powers of two in the scaling, plain sums in the assembly), so FMA contraction cannot make
// the clones round differently: same factor bit for bit.
FESD_KKT_KERNEL void sparse_factor(int n, int nz, const int* irn, const int* icn, double* a, int la,
                                   int* iw, int liw, int* ikeep, int* maxfrt, double pivtol,
                                   bool may_warm_scale, int* info, FesdKktStats* stats) {
  const double t0 = util::thread_cpu_seconds();
  std::fill_n(info, kInfo, 0);
  const Index fixed_la = static_cast<Index>(nz) + n;
  const Index pattern_end = kHeader + 2 * static_cast<Index>(nz);
  if (la < fixed_la) {
    info[0] = -4;
    info[1] = static_cast<int>(fixed_la + 2 * static_cast<Index>(nz) + 20 * static_cast<Index>(n));
    return;
  }
  if (liw < pattern_end) {
    info[0] = -3;
    info[1] = static_cast<int>(pattern_end + 4 * static_cast<Index>(n) + 2 * nz);
    return;
  }
  *maxfrt = 1;
  int* keep = n > 0 ? ikeep + 2 * n : nullptr;
  const auto addr = reinterpret_cast<std::uintptr_t>(iw);
  const int addr_lo = static_cast<int>(addr & 0x7fffffffU), addr_hi = static_cast<int>(addr >> 31);
  Workspace& ws = thread_workspace();
  bool reorder = false;
  if (n >= kLargeKktRows && n >= kKOrderSlots && keep[kKOrdering] == kOrderingReady &&
      keep[kKFactorizations] < kReorderChecks && keep[kKReorders] < kMaxReorders) {
    ++keep[kKFactorizations];
    const int zeros = count_zero_diagonal(n, nz, irn, icn, a, ws.diag, ws.rmax);
    if (zeros < keep[kKOrderZeros] - keep[kKOrderZeros] / kReorderZeroDrop) {
      std::copy_n(ikeep, n, ikeep + n);  // the old ordering, restored if the new one is worse
      keep[kKCompare] = 1;
      keep[kKOrdering] = kOrderingPending;
      ++keep[kKReorders];
      reorder = true;
      if (stats != nullptr) ++stats->reorderings;
    }
  }
  const bool cached = !reorder && n >= kKSlots && keep[kKOrdering] == kOrderingReady &&
                      keep[kKSymbolic] == 1 && keep[kKLiw] == liw && keep[kKAddrLo] == addr_lo &&
                      keep[kKAddrHi] == addr_hi && iw[kHMagic] == kMagic && iw[kHN] == n &&
                      iw[kHNz] == nz;
  if (!cached) {
    if (n >= kKSlots) keep[kKSymbolic] = 0;
    iw[kHMagic] = kMagic;
    iw[kHN] = n;
    iw[kHNz] = nz;
    for (int e = 0; e < nz; ++e) {
      const bool ok = valid(n, irn[e] - 1, icn[e] - 1);
      iw[kHeader + e] = ok ? irn[e] - 1 : -1;
      iw[kHeader + nz + e] = ok ? icn[e] - 1 : -1;
    }
  }
  iw[kHFronts] = 0;
  iw[kHFirst] = iw[kHEnd] = static_cast<int>(pattern_end);
  iw[kHMaxFront] = 0;
  if (n == 0) return;
  if (!cached) {
    if (keep[kKOrdering] != kOrderingReady) {
      compute_ordering(n, nz, irn, icn, a, ikeep);
      keep[kKOrdering] = kOrderingReady;
      if (n >= kLargeKktRows && n >= kKOrderSlots)
        keep[kKOrderZeros] = count_zero_diagonal(n, nz, irn, icn, a, ws.diag, ws.rmax);
    }
    Index end = build_symbolic(n, nz, irn, icn, ikeep, iw, pattern_end, liw);
    if (end <= liw && n >= kLargeKktRows && n >= kKOrderSlots) {
      const Index entries = static_factor_entries(iw);
      if (keep[kKCompare] == 1) {
        keep[kKCompare] = 0;
        if (static_cast<double>(entries) >
            kReorderKeep * static_cast<double>(keep[kKStaticEntries])) {
          std::copy_n(ikeep + n, n, ikeep);  // not smaller: the old ordering, for good
          keep[kKReorders] = kMaxReorders;
          if (stats != nullptr) ++stats->reorderings_undone;
          end = build_symbolic(n, nz, irn, icn, ikeep, iw, pattern_end, liw);
        }
      }
      if (end <= liw)
        keep[kKStaticEntries] = static_cast<int>(
            std::min<Index>(static_factor_entries(iw), std::numeric_limits<int>::max()));
    }
    if (end > liw) {
      info[0] = -3;
      info[1] =
          static_cast<int>(std::min<Index>(end + end / 2, std::numeric_limits<int>::max() / 4));
      return;
    }
    if (n >= kKSlots) {
      keep[kKSymbolic] = 1;
      keep[kKLiw] = liw;
      keep[kKAddrLo] = addr_lo;
      keep[kKAddrHi] = addr_hi;
    }
  }
  const Symbolic sym = symbolic_view(iw);
  const Index fixed_liw = iw[kHSymbolic] + symbolic_length(iw);
  iw[kHFirst] = iw[kHEnd] = static_cast<int>(fixed_liw);
  const int *cols_ptr = sym.cols_ptr, *sparent = sym.sparent, *cptr = sym.cptr, *clist = sym.clist;
  const int ns = sym.ns;

  // Equilibration: S A S with S = scale, three Ruiz sweeps (max-norm of the rows), each factor
  // rounded to a power of two: the scaled matrix is exact, and no sqrt or division per row (they
  // were a quarter of the work outside the fronts).
  double* scale = a + nz;
  const auto a_addr = reinterpret_cast<std::uintptr_t>(a);
  const int a_lo = static_cast<int>(a_addr & 0x7fffffffU), a_hi = static_cast<int>(a_addr >> 31);
  const bool warm = kReuseScaling && may_warm_scale && n >= kWarmMinRows && cached &&
                    n >= kKScaleSlots && keep[kKScaled] == 1 && keep[kKLa] == la &&
                    keep[kKAAddrLo] == a_lo && keep[kKAAddrHi] == a_hi;
  if (!warm) std::fill_n(scale, n, 1.0);
  if (warm && stats != nullptr) ++stats->warm_scalings;
  {
    std::vector<double>& rmax = ws.rmax;
    rmax.resize(n);
    // The pattern in IW: 0-based, -1 for out-of-range entries.
    const int *prow = iw + kHeader, *pcol = prow + nz;
    // Every triplet in range (the usual case): no per-entry test. The first sweep has scale = 1.
    const bool all_valid = iw[kHEntries] == nz;
    const auto sweep = [&]<bool kChecked, bool kFirst>() {
      std::fill(rmax.begin(), rmax.end(), 0.0);
      for (int e = 0; e < nz; ++e) {
        const int i = prow[e], j = pcol[e];
        if (kChecked && i < 0) continue;
        const double v = kFirst ? std::abs(a[e]) : std::abs(a[e]) * scale[i] * scale[j];
        rmax[i] = std::max(rmax[i], v);
        rmax[j] = std::max(rmax[j], v);
      }
      for (int i = 0; i < n; ++i) scale[i] *= inverse_sqrt_pow2(rmax[i]);
    };
    if (warm) {
      for (int k = 0; k < kWarmSweeps; ++k) {
        if (all_valid)
          sweep.template operator()<false, false>();
        else
          sweep.template operator()<true, false>();
      }
    } else if (all_valid) {
      sweep.template operator()<false, true>();
      sweep.template operator()<false, false>();
      sweep.template operator()<false, false>();
    } else {
      sweep.template operator()<true, true>();
      sweep.template operator()<true, false>();
      sweep.template operator()<true, false>();
    }
  }
  if (n >= kKScaleSlots) {
    keep[kKScaled] = 1;
    keep[kKLa] = la;
    keep[kKAAddrLo] = a_lo;
    keep[kKAAddrHi] = a_hi;
  }

  // Scaled values in the permuted lower triangle.
  std::vector<double>& cval = ws.cval;
  grow(cval, static_cast<std::size_t>(iw[kHEntries]));  // every entry is written below
  double amax = 0.0;
  {
    const int *prow = iw + kHeader, *pcol = prow + nz;
    for (int e = 0; e < nz; ++e) {
      const int i = prow[e];
      if (i < 0) continue;
      const double v = a[e] * scale[i] * scale[pcol[e]];
      amax = std::max(amax, std::abs(v));
      cval[sym.slot[e]] = v;
    }
  }
  const double tiny = (n >= kLargeKktRows ? kTinyRelLarge : kTinyRel) *
                      std::max(amax, std::numeric_limits<double>::min());
  const double u = std::clamp(pivtol, kMinPivtol, kMaxPivtol);

  // Multifrontal factorization; children (smaller last columns) come before their parent.
  std::vector<int>&fidx = ws.fidx, &kind = ws.kind;
  std::vector<double>&w1 = ws.w1, &w2 = ws.w2;
  std::vector<int>& w_pos = ws.lp;
  std::vector<Contribution>& cb = ws.cb;
  std::vector<double>& stack = ws.stack;
  std::vector<int>& stack_owner = ws.stack_owner;
  // Contribution records are reused (their index lists keep their capacity: allocating them per
  // front was 130000 new / delete per run of OCP (61)).
  if (cb.size() < static_cast<std::size_t>(ns)) cb.resize(ns);
  Index stack_top = 0, stack_peak = 0;
  const auto release = [&](Contribution& c) {
    c.idx.clear();
    c.ndelayed = 0;
    c.m = 0;
    while (!stack_owner.empty() && cb[stack_owner.back()].m == 0) {
      stack_top = cb[stack_owner.back()].offset;
      stack_owner.pop_back();
    }
  };
  stack_owner.clear();
  for (int s = 0; s < ns; ++s) release(cb[s]);
  Index a_next = fixed_la, iw_next = fixed_liw;
  int negative = 0, rank = n, maxnf = 0, nfronts = 0;
  long long delayed = 0;
  bool singular = false;
  for (int s = 0; s < ns; ++s) {
    const int nown = cols_ptr[s + 1] - cols_ptr[s];
    const int* srows = sym.frows + sym.fptr[s];
    const int nf0 = sym.fptr[s + 1] - sym.fptr[s];
    // Front order (original numbering): own columns, the children's delayed pivots (children in
    // order), then the static front's other rows; a static position sp >= nown moves down by nd.
    int nd = 0;
    for (int p = cptr[s]; p < cptr[s + 1]; ++p) nd += cb[clist[p]].ndelayed;
    const int nfs = nown + nd, nf = nf0 + nd;
    fidx.resize(nf);
    std::copy_n(srows, nown, fidx.begin());
    {
      int at = nown;
      for (int p = cptr[s]; p < cptr[s + 1]; ++p) {
        const Contribution& ch = cb[clist[p]];
        at = static_cast<int>(std::copy_n(ch.idx.begin(), ch.ndelayed, fidx.begin() + at) -
                              fidx.begin());
      }
    }
    std::copy(srows + nown, srows + nf0, fidx.begin() + nfs);
    maxnf = std::max(maxnf, nf);
    const int ld = front_ld(nf);
    // Fronts alternate between two buffers: a front whose parent comes next leaves its
    // contribution block in place, and the parent reads it from there (no copy).
    std::vector<double>& front = ws.front[s & 1];
    grow(front, static_cast<std::size_t>(ld) * nf);
    double* fr = front.data();
    zero_front(fr, nf);
    const auto shifted = [nown, nd](int sp) { return sp >= nown ? sp + nd : sp; };
    // The original entries: one flat scatter over the front's entries (column by column, the
    // columns hold ~4 entries each, and the per-column loop cost more than the scatter).
    if (nd == 0) {
#pragma GCC unroll 4
      for (int q = sym.qptr[s]; q < sym.qptr[s + 1]; ++q) fr[sym.aoff[q]] += cval[q];
    } else {
      const int ld0 = front_ld(nf0);
      for (int q = sym.qptr[s]; q < sym.qptr[s + 1]; ++q) {
        const int t = sym.aoff[q] / ld0, sp = sym.aoff[q] - t * ld0;
        fr[static_cast<std::size_t>(t) * ld + shifted(sp)] += cval[q];
      }
    }
    int delayed_at = nown;
    for (int p = cptr[s]; p < cptr[s + 1]; ++p) {
      Contribution& ch = cb[clist[p]];
      const int m = ch.m, chd = ch.ndelayed;
      const int* map = sym.emap + sym.eptr[p];
      if (nd == 0) {
        // No delayed pivots (chd = 0 too): the static map as it is, no triangle test. (Vector adds
        // for runs of consecutive positions, precomputed: as many instructions, no faster.)
        const double* col0 = ch.first_column(stack.data());
        const std::ptrdiff_t packed = ch.packed();
        std::ptrdiff_t at = 0, step = ch.step();
        for (int jb = 0; jb < m; ++jb, at += step, step -= packed) {
          const double* col = col0 + at;
          double* fc = fr + static_cast<std::size_t>(map[jb]) * ld;
#pragma GCC unroll 4
          for (int ib = jb; ib < m; ++ib) fc[map[ib]] += col[ib];
        }
      } else {
        // Positions of the child's rows in this front: its delayed pivots, then its static rows.
        w_pos.resize(m);
        for (int b = 0; b < chd; ++b) w_pos[b] = delayed_at + b;
        for (int b = chd; b < m; ++b) w_pos[b] = shifted(map[b - chd]);
        delayed_at += chd;
        const int* lp = w_pos.data();
        const double* col0 = ch.first_column(stack.data());
        const std::ptrdiff_t packed = ch.packed();
        std::ptrdiff_t at = 0, step = ch.step();
        for (int jb = 0; jb < m; ++jb, at += step, step -= packed) {
          const double* col = col0 + at;
          const int pj = lp[jb];
          if (jb < chd) {
            for (int ib = jb; ib < m; ++ib) {
              const int pi = lp[ib];
              const auto to = pi >= pj ? static_cast<std::size_t>(pj) * ld + pi
                                       : static_cast<std::size_t>(pi) * ld + pj;
              fr[to] += col[ib];
            }
          } else {
            double* fc = fr + static_cast<std::size_t>(pj) * ld;
#pragma GCC unroll 4
            for (int ib = jb; ib < m; ++ib) fc[lp[ib]] += col[ib];
          }
        }
      }
      release(ch);
    }
    grow(kind, nf);
    const PivotResult pr =
        partial_ldlt(nf, nfs, front.data(), fidx.data(), kind.data(), u, tiny, w1, w2);
    const int ne = pr.nelim;
    negative += pr.negative;
    if (pr.zero > 0) {
      singular = true;
      rank -= pr.zero;
    }
    // Record for the solve: L block in A, indices (original numbering) and pivot kinds in IW.
    const Index a_need = static_cast<Index>(nf) * ne, iw_need = 4 + nf + ne;
    if (a_next + a_need <= la && iw_next + iw_need <= liw) {
      for (int j = 0; j < ne; ++j)
        std::copy_n(fr + static_cast<std::size_t>(j) * ld, nf,
                    a + a_next + static_cast<Index>(j) * nf);
      int* rec = iw + iw_next;
      rec[0] = nf;
      rec[1] = ne;
      rec[2] = static_cast<int>(a_next);
      std::copy_n(fidx.data(), nf, rec + 3);
      std::copy_n(kind.data(), ne, rec + 3 + nf);
      rec[3 + nf + ne] = static_cast<int>(iw_next);
    }
    a_next += a_need;
    iw_next += iw_need;
    ++nfronts;
    const int m = nf - ne;
    delayed += nfs - ne;
    if (m > 0) {
      if (sparent[s] < 0) {
        // Only delayed pivots remain at a root: zero to round-off.
        singular = true;
        rank -= m;
      } else {
        // The block's rows: the pivots delayed to the parent (indices kept), then the static
        // front's rows below the fully summed ones (the parent's emap has their positions).
        Contribution& out = cb[s];
        out.idx.assign(fidx.begin() + ne, fidx.begin() + nfs);
        out.ndelayed = nfs - ne;
        out.m = m;
        if (sparent[s] == s + 1) {  // in place (the next front uses the other buffer)
          out.offset = -1;
          out.block = fr + static_cast<std::size_t>(ne) * ld + ne;
          out.ldb = ld;
        } else {
          const Index size = static_cast<Index>(m) * (m + 1) / 2;
          if (stack_top + size > static_cast<Index>(stack.size())) {
            // Grown by half (reserve: exactly that capacity; resize alone would double it).
            const auto len = static_cast<std::size_t>(
                std::max(stack_top + size, static_cast<Index>(stack.size() + stack.size() / 2)));
            stack.reserve(len);
            stack.resize(len);
          }
          out.offset = stack_top;
          out.block = nullptr;
          out.ldb = 0;
          double* dst = stack.data() + stack_top;
          for (int j = 0; j < m; ++j)  // lower triangle, packed
            std::copy_n(fr + static_cast<std::size_t>(ne + j) * ld + ne + j, m - j,
                        dst + packed_column(m, j));
          stack_owner.push_back(s);
          stack_top += size;
          stack_peak = std::max(stack_peak, stack_top);
        }
      }
    }
  }
  // After an outlier (a delayed-pivot cascade), give the memory back once the stack is far
  // larger than this factorization needed.
  if (static_cast<Index>(stack.size()) > std::max<Index>(4 * stack_peak, Index{1} << 23)) {
    stack.resize(static_cast<std::size_t>(stack_peak));
    stack.shrink_to_fit();
  }
  if (stats != nullptr) {
    stats->delayed_pivots += delayed;
    stats->last_n = n;
    stats->last_factor_entries = a_next - fixed_la;
    stats->scratch_bytes = ws.bytes();
    stats->last_static_entries = static_factor_entries(iw);
  }
  if (a_next > la || iw_next > liw) {
    info[0] = a_next > la ? -4 : -3;
    info[1] = static_cast<int>(
        std::min<Index>(a_next > la ? a_next : iw_next, std::numeric_limits<int>::max() / 4));
    return;
  }
  iw[kHFronts] = nfronts;
  iw[kHEnd] = static_cast<int>(iw_next);
  iw[kHMaxFront] = maxnf;
  *maxfrt = maxnf + 4 * n;  // MA27CD's W: front vector plus refinement vectors
  info[14] = negative;
  if (singular) {
    info[0] = 3;
    info[1] = rank;
  }
  if (stats != nullptr) {
    ++stats->factorizations;
    stats->factor_seconds += util::thread_cpu_seconds() - t0;
  }
}

void sparse_solve(int n, const double* a, const int* iw, double* w, double* rhs,
                  FesdKktStats* stats) {
  if (n == 0 || iw[kHMagic] != kMagic || iw[kHN] != n) return;
  const double t0 = util::thread_cpu_seconds();
  const int nz = iw[kHNz];
  const int* irn = iw + kHeader;
  const int* icn = irn + nz;
  double* b = w;          // right-hand side
  double* r = b + n;      // residual, then correction
  double* bound = r + n;  // row sums of |A|
  double* best = bound + n;
  double* work = best + n;  // one front
  std::copy_n(rhs, n, b);
  apply_inverse(a, iw, rhs, work);
  double best_berr = std::numeric_limits<double>::infinity();
  // r = b - A x; the first pass also sums |A| by rows (bound), which later passes reuse.
  // Without the range test when every triplet is in range (the usual case).
  const bool all_valid = iw[kHEntries] == nz;
  const auto residual_pass = [&]<bool kBound, bool kChecked>() {
    std::copy_n(b, n, r);
    if (kBound) std::fill_n(bound, n, 0.0);
    for (int e = 0; e < nz; ++e) {
      const int i = irn[e], j = icn[e];
      if (kChecked && i < 0) continue;
      r[i] -= a[e] * rhs[j];
      if (kBound) bound[i] += std::abs(a[e]);
      if (i != j) {
        r[j] -= a[e] * rhs[i];
        if (kBound) bound[j] += std::abs(a[e]);
      }
    }
  };
  const auto residual = [&]<bool kBound>() {
    if (all_valid)
      residual_pass.template operator()<kBound, false>();
    else
      residual_pass.template operator()<kBound, true>();
  };
  double anorm = 0.0, bnorm = 0.0;
  for (int it = 0;; ++it) {
    if (it == 0) {
      residual.template operator()<true>();
      for (int i = 0; i < n; ++i) {
        anorm = std::max(anorm, bound[i]);
        bnorm = std::max(bnorm, std::abs(b[i]));
      }
    } else {
      residual.template operator()<false>();
    }
    double rnorm = 0.0, xnorm = 0.0;
    for (int i = 0; i < n; ++i) {
      rnorm = std::max(rnorm, std::abs(r[i]));
      xnorm = std::max(xnorm, std::abs(rhs[i]));
    }
    const double scale_of = anorm * xnorm + bnorm;
    const double berr = rnorm == 0.0   ? 0.0
                        : scale_of > 0 ? rnorm / scale_of
                                       : std::numeric_limits<double>::infinity();
    if (berr >= best_berr) {  // no progress: keep the best solution
      std::copy_n(best, n, rhs);
      break;
    }
    best_berr = berr;
    if (berr <= kBerrTarget || it == kMaxRefine) break;
    std::copy_n(rhs, n, best);
    apply_inverse(a, iw, r, work);
    for (int i = 0; i < n; ++i) rhs[i] += r[i];
    if (stats != nullptr) ++stats->refinement_steps;
  }
  if (stats != nullptr) {
    ++stats->solves;
    stats->solve_seconds += util::thread_cpu_seconds() - t0;
  }
}

}  // namespace fesd::kkt
