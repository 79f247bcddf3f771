// The FESD integrator: one FesdInterval NLP, built once and re-solved for every step with the new
// start state (fixed variables) and a shifted initial guess.
#include "fesd/integrator.hpp"
#include "core/util.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/option_registry.hpp"
#include "dcs/step.hpp"
#include "dcs/stewart.hpp"
#include "discretization/fesd_interval.hpp"
#include "fesd/error.hpp"
#include "integrator/active_set.hpp"
#include "integrator/sensitivity.hpp"
#include "integrator/theta_guess.hpp"
#include "mpcc/problem.hpp"
#include "nlp/nlp_solver.hpp"

namespace fesd {
namespace {

using util::check_finite;
using util::gather;
using util::seconds_since;

using Clock = std::chrono::steady_clock;
/// Appends the N_FE elements of a step (NLP point w) to the result; advances t.
void append_step(IntegratorResult& res, const Pss& model, const discretization::FesdInterval& iv,
                 const Tableau& tab, const std::vector<double>& w, double& t) {
  const int n_x = model.n_x(), n_th = model.n_theta();
  for (int n = 0; n < iv.N_FE(); ++n) {
    const double hn = w[iv.h(n)];
    const std::vector<int> active = iv.active_set(w.data(), n);
    for (int s = 0; s < iv.n_s(); ++s) {
      res.t_stage.push_back(t + tab.c(s) * hn);
      res.x_stage.push_back(gather(w, iv.X(n, s, 0), n_x));
      res.theta.push_back(gather(w, iv.theta(n, s, 0), n_th));
      discretization::append_stage_multipliers(iv, model, w, n, s, res);
    }
    if (!res.active_set.empty() && res.active_set.back() != active)
      res.switches.push_back(
          {t, static_cast<int>(res.h.size()) - 1, res.active_set.back(), active});
    res.active_set.push_back(active);
    res.h.push_back(hn);
    t += hn;
    Eigen::VectorXd xn(n_x);
    for (int i = 0; i < n_x; ++i) xn[i] = w[iv.x(n + 1, i)];
    res.t.push_back(t);
    res.x.push_back(xn);
  }
}

/// The MPCC of one integration step: built once per step length and element count, re-solved
/// for every step with new fixed inputs (start state) and a new guess.
struct StepProblem {
  mpcc::Problem mpcc;
  discretization::IntervalInputs in;
  std::unique_ptr<discretization::FesdInterval> iv;
};

std::unique_ptr<StepProblem> build_step_problem(const Pss& model, const Tableau& tab,
                                                const DiscretizationOptions& d, double T_step,
                                                MpccMode mpcc_mode, const Eigen::VectorXd& u,
                                                const Eigen::VectorXd& p) {
  auto s = std::make_unique<StepProblem>();
  nlp::BlockNlp& nlp = s->mpcc.nlp();
  s->in = integrator::add_step_inputs(nlp, model, d.use_fesd, T_step, d.dcs_mode);
  s->iv = std::make_unique<discretization::FesdInterval>(model, tab, d);
  s->iv->build(nlp, s->in);
  s->mpcc.add_complementarity(s->iv->groups(), s->iv->residual_pairs());
  s->mpcc.relax(mpcc_mode);
  s->mpcc.fix(s->in.q, u);
  s->mpcc.fix(s->in.p, p);
  return s;
}

/// The input rules of integrate(): thrown as fesd::Error before any computation.
void check_input(const Pss& model, const Eigen::VectorXd& x0, double T_sim, int N_sim,
                 const IntegratorOptions& options, const Eigen::VectorXd& u,
                 const Eigen::VectorXd& p) {
  check(options);
  if (model.n_x() < 1) throw InvalidModel("model: empty (n_x = 0)");
  if (x0.size() != model.n_x())
    throw InvalidModel(fmt::format("x0 has {} entries, expected n_x = {}", x0.size(), model.n_x()));
  check_finite(x0, "x0");
  if (const auto e = registry::validate_simulation(T_sim, N_sim); !e.empty())
    throw InvalidOption(registry::join(e));
  if (auto e = discretization::FesdInterval::block_size_errors(model, options.discretization);
      !e.empty())
    throw InvalidModel(registry::join(e));
  if (u.size() != model.n_u())
    throw InvalidModel(fmt::format("u has {} entries, expected n_u = {}", u.size(), model.n_u()));
  if (p.size() != model.n_p())
    throw InvalidModel(fmt::format("p has {} entries, expected n_p = {}", p.size(), model.n_p()));
  check_finite(u, "u");
  check_finite(p, "p");
  if (const auto e = integrator::theta_guess_errors(model, options); !e.empty())
    throw InvalidOption(registry::join(e));
}

/// One run of integrate(): the step problems, the solver, the guess carried from step to step,
/// the result being filled, and the retry policy.
class Integrator {
 public:
  Integrator(const Pss& model, const Eigen::VectorXd& x0, double T_sim, int N_sim,
             const IntegratorOptions& options, Eigen::VectorXd u, Eigen::VectorXd p,
             Clock::time_point t_start)
      : model_(model),
        options_(options),
        d_(options.discretization),
        tab_(make_tableau(d_.rk_scheme, d_.n_s)),
        T_step_(T_sim / N_sim),
        N_sim_(N_sim),
        u_(std::move(u)),
        p_(std::move(p)),
        levels_(kMaxSplit + 1),
        x_(x0) {
    res_.summary.warnings = warnings(options.homotopy);
    settings_cannot_reach_ = !res_.summary.warnings.empty();
    for (auto& w : nlp::warnings(options.nlp)) res_.summary.warnings.push_back(std::move(w));
    // Initial guess of the first step: the LP at x0 (then the last stage of the step before).
    guess_ = dcs::solve_start(model_, d_.dcs_mode, x0, p_);
    // IntegratorOptions::theta_guess replaces the LP's theta; lambda and mu stay the LP's (on a
    // switching surface, where the guess matters, the g_i of the regions meeting there are equal,
    // so their lambda_i = 0 either way).
    if (options.theta_guess.size() > 0) guess_.theta = options.theta_guess;
    guess_xdot_ = xdot_at(x0, guess_.theta);
    // The standard method (use_fesd = false) has no free lengths to carry a switch: it always
    // runs on the homotopy path, whatever step_solver says.
    // The step form always runs on the homotopy path too (the active-set path's square system is
    // written in Stewart's form).
    if (options.step_solver == StepSolver::ActiveSet && d_.use_fesd &&
        d_.dcs_mode == DcsMode::Stewart)
      active_ = std::make_unique<integrator::ActiveSetStep>(model_, tab_, d_, T_step_, u_, p_);
    StepProblem& first = level(0, 0);
    first.mpcc.finalize();
    res_.summary.n_variables = first.mpcc.num_variables();
    res_.summary.n_constraints = first.mpcc.num_constraints();
    res_.summary.setup_s = seconds_since(t_start);
    solver_ = nlp::make_solver(options_.nlp);
    res_.t.push_back(0.0);
    res_.x.push_back(x0);
    if (options.sensitivities) {
      Sensitivities& sens = res_.sensitivities;
      sens.requested = sens.available = true;
      sens.x0 = Eigen::MatrixXd::Identity(model_.n_x(), model_.n_x());
      sens.u = Eigen::MatrixXd::Zero(model_.n_x(), model_.n_u());
      sens.p = Eigen::MatrixXd::Zero(model_.n_x(), model_.n_p());
      if (d_.dcs_mode == DcsMode::Step)
        sensitivity_unavailable("the square system is written in Stewart's form (dcs_mode = step)");
    }
  }

