// The stepping API (include/fesd/stepper.hpp, docs/active-set.md "Stepping API"): the active-set
// path of integrate() one step at a time, its work space kept from step to step.
#include "fesd/stepper.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "core/option_registry.hpp"
#include "dcs/stewart.hpp"
#include "discretization/fesd_interval.hpp"
#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "integrator/active_set.hpp"

namespace fesd {

namespace {

/// The creation rules beyond validate(options), one line each.
std::vector<std::string> stepper_errors(const Pss& model, double h, const IntegratorOptions& o) {
  std::vector<std::string> e = validate(o);
  if (!(std::isfinite(h) && h > 0))
    e.push_back(fmt::format("h = {}: the step length must be finite and > 0", h));
  else
    for (std::string& s : registry::validate_simulation(h, 1)) e.push_back(std::move(s));
  if (!o.discretization.use_fesd)
    e.push_back(
        "discretization.use_fesd = false: the Stepper needs FESD (the standard method has no "
        "active-set path); use integrate()");
  if (o.step_solver != StepSolver::ActiveSet)
    e.push_back(
        "step_solver = homotopy: the Stepper runs the active-set path (the homotopy is its "
        "fallback); use integrate() for the homotopy path");
  if (o.sensitivities)
    e.push_back(
        "sensitivities = true: not computed by the Stepper; use integrate() with sensitivities");
  if (o.theta_guess.size() > 0)
    e.push_back(
        "theta_guess: the guess of integrate()'s first step; the Stepper guesses theta from the "
        "LP at every cold start (leave theta_guess empty, or use integrate())");
  if (o.discretization.dcs_mode == DcsMode::Step)
    e.push_back(
        "discretization.dcs_mode = step: the Stepper runs the active-set path, written in "
        "Stewart's form; use integrate() for the step form");
  if (model.n_x() < 1) e.push_back("model: empty (n_x = 0)");
  return e;
}

}  // namespace

class Stepper::Impl {
 public:
  Impl(const Pss& model, double h, const IntegratorOptions& options)
      : model_(model), options_(options), h_(h) {
    if (auto e = stepper_errors(model_, h_, options_); !e.empty()) {
      const bool model_error = model_.n_x() < 1;
      if (model_error) throw InvalidModel(registry::join(e));
      throw InvalidOption(registry::join(e));
    }
    if (auto e = discretization::FesdInterval::block_size_errors(model_, options_.discretization);
        !e.empty())
      throw InvalidModel(registry::join(e));
    options_.on_step = nullptr;  // never called: a Stepper reports through last_step()
    tab_ = make_tableau(options_.discretization.rk_scheme, options_.discretization.n_s);
    const int n_x = model_.n_x(), n_th = model_.n_theta(), n_sys = model_.n_sys();
    u_zero_ = Eigen::VectorXd::Zero(model_.n_u());
    p_default_ = model_.p_default.size() == model_.n_p() ? model_.p_default
                                                         : Eigen::VectorXd::Zero(model_.n_p());
    // The active-set solvers of the whole step and its half and quarter pieces (integrate()'s
    // active_set_step(): a step without a consistent active set is solved in pieces).
    for (int k = 0; k <= kMaxSplit; ++k)
      levels_[static_cast<std::size_t>(k)] = std::make_unique<integrator::ActiveSetStep>(
          model_, tab_, options_.discretization, h_ / (1 << k), u_zero_, p_default_);
    x_.resize(n_x);
    u_ = u_zero_;
    p_ = p_default_;
    x_end_.resize(n_x);
    for (dcs::LpSolution* lp : {&guess_, &start_lp_}) {
      lp->g.resize(n_th);
      lp->theta.resize(n_th);
      lp->lambda.resize(n_th);
      lp->mu.resize(n_sys);
    }
    guess_xdot_.resize(n_x);
    start_x_.resize(n_x);
    start_xdot_.resize(n_x);
    predicted_.reserve(static_cast<std::size_t>(n_th));
    c_work_.reserve(static_cast<std::size_t>(std::max(model_.n_c(), model_.n_g())));
    gd_work_.reserve(static_cast<std::size_t>(model_.n_g()));
    f_work_.reserve(static_cast<std::size_t>(n_x));
    start_predicted_.reserve(static_cast<std::size_t>(n_th));
    info_.message.reserve(256);
  }

