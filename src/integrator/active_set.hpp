// src/integrator/active_set.hpp: the active-set step of the integrator (docs/active-set.md).
//
// Thm 15 of papers/fesd-filippov.txt: with the active set of every finite element fixed (theta = 0
// off it, lambda = 0 on it at every lambda point of the element), the FESD equations (32) of one
// integration step are a square nonlinear system in the stage values, the free lambda, mu and the
// element lengths h_n:
//
//   the equations of FesdInterval (stage states, dynamics (25), LP (9), simplex, sum h_n = T),
//   h_n - h_{n-1} = 0 at every interior boundary where the active set does not change (what step
//   equilibration (31) imposes there), and at a boundary where it changes the switch condition
//   instead: both regions have lambda = 0 at that point (cross complementarity), i.e. c(x) = 0.
//
// ActiveSetStep solves it by Newton's method with the exact Jacobian (forward AD of the blocks,
// a dense LU of Eigen), for the active set predicted from the previous step's end, then checks the
// signs (theta >= 0 on, lambda >= 0 off the active set, h_n within its bounds). A violated lambda_r
// >= 0 is a region entering inside the step: a crossing (r replaces its subsystem's regions), then
// a sliding entry (r added; accepted only with theta strictly inside the simplex, the Filippov
// condition), from an element boundary chosen from the estimated switch time, that boundary's
// length free. A violated theta_r >= 0 in a sliding set is an exit: r leaves, theta_r = 0 at the
// boundary is the switch condition. Co-dimension-2 sliding in one subsystem (a family of theta)
// is reduced to a regular selection (selections()). If no consistent active set is found within
// kMaxTries square systems, solve() returns false and the integrator uses the homotopy.
#pragma once
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "dcs/stewart.hpp"
#include "discretization/fesd_interval.hpp"
#include "fesd/model.hpp"
#include "fesd/options.hpp"
#include "fesd/tableau.hpp"
#include "integrator/sensitivity.hpp"
#include "integrator/sparse_lu.hpp"
#include "nlp/block_nlp.hpp"

namespace fesd::integrator {

/// The input variables of one integration step in `nlp`: s0, q, p (fixed by their bounds by the
/// caller), and for FESD lambda_{0,0}, mu_{0,0} tied to s0 by the LP (9) (lp_at_start); boundary
/// values at the step end (boundary_at_end). Shared by the homotopy's and the active-set path's
/// step problems. `mode`: the multipliers' sizes (dcs::n_lambda, dcs::n_mu).
discretization::IntervalInputs add_step_inputs(nlp::BlockNlp& nlp, const Pss& model, bool use_fesd,
                                               double T_step, DcsMode mode = DcsMode::Stewart);

/// One Newton solve (or a failed try) of the active-set path.
struct ActiveSetTry {
  bool converged = false;
  int iterations = 0;
};

class ActiveSetStep {
 public:
  /// A step of length T_step with d.N_FE elements; d must be FESD.
  ActiveSetStep(const Pss& model, const Tableau& tab, const DiscretizationOptions& d, double T_step,
                const Eigen::VectorXd& u, const Eigen::VectorXd& p);

  /// Solves the step from x0 with every element starting in the active set `predicted` (sorted
  /// region indices), the guess from `lp` (algebraic values) and `xdot`. True when a consistent
  /// active set was found; then solution() is the step (layout interval()).
  bool solve(const Eigen::VectorXd& x0, const std::vector<int>& prediction,
             const dcs::LpSolution& lp, const Eigen::VectorXd& xdot);

  /// The controls u and parameters p of the following solves (sizes n_u, n_p; no allocation).
  void set_inputs(const double* u, const double* p);

  /// The next solve() starts with fresh Jacobians (no LU held from a step before).
  void forget_lu() { lu_current_ = false; }

  const discretization::FesdInterval& interval() const { return *iv_; }
  const std::vector<double>& solution() const { return w_; }
  /// Of the last solve(): Newton iterations and square systems tried (all tries).
  int newton_iterations() const { return iterations_; }
  /// Jacobians evaluated and factored (simplified Newton reuses them across steps of one shape).
  int factorizations() const { return factorizations_; }
  int tries() const { return tries_; }
  /// Size of the square system (per active-set shape; the last one solved).
  int system_size() const { return cur_ == nullptr ? 0 : static_cast<int>(cur_->free.size()); }

