// include/fesd/options.hpp: discretization, homotopy and NLP options. Plain structs with documented
// defaults; validate() lists every broken rule. Problem-file keys (nosnoc's names where nosnoc has
// one) are given beside each field; docs/problem-files.md is the full table.
#pragma once
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fesd/summary.hpp"
#include "fesd/tableau.hpp"

namespace fesd {

/// Which form of cross complementarity (Sect. 3.2.2) enters the MPCC. All forms are equivalent at
/// an exact solution; they differ in how many constraints the relaxed NLPs have.
enum class CrossComp {
  /// (28): theta_{n,m,i} lambda_{n,m',i} = 0 for every stage m, every point m' != m, every i.
  Sparse,
  /// theta_{n,m,i} * sum_{m'} lambda_{n,m',i} = 0 for every stage m and i (nosnoc_py's default).
  StageSum,
  /// One constraint per finite element: the sum of all (28) products of that element.
  Element,
  /// (29): one constraint per pair of neighbouring finite elements.
  Neighbor,
};
/// Problem-file key `cross_comp_mode`: "sparse", "stage_sum", "element", "neighbor".
std::string_view to_string(CrossComp v);
bool parse(std::string_view name, CrossComp& out);

/// Step equilibration (Sect. 3.2.3): how the spurious degrees of freedom of h_n are removed.
enum class StepEq {
  None,     ///< h_n free within its bounds
  Eta,      ///< (31): (h_n - h_{n-1}) eta_n = 0
  EtaTanh,  ///< (31) with tanh(eta_n), better scaled
  /// penalty rho_h * sum_n (h_n - T / N_FE)^2 over every element n in the objective (nosnoc's
  /// HEURISTIC_MEAN; the default of nosnoc_py's later `Options`, not of its `NosnocOpts`)
  HeuristicMean,
  /// penalty rho_h * sum_{n >= 1} (h_n - h_{n-1})^2 in the objective, unscaled, over the pairs of
  /// neighbouring elements of one control interval (integration step), not across its
  /// boundaries: nosnoc_py's HEURISTIC_DELTA, the default of its NosnocOpts (rho_h = 1). Pulls
  /// neighbouring steps together, so like heuristic_mean it biases an OCP's switching times
  /// where the grid must change at a switch (docs/formulation.md).
  HeuristicDelta,
  /// penalty rho_h * sum_n tanh(eta_n) ((h_n - h_{n-1}) / h_0)^2: (31) as a smooth penalty. Zero
  /// on every piecewise-uniform grid whose steps change only at switches, so unlike
  /// heuristic_mean it does not bias a solution; unlike eta it has no corner where the grid
  /// leaves uniformity (docs/formulation.md).
  L2Relaxed,
};
/// Problem-file key `step_equilibration`: "none", "eta", "eta_tanh", "heuristic_mean",
/// "heuristic_delta", "l2_relaxed" (and nosnoc's spellings HEURISTIC_MEAN, HEURISTIC_DELTA).
std::string_view to_string(StepEq v);
bool parse(std::string_view name, StepEq& out);

/// Where the stage LPs (9) keep their sign condition lambda >= 0 (FESD only).
enum class StageLambdaSign {
  /// lambda >= 0 at every stage point: the paper's (32).
  All,
  /// lambda >= 0 only at the points that approximate x(t_n) to the order of the scheme: element
  /// boundaries (the last stage of a stiffly accurate scheme, the boundary values (33) otherwise).
  /// At the other stages lambda is free and only theta * lambda = 0 per stage remains, so the
  /// element's active set comes from its boundaries and sliding stages still satisfy g_i = g_j.
  /// For schemes of low stage order (Lobatto IIIC, explicit RK), whose stage *states* can leave
  /// the region of the element's vector field by O(h^2) next to a switch (docs/formulation.md).
  Boundary,
  /// Boundary for Lobatto IIIC and explicit RK, All otherwise (default).
  Auto,
};
/// Problem-file key `stage_lambda_sign`: "all", "boundary", "auto".
std::string_view to_string(StageLambdaSign v);
bool parse(std::string_view name, StageLambdaSign& out);

/// How the set-valued sign functions of c-form subsystems enter the complementarity system.
enum class DcsMode {
  /// Stewart's DCS (8)/(21): theta per region, the LP (7) with multipliers lambda, mu.
  Stewart,
  /// The Heaviside step form (nosnoc's DcsMode.Step): alpha in [0, 1] per switching function
  /// with multipliers lambda_p, lambda_n, c(x) = lambda_p - lambda_n, and the region weights
  /// theta_i = prod_j (alpha_j or 1 - alpha_j) (docs/formulation.md, "Heaviside step form").
  /// c-form subsystems only.
  Step,
};
/// Problem-file key `dcs_mode`: "stewart", "step" (and nosnoc's spellings Stewart, Step).
std::string_view to_string(DcsMode v);
bool parse(std::string_view name, DcsMode& out);

/// Discretization of one interval [0, T] (problem-file table [discretization]).
struct DiscretizationOptions {
  RkScheme rk_scheme = RkScheme::RadauIIA;  ///< `rk_scheme`
  int n_s = 2;           ///< `n_s`: RK stages, >= 1 (Lobatto >= 2, explicit <= 4)
  int N_FE = 2;          ///< `N_finite_elements`: finite elements per step, >= 1 (>= 2 for FESD)
  bool use_fesd = true;  ///< `use_fesd`: false = standard time-stepping (26)
  CrossComp cross_comp = CrossComp::StageSum;                 ///< `cross_comp_mode`
  StepEq step_eq = StepEq::HeuristicMean;                     ///< `step_equilibration`
  StageLambdaSign stage_lambda_sign = StageLambdaSign::Auto;  ///< `stage_lambda_sign`
  double gamma_h = 1.0;  ///< `gamma_h` in (0, 1]: h_n in [(1 - gamma_h) h0, (1 + gamma_h) h0] (59f)
  double rho_h = 1.0;    ///< `rho_h` > 0: weight of the step-equilibration penalty
  /// `pin_sliding_exits`: FESD with a stiffly accurate scheme (Radau IIA, Lobatto IIIC) only.
  /// Where a solution leaves a sliding mode at an element boundary while the weight theta of the
  /// region it leaves is still > 0 there (an exit up to O(h) early, which the FESD equations
  /// allow), the last NLP is solved once more with that exit pinned: theta = 0 at the element
  /// end, the element kept on the surface (docs/formulation.md). Measured: Example 3(c) leaves
  /// its sliding mode up to 0.17 early without it, to 7e-9 with it; Fig. 13's E(T) of Radau IIA
  /// n_s = 3, N_FE = 3 falls from 3.9e-8 to 3.3e-9 (the reference simulation's exit was early).
  bool pin_sliding_exits = true;
  /// `dcs_mode`: Stewart's form (default) or the Heaviside step form (c-form subsystems only).
  DcsMode dcs_mode = DcsMode::Stewart;
};

/// How the complementarity constraints of the MPCC are relaxed, smoothed or penalized in the
/// homotopy (Sect. 5.2). sigma is the homotopy parameter of every method: sigma_0, then
/// sigma_{k+1} = homotopy_update_slope * sigma_k (HomotopyOptions::homotopy_update_rule) down to
/// sigma_N.
enum class MpccMode {
  ScholtesIneq,  ///< every complementarity constraint  w1' w2 <= sigma  (default)
  ScholtesEq,    ///< w1' w2 = sigma
  /// smoothed C-function  a + B - sqrt(a^2 + B^2 + 2 sigma) = 0 per group with a common factor
  /// a (B = the sum of its partners); needs cross_comp_mode sparse or stage_sum
  FischerBurmeister,
  L1Penalty,    ///< (1 / sigma) * sum of all w1' w2 added to the objective
  ElasticIneq,  ///< w1' w2 <= s, s >= 0 one elastic variable, (1 / sigma) * s in the objective
  /// -s <= w1' w2 <= s for every complementarity constraint (free-sign ones included), s >= 0
  /// one elastic variable, (1 / sigma) * s in the objective (nosnoc: ELASTIC_TWO_SIDED)
  ElasticTwoSided,
};
/// Problem-file key `mpcc_mode`: "scholtes_ineq", "scholtes_eq", "fischer_burmeister",
/// "ell_1_penalty", "elastic_ineq", "elastic_two_sided".
std::string_view to_string(MpccMode v);
bool parse(std::string_view name, MpccMode& out);
/// elastic_ineq or elastic_two_sided: the modes with the elastic variable s
/// (HomotopyOptions::s_elastic_max, s_elastic_0).
constexpr bool is_elastic(MpccMode m) {
  return m == MpccMode::ElasticIneq || m == MpccMode::ElasticTwoSided;
}
/// The modes that put a penalty term in the objective (ell_1_penalty and the elastic modes):
/// those that HomotopyOptions::objective_scaling_direct applies to.
constexpr bool penalizes(MpccMode m) {
  return m == MpccMode::L1Penalty || is_elastic(m);
}

/// How sigma shrinks from one NLP of the homotopy to the next (nosnoc's homotopy_update_rule).
enum class HomotopyUpdateRule {
  Linear,       ///< sigma_{k+1} = max(sigma_N, slope sigma_k)  (default)
  Superlinear,  ///< sigma_{k+1} = max(sigma_N, min(slope sigma_k, sigma_k^exponent))
};
/// Problem-file key `homotopy_update_rule`: "linear", "superlinear" (nosnoc's LINEAR, SUPERLINEAR
/// too).
std::string_view to_string(HomotopyUpdateRule v);
bool parse(std::string_view name, HomotopyUpdateRule& out);

/// The MPCC homotopy: a sequence of relaxed NLPs with theta_i lambda_i <= sigma (Scholtes),
/// sigma_{k+1} = homotopy_update_slope * sigma_k (homotopy_update_rule), until the complementarity
/// residual (the largest product of a complementarity pair, cross-complementarity pairs included)
/// is <= complementarity_tol.
struct HomotopyOptions {
  MpccMode mpcc_mode = MpccMode::ScholtesIneq;  ///< `mpcc_mode`
  double sigma_0 = 1.0;                         ///< `sigma_0` > 0: first relaxation
  double homotopy_update_slope = 0.1;           ///< `homotopy_update_slope` in (0, 1)
  /// `homotopy_update_rule`: linear (default) or superlinear, sigma_{k+1} = max(sigma_N,
  /// min(slope sigma_k, sigma_k^homotopy_update_exponent)): the same steps as linear while
  /// sigma_k > slope^(1 / (exponent - 1)) (0.01 with nosnoc's 0.1 and 1.5), longer ones below.
  HomotopyUpdateRule homotopy_update_rule = HomotopyUpdateRule::Linear;
  /// `homotopy_update_exponent` in (1, 10]: the superlinear rule's exponent (nosnoc's default
  /// 1.5); unused by the linear rule.
  double homotopy_update_exponent = 1.5;
  double sigma_N = 1e-12;             ///< `sigma_N` > 0: smallest sigma used
  double complementarity_tol = 1e-9;  ///< `complementarity_tol` > 0: stop when residual <= this
  /// `N_homotopy`: maximum number of NLPs per solve, 0..1000. 0 (default): enough for sigma to
  /// reach sigma_N: ceil(log(sigma_N / sigma_0) / log(slope)) + 1 with the linear rule (13 with
  /// the defaults), as many as the superlinear rule takes with it (homotopy_length()).
  int max_homotopy_steps = 0;
  /// `homotopy_retries` 0..100 (optimal control; an integration step has its own retry policy and
  /// ignores it): an NLP that fails after a converged one at a point that violates the
  /// constraints (primal infeasibility > 1e-6, or failed evaluations) is discarded and the
  /// homotopy goes back to the converged NLP's point with half the logarithmic sigma step
  /// (sigma = sqrt(sigma_good * sigma_failed); a later retry from the same point takes half the
  /// step to the last retry's sigma instead if that is larger, so no sigma is tried twice from
  /// one point), then on to the failed sigma; at most this many
  /// times per homotopy (the retried NLPs and the smaller steps after them do not count towards
  /// N_homotopy). A failed NLP that ends feasible (e.g. at max_iter) is kept, and so is every
  /// failed NLP with 0: the homotopy goes on from its point, as nosnoc's does. The schedule's
  /// last NLP is retried also where it fails feasible (no NLP follows it to go on to). A failure
  /// the homotopy retries, and a warm-started NLP's failure at a feasible point that it goes on
  /// from (in a simulation step's homotopy too), are returned by the IPOPT backend before its
  /// scaling, pivoting and MUMPS retries (after the mu-strategy one, where there is one;
  /// docs/kkt-solver.md, "The caller's retry first" and "Failures the homotopy goes on from").
  int homotopy_retries = 4;
  /// `homotopy_cold_restart` (optimal control): a homotopy that would end with a failed NLP, after
  /// an NLP that failed at a point violating the constraints with no retry left
  /// (homotopy_retries), starts again once at that NLP's sigma (the schedule's) from the initial
  /// guess instead of the NLP before it, and goes on from there. Every homotopy that does not end
  /// failed or stalled is unchanged (a failure it recovers from on the way included). In the
  /// penalty modes (ell_1_penalty, elastic_*) also after a stall: a converged NLP whose
  /// complementarity residual stayed above half that of its start although sigma fell
  /// (HomotopyRow::stalled), when the homotopy would end with the residual still there
  /// (docs/formulation.md, "A stalled penalty": nosnoc_py's elastic ball in a box). The relaxed
  /// path of a loose first sigma can end where the tighter NLPs have no feasible neighbour
  /// (nosnoc_py's temperature control and 3-D gearbox, docs/nosnoc-examples.md rows 9 and 32); the
  /// cold start reaches the NLP's feasible set from elsewhere, usually at another local minimizer
  /// (the summary says so). The rows of the replaced path are marked `restarted`, the cold NLP
  /// `cold_start`.
  bool homotopy_cold_restart = true;
  /// `intermediate_tol` >= 0: IPOPT tol of the NLPs with sigma > 10 complementarity_tol (they
  /// only have to be good starting points for the next NLP); the later NLPs, and one that
  /// already meets complementarity_tol, are solved to ipopt.tol. 0: ipopt.tol for every NLP.
  /// Measured (docs/benchmarks-ocp.md): OCP (61) 371 -> 256 IPOPT iterations, the README
  /// oscillator 6783 -> 3945, same objective / an error of the same size (1.5e-9 -> 1.1e-9).
  double intermediate_tol = 1e-6;
  /// `fix_active_set`: after the homotopy, solve its last NLP once more with the active set of
  /// every finite element fixed (theta = 0 off it, lambda = 0 on it; FESD with a stiffly accurate
  /// scheme, i.e. Radau IIA or Lobatto IIIC). Complementarity then holds exactly instead of to
  /// complementarity_tol, so the state no longer carries the relaxation's O(complementarity_tol /
  /// theta) error, and sliding exits (pin_sliding_exits) are pinned in the same solve. If the
  /// re-solve fails, the homotopy's solution stays (Summary::active_set_failures). Measured
  /// (docs/formulation.md): the belt's x(10) error 4e-8 -> 1e-12 and its exit time 3e-2 -> 8e-9 at
  /// N_sim = 200, for ~1 NLP (3-4 IPOPT iterations) more per step.
  bool fix_active_set = true;
  /// `active_set_sigma` >= 0 (FESD with a stiffly accurate scheme, Radau IIA or Lobatto IIIC, as
  /// fix_active_set; optimal control and every integration step): once an NLP of the homotopy
  /// with sigma <= active_set_sigma has the same active set in every finite element as the NLP
  /// before it, the rest of the homotopy is replaced by one NLP with those active sets fixed
  /// (theta = 0 off them, lambda = 0 on them; sliding exits pinned as with pin_sliding_exits),
  /// whose complementarity holds exactly. If that NLP fails, the homotopy goes on, and that
  /// active set is not tried again. The integrator skips steps with a sliding element and keeps
  /// the fixed NLP only if it lies within sqrt(sigma) of the relaxed point. 0: off (every NLP
  /// down to complementarity_tol). Measured (docs/formulation.md): 1e-3 ends OCP (61) on another
  /// branch (cost 9.1710 instead of 9.1685); 1e-4 keeps every example's cost.
  double active_set_sigma = 1e-4;
  /// `s_elastic_max` > 0 (optimal control, elastic_ineq and elastic_two_sided): upper bound of
  /// the elastic variable s. Default 1e20: unbounded. nosnoc's s_elastic_max (its default 10).
  double s_elastic_max = 1e20;
  /// `s_elastic_0` >= 0, <= s_elastic_max (optimal control, elastic modes): the first NLP's guess
  /// of s. nosnoc's s_elastic_0 (its default 1).
  double s_elastic_0 = 0.0;
  /// `objective_scaling_direct` (optimal control, penalty modes ell_1_penalty, elastic_ineq,
  /// elastic_two_sided): the NLP objective J + (1/sigma) P (true, default) or sigma J + P (false,
  /// nosnoc's inverse scaling), P the penalty (sum of products or the elastic s). Same minimizers;
  /// the homotopy rows' objective is the NLP's, so sigma J + P with false.
  bool objective_scaling_direct = true;
};

/// The linear solver behind IPOPT's KKT systems (docs/kkt-solver.md).
enum class KktSolver {
  Auto,       ///< the sparse LDL' at every size (default; docs/kkt-solver.md)
  SparseLdl,  ///< fesd's sparse multifrontal LDL' at every size
  Dense,      ///< fesd's dense LAPACK LDL' at every size (O((n + m)^3) per factorization)
  Mumps,      ///< IPOPT's MUMPS
};
/// Problem-file key `kkt_solver`: "auto", "sparse_ldl", "dense", "mumps".
std::string_view to_string(KktSolver v);
bool parse(std::string_view name, KktSolver& out);

/// How fesd's sparse LDL' scales a KKT matrix before factorizing it (docs/kkt-solver.md,
/// "Scaling"). Symmetric Ruiz sweeps with powers of two either way; they keep the inertia, and the
/// choice changes round-off only.
enum class KktScaling {
  /// Matrices of at least 1000 rows start from the previous factorization's scaling and do one
  /// sweep; smaller ones three sweeps from the identity (default).
  Warm,
  /// Three sweeps from the identity at every factorization: the scaling depends on the matrix
  /// alone, not on the run's history; two sweeps more per factorization.
  Fresh,
};
/// Problem-file key `kkt_scaling`: "warm", "fresh".
std::string_view to_string(KktScaling v);
bool parse(std::string_view name, KktScaling& out);

/// IPOPT options (problem-file table [ipopt]). Any other IPOPT option can be passed by name.
struct NlpOptions {
  double tol = 1e-12;            ///< `tol` > 0 (IPOPT's default 1e-8 cannot reach 1e-12 accuracy)
  double acceptable_tol = 1e-6;  ///< `acceptable_tol` > 0
  int max_iter = 500;            ///< `max_iter` >= 1, per NLP
  int print_level = 0;           ///< `print_level` 0..12 (IPOPT's own output)
  /// `kkt_solver`: IPOPT's linear solver. An IPOPT `linear_solver` in `extra` overrides it. With
  /// sparse_ldl (also under auto) an NLP that fails is solved again from the same start, first
  /// with sparse_ldl and ma27_pivtol 0.01 (unless [ipopt] sets a larger one), then, if that
  /// fails too, with MUMPS; HomotopyRow::linear_solver names the runs.
  KktSolver kkt_solver = KktSolver::Auto;
  /// `kkt_scaling`: the scaling of the sparse LDL' (kkt_solver auto or sparse_ldl; with mumps or
  /// dense it is an error to ask for fresh). The MUMPS fallback does its own.
  KktScaling kkt_scaling = KktScaling::Warm;
  /// Extra IPOPT options as (name, value) strings, e.g. {"mu_strategy", "monotone"}. A
  /// warm-started NLP (every NLP of a homotopy after the first) that fails is solved again with
  /// IPOPT's monotone mu strategy from mu_init 1e-4, unless `mu_strategy` is set here; once that
  /// cured an NLP, the homotopy's later warm-started NLPs run monotone first, adaptive as the
  /// retry (docs/kkt-solver.md, "Retry, then fallback").
  std::vector<std::pair<std::string, std::string>> extra;
};

/// How the integrator solves the FESD equations of each step (docs/active-set.md).
enum class StepSolver {
  /// The MPCC homotopy of relaxed NLPs solved by IPOPT (10-13 NLPs per step), with the retry
  /// policy (tight, sparse, refined, split) and the re-solve with the active set fixed. Every
  /// step of the standard method (use_fesd = false) runs on this path.
  Homotopy,
  /// Thm 15: with the active set of every finite element fixed, the FESD equations of a step are
  /// a square nonlinear system, solved by Newton's method with the exact Jacobian (no IPOPT).
  /// The active set is predicted from the previous step's end; where the complementarity signs
  /// fail, a switch (crossing) is placed on an element boundary whose length becomes free. A
  /// step where no consistent active set is found in a few tries falls back to the homotopy
  /// (Summary::active_set_path_steps, homotopy_path_steps). The default; applies to FESD
  /// (use_fesd = true): the standard method has no free lengths and uses the homotopy.
  ActiveSet,
};
/// Problem-file key `step_solver` ([simulation]): "homotopy", "active_set".
std::string_view to_string(StepSolver v);
bool parse(std::string_view name, StepSolver& out);

/// Everything the FESD integrator needs besides the model.
struct IntegratorOptions {
  DiscretizationOptions discretization;
  HomotopyOptions homotopy;
  NlpOptions nlp;
  /// `step_solver` ([simulation]): the homotopy of IPOPT solves, or Newton's method on the square
  /// system of the predicted active set with the homotopy as fallback (StepSolver).
  StepSolver step_solver = StepSolver::ActiveSet;
  /// Called after every integration step (the CLI prints format_step_progress() of it); the
  /// library itself never prints.
  StepCallback on_step;
  /// `sensitivities` ([simulation]): compute dx(T)/dx0, dx(T)/du, dx(T)/dp by the implicit
  /// function theorem on every step's square system, chained over the steps
  /// (IntegratorResult::sensitivities; docs/sensitivities.md).
  bool sensitivities = false;
  /// `theta_guess` ([simulation]): the Stewart weights theta (n_theta entries in [0, 1]) guessed
  /// at every stage point of the first step, instead of the solution of the LP (8) at x0; the
  /// state guess follows them (x0 + t F(x0) theta). Empty: the LP's. Where the LP's theta is not
  /// unique (x0 on a switching surface from which several solutions start, as x' in sign(x) from
  /// x(0) = 0), this chooses the solution the first step converges to; nosnoc's EXTERNAL
  /// initialization. Stewart's form only (dcs_mode = "stewart"); integrate() and simulate() (the
  /// Stepper rejects it: it guesses from the LP at every cold start).
  Eigen::VectorXd theta_guess;
};

/// Empty if valid, else one line per broken rule: "discretization.n_s = 0: must be >= 1".
std::vector<std::string> validate(const DiscretizationOptions& o);
std::vector<std::string> validate(const HomotopyOptions& o);
std::vector<std::string> validate(const NlpOptions& o);
/// The three tables together, with the rules across them (fischer_burmeister needs
/// cross_comp_mode sparse or stage_sum).
std::vector<std::string> validate(const DiscretizationOptions& d, const HomotopyOptions& h,
                                  const NlpOptions& n);
std::vector<std::string> validate(const IntegratorOptions& o);
/// Throws fesd::InvalidOption with all messages of validate() if any.
void check(const IntegratorOptions& o);

/// The sigma of the NLP after one at sigma: homotopy_update_rule with homotopy_update_slope and
/// homotopy_update_exponent, never below sigma_N.
double next_sigma(const HomotopyOptions& o, double sigma);
/// Number of NLPs of one homotopy: N_homotopy, or (0) enough for sigma to reach sigma_N (linear:
/// ceil(log(sigma_N / sigma_0) / log(slope)) + 1).
int homotopy_length(const HomotopyOptions& o);
/// The sigma of a homotopy's last NLP: next_sigma() applied homotopy_length - 1 times to sigma_0.
double final_sigma(const HomotopyOptions& o);
/// Valid settings that cannot be expected to reach complementarity_tol, one sentence each: the
/// homotopy's last sigma above complementarity_tol (sigma_N too large, or N_homotopy too small
/// to get there). A relaxed NLP at sigma allows complementarity products up to sigma, so its
/// solution meets the tolerance only by chance (fix_active_set may still rescue a step). The
/// integrator and solve() copy them into Summary::warnings; `fesd check` and the CLI print them
/// before a run.
std::vector<std::string> warnings(const HomotopyOptions& o);

}  // namespace fesd
