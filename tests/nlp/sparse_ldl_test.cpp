// fesd's KKT module (src/nlp/kkt) through its MA27 interface, as IPOPT calls it: the sparse LDL'
// against a dense reference on random KKT-shaped matrices (exact inertia, normwise backward error <
// 1e-14), singular matrices, duplicate triplets, workspace negotiation, two structures alive at
// once; and OCP (61) solved with kkt_solver = sparse_ldl against MUMPS.
#include <dlfcn.h>

#include <link.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "../../bench/sliding_ocp.hpp"
#include "fesd/ocp.hpp"
#include "fesd/problem_file.hpp"
#include "nlp/kkt/kkt_module.h"

namespace {

struct Module {
  void (*request_mode)(int) = nullptr;
  void (*request_scaling)(int) = nullptr;
  void (*ma27id)(int*, double*) = nullptr;
  void (*ma27ad)(const int*, const int*, const int*, const int*, int*, const int*, int*, int*, int*,
                 int*, int*, double*, int*, double*) = nullptr;
  void (*ma27bd)(const int*, const int*, const int*, const int*, double*, const int*, int*,
                 const int*, int*, int*, int*, int*, int*, double*, int*) = nullptr;
  void (*ma27cd)(const int*, double*, const int*, int*, const int*, double*, const int*, double*,
                 int*, const int*, int*, double*) = nullptr;
  void (*stats)(FesdKktStats*) = nullptr;
};

const Module& module() {
  static const Module m = [] {
    Module r;
    void* h = dlopen(FESD_KKT_MODULE, RTLD_NOW | RTLD_GLOBAL);
    if (h == nullptr) return r;
    r.request_mode = reinterpret_cast<decltype(r.request_mode)>(dlsym(h, "fesd_kkt_request_mode"));
    r.request_scaling =
        reinterpret_cast<decltype(r.request_scaling)>(dlsym(h, "fesd_kkt_request_scaling"));
    r.ma27id = reinterpret_cast<decltype(r.ma27id)>(dlsym(h, "ma27id_"));
    r.ma27ad = reinterpret_cast<decltype(r.ma27ad)>(dlsym(h, "ma27ad_"));
    r.ma27bd = reinterpret_cast<decltype(r.ma27bd)>(dlsym(h, "ma27bd_"));
    r.ma27cd = reinterpret_cast<decltype(r.ma27cd)>(dlsym(h, "ma27cd_"));
    r.stats = reinterpret_cast<decltype(r.stats)>(dlsym(h, "fesd_kkt_stats"));
    return r;
  }();
  return m;
}

/// A symmetric matrix as IPOPT gives it: 1-based triplets of one triangle, duplicates allowed.
struct Triplets {
  int n = 0;
  std::vector<int> irn, icn;
  std::vector<double> val;
  void add(int i, int j, double v) {  // 0-based, either triangle
    irn.push_back(std::max(i, j) + 1);
    icn.push_back(std::min(i, j) + 1);
    val.push_back(v);
  }
  int nz() const { return static_cast<int>(val.size()); }
  Eigen::MatrixXd dense() const {
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
    for (int e = 0; e < nz(); ++e) {
      const int i = irn[e] - 1, j = icn[e] - 1;
      K(i, j) += val[e];
      if (i != j) K(j, i) += val[e];
    }
    return K;
  }
};

/// One MA27 "instance" the way IPOPT's Ma27TSolverInterface drives it (sizes from MA27AD times
/// 5, IW reallocated after the analysis, growth on IFLAG -3 / -4).
class Ma27 {
 public:
  Ma27(const Triplets& t, int mode) : t_(t) {
    const Module& m = module();
    m.ma27id(icntl_, cntl_);
    cntl_[0] = 1e-8;  // IPOPT's ma27_pivtol
    ikeep_.assign(3 * static_cast<std::size_t>(t.n), 0);
    std::vector<int> iw1(2 * static_cast<std::size_t>(t.n) + 1);
    int liw = 2 * (2 * t.nz() + 3 * t.n + 1), iflag = 0;
    std::vector<int> iw(static_cast<std::size_t>(liw));
    double ops = 0;
    m.request_mode(mode);
    m.ma27ad(&t.n, &nz_, t.irn.data(), t.icn.data(), iw.data(), &liw, ikeep_.data(), iw1.data(),
             &nsteps_, &iflag, icntl_, cntl_, info_, &ops);
    m.request_mode(FESD_KKT_AUTO);
    liw_ = 5 * info_[5];
    la_ = std::max(t.nz(), 5 * info_[4]);
    iw_.assign(static_cast<std::size_t>(liw_), 0);
    a_.assign(static_cast<std::size_t>(la_), 0.0);
  }
  int nsteps() const { return nsteps_; }
  /// Factorizes values (same structure); returns INFO(1). negative() is INFO(15).
  int factor(const std::vector<double>& values) {
    const Module& m = module();
    std::vector<int> iw1(2 * static_cast<std::size_t>(t_.n) + 1);
    for (int attempt = 0; attempt < 10; ++attempt) {
      std::copy(values.begin(), values.end(), a_.begin());
      m.ma27bd(&t_.n, &nz_, t_.irn.data(), t_.icn.data(), a_.data(), &la_, iw_.data(), &liw_,
               ikeep_.data(), &nsteps_, &maxfrt_, iw1.data(), icntl_, cntl_, info_);
      if (info_[0] == -3) {
        liw_ = 2 * info_[1];
        iw_.assign(static_cast<std::size_t>(liw_), 0);
        ++reallocations_;
      } else if (info_[0] == -4) {
        la_ = 2 * info_[1];
        a_.assign(static_cast<std::size_t>(la_), 0.0);
        ++reallocations_;
      } else {
        break;
      }
    }
    return info_[0];
  }
  int negative() const { return info_[14]; }
  /// The scaling of the last factorization (A = [values | scaling | factor], sparse_ldl.cpp).
  std::vector<double> scaling() const {
    return {a_.begin() + t_.nz(), a_.begin() + t_.nz() + t_.n};
  }
  int reallocations() const { return reallocations_; }
  void shrink_la(int la) {
    la_ = la;
    a_.assign(static_cast<std::size_t>(la_), 0.0);
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& b) {
    std::vector<double> w(static_cast<std::size_t>(std::max(1, maxfrt_)));
    std::vector<int> iw1(static_cast<std::size_t>(std::max(1, nsteps_)));
    Eigen::VectorXd x = b;
    module().ma27cd(&t_.n, a_.data(), &la_, iw_.data(), &liw_, w.data(), &maxfrt_, x.data(),
                    iw1.data(), &nsteps_, icntl_, cntl_);
    return x;
  }