  /// Step `step` (0-based) of N_sim: advances over it with the retry policy, reports progress.
  bool step(int step) {
    careful_ = false;
    const int newton_before = res_.summary.newton_iterations;
    const bool by_newton = active_ && active_set_step();
    bool ok = by_newton;
    if (!ok) {
      ++res_.summary.homotopy_path_steps;
      ok = advance(0);
    }
    if (ok) res_.step_path.push_back(by_newton ? StepSolver::ActiveSet : StepSolver::Homotopy);
    if (options_.on_step) {
      StepProgress p{step + 1, N_sim_, t_, 0, 0, 0.0, Status::Success};
      if (by_newton) {
        p.active_set_path = true;
        p.newton_iterations = res_.summary.newton_iterations - newton_before;
      } else {
        p.nlps = static_cast<int>(last_.rows.size());
        p.nlp_iterations = last_.nlp_iterations;
        p.comp_residual = last_.comp_residual;
        p.status = last_.status;
      }
      options_.on_step(p);
    }
    if (!ok) fail(step);
    return ok;
  }

  IntegratorResult finish(double wall_s) {
    if (res_.status == Status::NotRun) {
      res_.status = Status::Success;
      res_.message = std::string(describe(Status::Success));
    } else if (res_.sensitivities.available) {
      sensitivity_unavailable("the integration failed");
    }
    res_.summary.wall_s = wall_s;
    return std::move(res_);
  }

 private:
  // ---- the active-set path (step_solver = active_set; docs/active-set.md) ----

  /// The step by Newton's method on the square system of the active set predicted from the end
  /// of the step before (the LP at x0 for the first), with a switch located where the signs
  /// fail. Where no consistent active set is found for the whole step (e.g. two switches closer
  /// together than N_FE element boundaries allow: a short slide of the relay), the step is solved
  /// as two half steps of N_FE elements each, and each of those that fails as two quarter steps,
  /// every piece on the active-set path. False: some piece failed too; the homotopy takes the
  /// whole step (nothing of it is kept).
  bool active_set_step() {
    const auto t0 = Clock::now();
    Summary& sum = res_.summary;
    integrator::ActiveSetStep& as = *active_;
    // The whole step (no copies: most steps end here), then its pieces.
    bool ok = res_.active_set.empty() ? as.solve(x_, lp_active_set(guess_), guess_, guess_xdot_)
                                      : as.solve(x_, res_.active_set.back(), guess_, guess_xdot_);
    sum.newton_iterations += as.newton_iterations();
    sum.newton_factorizations += as.factorizations();
    sum.active_set_tries += as.tries();
    pieces_.clear();
    if (!ok) {
      PieceStart start{x_, res_.active_set.empty() ? lp_active_set(guess_) : res_.active_set.back(),
                       guess_, guess_xdot_};
      ok = solve_pieces(1, start) && solve_pieces(1, start);
    }
    sum.active_set_s += seconds_since(t0);
    if (!ok) return false;
    ++sum.active_set_path_steps;
    last_ = {};
    last_.status = Status::Success;
    last_.active_set_fixed = true;
    res_.homotopy.emplace_back();  // no NLPs: the step's homotopy table is empty
    if (pieces_.empty()) {
      if (res_.sensitivities.available) {
        integrator::StepSensitivity s;
        std::string why;
        if (as.sensitivity(s, why)) {
          jump_at_step_start(as.interval(), as.solution());
          chain(s);
        } else {
          sensitivity_unavailable(why);
        }
      }
      last_.comp_residual =
          mpcc::comp_residual(as.solution().data(), as.interval().residual_pairs());
      commit(as.interval(), as.solution(), last_.comp_residual, {});
      return true;
    }
    for (const Piece& piece : pieces_) {
      const discretization::FesdInterval& iv = active_level(piece.level).interval();
      if (res_.sensitivities.available) {
        if (piece.sens_why.empty()) {
          jump_at_step_start(iv, piece.w);
          chain(piece.sens);
        } else {
          sensitivity_unavailable(piece.sens_why);
        }
      }
      const double comp = mpcc::comp_residual(piece.w.data(), iv.residual_pairs());
      last_.comp_residual = std::max(last_.comp_residual, comp);
      commit(iv, piece.w, comp, {});
    }
    return true;
  }

  /// Where a piece of a step starts: the state, the predicted active set, the algebraic guess.
  struct PieceStart {
    Eigen::VectorXd x;
    std::vector<int> predicted;
    dcs::LpSolution lp;
    Eigen::VectorXd xdot;
  };
  /// A solved piece of a step on the active-set path: level k (length T_step / 2^k), solution w.
  struct Piece {
    int level = 0;
    std::vector<double> w;
    integrator::StepSensitivity sens;  // with IntegratorOptions::sensitivities
    std::string sens_why;              // why sens is not available (empty: it is)
  };

  /// The square-system solver of level k (steps of length T_step / 2^k), created when first used.
  integrator::ActiveSetStep& active_level(int k) {
    if (k == 0) return *active_;
    std::unique_ptr<integrator::ActiveSetStep>& a = active_split_[static_cast<std::size_t>(k - 1)];
    if (!a)
      a = std::make_unique<integrator::ActiveSetStep>(model_, tab_, d_, T_step_ / (1 << k), u_, p_);
    return *a;
  }

  /// Solves a piece of level k from `start` (advanced to its end on success) into pieces_; where
  /// that fails, its two halves (down to level kMaxActiveSplit).
  bool solve_pieces(int k, PieceStart& start) {
    integrator::ActiveSetStep& as = active_level(k);
    const bool ok = as.solve(start.x, start.predicted, start.lp, start.xdot);
    Summary& sum = res_.summary;
    sum.newton_iterations += as.newton_iterations();
    sum.newton_factorizations += as.factorizations();
    sum.active_set_tries += as.tries();
    if (ok) {
      const discretization::FesdInterval& iv = as.interval();
      const std::vector<double>& w = as.solution();
      pieces_.push_back({k, w, {}, {}});
      if (res_.sensitivities.available &&
          !as.sensitivity(pieces_.back().sens, pieces_.back().sens_why) &&
          pieces_.back().sens_why.empty())
        pieces_.back().sens_why = "the square system is singular";
      const int last = iv.N_FE() - 1;
      for (int i = 0; i < model_.n_x(); ++i) start.x[i] = w[iv.x(last + 1, i)];
      start.predicted = iv.active_set(w.data(), last);
      last_stage_guess(iv, w, start.lp, start.xdot);
      return true;
    }
    if (k == kMaxActiveSplit) return false;
    return solve_pieces(k + 1, start) && solve_pieces(k + 1, start);
  }

