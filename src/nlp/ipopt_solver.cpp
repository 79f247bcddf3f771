// IPOPT backend: a TNLP over a BlockNlp, one IpoptApplication reused for every solve.
// Exceptions never cross IPOPT: evaluations return false on non-finite values and IPOPT cuts the
// step; the status comes back in NlpResult.
#include "nlp/ipopt_solver.hpp"
#include "core/option_registry.hpp"
#include "core/util.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <tuple>

#include <fmt/format.h>
#include <IpIpoptApplication.hpp>
#include <IpIpoptData.hpp>
#include <IpRegOptions.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>

#include "fesd/error.hpp"
#include "nlp/kkt/kkt_module.h"
#include "nlp/retry_ladder.hpp"

namespace fesd::nlp {
namespace {

using util::seconds_since;

using Clock = std::chrono::steady_clock;
std::string status_name(Ipopt::ApplicationReturnStatus s) {
  switch (s) {
    case Ipopt::Solve_Succeeded:
      return "Solve_Succeeded";
    case Ipopt::Solved_To_Acceptable_Level:
      return "Solved_To_Acceptable_Level";
    case Ipopt::Infeasible_Problem_Detected:
      return "Infeasible_Problem_Detected";
    case Ipopt::Search_Direction_Becomes_Too_Small:
      return "Search_Direction_Becomes_Too_Small";
    case Ipopt::Diverging_Iterates:
      return "Diverging_Iterates";
    case Ipopt::User_Requested_Stop:
      return "User_Requested_Stop";
    case Ipopt::Feasible_Point_Found:
      return "Feasible_Point_Found";
    case Ipopt::Maximum_Iterations_Exceeded:
      return "Maximum_Iterations_Exceeded";
    case Ipopt::Restoration_Failed:
      return "Restoration_Failed";
    case Ipopt::Error_In_Step_Computation:
      return "Error_In_Step_Computation";
    case Ipopt::Maximum_CpuTime_Exceeded:
      return "Maximum_CpuTime_Exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom:
      return "Not_Enough_Degrees_Of_Freedom";
    case Ipopt::Invalid_Problem_Definition:
      return "Invalid_Problem_Definition";
    case Ipopt::Invalid_Option:
      return "Invalid_Option";
    case Ipopt::Invalid_Number_Detected:
      return "Invalid_Number_Detected";
    case Ipopt::Unrecoverable_Exception:
      return "Unrecoverable_Exception";
    case Ipopt::NonIpopt_Exception_Thrown:
      return "NonIpopt_Exception_Thrown";
    case Ipopt::Insufficient_Memory:
      return "Insufficient_Memory";
    case Ipopt::Internal_Error:
      return "Internal_Error";
  }
  return "Unknown_Status";
}

/// Where a solve's progress goes (NlpSolver::set_progress), shared by the runs of one NLP.
struct ProgressSink {
  const NlpProgressCallback& callback;
  double every_s = 0;
  Clock::time_point start = Clock::now(), last = start;
  int run = 0;                ///< 1-based, set per run
  int iterations_before = 0;  ///< of the earlier runs
};

class BlockTnlp final : public Ipopt::TNLP {
 public:
  BlockTnlp(const BlockNlp& nlp, Iterate& it, bool warm, ProgressSink* progress)
      : nlp_(nlp), it_(it), warm_(warm), progress_(progress) {}

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac, Ipopt::Index& nnz_h,
                    IndexStyleEnum& style) override {
    n = nlp_.num_variables();
    m = nlp_.num_constraints();
    nnz_jac = nlp_.jac_nnz();
    nnz_h = nlp_.hess_nnz();
    style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index m,
                       Ipopt::Number* g_l, Ipopt::Number* g_u) override {
    std::copy_n(nlp_.x_lb.data(), n, x_l);
    std::copy_n(nlp_.x_ub.data(), n, x_u);
    std::copy_n(nlp_.g_lb.data(), m, g_l);
    std::copy_n(nlp_.g_ub.data(), m, g_u);
    return true;
  }
  bool get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z,
                          Ipopt::Number* z_L, Ipopt::Number* z_U, Ipopt::Index m, bool init_lambda,
                          Ipopt::Number* lambda) override {
    if (init_x) std::copy_n(it_.x.data(), n, x);
    if (init_z || init_lambda) {
      if (!warm_ || !it_.has_duals()) return false;
      if (init_z) {
        std::copy_n(it_.z_L.data(), n, z_L);
        std::copy_n(it_.z_U.data(), n, z_U);
      }
      if (init_lambda) std::copy_n(it_.lambda.data(), m, lambda);
    }
    return true;
  }
  bool eval_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number& f) override {
    return timed([&] { return nlp_.eval_f(x, f); });
  }
  bool eval_grad_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number* g) override {
    return timed([&] { return nlp_.eval_grad_f(x, g); });
  }
  bool eval_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Number* g) override {
    return timed([&] { return nlp_.eval_g(x, g); });
  }
  bool eval_jac_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Index,
                  Ipopt::Index* rows, Ipopt::Index* cols, Ipopt::Number* values) override {
    if (values == nullptr) {
      std::copy(nlp_.jac_rows().begin(), nlp_.jac_rows().end(), rows);
      std::copy(nlp_.jac_cols().begin(), nlp_.jac_cols().end(), cols);
      return true;
    }
    return timed([&] { return nlp_.eval_jac_g(x, values); });
  }
  bool eval_h(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number obj_factor, Ipopt::Index,
              const Ipopt::Number* lambda, bool, Ipopt::Index, Ipopt::Index* rows,
              Ipopt::Index* cols, Ipopt::Number* values) override {
    if (values == nullptr) {
      std::copy(nlp_.hess_rows().begin(), nlp_.hess_rows().end(), rows);
      std::copy(nlp_.hess_cols().begin(), nlp_.hess_cols().end(), cols);
      return true;
    }
    return timed([&] { return nlp_.eval_h(x, obj_factor, lambda, values); });
  }
  void finalize_solution(Ipopt::SolverReturn, Ipopt::Index n, const Ipopt::Number* x,
                         const Ipopt::Number* z_L, const Ipopt::Number* z_U, Ipopt::Index m,
                         const Ipopt::Number*, const Ipopt::Number* lambda, Ipopt::Number obj,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    it_.x.assign(x, x + n);
    it_.z_L.assign(z_L, z_L + n);
    it_.z_U.assign(z_U, z_U + n);
    it_.lambda.assign(lambda, lambda + m);
    objective_ = obj;
  }
  bool intermediate_callback(Ipopt::AlgorithmMode, Ipopt::Index iter, Ipopt::Number obj,
                             Ipopt::Number inf_pr, Ipopt::Number inf_du, Ipopt::Number mu,
                             Ipopt::Number, Ipopt::Number, Ipopt::Number, Ipopt::Number,
                             Ipopt::Index, const Ipopt::IpoptData*,
                             Ipopt::IpoptCalculatedQuantities*) override {
    iterations_ = iter;
    inf_pr_ = inf_pr;
    inf_du_ = inf_du;
    if (progress_ != nullptr && progress_->callback) {
      const auto now = Clock::now();
      if (std::chrono::duration<double>(now - progress_->last).count() >= progress_->every_s) {
        progress_->last = now;
        progress_->callback(
            NlpProgress{.iteration = progress_->iterations_before + iter,
                        .run = progress_->run,
                        .objective = obj,
                        .inf_pr = inf_pr,
                        .inf_du = inf_du,
                        .mu = mu,
                        .wall_s = std::chrono::duration<double>(now - progress_->start).count()});
      }
    }
    return true;
  }

  double eval_s() const { return eval_s_; }
  int eval_failures() const { return eval_failures_; }
  double objective() const { return objective_; }
  int iterations() const { return iterations_; }
  double inf_pr() const { return inf_pr_; }
  double inf_du() const { return inf_du_; }

 private:
  template <class Fn>
  bool timed(Fn&& fn) {
    const auto t0 = Clock::now();
    const bool ok = fn();
    eval_s_ += seconds_since(t0);
    if (!ok) ++eval_failures_;
    return ok;
  }
  const BlockNlp& nlp_;
  Iterate& it_;
  bool warm_;
  ProgressSink* progress_;
  double eval_s_ = 0, objective_ = 0, inf_pr_ = 0, inf_du_ = 0;
  int eval_failures_ = 0, iterations_ = 0;
};

