// bench/kkt_solver.cpp: the KKT solvers behind IPOPT on OCP (61) (bench/sliding_ocp.hpp) against
// the NLP size (docs/kkt-solver.md).
//
// For each N_stages and each kkt_solver (dense only up to --dense-max KKT rows, it is O(n^3)), the
// whole OCP is solved and the table gives the NLP size, IPOPT iterations, CPU time per iteration
// (everything: IPOPT, derivatives, KKT), IPOPT's factorization time per iteration, and the
// objective. Then matrices of the sparse_ldl run (every --stride-th, at most --matrices) are
// factorized again, outside IPOPT, by fesd's sparse LDL' (its MA27 interface) and by MUMPS
// (called directly with IPOPT 3.11's settings): after one untimed pass each, --repeat passes over
// the matrices, the two solvers' passes alternating; the median pass's CPU time per factorization
// of the same matrices, analysis excluded.
//
//   kkt_solver [--stages 6,12,24] [--solvers dense,mumps,sparse_ldl] [--dense-max 1000]
//              [--stride 7] [--matrices 40] [--repeat 5] [--csv FILE] [--json FILE]
//              [--save DIR]
//
// --save DIR writes each N_stages' timed matrices to DIR/kkt_N.bin (int count; per matrix: int n,
// int nz, nz ints irn, nz ints icn, nz doubles a; 1-based, as captured), for profiling the
// factorization alone (callgrind) outside IPOPT.
#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <dmumps_c.h>
#include <fesd/ocp.hpp>

#include "bench_args.hpp"
#include "bench_timing.hpp"
#include "nlp/kkt/kkt_module.h"
#include "sliding_ocp.hpp"

namespace fesd_bench {
void usage(const std::string& why, int exit_code) {
  std::fprintf(stderr,
               "kkt_solver: %s\n"
               "usage: kkt_solver [--stages 6,12,24] [--solvers dense,mumps,sparse_ldl] "
               "[--dense-max ROWS]\n"
               "                  [--stride K] [--matrices M] [--repeat R] [--csv FILE] "
               "[--json FILE]\n"
               "                  [--save DIR]\n",
               why.c_str());
  std::exit(exit_code);
}
}  // namespace fesd_bench

namespace {

using fesd_bench::cpu_now;

/// Process CPU time in seconds. Everything timed here runs on this one thread (MUMPS is the
/// sequential build); on a machine shared with builds, wall time varied by +-30 %, CPU time less.
double seconds_since(double t0) {
  return cpu_now() - t0;
}

/// The KKT module's entry points, from the library next to libfesd.so.
struct Module {
  void (*capture)(int, int) = nullptr;
  int (*captured_count)() = nullptr;
  void (*captured)(int, int*, int*, const int**, const int**, const double**) = nullptr;
  void (*request_mode)(int) = nullptr;
  void (*stats)(FesdKktStats*) = nullptr;
  void (*ma27id)(int*, double*) = nullptr;
  void (*ma27ad)(const int*, const int*, const int*, const int*, int*, const int*, int*, int*, int*,
                 int*, int*, double*, int*, double*) = nullptr;
  void (*ma27bd)(const int*, const int*, const int*, const int*, double*, const int*, int*,
                 const int*, int*, int*, int*, int*, int*, double*, int*) = nullptr;
};

Module load_module() {
  Dl_info info;
  const auto in_libfesd = static_cast<std::string_view (*)(fesd::KktSolver)>(&fesd::to_string);
  if (dladdr(reinterpret_cast<void*>(in_libfesd), &info) == 0 || info.dli_fname == nullptr)
    fesd_bench::usage("cannot locate libfesd.so", 1);
  const auto path = std::filesystem::path(info.dli_fname).parent_path() / "libfesd_kkt.so";
  void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
  if (h == nullptr) fesd_bench::usage("cannot load " + path.string(), 1);
  Module m;
  auto sym = [&](auto& fn, const char* name) {
    fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(h, name));
    if (fn == nullptr) fesd_bench::usage(std::string("module lacks ") + name, 1);
  };
  sym(m.capture, "fesd_kkt_capture");
  sym(m.captured_count, "fesd_kkt_captured_count");
  sym(m.captured, "fesd_kkt_captured");
  sym(m.request_mode, "fesd_kkt_request_mode");
  sym(m.stats, "fesd_kkt_stats");
  sym(m.ma27id, "ma27id_");
  sym(m.ma27ad, "ma27ad_");
  sym(m.ma27bd, "ma27bd_");
  return m;
}