  /// The active regions of the LP solution at the start (theta above lambda and 1e-6), the
  /// stage-wise rule of FesdInterval::active_set().
  std::vector<int> lp_active_set(const dcs::LpSolution& lp) const {
    std::vector<int> a;
    for (int r = 0; r < model_.n_theta(); ++r)
      if (lp.theta[r] >
          std::max(std::abs(lp.lambda[r]), discretization::FesdInterval::kActiveThetaTol))
        a.push_back(r);
    return a;
  }

  // ---- the retry policy ----

  /// Advances over one step of level k (length T_step / 2^k): N_FE elements; where that fails
  /// (FESD only), 2 N_FE elements; where that fails too, two half steps (at most kMaxSplit
  /// times halved).
  bool advance(int k) {
    if (solve_step(k, 0)) return true;
    if (!d_.use_fesd || !retry_can_help(last_)) return false;
    return retry_refined(k) || retry_split(k);
  }

  /// The same step with 2 N_FE elements: two switches closer together than a step need two free
  /// element boundaries between them.
  bool retry_refined(int k) {
    ++res_.summary.refine_attempts;
    if (!solve_step(k, 1)) return false;
    ++res_.summary.refined_steps;
    return true;
  }

  /// The step as two half steps of N_FE elements each (each with the whole policy again).
  bool retry_split(int k) {
    if (k == kMaxSplit) return false;
    ++res_.summary.split_steps;
    return advance(k + 1) && advance(k + 1);
  }

  /// Solves one step of level (k, r) from x_: the homotopy; where it fails, the same NLPs all
  /// solved tight, then the sparse cross complementarity (28); on success sliding exits pinned,
  /// the step appended to the result and x_, t_, the guess advanced.
  bool solve_step(int k, int r) {
    StepProblem& sp = level(k, r);
    set_start(sp);
    // Once an attempt of this step has failed, every retry solves all its NLPs to ipopt.tol:
    // loosely solved early NLPs (intermediate_tol) can lead the homotopy astray in hard steps,
    // e.g. one starting on the co-dimension-2 sliding set of OCP (61) (docs/formulation.md).
    HomotopyOptions hopt = options_.homotopy;
    if (careful_) hopt.intermediate_tol = 0;
    std::vector<HomotopyRow> rows;
    std::vector<int> unlocated;  // regions whose exit in this step could not be pinned
    StepProblem* solved = &sp;   // the problem whose solution is the step
    mpcc::HomotopyResult hr = homotopy(sp, hopt, rows);
    rescue(sp, hr, rows, unlocated);
    if (retry_can_help(hr) && hopt.intermediate_tol > 0) {
      hr = retry_tight(sp, hopt, rows);
      rescue(sp, hr, rows, unlocated);
    }
    if (hr.status != Status::Success) careful_ = true;
    if (retry_can_help(hr) && can_fall_back()) {
      solved = &fallback(k, r, sp);
      hr = retry_sparse(*solved, hopt, rows);
      rescue(*solved, hr, rows, unlocated);
    }
    if (hr.status == Status::Success && !hr.active_set_fixed && solved->iv->can_pin_exits())
      unlocated = resolve_fixed(*solved, hr, rows);
    res_.homotopy.push_back(std::move(rows));
    last_ = hr;
    if (hr.status != Status::Success) {
      failed_ = solved;
      return false;
    }
    if (res_.sensitivities.available) homotopy_sensitivity(k, r, *solved);
    commit(*solved->iv, solved->mpcc.solution(), hr.comp_residual, unlocated);
    return true;
  }

  /// Appends a solved step (NLP point w of the interval iv) to the result, with its held
  /// switches and the exits whose pin failed.
  void commit(const discretization::FesdInterval& iv, const std::vector<double>& w,
              double comp_residual, const std::vector<int>& unlocated) {
    res_.summary.max_comp_residual = std::max(res_.summary.max_comp_residual, comp_residual);
    const std::size_t first_switch = res_.switches.size();
    const double t_step = t_;
    report_held_switches(iv, w, t_step);
    const std::size_t first_element = res_.active_set.size();
    accept(iv, w);
    if (res_.sensitivities.available) check_single_changes(first_element, t_step);
    jump_at_start_ = false;
    // An exit at the end of the step before, whose pin failed there, is recorded here (the switch
    // at a step boundary belongs to the step that starts at it).
    if (!carried_unlocated_.empty()) mark_switches(first_switch, carried_unlocated_);
    carried_unlocated_ = unlocated;
    if (!unlocated.empty()) mark_unlocated(first_switch, t_step, unlocated);
  }

  /// A homotopy whose NLPs converged but whose complementarity residual stayed above
  /// complementarity_tol (e.g. sigma_N above it, nosnoc's settings): the re-solve with the active
  /// set fixed (fix_active_set) makes complementarity exact, and the step succeeds after all.
  void rescue(StepProblem& sp, mpcc::HomotopyResult& hr, std::vector<HomotopyRow>& rows,
              std::vector<int>& unlocated) {
    if (hr.status != Status::ComplementarityNotMet || !options_.homotopy.fix_active_set ||
        !sp.iv->can_pin_exits())
      return;
    unlocated = resolve_fixed(sp, hr, rows);
    if (hr.status == Status::Success) ++res_.summary.rescued_steps;
  }

  /// Whether another attempt of the step can reach what this one did not: not when its NLPs
  /// converged and only complementarity_tol was missed while the settings cannot reach it (the
  /// homotopy's last sigma above it, warnings(HomotopyOptions)): every retry ends at the same
  /// sigma.
  bool retry_can_help(const mpcc::HomotopyResult& hr) const {
    if (hr.status == Status::Success) return false;
    return !(hr.status == Status::ComplementarityNotMet && settings_cannot_reach_);
  }

  /// The same NLPs from the same start, each solved to ipopt.tol (no intermediate_tol).
  mpcc::HomotopyResult retry_tight(StepProblem& sp, HomotopyOptions& hopt,
                                   std::vector<HomotopyRow>& rows) {
    careful_ = true;
    hopt.intermediate_tol = 0;
    return homotopy(sp, hopt, rows);
  }