/// The KKT module's own entry points (kkt_module.h), found once its library is loaded.
struct KktModule {
  void (*request_mode)(int) = nullptr;
  void (*request_scaling)(int) = nullptr;
  void (*stats)(FesdKktStats*) = nullptr;
  std::string problem;  // why it is not loaded ("" once it is)
  bool ok() const {
    return request_mode != nullptr && request_scaling != nullptr && stats != nullptr;
  }
};

/// Loads libfesd_kkt.so (next to libfesd.so) globally, so that IPOPT's loader, which opens
/// "libhsl.so" for linear_solver = ma27, finds it by its SONAME. Once per process.
const KktModule& kkt_module() {
  static const KktModule module = [] {
    KktModule m;
    Dl_info info;
    if (dladdr(reinterpret_cast<void*>(&kkt_module), &info) == 0 || info.dli_fname == nullptr) {
      m.problem = "the directory of libfesd.so is unknown (dladdr failed)";
      return m;
    }
    const auto path = std::filesystem::path(info.dli_fname).parent_path() / "libfesd_kkt.so";
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
    if (handle == nullptr) {
      const char* why = dlerror();
      m.problem = why != nullptr ? why : path.string() + ": dlopen failed";
      return m;
    }
    m.request_mode = reinterpret_cast<void (*)(int)>(dlsym(handle, "fesd_kkt_request_mode"));
    m.request_scaling = reinterpret_cast<void (*)(int)>(dlsym(handle, "fesd_kkt_request_scaling"));
    m.stats = reinterpret_cast<void (*)(FesdKktStats*)>(dlsym(handle, "fesd_kkt_stats"));
    if (!m.ok()) m.problem = path.string() + " is not fesd's KKT module (entry points missing)";
    return m;
  }();
  return module;
}

