// src/discretization/fesd_interval.hpp: the equations of one control interval [0, T] with N_FE
// finite elements and an n_s-stage RK method, written into a BlockNlp:
//
//   standard discretization (25)-(26):  per element n and stage m (differential form, lifted)
//     X_{n,m} = x_n + h_n sum_j a_{m,j} V_{n,j}                         stage states
//     V_{n,m} = sum_r f_r(X_{n,m}, q, p) theta_{n,m,r}                  (8a)/(21a)
//     g(X_{n,m}) - lambda_{n,m} - mu_{n,m} e = 0,  e' theta^k_{n,m} = 1   (9)/(21b,c)
//     x_{n+1} = x_n + h_n sum_m b_m V_{n,m}     (stiffly accurate schemes: x_{n+1} is X_{n,n_s})
//   FESD (32) adds: h_n free with sum h_n = T and bounds (59f); boundary values lambda, mu at
//   t_{n+1} for schemes that are not stiffly accurate (33)-(34); cross complementarity (28)/(29);
//   step equilibration (31).
//
// The complementarity pairs are returned, not imposed: the MPCC layer decides how to relax them.
// Integrator and OCP both build their NLPs from this block; its layout (which variable is
// theta_{n,m,r}, h_n, ...) stays reachable for active-set and sensitivity code.
#pragma once
#include <algorithm>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/util.hpp"
#include "dcs/stewart.hpp"
#include "fesd/model.hpp"
#include "fesd/options.hpp"
#include "fesd/tableau.hpp"
#include "nlp/block_nlp.hpp"

namespace fesd::discretization {

/// One complementarity pair a * b with a = theta (variable index) and b = lambda (variable index).
struct CompPair {
  int a = -1, b = -1;
};
/// A complementarity constraint: sum of products of its pairs, >= 0 by the variable bounds, = 0 at
/// a solution of the MPCC. The MPCC layer relaxes it (e.g. <= sigma).
struct CompGroup {
  std::vector<CompPair> pairs;
  /// b is a lambda without sign condition (StageLambdaSign::Boundary): the product must vanish
  /// but has no sign, so the relaxation bounds it on both sides (|a * b| <= sigma).
  bool two_sided = false;
};

/// Where the interval's inputs live in the NLP (variables, possibly fixed by their bounds).
struct IntervalInputs {
  std::vector<int> s0;            ///< n_x: state at the interval start
  std::vector<int> q;             ///< n_u: control of the interval
  std::vector<int> p;             ///< n_p: parameters
  std::vector<int> lambda_start;  ///< n_theta: lambda_{0,0} (continuity from before, or fixed)
  std::vector<int> mu_start;      ///< n_sys: mu_{0,0}
  double T = 0;                   ///< interval length
  /// For schemes that are not stiffly accurate: add boundary values (33) at the interval end too
  /// (needed when another interval follows).
  bool boundary_at_end = false;
  /// lambda_start, mu_start are free variables (lambda >= 0) that the interval ties to s0 with
  /// the LP equation (9): g(s0) - lambda_{0,0} - mu_{0,0} e = 0. Needed when s0 is a variable
  /// (OCP with free x0), and more robust than fixed values when s0 lies on a switching surface.
  bool lp_at_start = false;
};

/// Whether region r is in a (sorted or not) list of regions.
inline bool has(const std::vector<int>& regions, int r) {
  return std::find(regions.begin(), regions.end(), r) != regions.end();
}

class FesdInterval {
 public:
  FesdInterval(const Pss& model, const Tableau& tableau, const DiscretizationOptions& options);

  /// Adds variables and constraint/objective blocks to `nlp`.
  void build(nlp::BlockNlp& nlp, const IntervalInputs& in);

  /// The input check of build(): one message per block of the interval whose number of inputs
  /// would exceed ad::kMaxInputs (derivatives by forward AD). Sums and complementarity rows have
  /// no limit; the dynamics (25) and LP (9) blocks grow with n_x and the number of regions, the
  /// step equilibration (31) block with the number of regions. Each message starts with the
  /// problem-file key to change ("model.F = 1024 regions: ..."). Empty: build() will not fail.
  static std::vector<std::string> block_size_errors(const Pss& model,
                                                    const DiscretizationOptions& options);