  /// The same step with the sparse cross complementarity (28), which the homotopy follows more
  /// reliably (docs/benchmarks.md); same variables, same start.
  mpcc::HomotopyResult retry_sparse(StepProblem& fb, const HomotopyOptions& hopt,
                                    std::vector<HomotopyRow>& rows) {
    ++res_.summary.fallback_steps;
    return homotopy(fb, hopt, rows);
  }

  // scholtes_eq and fischer_burmeister impose one equation per pair: with the sparse form (28)
  // a theta gets more equations than it has freedom (IPOPT: Not_Enough_Degrees_Of_Freedom), so
  // the sparse retry is useless for them.
  bool can_fall_back() const {
    const MpccMode mode = options_.homotopy.mpcc_mode;
    return d_.use_fesd && d_.cross_comp != CrossComp::Sparse && mode != MpccMode::ScholtesEq &&
           mode != MpccMode::FischerBurmeister;
  }

  /// The bounds of the re-solve with the active sets of the current solution fixed and its
  /// sliding exits pinned (when pin_sliding_exits), which are returned in `pins`: the exits
  /// inside the step (FesdInterval::exits_to_pin) and one at the step start where the step
  /// before ended with the leaving region still active (step_start_exits).
  std::vector<nlp::Bound> fixed_set_bounds(
      StepProblem& sp, std::vector<discretization::FesdInterval::ExitPin>& pins) {
    const discretization::FesdInterval& iv = *sp.iv;
    const std::vector<double>& w = sp.mpcc.solution();
    pins.clear();
    if (d_.pin_sliding_exits) pins = iv.exits_to_pin(w.data(), /*control_jump_at_end=*/false);
    const double h0_min = d_.pin_sliding_exits ? step_start_exits(iv, w, pins) : 0.0;
    std::vector<nlp::Bound> bounds = iv.pin_bounds(w.data(), pins);
    const int h0 = iv.h(0);
    // A step-start exit: element 0 in [delta / 2, 2 delta] around the predicted exit time delta
    // (its guess moves into it): from the homotopy's element length, often 50x the exit's, IPOPT
    // needs ~90 iterations and may stop at its acceptable level (belt, N_sim = 240: exit time
    // off by 4.9e-6 -> 6.3e-8).
    if (h0_min > 0 && h0_min < sp.mpcc.upper(h0))
      bounds.push_back(
          {h0, std::max(sp.mpcc.lower(h0), h0_min), std::min(sp.mpcc.upper(h0), 4 * h0_min)});
    return bounds;
  }

  /// The re-solve of a solved step with its active set fixed (HomotopyOptions::fix_active_set;
  /// docs/formulation.md): every element keeps the active set the homotopy found, the sliding
  /// exits (pin_sliding_exits) are pinned in the same solve: the exits inside the step
  /// (FesdInterval::exits_to_pin) and one at its start where the step before ended with the
  /// leaving region still active (step_start_exits). If it fails, the homotopy's solution stays.
  /// On success hr's complementarity residual becomes the re-solve's. Returns the regions whose
  /// exit could not be pinned.
  std::vector<int> resolve_fixed(StepProblem& sp, mpcc::HomotopyResult& hr,
                                 std::vector<HomotopyRow>& rows) {
    std::vector<discretization::FesdInterval::ExitPin> pins;
    const std::vector<nlp::Bound> bounds = fixed_set_bounds(sp, pins);
    if (pins.empty() && !options_.homotopy.fix_active_set) return {};
    const int n_pins = static_cast<int>(pins.size());
    const mpcc::HomotopyResult again =
        sp.mpcc.solve_again(solver(), options_.homotopy, bounds, n_pins);
    account(again, rows);
    if (again.status == Status::Success) {
      ++res_.summary.active_set_solves;
      res_.summary.pinned_exits += n_pins;
      hr.comp_residual = again.comp_residual;
      hr.status = Status::Success;
      hr.active_set_fixed = true;
      return {};
    }
    if (n_pins == 0) {
      ++res_.summary.active_set_failures;
      return {};
    }
    ++res_.summary.pin_failures;
    std::vector<int> regions;
    for (const auto& pin : pins) regions.push_back(pin.r);
    return regions;
  }

  /// Switches of the accepted step held by the grid (FesdInterval::held_switches, as in the OCP):
  /// a neighbouring segment has every element length at a bound (1 +- gamma_h) h, so the switch
  /// may have been stopped short of its time. Counted and named in a warning, never silent.
  void report_held_switches(const discretization::FesdInterval& iv, const std::vector<double>& w,
                            double t_step) {
    for (double t : iv.held_switch_times(w.data(), t_step)) {
      ++res_.summary.held_switches;
      res_.summary.warnings.push_back(fmt::format(
          "the switch at t = {:.6g} is held by the grid: the element lengths next to it are at "
          "their bounds (1 +- gamma_h) h, so its time may be wrong (use a larger gamma_h, or "
          "another N_sim or N_FE)",
          t));
    }
  }

  /// Marks the exits among the switches from index `first` on (those of the step that started at
  /// t_step) whose region could not be pinned, and says so in the summary's warnings.
  void mark_unlocated(std::size_t first, double t_step, const std::vector<int>& regions) {
    mark_switches(first, regions);
    res_.summary.warnings.push_back(fmt::format(
        "the sliding exit{} of region{} {} in the step from t = {:.6g} could not be located (the "
        "re-solve with the exit pinned failed): its switch time may be off by up to one element "
        "length, {:.3g}; try another N_sim",
        regions.size() == 1 ? "" : "s", regions.size() == 1 ? "" : "s", fmt::join(regions, ", "),
        t_step, T_step_ / d_.N_FE));
  }

  /// Sets located = false on the switches from index `first` on that are exits of `regions`.
  void mark_switches(std::size_t first, const std::vector<int>& regions) {
    using discretization::FesdInterval;
    for (std::size_t i = first; i < res_.switches.size(); ++i) {
      SwitchEvent& s = res_.switches[i];
      for (int r : FesdInterval::exit_regions(model_, s.before, s.after))
        if (std::find(regions.begin(), regions.end(), r) != regions.end()) s.located = false;
    }
  }

