// src/mpcc/problem.cpp: the MPCC problem object and its homotopy (problem.hpp).
#include "mpcc/problem.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "fesd/error.hpp"

namespace fesd::mpcc {

namespace {
// NLPs with sigma <= this factor times complementarity_tol are solved with the configured tol
// (with a margin for the round-off of sigma_k = slope^k sigma_0: 0.1^8 is 1.0000000000000005e-8).
constexpr double kTightSigmaFactor = 10.0 * (1.0 + 1e-9);

// A failed NLP whose primal infeasibility is at most this is kept as the homotopy's next start
// (homotopy_retries): max_iter on row 30 of docs/nosnoc-examples.md ends at inf_pr 2e-12; the
// failures that the retries mend end at 3.6e-3 .. 0.76.
constexpr double kFeasibleFailure = 1e-6;

// A failed NLP whose point violates the constraints (or whose evaluations failed): no start for
// the next sigma. One that satisfies them (e.g. at max_iter) is a feasible point of the relaxed
// problem, and the homotopy can go on from it.
bool unusable(const nlp::NlpResult& r) {
  return r.eval_error || !(r.inf_pr <= kFeasibleFailure);
}

// A converged NLP of a penalty mode whose complementarity residual is more than this fraction of
// the residual of the point it started from, although sigma fell, has stalled: its point is a
// stationary point of the penalty (docs/formulation.md, "A stalled penalty").
constexpr double kStallRatio = 0.5;

// Adds the row of one NLP solve (k, sigma) to res and its times and iterations to the totals.
void record(HomotopyResult& res, const nlp::NlpResult& r, int k, double sigma) {
  // r.objective is the NLP's objective: in the penalty modes (ell_1_penalty, elastic_*) it
  // includes the penalty term, J + (1 / sigma) * (sum of groups, or s), or sigma J + penalty with
  // objective_scaling_direct = false.
  HomotopyRow row;
  row.k = k;
  row.sigma = sigma;
  row.comp_residual = res.comp_residual;
  row.objective = r.objective;
  row.inf_pr = r.inf_pr;
  row.nlp_iterations = r.iterations;
  row.nlp_status = r.status;
  row.cpu_s = r.cpu_s;
  row.wall_s = r.total_s;
  row.linear_solver = r.linear_solver;
  row.factor_s = r.factor_s;
  row.factorizations = r.factorizations;
  res.rows.push_back(std::move(row));
  res.eval_s += r.eval_s;
  res.solver_s += r.total_s - r.eval_s;
  res.nlp_iterations += r.iterations;
  res.last_nlp_status = r.status;
}

// Sets sigma in the NLP, and in the point's fixed sigma variable (fischer_burmeister): IPOPT takes
// a fixed variable's value from its bounds anyway; set it so the point itself is consistent (for
// other NlpSolver backends, and in the solution).
void apply_sigma(const Relaxation& relaxation, nlp::BlockNlp& nlp, nlp::Iterate& it, double sigma) {
  relaxation.set_sigma(nlp, sigma);
  if (const int v = relaxation.sigma_variable(); v >= 0 && v < static_cast<int>(it.x.size()))
    it.x[v] = sigma;
}

Status final_status(bool nlp_ok, bool eval_failed, double comp, double comp_tol) {
  if (nlp_ok && comp <= comp_tol) return Status::Success;
  if (!nlp_ok) return eval_failed ? Status::EvaluationFailed : Status::NlpFailed;
  return Status::ComplementarityNotMet;
}

}  // namespace

double comp_residual(const double* x, const std::vector<CompPair>& pairs) {
  double r = 0.0;
  for (const CompPair& p : pairs) r = std::max(r, std::abs(x[p.a] * x[p.b]));
  return r;
}

void append_discarded(HomotopyResult& to, const HomotopyResult& from) {
  to.rows.insert(to.rows.end(), from.rows.begin(), from.rows.end());
  to.eval_s += from.eval_s;
  to.solver_s += from.solver_s;
  to.nlp_iterations += from.nlp_iterations;
}

void append(HomotopyResult& to, const HomotopyResult& from) {
  append_discarded(to, from);
  to.comp_residual = from.comp_residual;
  to.last_nlp_status = from.last_nlp_status;
}

std::string cold_restart_warning(const HomotopyResult& h) {
  // The first replaced row says why: an NLP that failed, or one whose penalty stalled.
  const HomotopyRow* first = nullptr;
  for (const HomotopyRow& r : h.rows) {
    if (r.restarted && first == nullptr) first = &r;
    if (!r.cold_start) continue;
    const std::string why =
        first != nullptr && first->stalled
            ? fmt::format(
                  "the homotopy ended with the complementarity residual stalled since the NLP at "
                  "sigma = {:.3g} (a stationary point of the penalty)",
                  first->sigma)
            : fmt::format(
                  "the homotopy ended failed after the NLP at sigma = {:.3g} had failed (after the "
                  "retries)",
                  first != nullptr ? first->sigma : r.sigma);
    return why + fmt::format(
                     ", so it started again at sigma = {:.3g} from the initial guess "
                     "(homotopy_cold_restart): the result is the minimizer that start leads to, "
                     "not a continuation of the first NLPs",
                     r.sigma);
  }
  return {};
}

void add_to_summary(const HomotopyResult& h, Summary& summary, std::vector<HomotopyRow>& rows) {
  rows.insert(rows.end(), h.rows.begin(), h.rows.end());
  summary.homotopy_steps += static_cast<int>(h.rows.size());
  summary.nlp_iterations += h.nlp_iterations;
  summary.derivative_s += h.eval_s;
  summary.solver_s += h.solver_s;
}

// ---- description ------------------------------------------------------------------------------

nlp::BlockNlp& Problem::nlp() {
  if (relaxation_) throw InternalError("mpcc::Problem::nlp(): the problem is already relaxed");
  return nlp_;
}

void Problem::add_complementarity(const std::vector<CompGroup>& groups,
                                  const std::vector<CompPair>& residual_pairs) {
  if (relaxation_)
    throw InternalError("mpcc::Problem::add_complementarity(): the problem is already relaxed");
  groups_.insert(groups_.end(), groups.begin(), groups.end());
  residual_pairs_.insert(residual_pairs_.end(), residual_pairs.begin(), residual_pairs.end());
}

void Problem::relax(MpccMode mode, double s_elastic_max, double s_elastic_0, bool scaling_direct) {
  if (relaxation_) throw InternalError("mpcc::Problem::relax(): called twice");
  relaxation_.emplace(nlp_, groups_, mode, s_elastic_max, s_elastic_0, scaling_direct);
}

void Problem::finalize() {
  if (!relaxation_ || finalized())
    throw InternalError("mpcc::Problem::finalize(): needs relax() before, and only once");
  nlp_.finalize();
}

// ---- workspace --------------------------------------------------------------------------------

void Problem::fix(const std::vector<int>& vars, const Eigen::VectorXd& values) {
  for (std::size_t i = 0; i < vars.size(); ++i) {
    const double v = values[static_cast<Eigen::Index>(i)];
    nlp_.x_lb[vars[i]] = nlp_.x_ub[vars[i]] = nlp_.x_init[vars[i]] = v;
  }
}

void Problem::bound(int var, double lb, double ub) {
  nlp_.x_lb[var] = lb;
  nlp_.x_ub[var] = ub;
}

void Problem::set_guess(const std::vector<int>& vars, const Eigen::VectorXd& values) {
  for (std::size_t i = 0; i < vars.size(); ++i)
    nlp_.x_init[vars[i]] = values[static_cast<Eigen::Index>(i)];
}

void Problem::copy_inputs_from(const Problem& other) {
  if (other.nlp_.num_variables() != nlp_.num_variables())
    throw InternalError("mpcc::Problem::copy_inputs_from(): different variables");
  nlp_.x_lb = other.nlp_.x_lb;
  nlp_.x_ub = other.nlp_.x_ub;
  nlp_.x_init = other.nlp_.x_init;
}

// ---- solving ----------------------------------------------------------------------------------

HomotopyResult Problem::solve_homotopy(nlp::NlpSolver& solver, const HomotopyOptions& o,
                                       const HomotopyCallback& on_row, int warm_max_iter,
                                       const std::function<bool(HomotopyResult&)>& finish) {
  if (!finalized()) throw InternalError("mpcc::Problem::solve_homotopy(): not finalized");
  HomotopyResult res;
  it_ = nlp::Iterate{};
  it_.x = nlp_.x_init;
  double sigma = o.sigma_0;
  // The schedule's sigma that the homotopy is heading to: sigma itself, or (after a retry) a
  // sigma the failed step is being approached by in smaller steps.
  double target = sigma;
  // The last converged NLP's point and sigma: where a failed NLP is retried from.
  std::optional<nlp::Iterate> good;
  double sigma_good = 0;
  int retries = 0;
  // The sigma of the last retry from `good` (0: none): a later retry from the same point takes
  // half the logarithmic step to it when it lies above the failed sigma, so no sigma is tried
  // twice from one point.
  double sigma_retried = 0;
  // homotopy_cold_restart: where the homotopy starts again from the initial guess, once, if it
  // ends failed or stalled. `failed_at`: the first NLP that failed at a point violating the
  // constraints with no retry left; `stalled_at` (penalty modes): the first NLP whose residual
  // stalled. Each keeps its row, the schedule's sigma it was heading to, the NLPs counted then and
  // whether it was the tight re-solve.
  struct ColdStart {
    int row = -1;
    double sigma = 0;
    int scheduled = 0;
    bool tight = false;
  };
  std::optional<ColdStart> failed_at, stalled_at;
  // The penalty modes: sigma weighs a penalty term (1 / sigma) P instead of bounding each
  // product, so the complementarity residual is not held below sigma and can stall.
  const bool penalty = penalizes(relaxation_->mode());
  // The complementarity residual and sigma of the point the next NLP starts from (residual < 0:
  // the initial guess), and those of `good`.
  double start_residual = -1, start_sigma = 0, good_residual = -1;
  bool cold_restarted = false, cold_now = false;
  bool last_ok = false, eval_failed = false;
  bool tight_now = false;  // solve the next NLP with the configured tolerance
  const int max_steps = homotopy_length(o);
  // NLPs at the schedule's sigma (not retried) count towards max_steps; the retried NLPs and the
  // smaller steps after them (at most 2 homotopy_retries) do not. One NLP more than max_steps if
  // the last one met the tolerance only loosely (below).
  int scheduled = 0;
  const auto schedule_length = [&] { return max_steps + (tight_now ? 1 : 0); };
  for (;;) {
    for (; scheduled < schedule_length();) {
      const int k = static_cast<int>(res.rows.size());
      const bool on_schedule = sigma == target;
      apply_sigma(*relaxation_, nlp_, it_, sigma);
      // NLPs far from the end of the homotopy only need to be good starting points for the next
      // one: with intermediate_tol they stop earlier. The NLPs with sigma near
      // complementarity_tol, and the last, use the configured tolerance.
      const bool loose = !tight_now && o.intermediate_tol > 0 &&
                         sigma > kTightSigmaFactor * o.complementarity_tol && sigma > o.sigma_N;
      const bool warm = k > 0 && !cold_now;
      // The schedule's last NLP: the homotopy cannot go on from its point, a failure there ends
      // it failed, so it is retried even where its point is feasible.
      const bool ends_schedule =
          on_schedule && (sigma <= o.sigma_N || scheduled + 1 >= schedule_length());
      // Whether a failure of this NLP is retried below: back to the last converged NLP with a
      // smaller sigma step, where the failed point is unusable or ends the schedule; a feasible
      // failed point elsewhere is where the homotopy goes on from. (Only after a sigma step: the
      // tight re-solve at a loosely converged NLP's sigma has none to make smaller.)
      const auto retried_here = [&](const nlp::NlpResult& f) {
        return !f.success && (unusable(f) || ends_schedule) && good && sigma < sigma_good &&
               retries < o.homotopy_retries;
      };
      // The failures of a warm-started NLP that the homotopy handles itself: those it retries,
      // and those at a feasible point that it goes on from (not the schedule's last). The NLP
      // solver asks, and returns them before its linear-algebra fallbacks (nlp::CallerHandles).
      // The first NLP and a cold restart keep every fallback: only there did they cure an NLP
      // since the monotone retry (docs/kkt-solver.md, "Failures the homotopy goes on from").
      const auto handled_here = [&](const nlp::NlpResult& f) {
        return retried_here(f) || (warm && !f.success && !unusable(f) && !ends_schedule);
      };
      const nlp::NlpResult r =
          solver.solve(nlp_, it_, /*warm_start=*/warm, loose ? o.intermediate_tol : 0.0,
                       warm ? warm_max_iter : 0, handled_here);
      res.comp_residual = comp_residual(it_.x.data(), residual_pairs_);
      record(res, r, k, sigma);
      res.rows.back().cold_start = cold_now;
      cold_now = false;
      sigma_ = sigma;
      last_ok = r.success;
      eval_failed = r.eval_error;
      if (retried_here(r)) {
        // Back to the last converged NLP's point, and a sigma step of half the logarithm
        // (sigma_good * sqrt(sigma / sigma_good)) towards the same target.
        res.rows.back().retried = true;
        if (on_row) on_row(res.rows.back());
        ++retries;
        it_ = *good;
        start_residual = good_residual;
        start_sigma = sigma_good;
        // (A retry that ended feasible but failed is kept, and the failed sigma after it would
        // otherwise send the next retry to that same sigma again.)
        sigma = std::sqrt(sigma_good * std::max(sigma, sigma_retried));
        sigma_retried = sigma;
        continue;
      }
      // No retry left (or none possible): the homotopy goes on from the failed point, and where
      // the cold restart would start if it ends failed (the first such NLP).
      if (!last_ok && unusable(r) && k > 0 && !failed_at && !cold_restarted)
        failed_at = ColdStart{k, target, scheduled, tight_now};
      // A stalled penalty: the NLP converged, sigma fell (its weight 1 / sigma grew), and the
      // residual did not fall to half that of its start: the point is a stationary point of the
      // penalty, and the NLPs after it usually end there too (docs/formulation.md).
      if (last_ok && penalty && !stalled_at && !cold_restarted && start_residual > 0 &&
          sigma < start_sigma && res.comp_residual > o.complementarity_tol &&
          res.comp_residual > kStallRatio * start_residual) {
        stalled_at = ColdStart{k, target, scheduled, tight_now};
        res.rows.back().stalled = true;
      }
      start_residual = res.comp_residual;
      start_sigma = sigma;
      if (on_row) on_row(res.rows.back());
      if (on_schedule) ++scheduled;
      if (last_ok && o.homotopy_retries > 0) {  // (no copy when nothing can be retried)
        good = it_;
        sigma_good = sigma;
        good_residual = res.comp_residual;
        sigma_retried = 0;
      }
      if (last_ok && res.comp_residual <= o.complementarity_tol) {
        if (!loose) break;
        // Complementarity already met by a loosely solved NLP: solve it again at this sigma with
        // the configured tolerance (warm; usually a few iterations) before stopping.
        tight_now = true;
        continue;
      }
      if (sigma <= o.sigma_N) break;  // sigma cannot get smaller: another NLP would repeat this one
      if (last_ok && finish) {
        next_row_ = static_cast<int>(res.rows.size());
        if (finish(res)) {
          res.status = Status::Success;
          return res;
        }
      }
      // After a smaller step that converged, the step to the target; after that, the schedule's.
      if (sigma <= target) target = next_sigma(o, sigma);
      sigma = target;
    }
    // homotopy_cold_restart: a homotopy that would end with a failed NLP, after one that failed at
    // a point violating the constraints with no retry left, solves that NLP's sigma again from the
    // initial guess (without multipliers: IPOPT's cold start) and goes on from there, once. The
    // rows from that failure on are marked `restarted`. The same from a stalled penalty's NLP when
    // the homotopy would end failed without such a failure, or with the residual above
    // complementarity_tol and still above half the stalled one.
    const bool still_stalled =
        stalled_at && res.comp_residual > o.complementarity_tol &&
        res.comp_residual >
            kStallRatio * res.rows[static_cast<std::size_t>(stalled_at->row)].comp_residual;
    const std::optional<ColdStart> cold = !last_ok && failed_at       ? failed_at
                                          : !last_ok || still_stalled ? stalled_at
                                                                      : std::nullopt;
    if (cold && o.homotopy_cold_restart && !cold_restarted) {
      for (std::size_t i = static_cast<std::size_t>(cold->row); i < res.rows.size(); ++i)
        res.rows[i].restarted = true;
      cold_restarted = cold_now = true;
      it_ = nlp::Iterate{};
      it_.x = nlp_.x_init;
      good.reset();
      start_residual = -1;
      sigma = target = cold->sigma;
      scheduled = cold->scheduled;
      tight_now = cold->tight;
      continue;
    }
    break;
  }
  next_row_ = static_cast<int>(res.rows.size());
  res.status = final_status(last_ok, eval_failed, res.comp_residual, o.complementarity_tol);
  return res;
}

HomotopyResult Problem::solve_again(nlp::NlpSolver& solver, const HomotopyOptions& o,
                                    const std::vector<nlp::Bound>& changes, int pinned_exits,
                                    const std::vector<double>* start) {
  if (it_.x.empty()) throw InternalError("mpcc::Problem::solve_again(): no homotopy before");
  HomotopyResult res;
  const std::vector<double> x_lb = nlp_.x_lb, x_ub = nlp_.x_ub;
  nlp::Iterate trial = it_;
  if (start != nullptr) {
    if (start->size() != trial.x.size())
      throw InternalError("mpcc::Problem::solve_again(): start point of the wrong size");
    trial.x = *start;
  }
  for (const nlp::Bound& c : changes) {
    nlp_.x_lb[c.var] = c.lb;
    nlp_.x_ub[c.var] = c.ub;
    trial.x[c.var] = std::clamp(trial.x[c.var], c.lb, c.ub);
  }
  apply_sigma(*relaxation_, nlp_, trial, sigma_);
  const nlp::NlpResult r = solver.solve(nlp_, trial, /*warm_start=*/true, 0.0, kSolveAgainMaxIter,
                                        /*caller_handles=*/{});
  nlp_.x_lb = x_lb;
  nlp_.x_ub = x_ub;
  res.comp_residual = comp_residual(trial.x.data(), residual_pairs_);
  record(res, r, next_row_++, sigma_);
  res.rows.back().active_set_fixed = true;
  res.rows.back().pinned_exits = pinned_exits;
  res.status = final_status(r.success, r.eval_error, res.comp_residual, o.complementarity_tol);
  if (res.status == Status::Success) it_ = std::move(trial);
  return res;
}

}  // namespace fesd::mpcc