  /// Sets the initial guess w of every variable of the interval: states on the explicit Euler
  /// prediction from x0 with derivative xdot, algebraic variables from the LP solution.
  void set_guess(std::vector<double>& w, const Eigen::VectorXd& x0, const dcs::LpSolution& lp,
                 const Eigen::VectorXd& xdot) const;

  // ---- layout (valid after build); n: element, m: stage 0..n_s-1, i: state, r: region ----
  int N_FE() const { return N_FE_; }
  /// The inputs given to build().
  const IntervalInputs& inputs() const { return in_; }
  int n_s() const { return n_s_; }
  int x(int n, int i) const { return x_[n][i]; }  ///< n = 0..N_FE (n = 0: s0)
  int h(int n) const { return h_[n]; }
  int V(int n, int m, int i) const { return V_[idx(n, m)] + i; }
  int X(int n, int m, int i) const { return X_[idx(n, m)] + i; }
  int theta(int n, int m, int r) const { return theta_[idx(n, m)] + r; }
  int lambda(int n, int m, int r) const { return lambda_[idx(n, m)] + r; }
  int mu(int n, int m, int k) const { return mu_[idx(n, m)] + k; }
  // ---- the Heaviside step form (DiscretizationOptions::dcs_mode = step; dcs/step.hpp) ----
  // theta(n, m, r) is then theta(alpha) (a lifted variable), lambda(n, m, i) the multipliers
  // (lambda_n (i < n_c), lambda_p (i = n_c + j)), mu has no entries, and alpha(n, m, i) is alpha_j
  // (i = j < n_c) or beta_j = 1 - alpha_j (i = n_c + j).
  bool step_mode() const { return step_; }
  /// Multipliers per point: n_theta (Stewart), 2 n_c (step).
  int n_lambda() const { return n_lam_; }
  /// mu per point: n_sys (Stewart), 0 (step).
  int n_mu() const { return n_mu_; }
  int alpha(int n, int m, int i) const { return alpha_[idx(n, m)] + i; }
  /// The complementarity variables of a stage: theta (Stewart), (alpha, beta) (step); entry i
  /// pairs with entry i of each multiplier point.
  int n_comp() const { return step_ ? 2 * model_.n_c() : model_.n_theta(); }
  int comp_var(int n, int m, int i) const { return step_ ? alpha(n, m, i) : theta(n, m, i); }
  /// Stewart's lambda_{n,m,r}, or its analogue in the step form (dcs::region_multiplier: zero
  /// exactly where X_{n,m} is in the closure of region r).
  double region_lambda(const double* w, int n, int m, int r) const;
  /// lambda, mu at t_{n+1} (-1 where the scheme/options give none).
  int lambda_end(int n, int r) const { return lambda_end_[n].empty() ? -1 : lambda_end_[n][r]; }
  int mu_end(int n, int k) const { return mu_end_[n].empty() ? -1 : mu_end_[n][k]; }
  /// The lambda "points" of element n (Sect. 3.2.2): start (m' = 0), stages, end boundary.
  const std::vector<std::vector<int>>& lambda_points(int n) const { return points_[n]; }
  /// Whether lambda >= 0 holds at point q of element n (false only for free stage lambdas,
  /// StageLambdaSign::Boundary).
  bool point_signed(int n, int q) const { return point_signed_[n][q]; }
  /// Whether the stage lambdas of interior stages are free (StageLambdaSign resolved).
  bool boundary_sign() const { return boundary_sign_; }
  /// Every (28) product, standard ones included: the complementarity residual is their max.
  const std::vector<CompPair>& residual_pairs() const { return residual_pairs_; }
  /// The complementarity constraints in the form chosen by cross_comp_mode.
  const std::vector<CompGroup>& groups() const { return groups_; }
  /// Step-equilibration rows (31), for eta reporting; -1 if none.
  const std::vector<int>& step_eq_rows() const { return step_eq_rows_; }
  /// Active regions of element n at the NLP point w: r is active where sum_m theta_{n,m,r} >
  /// sum_m |lambda_{n,m,r}| over the element's stages (the factor of a complementarity pair that
  /// is zero is the smaller one, whatever complementarity the homotopy reached; |.| for free-sign
  /// stage lambdas) and theta_{n,m,r} > kActiveThetaTol at some stage (at a stage on a switching
  /// boundary both factors are ~0, and theta there may be any small value). theta alone cannot
  /// decide: an inactive region has theta ~ sigma / lambda at a relaxed solution, above 1e-6
  /// near a switch with complementarity_tol 1e-9 and almost everywhere with 1e-6; nor can lambda
  /// alone (it vanishes for every region at a switching boundary). Integrator and OCP report
  /// switches where this set changes.
  std::vector<int> active_set(const double* w, int n) const;
  /// The same into `active` (no allocation once its capacity is n_theta).
  void active_set(const double* w, int n, std::vector<int>& active) const;
  /// Region r at stage m of element n: theta_{n,m,r} > max(|lambda_{n,m,r}|, kActiveThetaTol),
  /// the stage-wise form of active_set().
  bool stage_active(const double* w, int n, int m, int r) const;
  /// active_set() of every element.
  std::vector<std::vector<int>> active_sets(const double* w) const;
  static constexpr double kActiveThetaTol = 1e-6;

