#include "mpcc/homotopy.hpp"

#include <algorithm>
#include <cmath>

namespace fesd::mpcc {

namespace {
// NLPs with sigma <= this factor times complementarity_tol are solved with the configured tol
// (with a margin for the round-off of sigma_k = slope^k sigma_0: 0.1^8 is 1.0000000000000005e-8).
constexpr double kTightSigmaFactor = 10.0 * (1.0 + 1e-9);

// Adds the row of one NLP solve (k, sigma) to res and its times and iterations to the totals.
void record(HomotopyResult& res, const nlp::NlpResult& r, int k, double sigma) {
  // r.objective is the NLP's objective: for ell_1_penalty and elastic_ineq it includes the
  // penalty term (1 / sigma) * (sum of groups, or s).
  res.rows.push_back({k, sigma, res.comp_residual, r.objective, r.inf_pr, r.iterations, r.status,
                      r.total_s, r.linear_solver});
  res.eval_s += r.eval_s;
  res.solver_s += r.total_s - r.eval_s;
  res.nlp_iterations += r.iterations;
  res.last_nlp_status = r.status;
}

// Sets sigma in the NLP, and in the start point's fixed sigma variable (fischer_burmeister): IPOPT
// takes a fixed variable's value from its bounds anyway; set it so the point itself is consistent
// (for other NlpSolver backends, and in the solution returned in `it`).
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

HomotopyResult solve_homotopy(nlp::BlockNlp& nlp, const Relaxation& relaxation,
                              const std::vector<CompPair>& residual_pairs, nlp::NlpSolver& solver,
                              nlp::Iterate& it, const HomotopyOptions& o,
                              const std::function<void(const HomotopyRow&)>& on_row) {
  HomotopyResult res;
  double sigma = o.sigma_0;
  bool last_ok = false, eval_failed = false;
  bool tight_now = false;  // solve the next NLP with the configured tolerance
  int max_steps = o.max_homotopy_steps;
  if (max_steps == 0)  // automatic: until sigma reaches sigma_N
    max_steps =
        1 + static_cast<int>(std::ceil(
                std::log(o.sigma_N / o.sigma_0) / std::log(o.homotopy_update_slope) - 1e-9));
  // One NLP more than max_steps if the last one met the tolerance only loosely (below).
  for (int k = 0; k < max_steps + (tight_now ? 1 : 0); ++k) {
    apply_sigma(relaxation, nlp, it, sigma);
    // NLPs far from the end of the homotopy only need to be good starting points for the next
    // one: with intermediate_tol they stop earlier. The NLPs with sigma near
    // complementarity_tol, and the last, use the configured tolerance.
    const bool loose = !tight_now && o.intermediate_tol > 0 &&
                       sigma > kTightSigmaFactor * o.complementarity_tol && sigma > o.sigma_N;
    const nlp::NlpResult r =
        solver.solve(nlp, it, /*warm_start=*/k > 0, loose ? o.intermediate_tol : 0.0, 0);
    res.comp_residual = comp_residual(it.x.data(), residual_pairs);
    record(res, r, k, sigma);
    if (on_row) on_row(res.rows.back());
    last_ok = r.success;
    eval_failed = r.eval_error;
    if (last_ok && res.comp_residual <= o.complementarity_tol) {
      if (!loose) break;
      // Complementarity already met by a loosely solved NLP: solve it again at this sigma with
      // the configured tolerance (warm; usually a few iterations) before stopping.
      tight_now = true;
      continue;
    }
    if (sigma <= o.sigma_N) break;  // sigma cannot get smaller: another NLP would repeat this one
    sigma = std::max(o.homotopy_update_slope * sigma, o.sigma_N);
  }
  res.status = final_status(last_ok, eval_failed, res.comp_residual, o.complementarity_tol);
  return res;
}

HomotopyResult solve_again(
    nlp::BlockNlp& nlp, const Relaxation& relaxation, const std::vector<CompPair>& residual_pairs,
    nlp::NlpSolver& solver, nlp::Iterate& it, double sigma, int k, const HomotopyOptions& o,
    const std::function<void(nlp::BlockNlp&, std::vector<double>&)>& change) {
  HomotopyResult res;
  const std::vector<double> x_lb = nlp.x_lb, x_ub = nlp.x_ub;
  nlp::Iterate trial = it;
  change(nlp, trial.x);
  apply_sigma(relaxation, nlp, trial, sigma);
  const nlp::NlpResult r = solver.solve(nlp, trial, /*warm_start=*/true, 0.0, kSolveAgainMaxIter);
  nlp.x_lb = x_lb;
  nlp.x_ub = x_ub;
  res.comp_residual = comp_residual(trial.x.data(), residual_pairs);
  record(res, r, k, sigma);
  res.status = final_status(r.success, r.eval_error, res.comp_residual, o.complementarity_tol);
  if (res.status == Status::Success) it = std::move(trial);
  return res;
}

}  // namespace fesd::mpcc