  Status step(const Eigen::Ref<const Eigen::VectorXd>& x,
              const Eigen::Ref<const Eigen::VectorXd>& u,
              const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::VectorXd> x_next) {
    check_input(x, u, p, x_next);
    x_ = x;  // (x_next may alias x)
    if (u.size() == 0)
      u_.setZero();
    else
      u_ = u;
    if (p.size() == 0)
      p_ = p_default_;
    else
      p_ = p;
    ++stats_.steps;
    info_.status = Status::NotRun;
    info_.path = StepSolver::ActiveSet;
    info_.pieces = info_.newton_iterations = info_.factorizations = info_.tries = 0;
    info_.switched = false;
    info_.message.clear();
    // The guess carried from the step before holds only where this step starts at its end.
    if (!warm_ || x_ != x_end_) cold_start();
    for (auto& level : levels_) level->set_inputs(u_.data(), p_.data());

    if (active_set_step()) {
      ++stats_.active_set_steps;
    } else if (homotopy_step()) {
      ++stats_.homotopy_steps;
      info_.path = StepSolver::Homotopy;
    } else {
      ++stats_.failed_steps;
      warm_ = false;
      return info_.status;
    }
    info_.status = Status::Success;
    x_next = x_end_;
    warm_ = true;
    return Status::Success;
  }

  void reset() {
    warm_ = false;
    for (auto& level : levels_) level->forget_lu();
  }

  Pss model_;
  IntegratorOptions options_;
  Tableau tab_;
  double h_;
  StepInfo info_;
  StepperStats stats_;

 private:
  static constexpr int kMaxSplit = 2;  // integrate()'s kMaxActiveSplit: halves, then quarters

  void check_input(const Eigen::Ref<const Eigen::VectorXd>& x,
                   const Eigen::Ref<const Eigen::VectorXd>& u,
                   const Eigen::Ref<const Eigen::VectorXd>& p,
                   const Eigen::Ref<Eigen::VectorXd>& x_next) const {
    if (x.size() != model_.n_x())
      throw InvalidModel(
          fmt::format("x has {} entries, expected n_x = {}", x.size(), model_.n_x()));
    if (x_next.size() != model_.n_x())
      throw InvalidModel(
          fmt::format("x_next has {} entries, expected n_x = {}", x_next.size(), model_.n_x()));
    if (u.size() != 0 && u.size() != model_.n_u())
      throw InvalidModel(fmt::format("u has {} entries, expected n_u = {} (or none: zero)",
                                     u.size(), model_.n_u()));
    if (p.size() != 0 && p.size() != model_.n_p())
      throw InvalidModel(fmt::format("p has {} entries, expected n_p = {} (or none: p_default)",
                                     p.size(), model_.n_p()));
    const auto finite = [](const Eigen::Ref<const Eigen::VectorXd>& v, const char* name) {
      if (!v.allFinite())
        throw InvalidModel(fmt::format("{} has a non-finite entry (NaN or inf)", name));
    };
    finite(x, "x");
    finite(u, "u");
    finite(p, "p");
  }

  /// The guess of a step that does not continue the last one: the LP at x, as integrate()'s
  /// first step.
  void cold_start() {
    ++stats_.cold_starts;
    dcs::solve_lp(model_, x_.data(), p_.data(), guess_, c_work_, gd_work_);
    dcs::eval_F_theta<double>(model_, x_.data(), u_.data(), p_.data(), guess_.theta.data(),
                              guess_xdot_.data(), f_work_);
    predicted_.clear();
    for (int r = 0; r < model_.n_theta(); ++r)
      if (guess_.theta[r] >
          std::max(std::abs(guess_.lambda[r]), discretization::FesdInterval::kActiveThetaTol))
        predicted_.push_back(r);
  }

  void count(const integrator::ActiveSetStep& as) {
    info_.newton_iterations += as.newton_iterations();
    info_.factorizations += as.factorizations();
    info_.tries += as.tries();
  }

  /// integrate()'s active_set_step(): the whole step from the carried guess, else its halves
  /// and quarters, every piece on the active-set path. On success x_end_ and the guess are of
  /// the step's end.
  bool active_set_step() {
    integrator::ActiveSetStep& as = *levels_[0];
    const bool ok = as.solve(x_, predicted_, guess_, guess_xdot_);
    count(as);
    if (ok) {
      info_.pieces = 1;
      info_.switched = as.kind() != integrator::ActiveSetStep::Kind::Prediction;
      end_of(as, x_end_, predicted_, guess_, guess_xdot_);
      return true;
    }
    start_x_ = x_;
    start_predicted_ = predicted_;
    start_lp_ = guess_;
    start_xdot_ = guess_xdot_;
    if (!(solve_pieces(1) && solve_pieces(1))) return false;
    x_end_ = start_x_;
    predicted_ = start_predicted_;
    guess_ = start_lp_;
    guess_xdot_ = start_xdot_;
    return true;
  }

  bool solve_pieces(int k) {
    integrator::ActiveSetStep& as = *levels_[static_cast<std::size_t>(k)];
    const bool ok = as.solve(start_x_, start_predicted_, start_lp_, start_xdot_);
    count(as);
    if (ok) {
      ++info_.pieces;
      info_.switched = info_.switched || as.kind() != integrator::ActiveSetStep::Kind::Prediction;
      end_of(as, start_x_, start_predicted_, start_lp_, start_xdot_);
      return true;
    }
    if (k == kMaxSplit) return false;
    return solve_pieces(k + 1) && solve_pieces(k + 1);
  }