  /// The previous step ended sliding with theta_r > 0 (guess_.theta: its last stage), and this
  /// one starts without r: an early exit at the step start. Element 0 is pinned: it stays on the
  /// surface until theta_r reaches 0. Returns a lower bound of its length, half the time theta_r
  /// takes to reach 0 at its rate in the previous element: a pinned element of length ~0 would
  /// meet theta_r = 0 only within the tolerance (the stage equations lose their hold on theta
  /// as h -> 0), without moving the exit.
  double step_start_exits(const discretization::FesdInterval& iv, const std::vector<double>& w,
                          std::vector<discretization::FesdInterval::ExitPin>& pins) const {
    using discretization::FesdInterval;
    double h0_min = 0;
    if (res_.active_set.empty()) return h0_min;
    const std::vector<int> first = iv.active_set(w.data(), 0);
    const int n_s = d_.n_s;
    for (int r : FesdInterval::exit_regions(model_, res_.active_set.back(), first)) {
      const double th_end = guess_.theta[r];
      const double lam_end = d_.dcs_mode == DcsMode::Step
                                 ? dcs::region_multiplier(model_, dcs::region_subsystem(model_), r,
                                                          guess_.lambda.data())
                                 : guess_.lambda[r];
      if (th_end <= std::max(FesdInterval::kExitThetaTol, lam_end)) continue;
      // theta_r at the first and last stage of the previous element (res_.theta, res_.t_stage).
      const std::size_t last = res_.theta.size() - 1, first_stage = last + 1 - n_s;
      const double dt = res_.t_stage[last] - res_.t_stage[first_stage];
      const double rate = dt > 0 ? (th_end - res_.theta[first_stage][r]) / dt : 0.0;
      if (rate >= 0) continue;  // theta_r not falling: no exit to expect near the step start
      pins.push_back({0, r, true});
      h0_min = std::max(h0_min, 0.5 * th_end / -rate);
    }
    return h0_min;
  }

  // ---- sensitivities (IntegratorOptions::sensitivities; docs/sensitivities.md) ----

  /// Chains the map of the step from x_ to its end: D(T) <- S D + dx_end/d(u, p).
  void chain(const integrator::StepSensitivity& s) {
    Sensitivities& sens = res_.sensitivities;
    sens.x0 = s.x0 * sens.x0;
    sens.u = s.x0 * sens.u + s.u;
    sens.p = s.x0 * sens.p + s.p;
  }

  /// A crossing exactly at the start of the step (solution w of iv) from x_, i.e. on a step
  /// boundary (a fixed time, which neither step's IFT can move): the jump (24) of the
  /// sensitivities there, D <- J D with J = I + (f_j - f_i) grad psi' / (grad psi' f_i),
  /// psi = g_i - g_j, for the region i of the element before and j of the first element (one
  /// region of one subsystem replaced by one other; the crossing transversal: grad psi' f_i > 0).
  /// A sliding entry (j joins the one region i of its subsystem; grad psi' f_j < 0) the same with
  /// f_j replaced by the sliding field f* (Prop. 9's remark). Then check_single_changes() accepts
  /// the switch there. A sliding exit on a step boundary is not done: not available, as before.
  void jump_at_step_start(const discretization::FesdInterval& iv, const std::vector<double>& w) {
    jump_at_start_ = false;
    if (!res_.sensitivities.available || res_.active_set.empty()) return;
    const std::vector<int>& before = res_.active_set.back();
    const std::vector<int> after = iv.active_set(w.data(), 0);
    if (after == before) return;
    int i = -1, j = -1;
    bool sliding = false;  // j joins i: a sliding entry (f* for f_j)
    for (int k = 0; k < model_.n_sys(); ++k) {
      const int first = model_.region_offset(k), end = model_.region_offset(k + 1);
      std::vector<int> b, a;
      for (int r : before)
        if (r >= first && r < end) b.push_back(r);
      for (int r : after)
        if (r >= first && r < end) a.push_back(r);
      if (a == b) continue;
      if (b.size() != 1 || i >= 0) return;  // not a single switch out of one region
      i = b[0];
      if (a.size() == 1) {
        j = a[0];
      } else if (a.size() == 2 && (a[0] == i || a[1] == i)) {
        j = a[0] == i ? a[1] : a[0];
        sliding = true;
      } else {
        return;
      }
    }
    constexpr int kMaxJet = 128;
    const int n_x = model_.n_x();
    if (i < 0 || n_x > kMaxJet) return;
    using Jet = ad::Jet<kMaxJet>;
    std::vector<Jet> xj(static_cast<std::size_t>(n_x)), pj(static_cast<std::size_t>(model_.n_p())),
        gj(static_cast<std::size_t>(model_.n_theta()));
    for (int a = 0; a < n_x; ++a) xj[a] = Jet::variable(x_[a], a, n_x);
    for (int b = 0; b < model_.n_p(); ++b) pj[b] = Jet(p_[b]);
    dcs::eval_g<Jet>(model_, xj.data(), pj.data(), gj.data());
    Eigen::VectorXd grad(n_x), f_i(n_x), f_j(n_x);
    for (int a = 0; a < n_x; ++a) grad[a] = gj[i].d(a) - gj[j].d(a);
    model_.functions().f(i, x_.data(), u_.data(), p_.data(), f_i.data());
    model_.functions().f(j, x_.data(), u_.data(), p_.data(), f_j.data());
    const double normal = grad.dot(f_i);
    if (!(normal > 1e-12 * grad.norm() * f_i.norm()) || !std::isfinite(normal)) return;
    if (sliding) {
      // Prop. 9's remark: f_j replaced by the sliding field f* = f_i + theta_j (f_j - f_i) with
      // grad psi' f* = 0; an attracting surface: grad psi' f_j < 0, so theta_j in (0, 1).
      const double normal_j = grad.dot(f_j);
      if (!(normal_j < -1e-12 * grad.norm() * f_j.norm()) || !std::isfinite(normal_j)) return;
      f_j = f_i + normal / (normal - normal_j) * (f_j - f_i);
    }
    const Eigen::MatrixXd J =
        Eigen::MatrixXd::Identity(n_x, n_x) + (f_j - f_i) * grad.transpose() / normal;
    Sensitivities& sens = res_.sensitivities;
    sens.x0 = J * sens.x0;
    sens.u = J * sens.u;
    sens.p = J * sens.p;
    jump_at_start_ = true;
  }

  /// The first step (from t_) whose sensitivity is not available ends the chain.
  void sensitivity_unavailable(const std::string& why) {
    Sensitivities& sens = res_.sensitivities;
    if (!sens.available) return;
    sens.available = false;
    sens.message = fmt::format("not available: the step from t = {:.6g}: {}", t_, why);
    sens.x0.resize(0, 0);
    sens.u.resize(0, 0);
    sens.p.resize(0, 0);
  }