 private:
  Triplets t_;
  int nz_ = t_.nz();
  int icntl_[30] = {}, info_[20] = {}, nsteps_ = 0, maxfrt_ = 0, la_ = 0, liw_ = 0;
  int reallocations_ = 0;
  double cntl_[5] = {};
  std::vector<int> ikeep_, iw_;
  std::vector<double> a_;
};

/// [H + Sigma, J'; J, -delta I] with a banded-plus-random H, some bounded variables (Sigma up to
/// 1e6, as near the end of an interior-point solve), and a sparse J; the constraint diagonal is
/// present (zero unless delta > 0), as in IPOPT's triplets.
Triplets random_kkt(std::mt19937& rng, int n, int m, double delta) {
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::uniform_int_distribution<int> col(0, n - 1);
  Triplets t;
  t.n = n + m;
  for (int i = 0; i < n; ++i) {
    const double sigma = U(rng) > 0.3 ? std::pow(10.0, 6.0 * (U(rng) + 1) / 2) : 0.0;
    t.add(i, i, U(rng) + sigma);
    for (int k = 1; k <= 2 && i + k < n; ++k)
      if (U(rng) > 0.0) t.add(i + k, i, U(rng));
    if (U(rng) > 0.8) t.add(col(rng), i, 0.1 * U(rng));
  }
  for (int r = 0; r < m; ++r) {
    const int c0 = (r * n) / std::max(1, m);
    t.add(n + r, std::min(n - 1, c0), 1.0 + U(rng));
    for (int k = 0; k < 3; ++k)
      if (U(rng) > 0.2) t.add(n + r, col(rng), U(rng));
    t.add(n + r, n + r, -delta);
  }
  return t;
}

struct Reference {
  int negative = 0;
  double min_abs_eig = 0, max_abs_eig = 0;
};
Reference reference(const Eigen::MatrixXd& K) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(K);
  Reference r;
  const Eigen::VectorXd ev = es.eigenvalues();
  r.negative = static_cast<int>((ev.array() < 0).count());
  r.min_abs_eig = ev.cwiseAbs().minCoeff();
  r.max_abs_eig = ev.cwiseAbs().maxCoeff();
  return r;
}

/// Normwise backward error |b - K x| / (|K| |x| + |b|) in the max-norm: what the module's
/// iterative refinement drives below 1e-15 (at most three corrections).
double backward_error(const Eigen::MatrixXd& K, const Eigen::VectorXd& x,
                      const Eigen::VectorXd& b) {
  const double r = (b - K * x).lpNorm<Eigen::Infinity>();
  const double k = K.cwiseAbs().rowwise().sum().maxCoeff();
  return r / (k * x.lpNorm<Eigen::Infinity>() + b.lpNorm<Eigen::Infinity>());
}

TEST(SparseLdl, ModuleLoads) {
  const Module& m = module();
  ASSERT_NE(m.ma27ad, nullptr) << FESD_KKT_MODULE;
  ASSERT_NE(m.request_mode, nullptr);
}