  // ---- sliding exits (docs/formulation.md, "Leaving a sliding mode") ----
  // Where a sliding mode ends, the theta of the region that is left falls to 0 continuously. The
  // FESD equations do not say so: an exit at an element boundary up to O(h) before the exact one
  // satisfies them too (lambda >= 0 at the next stage points holds, the state leaving the
  // surface quadratically), and the step penalties then choose where. Pinning the exit
  // (theta of the leaving region = 0 at the element end, the element kept on the surface)
  // removes that freedom.

  /// Regions whose sliding mode ends between two consecutive elements with active sets `before`
  /// and `after` (active_set()): per subsystem, the regions active before and not after, where
  /// another region of the subsystem is active on both sides (a crossing has none in common).
  static std::vector<int> exit_regions(const Pss& model, const std::vector<int>& before,
                                       const std::vector<int>& after);
  /// Exits can be pinned: FESD with a stiffly accurate scheme (theta at t_{n+1} is a variable).
  bool can_pin_exits() const { return opt_.use_fesd && stiffly_accurate_; }
  /// A sliding exit to pin: region r leaves at the end of element n. theta_zero: its theta
  /// reaches 0 there (false: the exit is made by a jump of the control at the interval end).
  struct ExitPin {
    int n = 0, r = 0;
    bool theta_zero = true;
  };
  /// The sliding exits inside the interval at the NLP point w: every exit between elements n and
  /// n+1 (exit_regions of their active sets), and an exit inside the last element (r active
  /// there together with another region of its subsystem, but not at its end point
  /// (stage_active): the state left the surface inside the element, which cross complementarity
  /// tolerates because both factors are small near an exit). The latter is pinned in the element
  /// before if that one slides on r too; or, with control_jump_at_end (an OCP interval, whose
  /// control changes at its end), in the last element without theta_zero: the mode is kept to
  /// the interval end, where the new control may end it.
  std::vector<ExitPin> exits_to_pin(const double* w, bool control_jump_at_end) const;
  /// The variable bounds of the pinned re-solve: the active set of every element is fixed (that
  /// of active_set() at w, with each pin's region kept in its element and, with theta_zero,
  /// removed from the next): theta_{n,m,r} = 0 off the set, lambda_{n,m,r} = 0 on it at every
  /// lambda point of the element (start, stages, end boundary), and for each pin with theta_zero
  /// theta_{n,n_s,r} = 0 (the region's weight reaches 0 at t_{n+1}). The complementarity
  /// constraints then hold exactly and the re-solve is a smooth problem in h and the stage
  /// values, the square system of Thm 15 plus the free element lengths. Fixing only the pinned
  /// exits left IPOPT to wander between degenerate complementarity branches (the belt of
  /// docs/formulation.md: converged to local infeasibility). Any FESD scheme without pins (the
  /// active set fixed only); pins need can_pin_exits().
  std::vector<nlp::Bound> pin_bounds(const double* w, const std::vector<ExitPin>& pins) const;
  /// The bounds that fix the given active set of every element (one sorted list per element):
  /// the part of pin_bounds() without pins.
  std::vector<nlp::Bound> active_set_bounds(const std::vector<std::vector<int>>& active) const;
  /// Between two integration steps an exit is pinned only when theta of the leaving region at
  /// the end of the step before exceeds this and its lambda there (below it the exit is early by
  /// ~ theta / |d theta / dt|, an error ~1e-12 in the state); else the first element would have
  /// to slide on without the region and shrink to length 0.
  static constexpr double kExitThetaTol = 1e-6;
  // ---- switches held by the grid (issue 14; docs/formulation.md, "Switches held by the grid")
  // Cross complementarity puts every switch on an element boundary, and a boundary can move only
  // as far as the lengths of its neighbouring elements allow: h_n in [(1 - gamma_h) h0,
  // (1 + gamma_h) h0] (59f). An optimizer that moves a switch (an OCP's) can carry it to the end
  // of that range and stop there, at a point that is stationary for the discretized MPCC but not
  // for the OCP: moving on needs the switch to change boundaries, through an element of length 0.