  /// The end state of a solved piece, its last element's active set (the next prediction) and
  /// its last stage (the next guess), as integrate()'s last_stage_guess().
  void end_of(const integrator::ActiveSetStep& as, Eigen::VectorXd& x_end,
              std::vector<int>& predicted, dcs::LpSolution& lp, Eigen::VectorXd& xdot) const {
    const discretization::FesdInterval& iv = as.interval();
    const std::vector<double>& w = as.solution();
    const int last = iv.N_FE() - 1, n_s = iv.n_s();
    for (int i = 0; i < model_.n_x(); ++i) x_end[i] = w[iv.x(last + 1, i)];
    iv.active_set(w.data(), last, predicted);
    for (int r = 0; r < model_.n_theta(); ++r) {
      lp.theta[r] = w[iv.theta(last, n_s - 1, r)];
      lp.lambda[r] = w[iv.lambda(last, n_s - 1, r)];
    }
    for (int k = 0; k < model_.n_sys(); ++k) lp.mu[k] = w[iv.mu(last, n_s - 1, k)];
    for (int i = 0; i < model_.n_x(); ++i) xdot[i] = w[iv.V(last, n_s - 1, i)];
  }

  /// The fallback: the step by integrate() on the homotopy path (allocates; the homotopy starts
  /// from the LP at x, not from the carried guess).
  bool homotopy_step() {
    IntegratorOptions o = options_;
    o.step_solver = StepSolver::Homotopy;
    const IntegratorResult r = integrate(model_, x_, h_, 1, o, u_, p_);
    info_.path = StepSolver::Homotopy;
    info_.pieces = 1;
    if (r.status != Status::Success || r.theta.empty()) {
      info_.status = r.status == Status::Success ? Status::NlpFailed : r.status;
      info_.message = fmt::format(
          "no consistent active set on the active-set path ({} square systems tried), and the "
          "homotopy fallback failed: {}",
          info_.tries, r.message);
      return false;
    }
    info_.switched = !r.switches.empty() || r.active_set.front() != predicted_;
    x_end_ = r.x.back();
    predicted_ = r.active_set.back();
    guess_.theta = r.theta.back();
    guess_.lambda = r.lambda.back();
    guess_.mu = r.mu.back();
    dcs::eval_F_theta<double>(model_, r.x_stage.back().data(), u_.data(), p_.data(),
                              guess_.theta.data(), guess_xdot_.data(), f_work_);
    return true;
  }

  Eigen::VectorXd u_zero_, p_default_;
  Eigen::VectorXd u_, p_;                          // of the current step
  std::vector<double> c_work_, gd_work_, f_work_;  // work space of the LP and x' at a cold start
  std::array<std::unique_ptr<integrator::ActiveSetStep>, kMaxSplit + 1> levels_;
  // the step: its start state, its end, the guess carried to the next step
  Eigen::VectorXd x_, x_end_;
  bool warm_ = false;  // x_end_, predicted_, guess_ are of the last step's end
  std::vector<int> predicted_;
  dcs::LpSolution guess_;
  Eigen::VectorXd guess_xdot_;
  // where the next piece of a step split in pieces starts
  Eigen::VectorXd start_x_, start_xdot_;
  std::vector<int> start_predicted_;
  dcs::LpSolution start_lp_;
};

Stepper::Stepper(const Pss& model, double h, const IntegratorOptions& options)
    : impl_(std::make_unique<Impl>(model, h, options)) {}
Stepper::~Stepper() = default;
Stepper::Stepper(Stepper&&) noexcept = default;
Stepper& Stepper::operator=(Stepper&&) noexcept = default;

Status Stepper::step(const Eigen::Ref<const Eigen::VectorXd>& x,
                     const Eigen::Ref<const Eigen::VectorXd>& u,
                     const Eigen::Ref<const Eigen::VectorXd>& p,
                     Eigen::Ref<Eigen::VectorXd> x_next) {
  return impl_->step(x, u, p, x_next);
}

Eigen::VectorXd Stepper::step(const Eigen::VectorXd& x, const Eigen::VectorXd& u,
                              const Eigen::VectorXd& p) {
  Eigen::VectorXd x_next(impl_->model_.n_x());
  impl_->step(x, u, p, x_next);
  if (impl_->info_.status != Status::Success) x_next = x;
  return x_next;
}

Status Stepper::status() const {
  return impl_->info_.status;
}
const StepInfo& Stepper::last_step() const {
  return impl_->info_;
}
const StepperStats& Stepper::stats() const {
  return impl_->stats_;
}
void Stepper::reset() {
  impl_->reset();
}
double Stepper::h() const {
  return impl_->h_;
}
const Pss& Stepper::model() const {
  return impl_->model_;
}
const IntegratorOptions& Stepper::options() const {
  return impl_->options_;
}

}  // namespace fesd