TEST(SparseLdl, RandomKktMatricesMatchTheDenseReference) {
  ASSERT_NE(module().ma27ad, nullptr);
  std::mt19937 rng(14);
  int checked = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int n = 5 + static_cast<int>(rng() % 160), m = 1 + static_cast<int>(rng() % (n / 2 + 1));
    const double delta = trial % 4 == 0 ? 1e-8 : 0.0;
    const Triplets t = random_kkt(rng, n, m, delta);
    const Eigen::MatrixXd K = t.dense();
    const Reference ref = reference(K);
    if (ref.min_abs_eig < 1e-12 * ref.max_abs_eig) continue;  // (nearly) singular: not this test
    Ma27 solver(t, FESD_KKT_SPARSE);
    ASSERT_EQ(solver.nsteps(), 2);
    ASSERT_EQ(solver.factor(t.val), 0) << "trial " << trial;
    EXPECT_EQ(solver.negative(), ref.negative) << "trial " << trial << " n " << n << " m " << m;
    // IPOPT's KKT matrix has exactly m negative eigenvalues at a good point; these random ones
    // may have more (indefinite H), which the inertia must report too.
    for (int k = 0; k < 2; ++k) {
      const Eigen::VectorXd b = Eigen::VectorXd::Random(t.n);
      const Eigen::VectorXd x = solver.solve(b);
      EXPECT_LT(backward_error(K, x, b), 1e-14) << "trial " << trial;
    }
    ++checked;
  }
  EXPECT_GE(checked, 40);
}

TEST(SparseLdl, SameValuesFactorizedAgainGiveTheSameSolution) {
  std::mt19937 rng(3);
  const Triplets t = random_kkt(rng, 120, 70, 0.0);
  Ma27 solver(t, FESD_KKT_SPARSE);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(t.n, -1, 1);
  ASSERT_EQ(solver.factor(t.val), 0);
  const Eigen::VectorXd x1 = solver.solve(b);
  // Other values on the same structure (the cached analysis is reused), then the first again.
  std::vector<double> other = t.val;
  for (double& v : other) v *= 1.5;
  ASSERT_EQ(solver.factor(other), 0);
  const Eigen::VectorXd x2 = solver.solve(b);
  EXPECT_LT(backward_error(1.5 * t.dense(), x2, b), 1e-14);
  ASSERT_EQ(solver.factor(t.val), 0);
  EXPECT_EQ(solver.solve(b), x1);
}

// Matrices of at least 1000 rows start their Ruiz sweeps from the previous factorization's
// scaling (one sweep instead of three from the identity; sparse_ldl.cpp, kWarmMinRows). A
// symmetric rescaling D K D by powers of ten up to 1e6 (as IPOPT's barrier terms move) starts the
// second factorization far from its equilibrium: same inertia (congruence), backward error as
// from the identity; then the first values again.
TEST(SparseLdl, WarmStartedScalingOnLargeMatrices) {
  std::mt19937 rng(61);
  // Regularized (delta_c = 1e-4, H shifted by 3) so that the reference inertia is well defined:
  // the unregularized random matrices of this size have |eigenvalues| down to 1e-17 of the largest.
  Triplets t = random_kkt(rng, 700, 500, 1e-4);
  for (int i = 0; i < 700; ++i) t.add(i, i, 3.0);
  ASSERT_GE(t.n, 1000);
  const Eigen::MatrixXd K = t.dense();
  const Reference ref = reference(K);
  ASSERT_GT(ref.min_abs_eig, 1e-12 * ref.max_abs_eig);
  EXPECT_EQ(ref.negative, 500);  // measured: one per constraint
  std::vector<double> d(static_cast<std::size_t>(t.n));
  for (double& di : d) di = std::pow(10.0, static_cast<double>(rng() % 7));
  Triplets scaled = t;
  for (int e = 0; e < t.nz(); ++e) scaled.val[e] *= d[t.irn[e] - 1] * d[t.icn[e] - 1];
  const Eigen::MatrixXd K1 = scaled.dense();
  Ma27 solver(t, FESD_KKT_SPARSE);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(t.n, -1, 1);
  const Triplets* const sequence[] = {&t, &scaled, &t};
  for (const Triplets* values : sequence) {
    ASSERT_EQ(solver.factor(values->val), 0);
    EXPECT_EQ(solver.negative(), ref.negative);
    const Eigen::VectorXd x = solver.solve(b);
    EXPECT_LT(backward_error(values == &t ? K : K1, x, b), 1e-14);
  }
}

// kkt_scaling = fresh (fesd_kkt_request_scaling(1)): every factorization scales from the identity,
// so the scaling depends on the matrix alone: a matrix factorized again after another one of its
// structure is scaled as the first time, bit for bit. With the default warm scaling (one sweep
// from the previous factorization's) it is not, which is what the fresh one removes.
TEST(SparseLdl, FreshScalingDependsOnTheMatrixAlone) {
  ASSERT_NE(module().request_scaling, nullptr);
  std::mt19937 rng(61);
  Triplets t = random_kkt(rng, 700, 500, 1e-4);
  for (int i = 0; i < 700; ++i) t.add(i, i, 3.0);
  ASSERT_GE(t.n, 1000);  // kWarmMinRows: smaller matrices are always scaled from the identity
  Triplets scaled = t;
  for (int e = 0; e < t.nz(); ++e)
    scaled.val[e] *= std::pow(10.0, static_cast<double>((t.irn[e] + t.icn[e]) % 7));
  const Eigen::MatrixXd K = t.dense();
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(t.n, -1, 1);
  // t's scaling after factorizing t, or t, scaled and t again.
  const auto scaling = [&](bool fresh, bool again) {
    module().request_scaling(fresh ? 1 : 0);
    Ma27 solver(t, FESD_KKT_SPARSE);
    EXPECT_EQ(solver.factor(t.val), 0);
    if (again) {
      EXPECT_EQ(solver.factor(scaled.val), 0);
      EXPECT_EQ(solver.factor(t.val), 0);
    }
    module().request_scaling(0);
    EXPECT_LT(backward_error(K, solver.solve(b), b), 1e-14);
    return solver.scaling();
  };
  const std::vector<double> first = scaling(true, false);
  EXPECT_EQ(scaling(true, true), first);
  EXPECT_NE(scaling(false, true), first);  // measured: the warm sweep from scaled's differs
  // The first factorization of a structure is scaled from the identity either way.
  EXPECT_EQ(scaling(false, false), first);
}