  /// Thm 19's setting: at every element boundary from `first` on (the one before it included) the
  /// number of active regions changes by at most one, and (FESD) no switch lies on the boundary
  /// `first` itself, a step boundary: a fixed time, not a free element length, so the IFT cannot
  /// move the switch (Example 3(a) with t_s = 1/3 on a step boundary gives 1, not 1/3). Else the
  /// sensitivities are not available.
  void check_single_changes(std::size_t first, double t_step) {
    const std::vector<std::vector<int>>& a = res_.active_set;
    for (std::size_t n = std::max<std::size_t>(first, 1); n < a.size(); ++n) {
      const auto d = static_cast<long>(a[n].size()) - static_cast<long>(a[n - 1].size());
      std::string why;
      if (std::abs(d) > 1)
        why = fmt::format(
            "at t = {:.6g} the active set changes from {} to {} regions (Thm 19 assumes at most "
            "one change per switch)",
            res_.t[n], a[n - 1].size(), a[n].size());
      else if (n == first && d_.use_fesd && a[n] != a[n - 1] && !jump_at_start_)
        why = fmt::format(
            "the switch at t = {:.6g} lies on a step boundary, a fixed time (not a free element "
            "boundary), where the derivative of the switch time is lost; another N_sim moves it "
            "inside a step",
            res_.t[n]);
      if (why.empty()) continue;
      const double t_keep = t_;
      t_ = t_step;
      sensitivity_unavailable(why);
      t_ = t_keep;
      return;
    }
  }

  /// The step of the homotopy path that starts at x_ (solution of sp, level (k, r)): FESD, the
  /// square system of its final active sets solved again by Newton from its solution
  /// (ActiveSetStep::solve_fixed), then the IFT there; the standard method, the square system of
  /// the stage-wise active sets with h fixed (StandardStepSensitivity).
  void homotopy_sensitivity(int k, int r, const StepProblem& sp) {
    const std::vector<double>& w = sp.mpcc.solution();
    integrator::StepSensitivity s;
    std::string why;
    bool ok = false;
    const DiscretizationOptions dr = level_options(r);
    const double T = T_step_ / std::ldexp(1.0, k);
    if (d_.use_fesd) {
      std::unique_ptr<integrator::ActiveSetStep>& a = sens_fesd_[{k, r}];
      if (!a) a = std::make_unique<integrator::ActiveSetStep>(model_, tab_, dr, T, u_, p_);
      ok = a->solve_fixed(x_, sp.iv->active_sets(w.data()), *sp.iv, sp.in, w, why) &&
           a->sensitivity(s, why);
      // Where the homotopy's final active sets do not make a square system with its solution
      // (e.g. a switch that active_sets() reads in a neighbouring element), the step as the
      // active-set path solves it, if that reaches the same end state.
      if (!ok &&
          a->solve(x_, res_.active_set.empty() ? lp_active_set(guess_) : res_.active_set.back(),
                   guess_, guess_xdot_)) {
        const discretization::FesdInterval& iv = a->interval();
        double diff = 0, scale = 1;
        for (int i = 0; i < model_.n_x(); ++i) {
          diff = std::max(
              diff, std::abs(a->solution()[iv.x(iv.N_FE(), i)] - w[sp.iv->x(sp.iv->N_FE(), i)]));
          scale = std::max(scale, std::abs(w[sp.iv->x(sp.iv->N_FE(), i)]));
        }
        std::string why2;
        if (diff <= 1e-6 * scale && a->sensitivity(s, why2))
          ok = true;
        else
          why += fmt::format("; the active-set path's solution of the step ends {:.2e} away", diff);
      }
    } else {
      std::unique_ptr<integrator::StandardStepSensitivity>& a = sens_standard_[{k, r}];
      if (!a)
        a = std::make_unique<integrator::StandardStepSensitivity>(model_, tab_, dr, T, u_, p_);
      ok = a->compute(x_, *sp.iv, w, s, why);
    }
    if (ok) {
      if (d_.use_fesd) jump_at_step_start(*sp.iv, w);
      chain(s);
    } else {
      sensitivity_unavailable(why.empty() ? "the square system failed" : why);
    }
  }

  // ---- pieces ----

  /// Level (k, r): a step of length T_step / 2^k with N_FE (r = 0) or 2 N_FE (r = 1) elements,
  /// its problem built on first need.
  StepProblem& level(int k, int r) {
    std::unique_ptr<StepProblem>& sp = levels_[k][r].primary;
    if (!sp)
      sp = build_step_problem(model_, tab_, level_options(r), T_step_ / std::ldexp(1.0, k),
                              options_.homotopy.mpcc_mode, u_, p_);
    return *sp;
  }
  /// The same level with the sparse cross complementarity (28), its inputs and guess those of
  /// `primary` (same variables).
  StepProblem& fallback(int k, int r, const StepProblem& primary) {
    std::unique_ptr<StepProblem>& fb = levels_[k][r].fallback;
    if (!fb) {
      DiscretizationOptions sparse = level_options(r);
      sparse.cross_comp = CrossComp::Sparse;
      fb = build_step_problem(model_, tab_, sparse, T_step_ / std::ldexp(1.0, k),
                              options_.homotopy.mpcc_mode, u_, p_);
    }
    fb->mpcc.copy_inputs_from(primary.mpcc);
    if (!fb->mpcc.finalized()) fb->mpcc.finalize();
    return *fb;
  }
  DiscretizationOptions level_options(int r) const {
    DiscretizationOptions dr = d_;
    dr.N_FE = r == 0 ? d_.N_FE : 2 * d_.N_FE;
    return dr;
  }

  /// Fixes the start state x_ and sets the guess: lambda, mu at the start from the LP at x_, the
  /// rest continuing the last stage of the step before.
  void set_start(StepProblem& sp) {
    const dcs::LpSolution lp = dcs::solve_start(model_, d_.dcs_mode, x_, p_);
    sp.mpcc.fix(sp.in.s0, x_);
    if (d_.use_fesd) {
      sp.mpcc.set_guess(sp.in.lambda_start, lp.lambda);
      sp.mpcc.set_guess(sp.in.mu_start, lp.mu);
    } else {
      sp.mpcc.fix(sp.in.lambda_start, lp.lambda);
      sp.mpcc.fix(sp.in.mu_start, lp.mu);
    }
    sp.iv->set_guess(sp.mpcc.guess(), x_, guess_, guess_xdot_);
    if (!sp.mpcc.finalized()) sp.mpcc.finalize();
  }

  mpcc::HomotopyResult homotopy(StepProblem& sp, const HomotopyOptions& hopt,
                                std::vector<HomotopyRow>& rows) {
    // A failed step goes through the retry policy of step(), not through the OCP's rungs.
    const HomotopyOptions h = mpcc::step_homotopy_options(hopt);
    mpcc::HomotopyResult hr =
        sp.mpcc.solve_homotopy(solver(), h, {}, mpcc::kStepWarmMaxIter, early_finish(sp, h));
    account(hr, rows);
    return hr;
  }