/// The stricter pivoting of a failed sparse_ldl NLP (RetryRung::StricterPivoting): IPOPT's
/// ma27_pivtol (CNTL(1): a pivot is accepted if at least u times its column's largest entry) and
/// the most IPOPT may raise it to. IPOPT's defaults are 1e-8 and 1e-4. Measured on
/// examples/nosnoc/hopper_exercise_ocp_step.toml (docs/kkt-solver.md, "Retry, then fallback"):
/// NLP 4's first run ends Restoration_Failed after 563 iterations; again with 1e-2 it solves in
/// 434 (with 1e-4: 883), where MUMPS took 382 at 4-5 times the cost per iteration. (That was
/// with the warm-started scaling; the run now factorizes with the fresh one: fresh_scaling_on.)
constexpr double kRetryPivtol = 1e-2;
constexpr double kRetryPivtolMax = 0.5;

/// The second run of a warm-started NLP whose first failed: IPOPT's monotone mu strategy from
/// this mu_init (the first run: the adaptive strategy, whose mu may climb far above the warm
/// start's). Measured on examples/nosnoc/hopper_ocp.toml (docs/kkt-solver.md, "Retry, then
/// fallback"): NLP 3 (sigma 0.1) ends Restoration_Failed with the adaptive mu climbing to 4e3
/// within 10 iterations; monotone from 1e-4, NLPs 3-5 solve.
constexpr double kWarmMuInit = 1e-4;