long long delayed_pivots() {
  FesdKktStats st{};
  module().stats(&st);
  return st.delayed_pivots;
}

TEST(SparseLdl, DelayedPivotsChangingBetweenFactorizationsOfOneStructure) {
  // The factorization keeps each front's rows and assembly maps per structure and shifts them by
  // the pivots its children delay. First values with -1 on the constraint diagonal (the ordering,
  // matched on them, pairs no constraint row with a variable), then the same matrix with zero
  // constraint diagonals (constraint rows before their variables: delayed pivots), then the first
  // values again (the same solution, bit for bit).
  ASSERT_NE(module().stats, nullptr);
  std::mt19937 rng(21);
  int with_delays = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const int n = 40 + static_cast<int>(rng() % 120), m = 5 + static_cast<int>(rng() % (n / 3));
    const Triplets z = random_kkt(rng, n, m, 0.0);
    Triplets t = z;
    for (int e = 0; e < t.nz(); ++e)
      if (t.irn[e] == t.icn[e] && t.irn[e] > n) t.val[e] = -1.0;
    const Reference ref_t = reference(t.dense()), ref_z = reference(z.dense());
    if (ref_t.min_abs_eig < 1e-12 * ref_t.max_abs_eig ||
        ref_z.min_abs_eig < 1e-12 * ref_z.max_abs_eig)
      continue;
    Ma27 solver(t, FESD_KKT_SPARSE);
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(t.n, -1, 2);
    ASSERT_EQ(solver.factor(t.val), 0) << "trial " << trial;
    const Eigen::VectorXd x1 = solver.solve(b);
    const long long before = delayed_pivots();
    ASSERT_EQ(solver.factor(z.val), 0) << "trial " << trial;
    if (delayed_pivots() > before) ++with_delays;
    EXPECT_EQ(solver.negative(), ref_z.negative) << "trial " << trial;
    EXPECT_LT(backward_error(z.dense(), solver.solve(b), b), 1e-14) << "trial " << trial;
    ASSERT_EQ(solver.factor(t.val), 0) << "trial " << trial;
    EXPECT_EQ(solver.negative(), ref_t.negative) << "trial " << trial;
    EXPECT_EQ(solver.solve(b), x1) << "trial " << trial;
  }
  EXPECT_GE(with_delays, 6);
}

/// The tests that solve through libfesd and read the module's counters here need the libfesd
/// this process runs to be the build's: it loads the KKT module next to itself, and the counters
/// read here are FESD_KKT_MODULE's. With LD_LIBRARY_PATH pointing at another build they would be
/// two modules. "" if they are one, else what differs.
std::string other_build() {
  void* h = dlopen("libfesd.so.0", RTLD_NOW | RTLD_NOLOAD);
  link_map* map = nullptr;
  if (h == nullptr || dlinfo(h, RTLD_DI_LINKMAP, &map) != 0 || map == nullptr)
    return "libfesd.so.0 is not loaded";
  namespace fs = std::filesystem;
  const fs::path lib = fs::canonical(map->l_name).parent_path();
  const fs::path kkt = fs::canonical(FESD_KKT_MODULE).parent_path();
  dlclose(h);
  if (lib == kkt) return {};
  return "this process runs " + lib.string() + "/libfesd.so.0, whose KKT module is not " +
         FESD_KKT_MODULE + " (LD_LIBRARY_PATH points at another build: unset it)";
}

FesdKktStats kkt_stats() {
  FesdKktStats st{};
  module().stats(&st);
  return st;
}

/// Normwise backward error as backward_error(), from the triplets (no dense matrix).
double sparse_backward_error(const Triplets& t, const Eigen::VectorXd& x,
                             const Eigen::VectorXd& b) {
  Eigen::VectorXd r = b, rowsum = Eigen::VectorXd::Zero(t.n);
  for (int e = 0; e < t.nz(); ++e) {
    const int i = t.irn[e] - 1, j = t.icn[e] - 1;
    r[i] -= t.val[e] * x[j];
    rowsum[i] += std::abs(t.val[e]);
    if (i != j) {
      r[j] -= t.val[e] * x[i];
      rowsum[j] += std::abs(t.val[e]);
    }
  }
  return r.lpNorm<Eigen::Infinity>() /
         (rowsum.maxCoeff() * x.lpNorm<Eigen::Infinity>() + b.lpNorm<Eigen::Infinity>());
}