  /// The early end of a step's homotopy (HomotopyOptions::active_set_sigma, as in the OCP): after
  /// a converged NLP with sigma <= active_set_sigma whose active sets equal those of the NLP
  /// before, the re-solve of resolve_fixed() (active sets fixed, sliding exits pinned) is solved
  /// there, unless an element slides (two regions of a subsystem active: on the co-dimension-2
  /// surfaces of the periodic stick-slip the active set there is not unique, and fixing it early
  /// listed 36 switches instead of 17 for 17 % fewer NLPs and 0.5 % fewer IPOPT iterations). It
  /// ends the homotopy (the result marked active_set_fixed, so the step is not
  /// re-solved again) if it converges to a point near the relaxed one: every h_n and every state
  /// at an element end within sqrt(sigma) (1 + |value|) of it. A set that lists both regions of
  /// a crossing for an element whose only stage lies on the surface (Radau IIA 1: the switch at
  /// the element's end) leaves h_n free in the fixed NLP, which then lands elsewhere (Example
  /// 3(a), h_0 0.0619 -> 0.1857): such a re-solve is discarded. Otherwise the homotopy goes on
  /// from the relaxed point, and that active set is not tried again.
  std::function<bool(mpcc::HomotopyResult&)> early_finish(StepProblem& sp,
                                                          const HomotopyOptions& hopt) {
    if (!(hopt.active_set_sigma > 0) || !hopt.fix_active_set || !d_.use_fesd ||
        !sp.iv->can_pin_exits())
      return {};
    using ActiveSets = std::vector<std::vector<int>>;
    auto before = std::make_shared<std::pair<ActiveSets, ActiveSets>>();  // last, failed
    return [this, &sp, &hopt, before](mpcc::HomotopyResult& h) {
      ActiveSets now = sp.iv->active_sets(sp.mpcc.solution().data());
      const bool stable = now == before->first;
      before->first = now;
      const double sigma = h.rows.back().sigma;
      if (!stable || now == before->second || !(sigma <= hopt.active_set_sigma) || slides(now))
        return false;
      std::vector<discretization::FesdInterval::ExitPin> pins;
      const std::vector<nlp::Bound> bounds = fixed_set_bounds(sp, pins);
      const int n_pins = static_cast<int>(pins.size());
      const nlp::Iterate relaxed = sp.mpcc.iterate();
      const mpcc::HomotopyResult again = sp.mpcc.solve_again(solver(), hopt, bounds, n_pins);
      if (again.status != Status::Success || !near(*sp.iv, relaxed.x, sp.mpcc.solution(), sigma)) {
        mpcc::append_discarded(h, again);  // the relaxed point, its residual and status stay
        sp.mpcc.restore(relaxed);
        before->second = std::move(now);
        return false;
      }
      mpcc::append(h, again);
      ++res_.summary.active_set_solves;
      res_.summary.pinned_exits += n_pins;
      h.active_set_fixed = true;
      return true;
    };
  }

  /// Whether some element has two or more active regions of one subsystem (a sliding mode, or
  /// a crossing whose switch lies on a stage).
  bool slides(const std::vector<std::vector<int>>& active) const {
    for (const std::vector<int>& a : active)
      for (int k = 0; k < model_.n_sys(); ++k) {
        const int first = model_.region_offset(k), end = model_.region_offset(k + 1);
        if (std::count_if(a.begin(), a.end(), [&](int r) { return r >= first && r < end; }) > 1)
          return true;
      }
    return false;
  }

  /// Whether the element lengths and the states at the element ends of w and v agree within
  /// sqrt(sigma) (1 + |value|).
  bool near(const discretization::FesdInterval& iv, const std::vector<double>& w,
            const std::vector<double>& v, double sigma) const {
    const double tol = std::sqrt(sigma);
    auto close = [&](int i) { return std::abs(w[i] - v[i]) <= tol * (1.0 + std::abs(w[i])); };
    for (int n = 0; n < iv.N_FE(); ++n) {
      if (!close(iv.h(n))) return false;
      for (int i = 0; i < model_.n_x(); ++i)
        if (!close(iv.x(n + 1, i))) return false;
    }
    return true;
  }

  void account(const mpcc::HomotopyResult& h, std::vector<HomotopyRow>& rows) {
    mpcc::add_to_summary(h, res_.summary, rows);
  }

  /// Appends the solved step to the result; its end state and last stage start the next step.
  void accept(const discretization::FesdInterval& iv, const std::vector<double>& w) {
    append_step(res_, model_, iv, tab_, w, t_);
    x_ = res_.x.back();
    last_stage_guess(iv, w, guess_, guess_xdot_);
  }

  /// theta, lambda, mu and x' at the last stage of the interval's solution w: the guess of the
  /// step (or piece of a step) that starts where it ends.
  void last_stage_guess(const discretization::FesdInterval& iv, const std::vector<double>& w,
                        dcs::LpSolution& lp, Eigen::VectorXd& xdot) const {
    const int last = iv.N_FE() - 1, n_s = d_.n_s;
    const int n_x = model_.n_x(), n_th = model_.n_theta();
    lp.theta = gather(w, iv.theta(last, n_s - 1, 0), n_th);
    lp.lambda = gather(w, iv.lambda(last, n_s - 1, 0), iv.n_lambda());
    lp.mu = gather(w, iv.mu(last, n_s - 1, 0), iv.n_mu());
    if (iv.step_mode()) lp.alpha = gather(w, iv.alpha(last, n_s - 1, 0), model_.n_c());
    xdot = gather(w, iv.V(last, n_s - 1, 0), n_x);
  }

  /// Ends the run at a failed step; the failed attempt's last iterate is reported too, so that
  /// the user sees where it went wrong.
  void fail(int step) {
    if (failed_ != nullptr)
      append_step(res_, model_, *failed_->iv, tab_, failed_->mpcc.solution(), t_);
    res_.status = last_.status;
    // The failed step's residual counts too (the report must not say 0 after a failure).
    res_.summary.max_comp_residual = std::max(res_.summary.max_comp_residual, last_.comp_residual);
    res_.message = fmt::format(
        "step {} of {} (t = {:.6g}): {} (last IPOPT status {}, complementarity residual {:.2e})",
        step + 1, N_sim_, t_, describe(last_.status), last_.last_nlp_status, last_.comp_residual);
    // The usual cause when a switch cannot be reached: its last attempt ends with the switch on a
    // boundary whose element lengths are at their bounds.
    if (failed_ != nullptr && !failed_->iv->held_switches(failed_->mpcc.solution().data()).empty())
      res_.message += fmt::format(
          "; its last attempt has a switch held by the grid (element lengths at their bounds "
          "(1 +- gamma_h) h, gamma_h = {:g}): a larger gamma_h or another N_sim lets the "
          "element boundaries reach it",
          d_.gamma_h);
  }

  Eigen::VectorXd xdot_at(const Eigen::VectorXd& x, const Eigen::VectorXd& theta) const {
    Eigen::VectorXd xd(model_.n_x());
    dcs::eval_F_theta<double>(model_, x.data(), u_.data(), p_.data(), theta.data(), xd.data());
    return xd;
  }

