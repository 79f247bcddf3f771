// include/fesd/stepper.hpp: the FESD integrator one step at a time, for real-time loops
// (hardware in the loop, MPC plant simulation; docs/active-set.md, "Stepping API").
//
//   fesd::Stepper stepper(model, /*h=*/0.01, options);      // all memory sized here
//   Eigen::VectorXd x = x0, x_next(model.n_x());
//   for (int k = 0; k < 1000; ++k) {
//     if (stepper.step(x, u, p, x_next) != fesd::Status::Success) break;  // no allocation
//     x = x_next;
//   }
//
// Each step(x, u, p) is one step of integrate(): N_FE finite elements of free length over [t, t +
// h] with exact switch detection, solved on the active-set path (step_solver = active_set: Newton's
// method on the square system of Thm 15 of papers/fesd-filippov.txt) with the homotopy of IPOPT
// solves as fallback. Fed its own output (x = the last x_next, same u and p), a Stepper gives the
// states of integrate(model, x0, N h, N, options, u, p) to round-off.
//
// Allocation: a step on the active-set path allocates nothing once the active-set shapes it meets
// (the active set of every element, where a switch sits) have been met in earlier steps: the square
// systems, their sparse LUs (KLU) and the work space of the switch search are kept per shape. A new
// shape, a step split in half or quarter steps for the first time, a step whose x is not the last
// step's output (its guess comes from the LP at x), and the homotopy fallback (a one-step
// integrate()) allocate. A test counts the allocations (tests/integrator/stepper_allocation.cpp).
#pragma once
#include <memory>
#include <string>

#include <Eigen/Dense>

#include "fesd/model.hpp"
#include "fesd/options.hpp"
#include "fesd/status.hpp"

namespace fesd {

/// What the last Stepper::step() did.
struct StepInfo {
  Status status = Status::NotRun;
  /// The path that solved the step: active_set (Newton, the step possibly in half or quarter
  /// pieces) or homotopy (the fallback).
  StepSolver path = StepSolver::ActiveSet;
  int pieces = 0;             ///< 1, or the half / quarter steps the active-set path needed
  int newton_iterations = 0;  ///< on the active-set path, all square systems tried
  int factorizations = 0;     ///< Jacobians factored (simplified Newton reuses them)
  int tries = 0;              ///< square systems tried (1 where the predicted active set held)
  bool switched = false;      ///< the active set changed inside the step or at its start
  /// Empty after a success; else one sentence: why the step failed.
  std::string message;
};

/// Counts over the life of a Stepper (reset() keeps them).
struct StepperStats {
  long steps = 0;             ///< step() calls
  long active_set_steps = 0;  ///< solved on the active-set path
  long homotopy_steps = 0;    ///< solved by the homotopy fallback
  long failed_steps = 0;
  long cold_starts = 0;  ///< steps whose x was not the last output (guess from the LP at x)
};

/// The FESD integrator as an object created once for a model, a step length h and options, then
/// stepped: step(x, u, p) returns x(t + h). Not thread-safe (one Stepper per thread); movable.
class Stepper {
 public:
  /// Validates and sizes everything: throws fesd::InvalidOption (options: validate() rules, h > 0
  /// and finite, use_fesd = true, step_solver = active_set, sensitivities off) or
  /// fesd::InvalidModel (model sizes, blocks too large) with one line per broken rule. The model
  /// is copied (its functions are shared).
  Stepper(const Pss& model, double h, const IntegratorOptions& options = {});
  ~Stepper();
  Stepper(Stepper&&) noexcept;
  Stepper& operator=(Stepper&&) noexcept;
  Stepper(const Stepper&) = delete;
  Stepper& operator=(const Stepper&) = delete;

  /// One step from x with controls u and parameters p held over it; x(t + h) written into x_next
  /// (size n_x; it may alias x). u empty: zero controls; p empty: the model's p_default. Returns
  /// Status::Success, or the failure (x_next untouched, last_step().message says why; the next
  /// step starts cold). Wrong sizes or non-finite x, u, p throw fesd::InvalidModel before any
  /// computation. No heap allocation on the active-set path once its shapes have been met.
  Status step(const Eigen::Ref<const Eigen::VectorXd>& x,
              const Eigen::Ref<const Eigen::VectorXd>& u,
              const Eigen::Ref<const Eigen::VectorXd>& p, Eigen::Ref<Eigen::VectorXd> x_next);
  /// The same, returning x(t + h) (a new vector: allocates). A failed step throws nothing: the
  /// returned state is x, and status() says what happened.
  Eigen::VectorXd step(const Eigen::VectorXd& x, const Eigen::VectorXd& u = {},
                       const Eigen::VectorXd& p = {});

  /// The last step's status (Status::NotRun before the first).
  Status status() const;
  const StepInfo& last_step() const;
  const StepperStats& stats() const;
  /// Forgets the warm start (the guess and active set carried from the last step, the LU held):
  /// the next step starts as the first. The memory stays.
  void reset();

  double h() const;
  const Pss& model() const;
  const IntegratorOptions& options() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fesd