// From 5000 rows on, a matrix with fewer zero diagonals than the one the ordering was matched on
// (IPOPT's first matrix of an NLP is often unperturbed: variables without curvature or bounds have
// a zero diagonal, which the later, perturbed matrices do not) gets the ordering computed again
// from its own values; the new ordering is kept if its factor has at most 0.8x the entries of the
// factorization before it, else the old one comes back (sparse_ldl.cpp, kReorderZeroDrop,
// kReorderKeep; docs/kkt-solver.md, "Hopper"). Never on more zeros, never below 5000 rows.
struct ReorderRun {
  long long reorders_first, reorders_second, reorders_third, undone, entries_unperturbed,
      entries_second, entries_fourth, fresh_entries;
  double berr;
};
ReorderRun reorder_run(int nx, int m, int zero_every) {
  std::mt19937 rng(77);
  Triplets perturbed = random_kkt(rng, nx, m, 0.0);
  for (int i = 0; i < nx; ++i) perturbed.add(i, i, 3.0);  // delta_x
  // Unperturbed: every zero_every-th variable without curvature or bound (diagonal exactly 0).
  Triplets unperturbed = perturbed;
  for (int e = 0; e < unperturbed.nz(); ++e) {
    const int i = unperturbed.irn[e] - 1;
    if (i == unperturbed.icn[e] - 1 && i < nx && i % zero_every == 0) unperturbed.val[e] = 0.0;
  }
  ReorderRun out{};
  Ma27 solver(perturbed, FESD_KKT_SPARSE);
  const FesdKktStats start = kkt_stats();
  long long before = start.reorderings;
  // The unperturbed matrices may be singular (IFLAG 3), as IPOPT's often are.
  EXPECT_GE(solver.factor(unperturbed.val), 0);
  out.entries_unperturbed = kkt_stats().last_factor_entries;
  out.reorders_first = kkt_stats().reorderings - before;
  before = kkt_stats().reorderings;
  EXPECT_EQ(solver.factor(perturbed.val), 0);
  out.reorders_second = kkt_stats().reorderings - before;
  out.entries_second = kkt_stats().last_static_entries;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(perturbed.n, -1, 2);
  out.berr = sparse_backward_error(perturbed, solver.solve(b), b);
  before = kkt_stats().reorderings;
  // More zeros again: no re-ordering (here also because an undone one ends them for the structure).
  EXPECT_GE(solver.factor(unperturbed.val), 0);
  out.reorders_third = kkt_stats().reorderings - before;
  EXPECT_EQ(solver.factor(perturbed.val), 0);
  out.entries_fourth = kkt_stats().last_static_entries;
  EXPECT_LT(sparse_backward_error(perturbed, solver.solve(b), b), 1e-14);
  out.undone = kkt_stats().reorderings_undone - start.reorderings_undone;
  Ma27 fresh(perturbed, FESD_KKT_SPARSE);
  EXPECT_EQ(fresh.factor(perturbed.val), 0);
  out.fresh_entries = kkt_stats().last_factor_entries;
  return out;
}

TEST(SparseLdl, OrderingComputedAgainWhenFewerDiagonalsAreZeroUndoneIfNotSmaller) {
  ASSERT_NE(module().stats, nullptr);
  // Random KKT matrices: the ordering of the perturbed matrix has about the static factor size of
  // the one matched on the unperturbed matrix (random coupling fills either way), so the
  // re-ordering is undone before anything is factorized with it: every factor of the structure
  // has the static fronts of the old ordering (entries without delayed pivots, which depend on the
  // warm-started scaling).
  for (int every : {2, 3}) {
    const ReorderRun r = reorder_run(3000, 2200, every);  // 5200 rows
    EXPECT_EQ(r.reorders_first, 0) << every;
    EXPECT_EQ(r.reorders_second, 1) << every;
    EXPECT_EQ(r.undone, 1) << every;
    EXPECT_EQ(r.reorders_third, 0) << every;  // not re-ordered again
    EXPECT_EQ(r.entries_second, r.entries_fourth) << every;
    EXPECT_LT(r.berr, 1e-14) << every;
  }
  const ReorderRun small = reorder_run(2500, 2000, 3);  // 4500 rows: never re-ordered
  EXPECT_EQ(small.reorders_second, 0);
  EXPECT_EQ(small.undone, 0);
  EXPECT_LT(small.berr, 1e-14);
}

/// nosnoc_py's hopper OCP (examples/nosnoc/hopper_ocp.toml, 25567 KKT rows) cut to `nlps` NLPs of
/// at most `max_iter` IPOPT iterations each, on the sparse LDL' (the NLPs cut by max_iter end
/// infeasible: no retry, no cold restart).
fesd::OcpProblem short_hopper_ocp(int nlps, int max_iter) {
  fesd::OcpProblem p =
      fesd::load_ocp_problem(std::string(FESD_SOURCE_DIR) + "/examples/nosnoc/hopper_ocp.toml");
  p.options.homotopy.max_homotopy_steps = nlps;
  p.options.homotopy.homotopy_retries = 0;
  p.options.homotopy.homotopy_cold_restart = false;
  p.options.nlp.max_iter = max_iter;
  p.options.nlp.kkt_solver = fesd::KktSolver::SparseLdl;
  return p;
}