  /// Boundaries n (1..N_FE-1) where the active set (active_set()) changes at w, with the
  /// interval's start (0) and end (N_FE) first and last: the segments of constant active set are
  /// the elements between two consecutive entries. A segment of length ~0 (elements collapsed at
  /// a switch) is joined to the segment after it (the last to the one before).
  std::vector<int> segment_boundaries(const double* w) const;
  /// The switches of w held by the grid: interior boundaries n where the active set changes and
  /// every element of a neighbouring segment (the elements up to the previous switch or the
  /// interval start, or up to the next switch or the interval end) has h_n at a bound (within
  /// kHeldTol h0; at the same bound, or some collapsed and the others at the upper bound).
  std::vector<int> held_switches(const double* w) const;
  /// The times of held_switches(w), the interval starting at t0 (for the warnings of the OCP and
  /// the integrator).
  std::vector<double> held_switch_times(const double* w, double t0) const;
  static constexpr double kHeldTol = 1e-6;
  /// Re-places the element boundaries of the interval for the switches of w_old: every segment
  /// (segment_boundaries()) keeps its length and gets a number of elements in proportion to it
  /// (at least one), all of equal length, so each switch lies on a boundary that can move both
  /// ways. The guess of each new element is the old solution on the same segment: states from
  /// the stage polynomial of the old element that contains the new stage time, V, theta,
  /// lambda, mu copied from it (the active set is unchanged). Writes the interval's variables of
  /// w_new (the rest stays). False (w_new unchanged) if it cannot: more segments than elements,
  /// or a segment whose uniform h would leave the bounds of h.
  bool regrid(const double* w_old, std::vector<double>& w_new) const;
  /// The number of elements of each segment of w (the differences of segment_boundaries()).
  std::vector<int> segment_counts(const double* w) const;
  /// As regrid(w_old, w_new), with `count[j]` elements in segment j (count.size() must equal
  /// the number of segments, each >= 1, summing to N_FE): an allocation of the elements to the
  /// segments (the OCP's allocation search). Where a segment's length over its count leaves the
  /// bounds of h, every segment's h becomes clamp(length / count + nu) with one nu that keeps
  /// the interval's length: the switches move, and the states of each segment extend its old
  /// polynomials. False (w_new unchanged) if count does not fit the segments.
  bool regrid(const double* w_old, std::vector<double>& w_new, const std::vector<int>& count) const;
  /// A touch: at boundary n (0..N_FE-1, the start of element n, of positive length; collapsed
  /// elements before it are skipped) the state lies on the boundary of
  /// region r (lambda_r at that point <= kTouchTol) while r is active neither in element n nor
  /// (n > 0) in element n-1, and `instead` is the one active region of r's subsystem in element
  /// n. The solution is then at a kink of the problem (e.g. an OCP's free x0 on a switching
  /// surface) where a switch could be born that the MPCC's stationarity conditions do not see.
  struct Touch {
    int n = 0, r = 0, instead = 0;
  };
  std::vector<Touch> touches(const double* w) const;
  static constexpr double kTouchTol = 1e-7;
  /// The probe of a touch: the active sets of w with element t.n in region t.r instead of
  /// t.instead (the switch born at boundary t.n + 1), and the guess `w_new` with theta moved to
  /// the new region in that element.
  std::vector<std::vector<int>> probe(const double* w, const Touch& t,
                                      std::vector<double>& w_new) const;