  static constexpr int kMaxSplit = 2;  // a failed step is retried as halves, then quarters
  struct Level {
    std::unique_ptr<StepProblem> primary, fallback;  // r: N_FE or 2 N_FE elements
  };

  const Pss& model_;
  const IntegratorOptions& options_;
  const DiscretizationOptions& d_;
  const Tableau tab_;
  const double T_step_;
  const int N_sim_;
  const Eigen::VectorXd u_, p_;
  std::vector<std::array<Level, 2>> levels_;
  std::unique_ptr<nlp::NlpSolver> solver_;
  std::unique_ptr<nlp::NlpSolver> mumps_;              // the retries' solver with kkt_solver = auto
  std::unique_ptr<integrator::ActiveSetStep> active_;  // step_solver = active_set
  /// Half and quarter steps of the active-set path (active_level()), and the pieces of a step.
  static constexpr int kMaxActiveSplit = 2;
  std::array<std::unique_ptr<integrator::ActiveSetStep>, kMaxActiveSplit> active_split_;
  std::vector<Piece> pieces_;
  /// The square systems of the homotopy path's steps for their sensitivities, per level (k, r).
  std::map<std::pair<int, int>, std::unique_ptr<integrator::ActiveSetStep>> sens_fesd_;
  std::map<std::pair<int, int>, std::unique_ptr<integrator::StandardStepSensitivity>>
      sens_standard_;

  /// The NLP solver of the current attempt: once an attempt of the step has failed (careful_),
  /// and kkt_solver is auto, its retries factor the KKT systems with MUMPS, the fallback of the
  /// sparse LDL' (docs/kkt-solver.md): on degenerate steps (co-dimension-2 sliding of the
  /// periodic stick-slip) the two can take different paths, and a retry on the other one is the
  /// better second try.
  nlp::NlpSolver& solver() {
    if (!careful_ || options_.nlp.kkt_solver != KktSolver::Auto) return *solver_;
    if (!mumps_) {
      NlpOptions o = options_.nlp;
      o.kkt_solver = KktSolver::Mumps;
      o.kkt_scaling = KktScaling::Warm;  // MUMPS scales on its own
      mumps_ = nlp::make_solver(o);
    }
    return *mumps_;
  }
  IntegratorResult res_;
  double t_ = 0.0;
  Eigen::VectorXd x_;                    // state at t_
  dcs::LpSolution guess_;                // algebraic guess of the next step
  Eigen::VectorXd guess_xdot_;           // x' guess of the next step
  bool careful_ = false;                 // an attempt of the current step failed
  mpcc::HomotopyResult last_;            // of the last attempt
  const StepProblem* failed_ = nullptr;  // the last failed attempt
  bool settings_cannot_reach_ = false;   // the homotopy's last sigma > complementarity_tol
  std::vector<int> carried_unlocated_;   // unpinned exits of the step before
  bool jump_at_start_ = false;           // jump_at_step_start() applied (24) at this step's start
};

}  // namespace

std::vector<double> IntegratorResult::switch_times() const {
  std::vector<double> ts;
  for (const auto& s : switches) ts.push_back(s.t);
  return ts;
}

IntegratorResult integrate(const Pss& model, const Eigen::VectorXd& x0, double T_sim, int N_sim,
                           const IntegratorOptions& options, const Eigen::VectorXd& u_in,
                           const Eigen::VectorXd& p_in) {
  const auto t_start = Clock::now();
  const Eigen::VectorXd u = u_in.size() == 0 ? Eigen::VectorXd::Zero(model.n_u()) : u_in;
  const Eigen::VectorXd p = p_in.size() == 0 ? model.p_default : p_in;
  check_input(model, x0, T_sim, N_sim, options, u, p);
  Integrator run(model, x0, T_sim, N_sim, options, u, p, t_start);
  for (int step = 0; step < N_sim; ++step)
    if (!run.step(step)) break;
  return run.finish(seconds_since(t_start));
}

std::string IntegratorResult::brief_report() const {
  std::ostringstream os;
  os << to_string(status) << ": ";
  if (!x.empty()) {
    os << "x(" << fmt::format("{:.6g}", t.back()) << ") = [";
    for (Eigen::Index i = 0; i < x.back().size(); ++i)
      os << (i ? ", " : "") << fmt::format("{:.12g}", x.back()[i]);
    os << "]";
  }
  os << fmt::format(", {} switch{}, {} NLPs, {} IPOPT iterations, {:.3f} s", switches.size(),
                    switches.size() == 1 ? "" : "es", summary.homotopy_steps,
                    summary.nlp_iterations, summary.wall_s);
  if (!std::isnan(accuracy.error_estimate))
    os << fmt::format(", error estimate {:.1e}", accuracy.error_estimate);
  return os.str();
}

std::string IntegratorResult::full_report() const {
  std::ostringstream os;
  os << "FESD integrator summary\n";
  os << fmt::format("  status               {} ({})\n", to_string(status), message);
  if (!x.empty()) {
    os << fmt::format("  final time           {:.12g}\n", t.back());
    os << "  final state          [";
    for (Eigen::Index i = 0; i < x.back().size(); ++i)
      os << (i ? ", " : "") << fmt::format("{:.15g}", x.back()[i]);
    os << "]\n";
  }
  os << fmt::format("  switches             {}\n", switches.size());
  for (const auto& s : switches) os << format_switch(s);
  // homotopy has one entry per solve attempt: a refinement follows a failed attempt, a split a
  // failed refinement.
  const std::size_t n_steps = homotopy.size() - static_cast<std::size_t>(summary.refine_attempts) -
                              static_cast<std::size_t>(summary.split_steps);
  os << fmt::format("  integration steps    {}  ({} finite elements)\n", n_steps, h.size());
  os << format_accuracy(accuracy);
  if (sensitivities.requested) {
    const Sensitivities& se = sensitivities;
    if (!se.available) {
      os << fmt::format("  sensitivities        {}\n", se.message);
    } else {
      const auto matrix = [](const Eigen::MatrixXd& m) {
        std::string out = "[";
        for (Eigen::Index i = 0; i < m.rows(); ++i) {
          out += i ? "; " : "";
          for (Eigen::Index j = 0; j < m.cols(); ++j)
            out += fmt::format("{}{:.10g}", j ? ", " : "", m(i, j));
        }
        return out + "]";
      };
      os << fmt::format("  sensitivities        dx(T)/dx0 = {}", matrix(se.x0));
      if (se.u.cols() > 0) os << fmt::format(", dx(T)/du = {}", matrix(se.u));
      if (se.p.cols() > 0) os << fmt::format(", dx(T)/dp = {}", matrix(se.p));
      os << "\n";
    }
  }
  os << format_warnings(summary);
  os << format_work(summary, n_steps == 0 ? 1.0 : static_cast<double>(n_steps));
  return os.str();
}

}  // namespace fesd