// The case the re-ordering is for: nosnoc_py's hopper OCP (examples/nosnoc/hopper_ocp.toml, 25567
// KKT rows). NLP 1's structure is matched on an unperturbed matrix; its first perturbed matrix
// has fewer zero diagonals and an ordering with 0.69x the static factor entries (measured:
// 1.96e6 -> 1.35e6), which is kept. 15 IPOPT iterations per NLP are enough to get there.
TEST(SparseLdl, HopperOcpKeepsTheOrderingOfItsPerturbedMatrices) {
  ASSERT_NE(module().stats, nullptr);
  ASSERT_EQ(other_build(), "");
  const fesd::OcpProblem p = short_hopper_ocp(2, 15);
  const FesdKktStats before = kkt_stats();
  const fesd::OcpResult r = fesd::solve(p.ocp, p.options);
  const FesdKktStats after = kkt_stats();
  ASSERT_EQ(r.homotopy.size(), 2U) << r.message;
  EXPECT_EQ(r.homotopy[1].linear_solver, "sparse_ldl");
  EXPECT_GE(after.reorderings - before.reorderings, 1);
  EXPECT_EQ(after.reorderings_undone - before.reorderings_undone, 0);
}

// The factorization's own memory (front buffers, contribution blocks) follows the largest
// factorization, not the history of them. The contribution blocks not in place were kept in a pool
// of vectors, each grown to the largest block it had ever held: on the hopper sweep's n_s = 5
// point the pool reached 619 MB for factors of 6e6 entries (48 MB), then 2.1 GB after one
// delayed-pivot cascade, and the out-of-memory killer ended the run at 16.9 GB
// (docs/kkt-solver.md, "Memory"). Now they are one stack. Measured here (3 NLPs of 20 iterations):
// 8.1 MB of scratch for a factor of 10.9 MB (the stack 5.2 MB, the largest factorization's peak);
// with the pool 28.9 MB. (The bound tells the stack from the pool; a stack that popped nothing
// until the end of a factorization would still pass: 9.6 MB, measured in review.)
TEST(SparseLdl, ScratchMemoryIsAFractionOfTheFactorOnTheHopperOcp) {
  ASSERT_NE(module().stats, nullptr);
  ASSERT_EQ(other_build(), "");
  const fesd::OcpProblem p = short_hopper_ocp(3, 20);
  FesdKktStats after{};
  // A thread of its own: the scratch memory is per thread, this one starts with none.
  std::thread([&] {
    const fesd::OcpResult r = fesd::solve(p.ocp, p.options);
    EXPECT_EQ(r.homotopy.size(), 3U) << r.message;
    after = kkt_stats();
  }).join();
  ASSERT_GT(after.factorizations, 40);
  const double factor_bytes = 8.0 * static_cast<double>(after.last_factor_entries);
  EXPECT_GT(after.scratch_bytes, 0);
  EXPECT_LT(static_cast<double>(after.scratch_bytes), 1.5 * factor_bytes)
      << after.scratch_bytes << " bytes of scratch for a factor of " << factor_bytes << " bytes";
}

TEST(SparseLdl, TwoStructuresAliveAtOnce) {
  // Like two IPOPT solves (or IPOPT's restoration phase) using the module in turn.
  std::mt19937 rng(5);
  const Triplets t1 = random_kkt(rng, 90, 40, 0.0), t2 = random_kkt(rng, 150, 100, 0.0);
  Ma27 s1(t1, FESD_KKT_SPARSE), s2(t2, FESD_KKT_SPARSE);
  for (int round = 0; round < 3; ++round) {
    ASSERT_EQ(s1.factor(t1.val), 0);
    ASSERT_EQ(s2.factor(t2.val), 0);
    const Eigen::VectorXd b1 = Eigen::VectorXd::Ones(t1.n), b2 = Eigen::VectorXd::Ones(t2.n);
    EXPECT_LT(backward_error(t1.dense(), s1.solve(b1), b1), 1e-14);
    EXPECT_LT(backward_error(t2.dense(), s2.solve(b2), b2), 1e-14);
    EXPECT_EQ(s1.negative(), reference(t1.dense()).negative);
    EXPECT_EQ(s2.negative(), reference(t2.dense()).negative);
  }
}

TEST(SparseLdl, DuplicateTripletsAreSummed) {
  std::mt19937 rng(7);
  const Triplets t = random_kkt(rng, 100, 60, 0.0);
  // Every entry split in two halves, in reverse order, half of them given in the other triangle.
  Triplets d;
  d.n = t.n;
  for (int e = t.nz() - 1; e >= 0; --e) {
    d.irn.push_back(t.irn[e]);
    d.icn.push_back(t.icn[e]);
    d.val.push_back(0.25 * t.val[e]);
    d.irn.push_back(e % 2 == 0 ? t.icn[e] : t.irn[e]);
    d.icn.push_back(e % 2 == 0 ? t.irn[e] : t.icn[e]);
    d.val.push_back(0.75 * t.val[e]);
  }
  ASSERT_TRUE(d.dense().isApprox(t.dense(), 1e-15));
  Ma27 a(t, FESD_KKT_SPARSE), b(d, FESD_KKT_SPARSE);
  ASSERT_EQ(a.factor(t.val), 0);
  ASSERT_EQ(b.factor(d.val), 0);
  EXPECT_EQ(a.negative(), b.negative());
  const Eigen::VectorXd rhs = Eigen::VectorXd::Random(t.n);
  const Eigen::VectorXd xa = a.solve(rhs), xb = b.solve(rhs);
  EXPECT_LT((xa - xb).norm(), 1e-10 * (1 + xa.norm()));
  EXPECT_LT(backward_error(t.dense(), xb, rhs), 1e-14);
}