struct Matrix {
  int n = 0, nz = 0;
  std::vector<int> irn, icn;
  std::vector<double> a;
};

/// fesd's sparse factorization of the matrices (one structure) through its MA27 interface: the
/// analysis and one untimed pass over them (ordering, symbolic analysis, the scratch memory's
/// growth) at construction, then pass() times one factorization of each, in CPU seconds.
class SparseLdlRunner {
 public:
  SparseLdlRunner(const Module& m, const std::vector<Matrix>& mats) : m_(m), mats_(mats) {
    const Matrix& s = mats.front();
    int icntl_iflag = 0, info[20];
    double ops = 0;
    m.ma27id(icntl_, cntl_);
    cntl_[0] = 1e-8;  // IPOPT's ma27_pivtol
    ikeep_.resize(3 * static_cast<std::size_t>(s.n));
    iw1_.resize(2 * static_cast<std::size_t>(s.n));
    int liw0 = 2 * (2 * s.nz + 3 * s.n + 1);
    std::vector<int> iw0(static_cast<std::size_t>(liw0));
    m.request_mode(FESD_KKT_SPARSE);
    m.ma27ad(&s.n, &s.nz, s.irn.data(), s.icn.data(), iw0.data(), &liw0, ikeep_.data(), iw1_.data(),
             &nsteps_, &icntl_iflag, icntl_, cntl_, info, &ops);
    m.request_mode(FESD_KKT_AUTO);
    la_ = std::max(s.nz, 5 * info[4]);
    liw_ = 5 * info[5];
    a_.resize(static_cast<std::size_t>(la_));
    iw_.resize(static_cast<std::size_t>(liw_));
    for (const Matrix& x : mats_) factor(x);
  }
  double pass() {
    const double t0 = cpu_now();
    for (const Matrix& x : mats_) factor(x);
    return seconds_since(t0) / static_cast<double>(mats_.size());
  }

 private:
  void factor(const Matrix& x) {
    int info[20];
    for (;;) {
      std::copy(x.a.begin(), x.a.end(), a_.begin());
      m_.ma27bd(&x.n, &x.nz, x.irn.data(), x.icn.data(), a_.data(), &la_, iw_.data(), &liw_,
                ikeep_.data(), &nsteps_, &maxfrt_, iw1_.data(), icntl_, cntl_, info);
      if (info[0] == -3) {
        liw_ = 2 * info[1];
        iw_.assign(static_cast<std::size_t>(liw_), 0);
      } else if (info[0] == -4) {
        la_ = 2 * info[1];
        a_.assign(static_cast<std::size_t>(la_), 0.0);
      } else {
        return;
      }
    }
  }
  const Module& m_;
  const std::vector<Matrix>& mats_;
  int icntl_[30] = {}, nsteps_ = 0, maxfrt_ = 0, la_ = 0, liw_ = 0;
  double cntl_[5] = {};
  std::vector<int> ikeep_, iw1_, iw_;
  std::vector<double> a_;
};

/// MUMPS's factorization (JOB = 2) of the matrices with IPOPT 3.11's MUMPS settings (symmetric
/// indefinite, pivtol 1e-6, scaling 77, ordering and permutation automatic, mem_percent 1000):
/// one analysis (JOB = 1) and one untimed pass at construction, then pass() as above.
class MumpsRunner {
 public:
  explicit MumpsRunner(const std::vector<Matrix>& mats) : mats_(mats) {
    id_.comm_fortran = -987654;  // USE_COMM_WORLD (the sequential MPI stub)
    id_.par = 1;
    id_.sym = 2;
    id_.job = -1;
    dmumps_c(&id_);
    id_.icntl[0] = id_.icntl[1] = id_.icntl[2] = -1;  // no output
    id_.icntl[3] = 0;
    id_.icntl[5] = 7;      // ICNTL(6) permuting_scaling
    id_.icntl[6] = 7;      // ICNTL(7) pivot order: automatic
    id_.icntl[7] = 77;     // ICNTL(8) scaling: automatic
    id_.icntl[9] = 0;      // ICNTL(10) no iterative refinement
    id_.icntl[13] = 1000;  // ICNTL(14) memory percent
    id_.cntl[0] = 1e-6;    // CNTL(1) pivtol
    const Matrix& s = mats.front();
    irn_ = s.irn;
    icn_ = s.icn;
    a_ = s.a;
    id_.n = s.n;
    id_.nz = s.nz;
    id_.irn = irn_.data();
    id_.jcn = icn_.data();
    id_.a = a_.data();
    id_.job = 1;
    dmumps_c(&id_);
    for (const Matrix& x : mats_) factor(x);
  }
  ~MumpsRunner() {
    id_.job = -2;
    dmumps_c(&id_);
  }
  MumpsRunner(const MumpsRunner&) = delete;
  MumpsRunner& operator=(const MumpsRunner&) = delete;
  double pass() {
    const double t0 = cpu_now();
    for (const Matrix& x : mats_) factor(x);
    return seconds_since(t0) / static_cast<double>(mats_.size());
  }