  /// The square system with the active sets `active` (one per element; an exit of a sliding mode
  /// between elements n-1 and n pinned by theta_r = 0 at the end of element n-1, as in solve())
  /// solved by Newton from the solution w_other of `other` (an interval of the same scheme and
  /// N_FE, inputs other_in: the homotopy path's step). False with `why` if it does not converge.
  bool solve_fixed(const Eigen::VectorXd& x0, const std::vector<std::vector<int>>& active,
                   const discretization::FesdInterval& other,
                   const discretization::IntervalInputs& other_in,
                   const std::vector<double>& w_other, std::string& why);
  /// d x_end / d(s0, u, p) of the last successful solve() or solve_fixed() by the implicit
  /// function theorem on its square system (docs/sensitivities.md). False with `why` if the
  /// system is singular there.
  bool sensitivity(StepSensitivity& out, std::string& why);

  /// What the accepted solution of the last solve() is.
  enum class Kind { Prediction, Crossing, SlidingEntry, Exit };
  Kind kind() const { return kind_; }

  /// Square systems tried per step before the homotopy takes over.
  static constexpr int kMaxTries = 12;
  /// A sliding entry is accepted only with every theta of the sliding subsystem above this at
  /// every stage after the entry (strictly inside the simplex: sliding_is_filippov()).
  static constexpr double kSlidingThetaTol = 1e-6;
  static constexpr int kMaxNewton = 25;
  /// Simplified Newton: a step whose shape is that of the system solved before starts with the
  /// LU held (factored at an earlier step) while every Newton step is at most kChordContraction
  /// of the one before, for at most kMaxStale iterations; then Newton's method (a Jacobian at
  /// every iterate). A converged simplified iteration is accepted only if the Jacobian at its
  /// solution is regular (that LU is then held for the next step); a step whose prediction
  /// converged so and whose signs fail is solved again without the LU held.
  static constexpr double kChordContraction = 0.25;
  static constexpr int kMaxStale = 8;
  /// Sign tolerance of theta >= 0, lambda >= 0 (a switch within ~kSignTol / |c'| of a step end
  /// is taken at the step end).
  static constexpr double kSignTol = 1e-9;

 private:
  using Sets = std::vector<std::vector<int>>;
  /// Newton's method from w_ with the active sets `active` and the bounds `extra` on top (a
  /// sliding exit: theta_r = 0 at the end of the element before it); w_ is the result.
  ActiveSetTry newton(const Sets& active, const std::vector<nlp::Bound>& extra = {});
  /// The iterations of newton() from w_ on the current shape; reuse: start with the LU held
  /// (simplified Newton), else with a Jacobian of w_.
  ActiveSetTry iterate(bool reuse);
  /// The Jacobian at w_ restricted to the free columns, LU-factored into lu_; false if an
  /// evaluation fails or the LU is singular (pivot ratio below 1e-14).
  bool factor();
  /// The first violated sign in time order, or r = -1 if the signs hold: lambda_r < 0 off the set
  /// (a region entering, exit = false) or theta_r < 0 on it (a region leaving a sliding mode,
  /// exit = true), at time t_bad, with value val_bad; t_ok, val_ok: the last point where that
  /// region's sign held. `bad`: h_n out of bounds (no switch repairs it).
  struct Violation {
    int r = -1;
    bool exit = false;
    double t_ok = 0, t_bad = 0, val_ok = 0, val_bad = 0;
    bool bad = false;
  };
  /// Also fills also_ for an entry: every region of r's subsystem off the set whose lambda fails
  /// at that point (r first).
  Violation check_signs(const Sets& active) const;
  /// The candidates tried after a failed prediction: elements from b on have the set `after`.
  struct Candidate {
    Kind kind;
    std::vector<int> after;
    int b = 0;
    /// An exit into another region j of the subsystem: lambda_j at the boundary stays free.
    int free_at_boundary = -1;
  };
  /// The active sets tried for the step's prediction, in order: `prediction` (the end of the step
  /// before), then for every subsystem with three or more active regions (co-dimension >= 2
  /// sliding, whose theta may be a one-parameter family) the prediction without its region of
  /// least theta in `lp` (the step start), without the two least, ... down to two regions, then
  /// without each other one.
  /// Written into sel_ (its first n_sel_ entries).
  void selections(const std::vector<int>& prediction, const dcs::LpSolution& lp);
  /// A sliding entry into subsystem k at boundary b is a Filippov sliding mode: theta^k strictly
  /// inside its simplex at every stage from element b on (kSlidingThetaTol).
  bool sliding_is_filippov(const Sets& active, int k, int b) const;
  /// Boundaries b (0..N_FE-1) where a switch at time ts can sit with every h_n within its bounds,
  /// best first (the least sum (h_n - T/N_FE)^2, the homotopy's heuristic_mean choice); written
  /// into bounds_.
  void boundaries_for(double ts);
  /// Guess of the switched system: elements from b on with `after` instead of `before`, element
  /// lengths ts / b and (T - ts) / (N_FE - b), from the converged prediction w_pred.
  void switched_guess(const std::vector<double>& w_pred, const std::vector<int>& before,
                      const std::vector<int>& after, int b, double ts);