/// Whether a failed solve is worth repeating with another setting (IpoptSolver::solve: the
/// monotone mu strategy, a fresh scaling, a stricter pivoting, MUMPS): not for the limits, the
/// caller's stop and bad input, which no setting changes, nor for a detected infeasibility (the
/// monotone run cured none of row 9's, docs/nosnoc-examples.md).
bool worth_retrying(Ipopt::ApplicationReturnStatus s) {
  switch (s) {
    case Ipopt::Maximum_Iterations_Exceeded:
    case Ipopt::Maximum_CpuTime_Exceeded:
    case Ipopt::User_Requested_Stop:
    case Ipopt::Invalid_Option:
    case Ipopt::Invalid_Problem_Definition:
    case Ipopt::Not_Enough_Degrees_Of_Freedom:
    case Ipopt::Infeasible_Problem_Detected:
      return false;
    default:
      return true;
  }
}

void set_option(Ipopt::IpoptApplication& app, const std::string& name, const std::string& value) {
  if (name == "option_file_name")
    throw InvalidOption(fmt::format(
        "ipopt.option_file_name = '{}': fesd reads no IPOPT options file (give the options in "
        "[ipopt] or with --ipopt NAME=VALUE)",
        value));
  Ipopt::SmartPtr<const Ipopt::RegisteredOption> opt = app.RegOptions()->GetOption(name);
  if (!Ipopt::IsValid(opt)) throw InvalidOption(fmt::format("ipopt.{}: not an IPOPT option", name));
  bool ok = false;
  switch (opt->Type()) {
    case Ipopt::OT_Number: {
      char* end = nullptr;
      const double v = std::strtod(value.c_str(), &end);
      ok = end != value.c_str() && *end == '\0' && app.Options()->SetNumericValue(name, v);
      break;
    }
    case Ipopt::OT_Integer: {
      char* end = nullptr;
      const long v = std::strtol(value.c_str(), &end, 10);
      ok = end != value.c_str() && *end == '\0' &&
           app.Options()->SetIntegerValue(name, static_cast<Ipopt::Index>(v));
      break;
    }
    default:
      ok = app.Options()->SetStringValue(name, value);
      break;
  }
  if (!ok)
    throw InvalidOption(fmt::format("ipopt.{} = '{}': IPOPT rejects this value", name, value));
}

}  // namespace

struct IpoptSolver::Impl {
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app;
  bool user_linear_solver = false;  // the caller chose IPOPT's linear_solver: never override it
  bool user_mu_strategy = false;    // the caller chose IPOPT's mu_strategy: no monotone retry
  // A warm-started NLP since the last cold start failed with the adaptive mu strategy and solved
  // on the monotone retry: the next warm-started NLPs run monotone first (kWarmMuInit).
  bool warm_monotone = false;
  KktSolver kkt_solver = KktSolver::Auto;
  KktScaling kkt_scaling = KktScaling::Warm;
  double tol = 0;    // the configured tol (NlpOptions::tol or [ipopt] extra)
  int max_iter = 0;  // the configured max_iter
};

