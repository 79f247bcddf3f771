// The active-set step of the integrator: Newton's method on the square system of Thm 15
// (active_set.hpp, docs/active-set.md).
#include "integrator/active_set.hpp"

#include "core/util.hpp"
#include "dcs/step.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>

#include "fesd/error.hpp"

namespace fesd::integrator {
namespace {

using util::range_of;

void fix(nlp::BlockNlp& nlp, const std::vector<int>& vars, const Eigen::VectorXd& values) {
  for (std::size_t i = 0; i < vars.size(); ++i) {
    const double v = values[static_cast<Eigen::Index>(i)];
    nlp.x_lb[vars[i]] = nlp.x_ub[vars[i]] = nlp.x_init[vars[i]] = v;
  }
}

/// The subsystem of region r.
int subsystem_of(const Pss& model, int r) {
  int k = 0;
  while (k + 1 < model.n_sys() && r >= model.region_offset(k + 1)) ++k;
  return k;
}

}  // namespace

discretization::IntervalInputs add_step_inputs(nlp::BlockNlp& nlp, const Pss& model, bool use_fesd,
                                               double T_step, DcsMode mode) {
  discretization::IntervalInputs in;
  const int n_th = dcs::n_lambda(model, mode), n_sys = dcs::n_mu(model, mode);
  in.s0 = range_of(nlp.add_variables(model.n_x(), 0.0, 0.0, 0.0), model.n_x());
  in.q = range_of(nlp.add_variables(model.n_u(), 0.0, 0.0, 0.0), model.n_u());
  in.p = range_of(nlp.add_variables(model.n_p(), 0.0, 0.0, 0.0), model.n_p());
  // FESD: lambda_{0,0}, mu_{0,0} are variables tied to s0 by the LP equation (9), not fixed
  // numbers, so that a step starting on a switching surface (c(s0) = O(1e-13)) is not made
  // infeasible by the round-off sign of a fixed lambda_{0,0}. The standard method does not use
  // them (no cross complementarity): fixed.
  if (use_fesd) {
    in.lambda_start = range_of(nlp.add_variables(n_th, 0.0, nlp::kInf, 0.0), n_th);
    in.mu_start = range_of(nlp.add_variables(n_sys, -nlp::kInf, nlp::kInf, 0.0), n_sys);
    in.lp_at_start = true;
  } else {
    in.lambda_start = range_of(nlp.add_variables(n_th, 0.0, 0.0, 0.0), n_th);
    in.mu_start = range_of(nlp.add_variables(n_sys, 0.0, 0.0, 0.0), n_sys);
  }
  in.T = T_step;
  // Non-stiffly-accurate schemes: boundary values (33) at the step end too, so that a switch
  // cannot hide between the last stage and the end of the step.
  in.boundary_at_end = true;
  return in;
}

ActiveSetStep::ActiveSetStep(const Pss& model, const Tableau& tab, const DiscretizationOptions& d,
                             double T_step, const Eigen::VectorXd& u, const Eigen::VectorXd& p)
    : model_(model), tab_(tab), d_(d), T_(T_step) {
  if (!d.use_fesd) throw InternalError("ActiveSetStep needs FESD");
  // The element lengths are set by the square system's own rows (h_n = h_{n-1}, or a switch):
  // no step-equilibration rows, penalties or lifted sums.
  d_.step_eq = StepEq::None;
  in_ = add_step_inputs(nlp_, model, true, T_step);
  iv_ = std::make_unique<discretization::FesdInterval>(model, tab_, d_);
  iv_->build(nlp_, in_);
  fix(nlp_, in_.q, u);
  fix(nlp_, in_.p, p);
  for (int i = 0; i < nlp_.num_constraints(); ++i)
    if (nlp_.g_lb[i] != nlp_.g_ub[i])
      throw InternalError("ActiveSetStep: the FESD equations of a step must be equalities");
  nlp_.finalize();
  g_.resize(nlp_.num_constraints());
  jac_.resize(nlp_.jac_nnz());
  // the work space of solve() (no allocation in steps once the shapes met have been set up)
  const int n_th = model.n_theta();
  w_.reserve(nlp_.x_init.size());
  w_guess_.reserve(nlp_.x_init.size());
  w_pred_.reserve(nlp_.x_init.size());
  w_start_.reserve(nlp_.x_init.size());
  theta_start_.resize(n_th);
  for (auto* v :
       {&predicted_, &active_k_, &off_k_, &sliding_, &pool_, &also_, &bounds_, &sw_in_, &sw_out_})
    v->reserve(static_cast<std::size_t>(n_th) + 1);
  for (auto* sets : {&sets_, &predicted_sets_, &active_try_}) {
    sets->resize(static_cast<std::size_t>(d.N_FE));
    for (auto& a : *sets) a.reserve(static_cast<std::size_t>(n_th));
  }
  t_ok_.reserve(n_th);
  val_ok_.reserve(n_th);
  cost_.reserve(static_cast<std::size_t>(d.N_FE));
}

void ActiveSetStep::set_inputs(const double* u, const double* p) {
  for (std::size_t i = 0; i < in_.q.size(); ++i)
    nlp_.x_lb[in_.q[i]] = nlp_.x_ub[in_.q[i]] = nlp_.x_init[in_.q[i]] = u[i];
  for (std::size_t i = 0; i < in_.p.size(); ++i)
    nlp_.x_lb[in_.p[i]] = nlp_.x_ub[in_.p[i]] = nlp_.x_init[in_.p[i]] = p[i];
}

ActiveSetStep::Candidate& ActiveSetStep::add_candidate(Kind kind, int b, int free_at_boundary) {
  if (n_cand_ == static_cast<int>(cand_.size())) cand_.emplace_back();
  Candidate& c = cand_[static_cast<std::size_t>(n_cand_++)];
  c.kind = kind;
  c.b = b;
  c.free_at_boundary = free_at_boundary;
  c.after.clear();
  return c;
}

bool ActiveSetStep::solve(const Eigen::VectorXd& x0, const std::vector<int>& prediction,
                          const dcs::LpSolution& lp, const Eigen::VectorXd& xdot) {
  iterations_ = tries_ = factorizations_ = 0;
  kind_ = Kind::Prediction;
  fix(nlp_, in_.s0, x0);
  w_ = nlp_.x_init;
  for (int r = 0; r < model_.n_theta(); ++r) w_[in_.lambda_start[r]] = lp.lambda[r];
  for (int k = 0; k < model_.n_sys(); ++k) w_[in_.mu_start[k]] = lp.mu[k];
  iv_->set_guess(w_, x0, lp, xdot);
  theta_start_ = lp.theta;

  // The prediction, then (if its system is not square or singular) the selections of a
  // co-dimension-2 sliding mode (selections()).
  predicted_.clear();
  w_guess_ = w_;
  ++tries_;
  sets_.assign(iv_->N_FE(), prediction);
  if (newton(sets_).converged) {
    predicted_ = prediction;
  } else {
    selections(prediction, lp);
    for (int i = 1; i < n_sel_; ++i) {
      const std::vector<int>& sel = sel_[static_cast<std::size_t>(i)];
      if (tries_ >= kMaxTries) return false;
      w_ = w_guess_;
      ++tries_;
      sets_.assign(iv_->N_FE(), sel);
      if (newton(sets_).converged) {
        predicted_ = sel;
        break;
      }
    }
  }
  if (predicted_.empty()) return false;
  const std::vector<int>& predicted = predicted_;
  predicted_sets_.assign(iv_->N_FE(), predicted);
  const Sets& predicted_sets = predicted_sets_;
  const Violation v = check_signs(predicted_sets);
  if (!v.bad && v.r < 0) return true;
  if (chord_converged_) {
    // A switch (or a bad h) in a step whose prediction converged with the LU of a step before:
    // solved again as if no LU were held, so that every step that switches, and every square
    // system it tries, goes through the singularity check of a fresh factorization (a stale LU
    // can converge where the system of this step is singular: temperature_control at the triple
    // point psi = 1, w = 0).
    // (its Newton iterations and factorizations are counted, the discarded try is not)
    const int iterations = iterations_, factorizations = factorizations_;
    lu_current_ = false;
    const bool ok = solve(x0, prediction, lp, xdot);
    iterations_ += iterations;
    factorizations_ += factorizations;
    return ok;
  }
  if (v.bad) return false;

  // A switch inside the step: region v.r enters (v.exit: leaves). Its time from lambda_r (theta_r),
  // linear between the last point where the sign held and the first where it failed.
  const double ts = v.t_ok + (v.t_bad - v.t_ok) * v.val_ok / std::max(v.val_ok - v.val_bad, 1e-300);
  const int k = subsystem_of(model_, v.r);
  // Appends the predicted set's regions of the other subsystems to `set` (subsystem k's regions
  // replaced by those in it), sorted. The sets live in the members (no allocation once sized).
  const auto with_k = [&](std::vector<int>& set) {
    for (int r : predicted)
      if (subsystem_of(model_, r) != k) set.push_back(r);
    std::sort(set.begin(), set.end());
  };
  active_k_.clear();
  off_k_.clear();
  for (int r = model_.region_offset(k); r < model_.region_offset(k + 1); ++r)
    (discretization::has(predicted, r) ? active_k_ : off_k_).push_back(r);
  n_cand_ = 0;
  boundaries_for(ts);
  if (v.exit) {
    // Leaving a sliding mode: r leaves the set; at the boundary b theta_r = 0 (the pin of
    // FesdInterval::pin_bounds) replaces h_b = h_{b-1}. b = 0: the whole step without r. Then
    // (co-dimension 2: the state leaves both surfaces at once) a region j off the set replacing
    // the subsystem's regions after the pin, lambda_j at the boundary free (not a second switch
    // condition: on the intersection lambda_j = 0 holds whatever the boundary's time).
    for (int b : bounds_) {
      if (b > 0 && !iv_->can_pin_exits()) continue;
      Candidate& c = add_candidate(Kind::Exit, b, -1);
      c.after = predicted;
      std::erase(c.after, v.r);
      if (b > 0)
        for (int j : off_k_) {
          Candidate& cj = add_candidate(Kind::Exit, b, j);
          cj.after.push_back(j);
          with_k(cj.after);
        }
    }
  } else {
    // A crossing: r replaces the active regions of its subsystem. Entering a sliding mode: r is
    // added to them. Per boundary the crossing first; the sliding candidate is accepted only
    // with theta strictly inside the simplex (sliding_is_filippov). Then, where several regions
    // of the subsystem fail at the same point (the state reaches two surfaces' intersection:
    // periodic_stick_slip.toml), the two-region sets {j, r'} with r' failing and j active or
    // failing: a regular selection of the co-dimension-2 sliding mode (see selections()).
    sliding_ = active_k_;
    sliding_.push_back(v.r);
    std::sort(sliding_.begin(), sliding_.end());
    pool_ = active_k_;
    pool_.insert(pool_.end(), also_.begin(), also_.end());
    n_pairs_ = 0;
    for (int r2 : also_)
      for (int j : pool_) {
        if (j == r2) continue;
        const int a = std::min(j, r2), b = std::max(j, r2);
        const auto is_pair = [&](const std::vector<int>& set) {
          return set.size() == 2 && set[0] == a && set[1] == b;
        };
        if (is_pair(sliding_) || std::any_of(pairs_.begin(), pairs_.begin() + n_pairs_, is_pair))
          continue;
        if (n_pairs_ == static_cast<int>(pairs_.size())) pairs_.emplace_back();
        std::vector<int>& pair = pairs_[static_cast<std::size_t>(n_pairs_++)];
        pair.clear();
        pair.push_back(a);
        pair.push_back(b);
      }
    for (int b : bounds_) {
      add_candidate(Kind::Crossing, b, -1).after.push_back(v.r);
      with_k(cand_[static_cast<std::size_t>(n_cand_ - 1)].after);
      add_candidate(Kind::SlidingEntry, b, -1).after = sliding_;
      with_k(cand_[static_cast<std::size_t>(n_cand_ - 1)].after);
      if (also_.size() > 1)
        for (int i = 0; i < n_pairs_; ++i) {
          add_candidate(Kind::SlidingEntry, b, -1).after = pairs_[static_cast<std::size_t>(i)];
          with_k(cand_[static_cast<std::size_t>(n_cand_ - 1)].after);
        }
    }
  }
  w_pred_ = w_;
  for (int i = 0; i < n_cand_; ++i) {
    const Candidate& c = cand_[static_cast<std::size_t>(i)];
    if (tries_ >= kMaxTries) return false;
    active_try_ = predicted_sets;
    for (int n = c.b; n < iv_->N_FE(); ++n) active_try_[static_cast<std::size_t>(n)] = c.after;
    switched_guess(w_pred_, predicted, c.after, c.b, ts);
    ++tries_;
    extra_.clear();
    int lam_free = -1;
    if (c.kind == Kind::Exit && c.b > 0) {
      extra_.push_back({iv_->theta(c.b - 1, iv_->n_s() - 1, v.r), 0.0, 0.0});
      if (c.free_at_boundary >= 0) {
        lam_free = iv_->lambda_points(c.b)[0][c.free_at_boundary];
        extra_.push_back({lam_free, nlp_.x_lb[lam_free], nlp_.x_ub[lam_free]});
      }
    }
    if (!newton(active_try_, extra_).converged) continue;
    const Violation again = check_signs(active_try_);
    if (again.bad || again.r >= 0) continue;
    // an exit into region j: the state is on j's boundary there (lambda_j = 0 to the tolerance)
    if (lam_free >= 0 && std::abs(w_[lam_free]) > kSignTol) continue;
    if (c.kind == Kind::SlidingEntry && !sliding_is_filippov(active_try_, k, c.b)) continue;
    kind_ = c.kind;
    return true;
  }
  return false;
}

bool ActiveSetStep::solve_fixed(const Eigen::VectorXd& x0, const Sets& active,
                                const discretization::FesdInterval& other,
                                const discretization::IntervalInputs& other_in,
                                const std::vector<double>& w_other, std::string& why) {
  const discretization::FesdInterval& iv = *iv_;
  iterations_ = tries_ = factorizations_ = 0;
  fix(nlp_, in_.s0, x0);
  w_ = nlp_.x_init;
  copy_interval(model_, other, w_other, iv, w_);
  for (int r = 0; r < model_.n_theta(); ++r)
    w_[in_.lambda_start[r]] = w_other[other_in.lambda_start[r]];
  for (int k = 0; k < model_.n_sys(); ++k) w_[in_.mu_start[k]] = w_other[other_in.mu_start[k]];
  // the switch conditions of sliding exits between elements: theta_r = 0 at the boundary
  std::vector<nlp::Bound> extra;
  for (int n = 1; n < iv.N_FE(); ++n)
    for (int r : discretization::FesdInterval::exit_regions(model_, active[n - 1], active[n])) {
      if (!iv.can_pin_exits()) {
        why =
            "a sliding exit inside the step needs a stiffly accurate scheme (Radau IIA, "
            "Lobatto IIIC)";
        return false;
      }
      extra.push_back({iv.theta(n - 1, iv.n_s() - 1, r), 0.0, 0.0});
    }
  ++tries_;
  const ActiveSetTry t = newton(active, extra);
  if (!t.converged) {
    why =
        "Newton's method on the square system of the final active set did not converge (not "
        "square, singular, or no solution near the homotopy's)";
    return false;
  }
  // the polished solution must be the homotopy's (the same switch times and end state)
  for (int n = 0; n < iv.N_FE(); ++n) {
    const double t_a = w_[iv.h(n)], t_b = w_other[other.h(n)];
    if (std::abs(t_a - t_b) > 1e-6 * (1 + std::abs(t_b))) {
      why = fmt::format(
          "the square system of the final active set moved element {} from "
          "h = {:.9g} to {:.9g}",
          n, t_b, t_a);
      return false;
    }
  }
  return true;
}

bool ActiveSetStep::sensitivity(StepSensitivity& out, std::string& why) {
  const discretization::FesdInterval& iv = *iv_;
  std::vector<std::pair<int, int>> equal;
  for (int n : cur_->equal) equal.emplace_back(iv.h(n), iv.h(n - 1));
  SquareSystem sys(nlp_, cur_->free, std::move(equal));
  std::vector<int> inputs = in_.s0, x_end;
  inputs.insert(inputs.end(), in_.q.begin(), in_.q.end());
  inputs.insert(inputs.end(), in_.p.begin(), in_.p.end());
  for (int i = 0; i < model_.n_x(); ++i) x_end.push_back(iv.x(iv.N_FE(), i));
  Eigen::MatrixXd d;
  if (!sys.ift(w_, inputs, x_end, d, why)) return false;
  out = split_inputs(d, model_.n_x(), model_.n_u(), model_.n_p());
  return true;
}

void ActiveSetStep::selections(const std::vector<int>& prediction, const dcs::LpSolution& lp) {
  // A subsystem with more active regions than one plus its number of independent switching
  // conditions has a family of theta (periodic_stick_slip.toml on x2 = 0.2, x3 = 0.4: f_0 = f_1
  // there, theta_0 + theta_1 is determined, the split is not): the square system is singular, or
  // not square at all (the LP at the fixed start state repeats a condition). Selection rule:
  // regions of such a subsystem are left out (theta = 0 for them: one member of the family), the
  // one of least theta at the step start, then the two least, ... down to two regions, then each
  // other one alone; the signs then decide as for any set (lambda >= 0 of the left-out regions
  // included), so a selection that changes the state is refused.
  // (the sets in sel_, the first n_sel_ of them: no allocation once sized)
  const auto add = [&]() -> std::vector<int>& {
    if (n_sel_ == static_cast<int>(sel_.size())) sel_.emplace_back();
    return sel_[static_cast<std::size_t>(n_sel_++)];
  };
  n_sel_ = 0;
  add() = prediction;
  std::vector<int>& in_k = pool_;
  for (int k = 0; k < model_.n_sys(); ++k) {
    in_k.clear();
    for (int r : prediction)
      if (subsystem_of(model_, r) == k) in_k.push_back(r);
    if (in_k.size() < 3) continue;
    std::sort(in_k.begin(), in_k.end(), [&](int a, int b) { return lp.theta[a] < lp.theta[b]; });
    // the least theta out, then the two least, ... down to two regions; then each other one out
    for (std::size_t i = 0; i + 2 < in_k.size(); ++i) {
      const std::size_t before = static_cast<std::size_t>(n_sel_ - 1);
      std::vector<int>& set = add();
      set = i == 0 ? prediction : sel_[before];
      std::erase(set, in_k[i]);
    }
    for (std::size_t i = 1; i < in_k.size(); ++i) {
      std::vector<int>& set = add();
      set = prediction;
      std::erase(set, in_k[i]);
      if (std::find(sel_.begin(), sel_.begin() + n_sel_ - 1, set) != sel_.begin() + n_sel_ - 1)
        --n_sel_;
    }
  }
}

bool ActiveSetStep::sliding_is_filippov(const Sets& active, int k, int b) const {
  // With the entering region r in the set, the sliding theta^k lies strictly inside the simplex
  // at every stage after the entry: both fields point toward the surface (for two regions theta_r
  // = grad c . f_a / grad c . (f_a - f_r) in (0, 1) iff the normal components have opposite
  // signs, and f_a points toward the surface, since the state reached it). A theta at 0 (a field
  // tangent to the surface, e.g. a Filippov equilibrium on it) is not accepted: the crossing
  // failed, and the homotopy decides.
  const discretization::FesdInterval& iv = *iv_;
  for (int n = b; n < iv.N_FE(); ++n)
    for (int s = 0; s < iv.n_s(); ++s)
      for (int r : active[n])
        if (subsystem_of(model_, r) == k && !(w_[iv.theta(n, s, r)] > kSlidingThetaTol))
          return false;
  return true;
}

ActiveSetTry ActiveSetStep::newton(const Sets& active, const std::vector<nlp::Bound>& extra) {
  use_shape(active, extra);
  Shape& sh = *cur_;
  // the inputs s0, q, p (the only bounds that change between steps of one shape)
  for (const std::vector<int>* vars : {&in_.s0, &in_.q, &in_.p})
    for (int j : *vars) sh.lb[j] = sh.ub[j] = nlp_.x_lb[j];
  for (int j : sh.fixed) w_[j] = sh.lb[j];
  if (!sh.square) return {};  // not square: not handled here
  chord_converged_ = false;
  if (!lu_current_) return iterate(false);
  // The LU of a step before with this shape: simplified Newton from it first; where that does
  // not converge, Newton with fresh Jacobians from the same start.
  w_start_ = w_;  // sized once
  ActiveSetTry out = iterate(true);
  // Converged: the Jacobian at the solution must be regular (Thm 15's local uniqueness; a stale
  // LU can converge where it is singular), and its LU is the one held for the next step.
  chord_converged_ = out.converged && factor();
  if (chord_converged_) return out;
  std::copy(w_start_.begin(), w_start_.end(), w_.begin());
  const int chord_iterations = out.iterations;
  out = iterate(false);
  out.iterations += chord_iterations;
  return out;
}

bool ActiveSetStep::factor() {
  lu_current_ = false;
  if (!nlp_.eval_jac_g(w_.data(), jac_.data())) return false;
  // the restricted Jacobian: the entries of free columns (zeroed first: an entry may be the sum
  // of several); the equal-length rows are constant (restrict_to)
  const Shape& sh = *cur_;
  double* J = J_.data();
  for (const auto& [e, pos] : sh.jac_map) J[pos] = 0;
  for (const auto& [e, pos] : sh.jac_map) J[pos] += jac_[e];
  for (const auto& [pos, value] : sh.constant) J[pos] = value;
  ++factorizations_;
  // A singular Jacobian (not square in effect): the smallest pivot of the LU against the largest
  // (SparseLu::factor).
  lu_current_ = cur_->lu.factor(J);
  return lu_current_;
}

ActiveSetTry ActiveSetStep::iterate(bool reuse) {
  const discretization::FesdInterval& iv = *iv_;
  const int m = nlp_.num_constraints();
  const std::vector<int>& free = cur_->free;
  const std::vector<int>& equal = cur_->equal;
  const int n_free = static_cast<int>(free.size());
  const Eigen::Map<Eigen::VectorXd> F(F_.data(), n_free), dz(dz_.data(), n_free);
  ActiveSetTry out;
  // Newton's method: a Jacobian of every iterate. With `reuse`, simplified Newton with the LU
  // held until it stops contracting (or kMaxStale iterations), then Newton's method.
  bool full = !reuse;
  int stale = 0;         // simplified-Newton iterations so far
  double dz_before = 0;  // ||dz|| of the iteration before (the contraction test)
  for (int it = 0; it < kMaxNewton; ++it) {
    if (!nlp_.eval_g(w_.data(), g_.data())) return out;
    for (int i = 0; i < m; ++i) F_[i] = g_[i] - nlp_.g_lb[i];
    for (std::size_t e = 0; e < equal.size(); ++e)
      F_[m + e] = w_[iv.h(equal[e])] - w_[iv.h(equal[e] - 1)];
    double w_max = 1;
    for (int j : free) w_max = std::max(w_max, std::abs(w_[j]));
    if (F.lpNorm<Eigen::Infinity>() <= 1e-13 * w_max) {
      out.converged = true;
      return out;
    }
    if (full && !factor()) return out;
    for (int i = 0; i < n_free; ++i) dz_[i] = -F_[i];
    cur_->lu.solve(dz_.data());
    ++out.iterations;
    ++iterations_;
    if (!dz.allFinite()) return out;
    for (int i = 0; i < n_free; ++i) w_[free[i]] += dz_[i];
    const double dz_norm = dz.lpNorm<Eigen::Infinity>();
    // A step below round-off counts as converged with a Jacobian of this iterate only (with an
    // older one the remaining error is not bounded by the step).
    if (full && dz_norm <= 1e-14 * w_max) {
      out.converged = true;
      return out;
    }
    // The simplified iteration contracts too slowly: Newton's method from the next iterate.
    if (!full)
      full = ++stale >= kMaxStale || (dz_before > 0 && dz_norm > kChordContraction * dz_before);
    dz_before = dz_norm;
  }
  return out;
}

bool ActiveSetStep::same_shape(const Shape& sh, const Sets& active,
                               const std::vector<nlp::Bound>& extra) {
  if (active != sh.active || extra.size() != sh.extra.size()) return false;
  for (std::size_t i = 0; i < extra.size(); ++i)
    if (extra[i].var != sh.extra[i].var || extra[i].lb != sh.extra[i].lb ||
        extra[i].ub != sh.extra[i].ub)
      return false;
  return true;
}

void ActiveSetStep::use_shape(const Sets& active, const std::vector<nlp::Bound>& extra) {
  ++use_clock_;
  if (cur_ != nullptr && same_shape(*cur_, active, extra)) {
    cur_->last_use = use_clock_;
    return;
  }
  // Another shape: the LU held was of the one before (a kept shape's LU is of an older step, not
  // used for simplified Newton; its KLU workspaces and pivot order are reused by factor()).
  lu_current_ = false;
  Shape* sh = nullptr;
  for (const auto& kept : shapes_)
    if (same_shape(*kept, active, extra)) {
      sh = kept.get();
      break;
    }
  if (sh == nullptr) {
    if (static_cast<int>(shapes_.size()) < kMaxShapes) {
      shapes_.push_back(std::make_unique<Shape>());
      sh = shapes_.back().get();
    } else {
      sh = std::min_element(shapes_.begin(), shapes_.end(), [](const auto& a, const auto& b) {
             return a->last_use < b->last_use;
           })->get();
    }
    restrict_to(*sh, active, extra);
  }
  cur_ = sh;
  cur_->last_use = use_clock_;
}

void ActiveSetStep::restrict_to(Shape& sh, const Sets& active,
                                const std::vector<nlp::Bound>& extra) {
  const discretization::FesdInterval& iv = *iv_;
  const int N = iv.N_FE();
  sh.active = active;
  sh.extra = extra;
  std::vector<double>& lb = sh.lb;
  std::vector<double>& ub = sh.ub;
  lb = nlp_.x_lb;
  ub = nlp_.x_ub;
  for (const nlp::Bound& bd : iv.active_set_bounds(active)) {
    lb[bd.var] = bd.lb;
    ub[bd.var] = bd.ub;
  }
  // Schemes that are not stiffly accurate (Gauss-Legendre): the end point x_{n+1} of an element is
  // not a stage, and its boundary LP (33) has its own lambda_end, mu_end. In a sliding element
  // (m >= 2 regions of subsystem k active) lambda_end = 0 for all m would make the LP at x_{n+1}
  // m rows in one unknown mu_end: c(x_{n+1}) = 0 on top of c = 0 at the n_s stages, which already
  // imply it (for an affine c exactly: c(X_s) = 0 for all s and c(x_n) = 0 give grad c . V_s = 0,
  // A being regular, so c(x_{n+1}) = 0). As at the step start (FesdInterval::active_set_bounds),
  // all but the first of them stay free there, without a sign bound (O(h^p) of either sign for a
  // curved surface), where the element after has the same regions of k (or n is the last element).
  // At an entry (the element after slides, this one does not) the fixed lambda is the switch
  // condition and stays.
  for (int n = 0; n < N; ++n) {
    if (iv.lambda_end(n, 0) < 0 || iv.lambda_end(n, 0) == iv.lambda(n, iv.n_s() - 1, 0)) continue;
    for (int k = 0; k < model_.n_sys(); ++k) {
      const int first = model_.region_offset(k), end = model_.region_offset(k + 1);
      const auto in_k = [&](const std::vector<int>& a) {
        return std::count_if(a.begin(), a.end(), [&](int r) { return r >= first && r < end; });
      };
      if (in_k(active[n]) < 2) continue;
      bool same_after = true;
      if (n + 1 < N)
        for (int r = first; r < end; ++r)
          same_after = same_after &&
                       discretization::has(active[n], r) == discretization::has(active[n + 1], r);
      if (!same_after) continue;
      bool first_kept = false;
      for (int r : active[n]) {
        if (r < first || r >= end) continue;
        if (first_kept) {
          lb[iv.lambda_end(n, r)] = -nlp::kInf;
          ub[iv.lambda_end(n, r)] = nlp::kInf;
        }
        first_kept = true;
      }
    }
  }
  for (const nlp::Bound& bd : extra) {  // a sliding exit: theta_r = 0 at the boundary
    lb[bd.var] = bd.lb;
    ub[bd.var] = bd.ub;
  }
  std::vector<int>& free = sh.free;
  std::vector<int>& fixed = sh.fixed;
  std::vector<int>& col_of = sh.col_of;
  std::vector<int>& equal = sh.equal;
  free.clear();
  fixed.clear();
  col_of.assign(lb.size(), -1);
  for (std::size_t j = 0; j < lb.size(); ++j) {
    if (lb[j] < ub[j]) {
      col_of[j] = static_cast<int>(free.size());
      free.push_back(static_cast<int>(j));
    } else {
      fixed.push_back(static_cast<int>(j));
    }
  }
  // h_n = h_{n-1} where the active set does not change; at a switch the boundary's length is
  // free and the switch condition takes its row: lambda = 0 of both regions there (a crossing,
  // a sliding entry; fixed above), or theta_r = 0 of the leaving region (an exit: the pin).
  equal.clear();
  for (int n = 1; n < N; ++n)
    if (active[n] == active[n - 1]) equal.push_back(n);
  const int m = nlp_.num_constraints();
  const int n_free = static_cast<int>(free.size());
  sh.square = m + static_cast<int>(equal.size()) == n_free;
  if (!sh.square) return;  // not square: newton() says so
  const auto n2 = static_cast<std::size_t>(n_free) * static_cast<std::size_t>(n_free);
  if (J_.size() < n2) J_.resize(n2);
  if (F_.size() < static_cast<std::size_t>(n_free)) {
    F_.resize(static_cast<std::size_t>(n_free));
    dz_.resize(static_cast<std::size_t>(n_free));
  }
  const std::vector<int>& rows = nlp_.jac_rows();
  const std::vector<int>& cols = nlp_.jac_cols();
  std::vector<std::pair<int, int>>& jac_map = sh.jac_map;
  jac_map.clear();
  sh.constant.clear();
  for (std::size_t e = 0; e < jac_.size(); ++e)
    if (const int c = col_of[cols[e]]; c >= 0)
      jac_map.emplace_back(static_cast<int>(e), rows[e] + n_free * c);
  std::vector<int> pattern;
  pattern.reserve(jac_map.size() + 2 * equal.size());
  for (const auto& [e, pos] : jac_map) pattern.push_back(pos);
  for (std::size_t e = 0; e < equal.size(); ++e) {
    const int row = m + static_cast<int>(e);
    for (const auto& [col, value] :
         {std::pair{col_of[iv.h(equal[e])], 1.0}, std::pair{col_of[iv.h(equal[e] - 1)], -1.0}}) {
      sh.constant.emplace_back(row + n_free * col, value);
      pattern.push_back(row + n_free * col);
    }
  }
  sh.lu.analyze(n_free, std::move(pattern));
}

ActiveSetStep::Violation ActiveSetStep::check_signs(const Sets& active) const {
  const discretization::FesdInterval& iv = *iv_;
  const int N = iv.N_FE(), n_s = iv.n_s(), n_th = model_.n_theta();
  Violation v;
  also_.clear();
  const double h_tol = 1e-12 * T_;
  for (int n = 0; n < N; ++n) {
    const double hn = w_[iv.h(n)];
    if (hn < nlp_.x_lb[iv.h(n)] - h_tol || hn > nlp_.x_ub[iv.h(n)] + h_tol) {
      v.bad = true;
      return v;
    }
  }
  // In time order: theta >= 0 on the active set (a failure in a sliding set is an exit of that
  // region; in a set with one region of its subsystem theta is 1), lambda >= 0 off it (an entry);
  // per region the last point where its sign held.
  // Before the first stage: theta at the step start (the end of the step before).
  t_ok_.assign(n_th, 0.0);
  val_ok_.assign(n_th, 0.0);
  std::vector<double>& t_ok = t_ok_;
  std::vector<double>& val_ok = val_ok_;
  for (int r : active[0]) val_ok[r] = std::max(theta_start_[r], 0.0);
  const auto violated = [&](int r, double t, double val, bool exit) {
    v.r = r;
    v.exit = exit;
    v.t_ok = t_ok[r];
    v.val_ok = val_ok[r];
    v.t_bad = t;
    v.val_bad = val;
  };
  double t_n = 0;
  for (int n = 0; n < N; ++n) {
    const double hn = w_[iv.h(n)];
    const auto& points = iv.lambda_points(n);
    for (std::size_t q = 0; q < points.size(); ++q) {
      const int qi = static_cast<int>(q);
      const double t = q == 0 ? t_n : qi <= n_s ? t_n + tab_.c(qi - 1) * hn : t_n + hn;
      if (qi >= 1 && qi <= n_s)
        for (int r : active[n]) {
          const double th = w_[iv.theta(n, qi - 1, r)];
          if (th < -kSignTol) {
            violated(r, t, th, true);
            return v;
          }
          t_ok[r] = t;
          val_ok[r] = th;
        }
      if (!iv.point_signed(n, qi)) continue;
      for (int r = 0; r < n_th; ++r) {
        if (discretization::has(active[n], r)) continue;
        const double lam = w_[points[q][r]];
        if (lam < -kSignTol) {
          violated(r, t, lam, false);
          // the other regions of r's subsystem that fail at the same point
          const int k = subsystem_of(model_, r);
          for (int j = r; j < model_.region_offset(k + 1); ++j)
            if (!discretization::has(active[n], j) && w_[points[q][j]] < -kSignTol)
              also_.push_back(j);
          return v;
        }
        t_ok[r] = t;
        val_ok[r] = lam;
      }
    }
    t_n += hn;
  }
  return v;
}

void ActiveSetStep::boundaries_for(double ts) {
  const int N = iv_->N_FE();
  std::vector<int>& out = bounds_;
  out.clear();
  // The switch at the step's start (within 1e-9 T: an exit of a region whose theta reached 0 at
  // the end of the step before), not after an element of length ~0.
  if (ts <= 1e-9 * T_) {
    out.push_back(0);
    return;
  }
  const double h0 = T_ / N, lo = nlp_.x_lb[iv_->h(0)], hi = nlp_.x_ub[iv_->h(0)];
  const auto within = [&](double h) { return h >= lo && h <= hi; };
  std::vector<std::pair<double, int>>& cost = cost_;
  cost.clear();
  for (int b = 1; b < N; ++b) {
    const double before = ts / b, after = (T_ - ts) / (N - b);
    if (!within(before) || !within(after)) continue;
    cost.push_back({b * (before - h0) * (before - h0) + (N - b) * (after - h0) * (after - h0), b});
  }
  std::sort(cost.begin(), cost.end());
  for (const auto& [c, b] : cost) out.push_back(b);
  // A switch at (or just after) the step start: the whole step in the new active set.
  if (ts < h0) out.push_back(0);
}

void ActiveSetStep::switched_guess(const std::vector<double>& w_pred,
                                   const std::vector<int>& before, const std::vector<int>& after,
                                   int b, double ts) {
  const discretization::FesdInterval& iv = *iv_;
  const int N = iv.N_FE(), n_s = iv.n_s();
  w_ = w_pred;
  for (int n = 0; n < N; ++n) w_[iv.h(n)] = b == 0 ? T_ / N : n < b ? ts / b : (T_ - ts) / (N - b);
  std::vector<int>& in = sw_in_;
  std::vector<int>& out = sw_out_;
  in.clear();
  out.clear();
  for (int r : after)
    if (!discretization::has(before, r)) in.push_back(r);
  for (int r : before)
    if (!discretization::has(after, r)) out.push_back(r);
  if (in.empty() && out.size() == 1) {
    // A sliding exit: theta of the leaving region is shared among the others of its subsystem.
    const int r_out = out[0], k = subsystem_of(model_, r_out);
    for (int n = b; n < N; ++n)
      for (int s = 0; s < n_s; ++s) {
        double rest = 0;
        for (int r : after)
          if (subsystem_of(model_, r) == k) rest += w_[iv.theta(n, s, r)];
        const double scale = rest > 0 ? 1 / rest : 0;
        for (int r : after)
          if (subsystem_of(model_, r) == k) w_[iv.theta(n, s, r)] *= scale;
        w_[iv.theta(n, s, r_out)] = 0;
      }
    return;
  }
  if (in.size() != 1 || out.size() > 1) {
    // Several regions in or out (co-dimension 2): theta uniform on the new set of each subsystem
    // that changes.
    const auto uniform = [&](int r) {
      const int k = subsystem_of(model_, r);
      int m = 0;
      for (int j : after) m += subsystem_of(model_, j) == k;
      for (int n = b; n < N; ++n)
        for (int s = 0; s < n_s; ++s)
          for (int j = model_.region_offset(k); j < model_.region_offset(k + 1); ++j)
            w_[iv.theta(n, s, j)] = discretization::has(after, j) ? 1.0 / std::max(m, 1) : 0.0;
    };
    for (int r : in) uniform(r);
    for (int r : out) uniform(r);
    return;
  }
  const int r_in = in[0], k = subsystem_of(model_, r_in);
  const int r_out = out.size() == 1 ? out[0] : -1;
  for (int n = b; n < N; ++n) {
    // theta moves to the entering region (shared with the old one when sliding).
    for (int s = 0; s < n_s; ++s) {
      double& th_in = w_[iv.theta(n, s, r_in)];
      if (r_out >= 0) {
        th_in = w_pred[iv.theta(n, s, r_out)];
        w_[iv.theta(n, s, r_out)] = 0;
      } else {
        for (int r : before)
          if (subsystem_of(model_, r) == k) th_in = w_[iv.theta(n, s, r)] *= 0.5;
      }
    }
    // lambda and mu at the element's stages and end: g_out - g_in = -lambda_in of the prediction.
    const auto& points = iv.lambda_points(n);
    for (std::size_t q = 1; q < points.size(); ++q) {
      const int qi = static_cast<int>(q);
      const int mu = qi <= n_s ? iv.mu(n, qi - 1, k) : iv.mu_end(n, k);
      const double lam_in = w_pred[points[q][r_in]];
      w_[points[q][r_in]] = 0;
      if (r_out < 0) continue;
      w_[points[q][r_out]] = -lam_in;
      if (mu >= 0) w_[mu] += lam_in;
    }
  }
}

}  // namespace fesd::integrator