TEST(SparseLdl, SingularMatricesAreReported) {
  std::mt19937 rng(11);
  // Two identical constraint rows: rank-deficient J, so the KKT matrix is singular.
  Triplets t = random_kkt(rng, 60, 30, 0.0);
  const int n = 60, r0 = n, r1 = n + 1;
  Triplets s;
  s.n = t.n;
  for (int e = 0; e < t.nz(); ++e)
    if (t.irn[e] - 1 != r1) s.add(t.irn[e] - 1, t.icn[e] - 1, t.val[e]);
  for (int e = 0; e < t.nz(); ++e)
    if (t.irn[e] - 1 == r0) s.add(r1, t.icn[e] - 1 == r0 ? r1 : t.icn[e] - 1, t.val[e]);
  ASSERT_LT(reference(s.dense()).min_abs_eig, 1e-10);
  Ma27 solver(s, FESD_KKT_SPARSE);
  EXPECT_EQ(solver.factor(s.val), 3);  // MA27's "singular": IPOPT regularizes
  // With IPOPT's regularization -delta_c on the constraint block it factorizes.
  std::vector<double> reg = s.val;
  for (int e = 0; e < s.nz(); ++e)
    if (s.irn[e] == s.icn[e] && s.irn[e] > n) reg[e] -= 1e-8;
  Triplets sr = s;
  sr.val = reg;
  EXPECT_EQ(solver.factor(reg), 0);
  EXPECT_EQ(solver.negative(), reference(sr.dense()).negative);

  // The zero matrix.
  Triplets z;
  z.n = 8;
  for (int i = 0; i < 8; ++i) z.add(i, i, 0.0);
  Ma27 zero(z, FESD_KKT_SPARSE);
  EXPECT_EQ(zero.factor(z.val), 3);
}

TEST(SparseLdl, ZeroColumnsOfSingularMatricesAreNotDelayed) {
  // Every tenth constraint row repeated: each copy's column of the Schur complement is zero to
  // round-off once its original and variables are eliminated. Carried as a delayed pivot, it
  // would travel up the elimination tree to the root (on the hopper OCP's singular KKT matrices
  // 5e5 delayed pivots and fronts of 1800 rows); it is eliminated as a zero pivot where it
  // becomes fully summed, and the matrix is reported singular with its rank.
  ASSERT_NE(module().stats, nullptr);
  std::mt19937 rng(29);
  const int n = 1500, m = 700, copies = m / 10;
  const Triplets t = random_kkt(rng, n, m, 0.0);
  Triplets s = t;
  s.n = t.n + copies;
  for (int c = 0; c < copies; ++c) {
    const int r = n + 10 * c, r_copy = t.n + c;
    for (int e = 0; e < t.nz(); ++e)
      if (t.irn[e] - 1 == r) s.add(r_copy, t.icn[e] - 1 == r ? r_copy : t.icn[e] - 1, t.val[e]);
  }
  Ma27 regular(t, FESD_KKT_SPARSE);
  long long before = delayed_pivots();
  ASSERT_EQ(regular.factor(t.val), 0);
  const long long delayed_regular = delayed_pivots() - before;
  Ma27 solver(s, FESD_KKT_SPARSE);
  before = delayed_pivots();
  EXPECT_EQ(solver.factor(s.val), 3);
  const long long delayed_singular = delayed_pivots() - before;
  // Measured: 70 and 127 delayed pivots (2217 for the singular one without the zero pivots).
  EXPECT_LE(delayed_singular, delayed_regular + copies);
}

TEST(SparseLdl, SmallPivotsAreZeroOnlyInSmallMatrices) {
  // Blocks [1 1; 1 1 + d] with d = 2^-50: the Schur complement is d exactly, 8.9e-16 of the
  // largest entry (Ruiz leaves the blocks as they are), and the matrix is positive definite.
  // Below 5000 rows d counts as zero (1e-14 of the largest entry): singular, IPOPT regularizes.
  // From 5000 rows on only pivots below 1e-20 of it do (docs/kkt-solver.md, "Row 30"), so the
  // factorization succeeds with no negative eigenvalue.
  const double d = std::ldexp(1.0, -50);
  const auto blocks = [&](int n) {
    Triplets t;
    t.n = n;
    for (int i = 0; i < n; i += 2) {
      t.add(i, i, 1.0);
      t.add(i + 1, i, 1.0);
      t.add(i + 1, i + 1, 1.0 + d);
    }
    return t;
  };
  const Triplets small = blocks(4998), large = blocks(5000);
  Ma27 a(small, FESD_KKT_SPARSE), b(large, FESD_KKT_SPARSE);
  EXPECT_EQ(a.factor(small.val), 3);
  EXPECT_EQ(b.factor(large.val), 0);
  EXPECT_EQ(b.negative(), 0);
}