 private:
  void factor(const Matrix& x) {
    std::copy(x.a.begin(), x.a.end(), a_.begin());
    id_.job = 2;
    dmumps_c(&id_);
  }
  const std::vector<Matrix>& mats_;
  DMUMPS_STRUC_C id_{};
  std::vector<int> irn_, icn_;
  std::vector<double> a_;
};

/// Median CPU seconds per factorization of either solver over `repeat` passes, the two solvers'
/// passes alternating: on a shared machine the load changes by up to 2x within seconds, and
/// timing one solver after the other put different loads into one ratio.
std::pair<double, double> time_both(const Module& m, const std::vector<Matrix>& mats, int repeat) {
  SparseLdlRunner sparse(m, mats);
  MumpsRunner mumps(mats);
  std::vector<double> ts, tm;
  for (int r = 0; r < std::max(1, repeat); ++r) {
    ts.push_back(sparse.pass());
    tm.push_back(mumps.pass());
  }
  const auto median = [](std::vector<double>& v) {
    std::sort(v.begin(), v.end());
    const std::size_t h = v.size() / 2;
    return v.size() % 2 == 1 ? v[h] : 0.5 * (v[h - 1] + v[h]);
  };
  return {median(ts), median(tm)};
}

/// The matrices in the binary format of --save.
void save_matrices(const std::string& path, const std::vector<Matrix>& mats) {
  std::ofstream os(path, std::ios::binary);
  const auto put = [&os](const auto* p, std::size_t count) {
    os.write(reinterpret_cast<const char*>(p), static_cast<std::streamsize>(count * sizeof *p));
  };
  const int count = static_cast<int>(mats.size());
  put(&count, 1);
  for (const Matrix& m : mats) {
    put(&m.n, 1);
    put(&m.nz, 1);
    put(m.irn.data(), m.irn.size());
    put(m.icn.data(), m.icn.size());
    put(m.a.data(), m.a.size());
  }
  if (!os) fesd_bench::usage("cannot write " + path, 1);
}

struct Row {
  int N_stages = 0;
  std::string solver, status;
  int n_vars = 0, n_cons = 0, kkt_rows = 0, iterations = 0;
  double s_per_iter = 0, factor_s_per_iter = 0, objective = NAN;
  long long factorizations = 0;
  double factor_s_per_call = NAN;  // fesd's module only (its own count)
  long long solves = 0, refinements = 0, delayed = 0, reorderings = 0, undone = 0;
  double solve_s_per_iter = NAN;
};