  const Pss& model_;
  Tableau tab_;
  DiscretizationOptions d_;
  double T_;
  nlp::BlockNlp nlp_;
  discretization::IntervalInputs in_;
  std::unique_ptr<discretization::FesdInterval> iv_;
  std::vector<double> w_;
  /// The square system of one shape (active sets and extra bounds): the bounds with the active
  /// set applied, the free variables (column map), the fixed ones, the equal-length rows, where
  /// each Jacobian entry goes in the dense storage J_, and its sparse LU (pattern analysed once).
  /// Shapes are kept (up to kMaxShapes, the least recently used replaced): a shape met before is
  /// set up again without allocation, its KLU workspaces reused (docs/active-set.md, "Stepping
  /// API").
  struct Shape {
    Sets active;
    std::vector<nlp::Bound> extra;
    std::vector<double> lb, ub;
    std::vector<int> free, col_of, fixed, equal;
    std::vector<std::pair<int, int>> jac_map;      // (Jacobian entry, index into J_)
    std::vector<std::pair<int, double>> constant;  // the equal-length rows: (index, value)
    SparseLu lu;
    bool square = false;
    long last_use = 0;
  };
  static constexpr int kMaxShapes = 64;
  /// Makes the shape of (active, extra) current: found among those kept, else set up (restrict_to).
  /// newton() with the shape of the call before (most steps: the prediction, as the step before)
  /// only refreshes the inputs s0, q, p.
  void use_shape(const Sets& active, const std::vector<nlp::Bound>& extra);
  void restrict_to(Shape& sh, const Sets& active, const std::vector<nlp::Bound>& extra);
  static bool same_shape(const Shape& sh, const Sets& active, const std::vector<nlp::Bound>& extra);

  std::vector<std::unique_ptr<Shape>> shapes_;
  Shape* cur_ = nullptr;
  long use_clock_ = 0;
  std::vector<double> J_;  // dense column-major storage of the current shape's Jacobian
  // cur_->lu factors a Jacobian of the current shape (of this step or one before)
  bool lu_current_ = false;
  bool chord_converged_ = false;  // the last newton() converged with the LU of a step before
  std::vector<double> w_start_;   // newton()'s start, for the restart with fresh Jacobians
  std::vector<double> F_, dz_;
  std::vector<double> g_, jac_;
  Eigen::VectorXd theta_start_;  // theta at the step start (the guess's LP): exit times
  // work space of solve() and check_signs(), kept between steps (no allocation once sized)
  std::vector<double> w_guess_, w_pred_;
  std::vector<int> predicted_;
  Sets sets_, predicted_sets_, active_try_;
  mutable std::vector<double> t_ok_, val_ok_;
  mutable std::vector<int> also_;
  std::vector<std::vector<int>> sel_;  // selections(): n_sel_ sets
  int n_sel_ = 0;
  std::vector<int> bounds_;                   // boundaries_for()
  std::vector<std::pair<double, int>> cost_;  // boundaries_for()
  std::vector<int> active_k_, off_k_, sliding_, pool_;
  std::vector<std::vector<int>> pairs_;
  int n_pairs_ = 0;
  std::vector<Candidate> cand_;  // the candidates of solve(): n_cand_ of them
  int n_cand_ = 0;
  std::vector<nlp::Bound> extra_;
  std::vector<int> sw_in_, sw_out_;  // switched_guess()
  /// The next of the n_cand_ candidates (cand_ grows only past its largest count so far).
  Candidate& add_candidate(Kind kind, int b, int free_at_boundary);
  int iterations_ = 0, tries_ = 0, factorizations_ = 0;
  Kind kind_ = Kind::Prediction;
};

}  // namespace fesd::integrator