IpoptSolver::IpoptSolver(const NlpOptions& o) : impl_(std::make_unique<Impl>()) {
  impl_->app = IpoptApplicationFactory();
  Ipopt::IpoptApplication& app = *impl_->app;
  app.Options()->SetStringValue("sb", "yes");  // no banner
  app.Options()->SetIntegerValue("print_level", o.print_level);
  app.Options()->SetNumericValue("tol", o.tol);
  app.Options()->SetNumericValue("acceptable_tol", o.acceptable_tol);
  app.Options()->SetIntegerValue("max_iter", o.max_iter);
  app.Options()->SetStringValue("mu_strategy", "adaptive");
  app.Options()->SetStringValue("print_timing_statistics", "no");
  // IPOPT relaxes every bound by 1e-8 by default, so "product <= sigma" would only hold up to
  // 1e-8: complementarity could never get below that. Bounds are kept exact.
  app.Options()->SetNumericValue("bound_relax_factor", 0.0);
  for (const auto& [name, value] : o.extra) set_option(app, name, value);
  impl_->user_linear_solver = registry::user_sets(o, "linear_solver");
  impl_->user_mu_strategy = registry::user_sets(o, "mu_strategy");
  impl_->kkt_solver = o.kkt_solver;
  impl_->kkt_scaling = o.kkt_scaling;
  const bool needs_module =
      o.kkt_solver == KktSolver::SparseLdl || o.kkt_solver == KktSolver::Dense;
  if (needs_module && !impl_->user_linear_solver && !kkt_module().ok())
    throw InvalidOption(fmt::format(
        "kkt_solver = {}: fesd's KKT module is not available ({}); libfesd_kkt.so belongs next to "
        "libfesd.so, or choose kkt_solver = mumps",
        to_string(o.kkt_solver), kkt_module().problem));
  app.Options()->GetNumericValue("tol", impl_->tol, "");
  app.Options()->GetIntegerValue("max_iter", impl_->max_iter, "");
  // Initialize() without a file name would read the option_file_name option's file, by default
  // "ipopt.opt" in the working directory, and let it change every solve. "" reads no file; the
  // options are only those above (no output file unless [ipopt] output_file asks for one).
  if (app.Initialize("") != Ipopt::Solve_Succeeded)
    throw InvalidOption("ipopt: initialization failed (check the [ipopt] options)");
}

IpoptSolver::~IpoptSolver() = default;

std::vector<std::string> warnings(const NlpOptions& o) {
  if (registry::user_sets(o, "linear_solver") || o.kkt_solver != KktSolver::Auto ||
      kkt_module().ok())
    return {};
  return {fmt::format(
      "kkt_solver = auto: fesd's KKT module is not available ({}), so IPOPT solves every KKT "
      "system with MUMPS (4-5x the time per iteration on large OCPs); libfesd_kkt.so belongs next "
      "to libfesd.so",
      kkt_module().problem)};
}