struct Direct {
  int N_stages = 0, kkt_rows = 0, matrices = 0;
  double sparse_ldl_s = NAN, mumps_s = NAN;
};

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> stages{6, 12, 24};
  std::vector<std::string> solvers{"dense", "mumps", "sparse_ldl"};
  int dense_max = 1000, stride = 7, max_matrices = 40, repeat = 5;
  std::string csv, json_path, save_dir;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) fesd_bench::usage(a + ": missing value");
      return argv[++i];
    };
    if (a == "--stages")
      stages = fesd_bench::parse_list(a, value());
    else if (a == "--solvers")
      solvers = fesd_bench::split(value(), ',');
    else if (a == "--dense-max")
      dense_max = fesd_bench::parse_int(a, value());
    else if (a == "--stride")
      stride = fesd_bench::parse_int(a, value());
    else if (a == "--matrices")
      max_matrices = fesd_bench::parse_int(a, value());
    else if (a == "--repeat")
      repeat = fesd_bench::parse_int(a, value());
    else if (a == "--csv")
      csv = value();
    else if (a == "--json")
      json_path = value();
    else if (a == "--save")
      save_dir = value();
    else
      fesd_bench::usage("unknown argument " + a);
  }
  for (const std::string& s : solvers) {
    fesd::KktSolver k{};
    if (!fesd::parse(s, k)) fesd_bench::usage("unknown solver " + s);
  }
  // Dense last: it runs only if the NLP (n + m, known from the other runs) is small enough.
  std::stable_partition(solvers.begin(), solvers.end(),
                        [](const std::string& s) { return s != "dense"; });
  const Module module = load_module();

  std::vector<Row> rows;
  std::vector<Direct> direct;
  fmt::print("{:>8} {:>11} {:>6} {:>6} {:>6} {:>6} {:>11} {:>12} {:>8} {:>13} {:>16}\n", "N_stages",
             "solver", "n", "m", "kkt", "iter", "ms/iter", "fact ms/it", "n_fact", "fact ms/call",
             "objective");
  for (int N : stages) {
    int kkt_rows = 0, nlp_size = 0;
    std::vector<Matrix> captured;
    for (const std::string& name : solvers) {
      fesd::Ocp ocp = fesd_bench::sliding_ocp_paper();
      ocp.N_stages = N;
      fesd::OcpOptions o = fesd_bench::sliding_options();
      fesd::parse(name, o.nlp.kkt_solver);
      if (o.nlp.kkt_solver == fesd::KktSolver::Dense && nlp_size > dense_max) continue;
      const bool capture = o.nlp.kkt_solver == fesd::KktSolver::SparseLdl;
      if (capture) module.capture(stride, max_matrices);
      FesdKktStats before{}, after{};
      module.stats(&before);
      const double t0 = cpu_now();
      const fesd::OcpResult r = fesd::solve(ocp, o);
      const double cpu = seconds_since(t0);
      module.stats(&after);
      Row row;
      row.N_stages = N;
      row.solver = name;
      row.status = std::string(fesd::to_string(r.status));
      row.n_vars = r.summary.n_variables;
      row.n_cons = r.summary.n_constraints;
      row.objective = r.objective;
      nlp_size = row.n_vars + row.n_cons;
      double factor_s = 0;
      for (const fesd::HomotopyRow& h : r.homotopy) {
        row.iterations += h.nlp_iterations;
        factor_s += h.factor_s;
        row.factorizations += h.factorizations;
      }
      const double it = std::max(1, row.iterations);
      row.s_per_iter = cpu / it;
      row.factor_s_per_iter = factor_s / it;
      if (capture) {
        row.factor_s_per_call = (after.factor_seconds - before.factor_seconds) /
                                static_cast<double>(std::max(1LL, row.factorizations));
        row.solves = after.solves - before.solves;
        row.refinements = after.refinement_steps - before.refinement_steps;
        row.delayed = after.delayed_pivots - before.delayed_pivots;
        row.reorderings = after.reorderings - before.reorderings;
        row.undone = after.reorderings_undone - before.reorderings_undone;
        row.solve_s_per_iter = (after.solve_seconds - before.solve_seconds) / it;
        for (int i = 0; i < module.captured_count(); ++i) {
          Matrix m;
          const int *irn = nullptr, *icn = nullptr;
          const double* v = nullptr;
          module.captured(i, &m.n, &m.nz, &irn, &icn, &v);
          m.irn.assign(irn, irn + m.nz);
          m.icn.assign(icn, icn + m.nz);
          m.a.assign(v, v + m.nz);
          captured.push_back(std::move(m));
        }
        module.capture(0, 0);
        // The main NLP's KKT order (the last matrix may be a smaller re-solve's).
        if (!captured.empty()) kkt_rows = captured.front().n;
      }
      row.kkt_rows = kkt_rows;
      fmt::print("{:>8} {:>11} {:>6} {:>6} {:>6} {:>6} {:>11.3f} {:>12} {:>8} {:>13} {:>16.10g}\n",
                 N, name, row.n_vars, row.n_cons, capture ? fmt::format("{}", kkt_rows) : "",
                 row.iterations, 1e3 * row.s_per_iter,
                 o.nlp.kkt_solver == fesd::KktSolver::Mumps
                     ? std::string("")
                     : fmt::format("{:.3f}", 1e3 * row.factor_s_per_iter),
                 row.factorizations,
                 capture ? fmt::format("{:.3f}", 1e3 * row.factor_s_per_call) : "", row.objective);
      if (capture)
        fmt::print(
            "{:>20} solves {} ({:.3f} ms/iter), refinement steps {}, delayed pivots {:.1f} "
            "per factorization, re-orderings {} ({} undone)\n",
            "", row.solves, 1e3 * row.solve_s_per_iter, row.refinements,
            static_cast<double>(row.delayed) /
                static_cast<double>(std::max(1LL, row.factorizations)),
            row.reorderings, row.undone);
      std::fflush(stdout);
      rows.push_back(row);
    }
    // The same matrices factorized by both, outside IPOPT: one structure (the main NLPs') only.
    if (!captured.empty()) {
      const int n0 = captured.front().n, nz0 = captured.front().nz;
      std::erase_if(captured, [&](const Matrix& m) {
        return m.n != n0 || m.nz != nz0 || m.irn != captured.front().irn;
      });
      if (!save_dir.empty()) save_matrices(save_dir + fmt::format("/kkt_{}.bin", N), captured);
      Direct d;
      d.N_stages = N;
      d.kkt_rows = n0;
      d.matrices = static_cast<int>(captured.size());
      std::tie(d.sparse_ldl_s, d.mumps_s) = time_both(module, captured, repeat);
      direct.push_back(d);
    }
  }
  fmt::print(
      "\nsame matrices, factorization only (analysis excluded), CPU ms per factorization, median "
      "of {} passes over them, the two solvers' passes alternating:\n",
      repeat);
  fmt::print("{:>8} {:>6} {:>9} {:>16} {:>11} {:>8}\n", "N_stages", "kkt", "matrices",
             "sparse_ldl ms", "mumps ms", "ratio");
  for (const Direct& d : direct)
    fmt::print("{:>8} {:>6} {:>9} {:>16.3f} {:>11.3f} {:>8.1f}\n", d.N_stages, d.kkt_rows,
               d.matrices, 1e3 * d.sparse_ldl_s, 1e3 * d.mumps_s, d.mumps_s / d.sparse_ldl_s);

  if (!csv.empty()) {
    std::ofstream os(csv);
    os << "N_stages,solver,n_variables,n_constraints,kkt_rows,iterations,s_per_iteration,"
          "factor_s_per_iteration,factorizations,factor_s_per_call,solves,solve_s_per_iteration,"
          "refinement_steps,delayed_pivots,reorderings,reorderings_undone,objective,status\n";
    for (const Row& r : rows)
      os << fmt::format(
          "{},{},{},{},{},{},{:.6g},{:.6g},{},{:.6g},{},{:.6g},{},{},{},{},{:.12g},{}\n",
          r.N_stages, r.solver, r.n_vars, r.n_cons, r.kkt_rows, r.iterations, r.s_per_iter,
          r.factor_s_per_iter, r.factorizations, r.factor_s_per_call, r.solves, r.solve_s_per_iter,
          r.refinements, r.delayed, r.reorderings, r.undone, r.objective, r.status);
    os << "\nN_stages,kkt_rows,matrices,sparse_ldl_factor_s,mumps_factor_s\n";
    for (const Direct& d : direct)
      os << fmt::format("{},{},{},{:.6g},{:.6g}\n", d.N_stages, d.kkt_rows, d.matrices,
                        d.sparse_ldl_s, d.mumps_s);
  }
  if (!json_path.empty()) {
    nlohmann::json j;
    for (const Row& r : rows)
      j["runs"].push_back({{"N_stages", r.N_stages},
                           {"solver", r.solver},
                           {"n_variables", r.n_vars},
                           {"n_constraints", r.n_cons},
                           {"kkt_rows", r.kkt_rows},
                           {"iterations", r.iterations},
                           {"s_per_iteration", r.s_per_iter},
                           {"factor_s_per_iteration", r.factor_s_per_iter},
                           {"factorizations", r.factorizations},
                           {"factor_s_per_call", r.factor_s_per_call},
                           {"solves", r.solves},
                           {"solve_s_per_iteration", r.solve_s_per_iter},
                           {"refinement_steps", r.refinements},
                           {"delayed_pivots", r.delayed},
                           {"reorderings", r.reorderings},
                           {"reorderings_undone", r.undone},
                           {"objective", r.objective},
                           {"status", r.status}});
    for (const Direct& d : direct)
      j["factorization"].push_back({{"N_stages", d.N_stages},
                                    {"kkt_rows", d.kkt_rows},
                                    {"matrices", d.matrices},
                                    {"sparse_ldl_s", d.sparse_ldl_s},
                                    {"mumps_s", d.mumps_s}});
    std::ofstream(json_path) << j.dump(2) << "\n";
  }
  return 0;
}