TEST(SparseLdl, TooSmallWorkspaceIsNegotiated) {
  std::mt19937 rng(13);
  const Triplets t = random_kkt(rng, 150, 80, 0.0);
  Ma27 solver(t, FESD_KKT_SPARSE);
  solver.shrink_la(t.nz() + t.n + 10);  // room for the values, not the factor: IFLAG = -4
  ASSERT_EQ(solver.factor(t.val), 0);
  EXPECT_GE(solver.reallocations(), 1);
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(t.n);
  EXPECT_LT(backward_error(t.dense(), solver.solve(b), b), 1e-14);
}

TEST(SparseLdl, AutoModeKeepsTheDenseSolverForSmallMatrices) {
  std::mt19937 rng(17);
  const Triplets small = random_kkt(rng, 60, 40, 0.0), large = random_kkt(rng, 120, 60, 0.0);
  EXPECT_EQ(Ma27(small, FESD_KKT_AUTO).nsteps(), 1);  // dense: N = 100 <= 128
  EXPECT_EQ(Ma27(large, FESD_KKT_AUTO).nsteps(), 2);  // sparse: N = 180
  EXPECT_EQ(Ma27(large, FESD_KKT_DENSE).nsteps(), 1);
  EXPECT_EQ(Ma27(small, FESD_KKT_SPARSE).nsteps(), 2);
}

TEST(SparseLdl, SlidingOcpGivesMumpsObjective) {
  // OCP (61), 1356 variables: the sparse LDL' and MUMPS reach the same optimum.
  const fesd::Ocp ocp = fesd_bench::sliding_ocp_paper();
  fesd::OcpOptions sparse = fesd_bench::sliding_options(), mumps = sparse;
  sparse.nlp.kkt_solver = fesd::KktSolver::SparseLdl;
  mumps.nlp.kkt_solver = fesd::KktSolver::Mumps;
  const fesd::OcpResult a = fesd::solve(ocp, sparse);
  const fesd::OcpResult b = fesd::solve(ocp, mumps);
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  EXPECT_NEAR(a.objective, b.objective, 1e-8 * std::abs(b.objective));
  EXPECT_EQ(a.homotopy.front().linear_solver, "sparse_ldl");
  EXPECT_EQ(b.homotopy.front().linear_solver, "mumps");
  EXPECT_GT(a.homotopy.front().factorizations, 0);
  int ia = 0, ib = 0;
  for (const auto& r : a.homotopy) ia += r.nlp_iterations;
  for (const auto& r : b.homotopy) ib += r.nlp_iterations;
  // Same iterates up to round-off: the counts differ by a few per cent at most (measured: 370
  // against 372, docs/kkt-solver.md).
  EXPECT_LE(std::abs(ia - ib), ib / 10) << ia << " vs " << ib;
}

// kkt_scaling reaches the module: with fresh no factorization starts from the previous scaling,
// with warm (default) those of at least 1000 rows do; the optimum is the same.
TEST(SparseLdl, KktScalingOptionOnTheSlidingOcp) {
  ASSERT_NE(module().stats, nullptr);
  ASSERT_EQ(other_build(), "");
  const fesd::Ocp ocp = fesd_bench::sliding_ocp_paper();
  fesd::OcpOptions warm = fesd_bench::sliding_options(), fresh = warm;
  fresh.nlp.kkt_scaling = fesd::KktScaling::Fresh;
  const auto warm_scalings = [] {
    FesdKktStats st{};
    module().stats(&st);
    return st.warm_scalings;
  };
  const long long w0 = warm_scalings();
  const fesd::OcpResult a = fesd::solve(ocp, warm);
  const long long w1 = warm_scalings();
  const fesd::OcpResult b = fesd::solve(ocp, fresh);
  const long long w2 = warm_scalings();
  ASSERT_EQ(a.status, fesd::Status::Success) << a.message;
  ASSERT_EQ(b.status, fesd::Status::Success) << b.message;
  EXPECT_GT(w1 - w0, 0);
  EXPECT_EQ(w2 - w1, 0);
  EXPECT_NEAR(a.objective, b.objective, 1e-8 * std::abs(a.objective));
  // Not with a solver that is not fesd's sparse LDL'.
  fesd::OcpOptions mumps = fresh;
  mumps.nlp.kkt_solver = fesd::KktSolver::Mumps;
  try {
    (void)fesd::solve(ocp, mumps);
    ADD_FAILURE() << "kkt_scaling = fresh with MUMPS accepted";
  } catch (const fesd::InvalidOption& e) {
    EXPECT_NE(std::string(e.what()).find("ipopt.kkt_scaling = fresh applies to fesd's sparse LDL'"),
              std::string::npos)
        << e.what();
  }
}

TEST(SparseLdl, KktSolverOptionNames) {
  fesd::KktSolver k{};
  for (const char* name : {"auto", "sparse_ldl", "dense", "mumps"}) {
    ASSERT_TRUE(fesd::parse(name, k)) << name;
    EXPECT_EQ(fesd::to_string(k), name);
  }
  EXPECT_FALSE(fesd::parse("ma27", k));
  fesd::KktScaling s{};
  for (const char* name : {"warm", "fresh"}) {
    ASSERT_TRUE(fesd::parse(name, s)) << name;
    EXPECT_EQ(fesd::to_string(s), name);
  }
  EXPECT_FALSE(fesd::parse("identity", s));
}

}  // namespace