NlpResult IpoptSolver::solve(const BlockNlp& nlp, Iterate& start, bool warm_start, double tol,
                             int max_iter, const CallerHandles& caller_handles) {
  const auto t0 = Clock::now();
  const double cpu0 = util::thread_cpu_seconds();
  Ipopt::IpoptApplication& app = *impl_->app;
  app.Options()->SetNumericValue("tol", std::max(tol, impl_->tol));
  app.Options()->SetIntegerValue(
      "max_iter", max_iter > 0 ? std::min(max_iter, impl_->max_iter) : impl_->max_iter);
  const bool warm = warm_start && start.has_duals();
  app.Options()->SetStringValue("warm_start_init_point", warm ? "yes" : "no");
  if (!warm) impl_->warm_monotone = false;  // a new homotopy (or a cold restart)
  // Which KKT solver: IPOPT's linear_solver if the caller set it, else kkt_solver's choice, the
  // dense and sparse LDL' through fesd's module as IPOPT's "ma27".
  int mode = -1;  // the module's mode, -1: not the module
  std::string name;
  if (impl_->user_linear_solver) {
    app.Options()->GetStringValue("linear_solver", name, "");
  } else {
    switch (impl_->kkt_solver) {
      // The sparse LDL' at every size: on the integrator's NLPs (n + m = 30-120), where auto used
      // to pick the dense LAPACK solver, it takes 1.4-2.5x fewer instructions per run
      // (docs/kkt-solver.md, "Choosing the solver").
      case KktSolver::Auto:
        mode = FESD_KKT_SPARSE;
        break;
      case KktSolver::Dense:
        mode = FESD_KKT_DENSE;
        break;
      case KktSolver::SparseLdl:
        mode = FESD_KKT_SPARSE;
        break;
      case KktSolver::Mumps:
        break;
    }
    if (mode >= 0 && !kkt_module().ok()) mode = -1;
    name = mode == FESD_KKT_DENSE ? "dense" : mode == FESD_KKT_SPARSE ? "sparse_ldl" : "mumps";
  }
  // A failed NLP is solved again from the same start (below): keep it.
  const bool warm_retry = warm && !impl_->user_mu_strategy;
  const bool may_retry = mode == FESD_KKT_SPARSE || warm_retry;
  const Iterate start_copy = may_retry ? start : Iterate{};
  ProgressSink progress{on_progress_, progress_every_s_};
  bool fresh_scaling = impl_->kkt_scaling == KktScaling::Fresh;  // the retry may set it (below)
  const auto run = [&](int run_mode) {
    if (!impl_->user_linear_solver)
      app.Options()->SetStringValue("linear_solver", run_mode >= 0 ? "ma27" : "mumps");
    FesdKktStats before{};
    if (run_mode >= 0) {
      kkt_module().request_mode(run_mode);
      kkt_module().request_scaling(fresh_scaling ? 1 : 0);
      kkt_module().stats(&before);
    }
    ++progress.run;
    Ipopt::SmartPtr<BlockTnlp> tnlp = new BlockTnlp(nlp, start, warm, &progress);
    const Ipopt::ApplicationReturnStatus s =
        app.OptimizeTNLP(Ipopt::SmartPtr<Ipopt::TNLP>(Ipopt::GetRawPtr(tnlp)));
    progress.iterations_before += tnlp->iterations();
    NlpResult r;
    if (run_mode >= 0) {
      FesdKktStats after{};
      kkt_module().stats(&after);
      kkt_module().request_mode(FESD_KKT_AUTO);
      kkt_module().request_scaling(0);
      r.factorizations = after.factorizations - before.factorizations;
      if (run_mode == FESD_KKT_DENSE) r.factorizations = 0;  // the dense path keeps no counters
    }
    const Ipopt::SmartPtr<Ipopt::IpoptData> data = app.IpoptDataObject();
    if (Ipopt::IsValid(data))
      r.factor_s = data->TimingStats().LinearSystemFactorization().TotalWallclockTime();
    r.status = status_name(s);
    r.success = s == Ipopt::Solve_Succeeded || s == Ipopt::Solved_To_Acceptable_Level;
    r.eval_error = tnlp->eval_failures() > 0 && !r.success;
    r.iterations = tnlp->iterations();
    r.objective = tnlp->objective();
    r.inf_pr = tnlp->inf_pr();
    r.inf_du = tnlp->inf_du();
    r.eval_s = tnlp->eval_s();
    return std::pair{r, s};
  };
  // The mu strategy of a warm-started NLP: fesd's adaptive one (or [ipopt]'s mu_init with it), or
  // IPOPT's monotone one from kWarmMuInit, first once an NLP of this homotopy needed it.
  std::string mu_strategy;
  app.Options()->GetStringValue("mu_strategy", mu_strategy, "");
  double mu_init = 0.1;  // IPOPT's default, unless set in [ipopt]
  app.Options()->GetNumericValue("mu_init", mu_init, "");
  const auto set_monotone = [&] {
    app.Options()->SetStringValue("mu_strategy", "monotone");
    app.Options()->SetNumericValue("mu_init", kWarmMuInit);
  };
  const auto reset_mu = [&] {
    app.Options()->SetStringValue("mu_strategy", mu_strategy);
    app.Options()->SetNumericValue("mu_init", mu_init);
  };
  const bool monotone_first = warm_retry && impl_->warm_monotone;
  if (monotone_first) set_monotone();
  auto [r, s] = run(mode);
  if (monotone_first) reset_mu();
  const std::string monotone = fmt::format("mu_strategy monotone from mu_init {:g}", kWarmMuInit);
  r.linear_solver =
      monotone_first ? fmt::format("{} ({}, as an NLP before needed)", name, monotone) : name;
  // A failed solve that another setting may cure (worth_retrying) is repeated from a copy of
  // the same start with the settings of retry_ladder, each run only if the one before failed too
  // (nlp/retry_ladder.hpp). The result names the failed runs in linear_solver and counts the
  // iterations and evaluation time of every run.
  std::string tried =
      fmt::format("first run{}: {} after {} iterations",
                  monotone_first ? " (" + monotone + ")" : std::string(), r.status, r.iterations);
  const auto may_cure = [&] { return !r.success && !r.eval_error && worth_retrying(s); };
  const auto again = [&](int run_mode, std::string_view what, const auto& set, const auto& reset) {
    const NlpResult failed = r;
    start = start_copy;
    set();
    std::tie(r, s) = run(run_mode);
    reset();
    r.eval_s += failed.eval_s;
    r.iterations += failed.iterations;
    const std::string solver = run_mode == mode ? name : "mumps";
    r.linear_solver = fmt::format("{} ({}; {})", solver, what, tried);
    if (!r.success)
      tried += fmt::format("; {}: {} after {} iterations", what, r.status,
                           r.iterations - failed.iterations);
  };
  double pivtol = 1e-8, pivtolmax = 1e-4;  // IPOPT's defaults, unless set in [ipopt]
  app.Options()->GetNumericValue("ma27_pivtol", pivtol, "");
  app.Options()->GetNumericValue("ma27_pivtolmax", pivtolmax, "");
  const RetryLadderInput ladder{.warm_retry = warm_retry,
                                .sparse_ldl = mode == FESD_KKT_SPARSE,
                                .fresh_scaling = fresh_scaling,
                                .pivtol = pivtol,
                                .retry_pivtol = kRetryPivtol};
  const std::vector<RetryRung> rungs = retry_ladder(ladder);
  const auto run_rung = [&](RetryRung rung) {
    fresh_scaling = fresh_scaling_on(rung, ladder);  // each rung's scaling (the run reads it)
    switch (rung) {
      case RetryRung::OtherMuStrategy:
        if (monotone_first) {
          again(
              mode, "again with mu_strategy " + mu_strategy, [] {}, [] {});
          if (r.success) impl_->warm_monotone = false;  // this homotopy's NLPs no longer need it
        } else {
          again(mode, "again with " + monotone, set_monotone, reset_mu);
          if (r.success) impl_->warm_monotone = true;
        }
        break;
      case RetryRung::FreshScaling:
        again(
            mode, "again with kkt_scaling fresh", [] {}, [] {});
        break;
      case RetryRung::StricterPivoting:
        again(
            mode,
            fmt::format("again with ma27_pivtol {:g}{}", kRetryPivtol,
                        fresh_scaling && !ladder.fresh_scaling ? " and kkt_scaling fresh" : ""),
            [&] {
              app.Options()->SetNumericValue("ma27_pivtol", kRetryPivtol);
              app.Options()->SetNumericValue("ma27_pivtolmax",
                                             std::max(pivtolmax, kRetryPivtolMax));
            },
            [&] {
              app.Options()->SetNumericValue("ma27_pivtol", pivtol);
              app.Options()->SetNumericValue("ma27_pivtolmax", pivtolmax);
            });
        break;
      case RetryRung::Mumps:
        again(
            -1, "sparse_ldl fallback", [] {}, [] {});
        break;
    }
  };
  const bool left_to_caller = climb(
      rungs, may_cure, [&] { return caller_handles && caller_handles(r); }, run_rung);
  // (Every run so far was on `mode`: only the mu strategy precedes the rungs left out.)
  if (left_to_caller)
    r.linear_solver = fmt::format("{} ({}; then left to the caller)", name, tried);
  r.total_s = seconds_since(t0);
  r.cpu_s = util::thread_cpu_seconds() - cpu0;
  return r;
}

}  // namespace fesd::nlp