  /// Recomputes the lifted sums of step equilibration (if any) in the guess w from its other
  /// entries; call after changing the guess of lambda or theta.
  void update_lifted_guess(std::vector<double>& w) const;
  /// eta_n (31) at a solution x, n = 1..N_FE-1 (entry 0 unused, set to NaN).
  std::vector<double> eta(const double* x) const;

 private:
  int idx(int n, int m) const { return n * n_s_ + m; }
  /// Tolerance of "h_n at a bound" and of a collapsed element (h_n ~ 0): kHeldTol h0.
  double held_tol() const { return kHeldTol * in_.T / N_FE_; }
  bool collapsed(const double* w, int n) const { return w[h(n)] <= held_tol(); }
  void build_complementarity();
  std::vector<nlp::Bound> step_active_set_bounds(const std::vector<std::vector<int>>& active) const;

  const Pss& model_;
  Tableau tab_;
  DiscretizationOptions opt_;
  IntervalInputs in_;
  int N_FE_ = 0, n_s_ = 0;
  bool stiffly_accurate_ = false;
  std::vector<std::vector<int>> x_;
  std::vector<int> h_, V_, X_, theta_, lambda_, mu_, alpha_;
  bool step_ = false;
  int n_lam_ = 0, n_mu_ = 0;
  std::vector<int> owner_;  // subsystem of each region
  std::vector<std::vector<int>> lambda_end_, mu_end_;
  std::vector<bool> boundary_vars_;  // element n has boundary LP variables (33) at t_{n+1}
  std::vector<std::vector<std::vector<int>>> points_;
  std::vector<std::vector<bool>> point_signed_;
  std::vector<bool> stage_signed_;  // per idx(n, m): lambda_{n,m} >= 0
  bool boundary_sign_ = false;
  std::vector<CompPair> residual_pairs_;
  std::vector<CompGroup> groups_;
  std::vector<int> step_eq_rows_;
  std::vector<std::vector<int>> lam_sum_, th_sum_;  // lifted sums of (31), per element, region
};

/// Appends the multipliers of stage (n, m) of the solution w to a result (IntegratorResult or
/// OcpResult): lambda per region (in the step form the per-region multiplier made from lambda_n,
/// lambda_p) and, in the step form, alpha, lambda_n and lambda_p; in Stewart's form also mu where
/// the result has it.
template <class Result>
void append_stage_multipliers(const FesdInterval& iv, const Pss& model,
                              const std::vector<double>& w, int n, int m, Result& res) {
  const int n_th = model.n_theta();
  if (model.n_z() > 0) {  // the algebraic variables z(X_{n,m}, q, p)
    const IntervalInputs& in = iv.inputs();
    std::vector<double> x(static_cast<std::size_t>(model.n_x())), q, p;
    for (int i = 0; i < model.n_x(); ++i) x[static_cast<std::size_t>(i)] = w[iv.X(n, m, i)];
    for (int j : in.q) q.push_back(w[j]);
    for (int j : in.p) p.push_back(w[j]);
    Eigen::VectorXd z(model.n_z());
    model.functions().algebraic(x.data(), q.empty() ? nullptr : q.data(), p.data(), z.data());
    res.z.push_back(z);
  }
  if (iv.step_mode()) {
    Eigen::VectorXd lam(n_th);
    for (int r = 0; r < n_th; ++r) lam[r] = iv.region_lambda(w.data(), n, m, r);
    res.lambda.push_back(lam);
    const int n_c = model.n_c();
    res.alpha.push_back(util::gather(w, iv.alpha(n, m, 0), n_c));
    res.lambda_n.push_back(util::gather(w, iv.lambda(n, m, 0), n_c));
    res.lambda_p.push_back(util::gather(w, iv.lambda(n, m, n_c), n_c));
    return;
  }
  res.lambda.push_back(util::gather(w, iv.lambda(n, m, 0), n_th));
  if constexpr (requires { res.mu; })
    res.mu.push_back(util::gather(w, iv.mu(n, m, 0), model.n_sys()));
}

}  // namespace fesd::discretization
