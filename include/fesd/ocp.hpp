// include/fesd/ocp.hpp: direct optimal control of piecewise smooth systems with FESD, Sect. 5 of
// papers/fesd-filippov.txt.
//
//   min  int_0^T f_q(x, u, p) dt + f_q_T(x(T), p)                                          (58a)
//   s.t. x(0) = x0 (or x0 free within bounds),  Filippov dynamics of the Pss (58c-f),
//        lbg_path <= g_path(x, u, p) <= ubg_path,  lbx <= x <= ubx,  lbu <= u <= ubu,       (58g)
//        lbg_terminal <= g_terminal(x(T), p) <= ubg_terminal                                (58h)
//
// discretized as (59): N_stages control intervals of equal length T / N_stages with a constant
// control each, and on every interval one FESD discretization (32) with N_FE finite elements
// (src/discretization/fesd_interval.hpp). The Lagrange term is integrated with the RK scheme's own
// quadrature, sum_n h_n sum_j b_j f_q(X_{n,j}, q_k, p). The resulting MPCC is solved by a homotopy
// (HomotopyOptions::mpcc_mode).
//
// User functions are templates on the scalar type, as for models (model.hpp); all are optional:
//
//   template <class T> T f_q(const T* x, const T* u, const T* p) const;             // Lagrange
//   term template <class T> T f_q_T(const T* x, const T* p) const;                       // Mayer
//   term template <class T> void g_path(const T* x, const T* u, const T* p, T* out) const; template
//   <class T> void g_terminal(const T* x, const T* p, T* out) const; template <class T> void
//   g_path_comp(const T* x, const T* u, const T* p, T* out) const;  // a, then b
//   template <class T> void g_rk_comp(const T* x, const T* u, const T* p, const T* y, T* out)
//   const;  // a, then b, at the RK stage points; y: the stage's theta, ... (RkAlgebraic)
//
// Example (the sensitivity OCP (56): min int_0^2 x^2 dt + (x(2) - 5/3)^2 over x0):
//
//   struct Cost {
//     template <class T> T f_q(const T* x, const T*, const T*) const { return x[0] * x[0]; }
//     template <class T> T f_q_T(const T* x, const T*) const { return (x[0] - 5.0 / 3) * (x[0]
//     - 5.0 / 3); }
//   };
//   fesd::Ocp ocp;
//   ocp.model = ...;  ocp.functions = fesd::make_ocp_functions(Cost{});
//   ocp.T = 2;  ocp.x0 = Eigen::VectorXd::Constant(1, -1.0);  ocp.lbx0 = ...;  ocp.ubx0 = ...;
//   fesd::OcpResult r = fesd::solve(ocp, options);
#pragma once
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "fesd/ad.hpp"
#include "fesd/integrator.hpp"
#include "fesd/model.hpp"
#include "fesd/options.hpp"
#include "fesd/pds.hpp"
#include "fesd/status.hpp"
#include "fesd/summary.hpp"

namespace fesd {

/// Type-erased OCP functions, one virtual per scalar type (made by make_ocp_functions and by
/// problem files). `has_*` say which ones the user gave.
class OcpFunctions {
 public:
  virtual ~OcpFunctions() = default;
  virtual bool has_f_q() const = 0;
  virtual bool has_f_q_T() const = 0;
  /// Path complementarity pairs (OcpData::n_g_path_comp of them): out[i] = a_i(x, u, p),
  /// out[n + i] = b_i(x, u, p), for 0 <= a_i perp b_i >= 0. Optional (the default writes nothing).
#define FESD_DECLARE_OCP_FUNCTIONS(T)                                                           \
  virtual T f_q(const T* x, const T* u, const T* p) const = 0;                                  \
  virtual T f_q_T(const T* x, const T* p) const = 0;                                            \
  virtual void g_path(const T* x, const T* u, const T* p, T* out) const = 0;                    \
  virtual void g_terminal(const T* x, const T* p, T* out) const = 0;                            \
  virtual void g_path_comp(const T* /*x*/, const T* /*u*/, const T* /*p*/, T* /*out*/) const {} \
  virtual void g_rk_comp(const T* /*x*/, const T* /*u*/, const T* /*p*/, const T* /*y*/,        \
                         T* /*out*/) const {}
  FESD_FOR_EACH_SCALAR(FESD_DECLARE_OCP_FUNCTIONS)
#undef FESD_DECLARE_OCP_FUNCTIONS
  // g_rk_comp (above): the stage complementarity pairs (OcpData::n_g_rk_comp of them), out[i] =
  // a_i(x, u, p, y), out[n + i] = b_i(x, u, p, y) at an RK stage point, y the stage's DCS
  // algebraic variables in the RkAlgebraic layout. Optional (the default writes nothing).
  /// The entries of y (indices into the RkAlgebraic layout) that g_rk_comp reads; empty: every
  /// entry that the discretization's form has (RkAlgebraic::exists).
  virtual std::vector<int> g_rk_comp_inputs() const {
    return {};
  }
};

/// The DCS algebraic variables of one RK stage point that OcpFunctions::g_rk_comp reads, one layout
/// for both forms of DiscretizationOptions::dcs_mode (nosnoc's names, 1-based in problem files):
///
///   y = [ theta_1 .. theta_{n_theta},  lambda_1 .. lambda_{n_theta},
///         alpha_1 .. alpha_{n_c},  lambda_n_1 .. lambda_n_{n_c},  lambda_p_1 .. lambda_p_{n_c} ]
///
/// theta: Stewart's region weights, in the step form theta(alpha) (both forms); lambda: Stewart's
/// multipliers (Stewart only); alpha, lambda_n, lambda_p: the step form's (step only). The entries
/// a form does not have are 0.
struct RkAlgebraic {
  int n_theta = 0;  ///< regions of the model (all subsystems)
  int n_c = 0;      ///< switching functions of the model (all c-form subsystems)
  enum class Kind { Theta, Lambda, Alpha, LambdaN, LambdaP };
  int size() const { return 2 * n_theta + 3 * n_c; }
  /// The kind of entry i and its index within the kind (0-based).
  std::pair<Kind, int> entry(int i) const {
    if (i < n_theta) return {Kind::Theta, i};
    if (i < 2 * n_theta) return {Kind::Lambda, i - n_theta};
    const int j = i - 2 * n_theta;
    return {j < n_c ? Kind::Alpha : (j < 2 * n_c ? Kind::LambdaN : Kind::LambdaP), j % n_c};
  }
  /// Whether entry i is a variable of the form (step: the Heaviside step form).
  bool exists(int i, bool step) const {
    const Kind k = entry(i).first;
    return k == Kind::Theta || (k == Kind::Lambda ? !step : step);
  }
  /// The problem-file name of entry i: theta_1, lambda_2, alpha_1, lambda_n_1, lambda_p_3, ...
  std::string name(int i) const {
    static constexpr const char* kNames[] = {"theta", "lambda", "alpha", "lambda_n", "lambda_p"};
    const auto [k, j] = entry(i);
    return std::string(kNames[static_cast<int>(k)]) + "_" + std::to_string(j + 1);
  }
};

/// A global decision variable (nosnoc: v_global): model parameter `index` becomes an NLP variable
/// within [lb, ub] with one value for the whole horizon, chosen by the optimizer. Its guess is the
/// parameter's value (OcpData::p, or the model's p_default; with p_stage the first row). The model
/// (f, c), the costs and the constraints read it like any parameter.
struct GlobalVariable {
  int index = 0;  ///< the parameter, 0 <= index < n_p
  double lb = -std::numeric_limits<double>::infinity();
  double ub = std::numeric_limits<double>::infinity();
};

/// How the terminal constraints are imposed (nosnoc: relax_terminal_constraint).
enum class TerminalConstraint {
  Hard,  ///< lbg_terminal <= g_terminal <= ubg_terminal exactly
  /// l1 penalty: rho_terminal * sum_i s_i in the objective, with slacks s >= 0,
  /// g_i - ubg_i <= s_i and lbg_i - g_i <= s_i (the paper's rho ||q(T) - q_final||_1 of (61)).
  L1,
};
/// Problem-file key `relax_terminal_constraint`: "none" (Hard), "ell_1" (L1).
std::string_view to_string(TerminalConstraint v);
bool parse(std::string_view name, TerminalConstraint& out);

/// Everything of an optimal control problem but its dynamics (shared by Ocp and PdsOcp). Vectors
/// left empty mean "none" (bounds) or "zero" (guesses).
struct OcpData {
  std::shared_ptr<const OcpFunctions> functions;  ///< costs and constraints; may be null
  double T = 0;                                   ///< horizon (nosnoc: T), > 0
  int N_stages = 1;  ///< control intervals of equal length (nosnoc: N_stages)
  /// Finite elements per control interval; empty: options.discretization.N_FE for every interval.
  std::vector<int> N_FE;

  Eigen::VectorXd x0;          ///< initial state; the initial guess of x0 if it is free
  Eigen::VectorXd lbx0, ubx0;  ///< if given, x0 is a decision variable within these bounds
  Eigen::VectorXd lbx, ubx;    ///< state bounds at every element boundary (and stage point)
  Eigen::VectorXd lbu, ubu;    ///< control bounds
  Eigen::VectorXd u_guess;     ///< initial guess of every control
  Eigen::VectorXd p;           ///< parameter values; empty: model.p_default
  /// Time-varying parameters (nosnoc: p_time_var): N_stages vectors of n_p, the parameter values
  /// of control interval k; empty: p in every interval. The Mayer term and the terminal
  /// constraints use the last interval's values.
  std::vector<Eigen::VectorXd> p_stage;
  /// Initial guess of the controls per interval (N_stages vectors of n_u); empty: u_guess in
  /// every interval.
  std::vector<Eigen::VectorXd> u_guess_stage;
  /// Initial guess of the states on the control grid t_k = k T / N_stages (N_stages + 1 vectors
  /// of n_x; the first is the guess at t = 0), for OcpInitialization::External.
  std::vector<Eigen::VectorXd> x_guess;

  int n_g_path = 0;  ///< number of path constraints g_path(x, u, p)
  Eigen::VectorXd lbg_path, ubg_path;
  int n_g_terminal = 0;  ///< number of terminal constraints g_terminal(x(T), p)
  Eigen::VectorXd lbg_terminal, ubg_terminal;
  TerminalConstraint terminal_constraint = TerminalConstraint::Hard;
  double rho_terminal = 1e3;  ///< weight of the l1 terminal penalty, > 0

  /// Global decision variables (nosnoc: v_global): parameters the optimizer chooses.
  std::vector<GlobalVariable> v_global;

  /// Path complementarity constraints (nosnoc: g_path_comp): n_g_path_comp pairs
  /// 0 <= a_i(x, u, p) perp b_i(x, u, p) >= 0 (OcpFunctions::g_path_comp) at x0 and every element
  /// boundary (and stage point with constraints_at_stages), each with the interval's control;
  /// relaxed by the MPCC method and homotopy of FESD's own complementarity constraints.
  int n_g_path_comp = 0;
  /// Stage complementarity constraints (nosnoc: g_path_comp pairs that read the DCS algebraic
  /// variables, its g_rk_comp): n_g_rk_comp pairs 0 <= a_i(x, u, p, y) perp b_i(x, u, p, y) >= 0
  /// (OcpFunctions::g_rk_comp) at every RK stage point X_{n,m} of every finite element, y that
  /// stage's theta, lambda, alpha, ... (RkAlgebraic), with the interval's control; lifted and
  /// relaxed like the path complementarity pairs. Piecewise smooth OCPs only.
  int n_g_rk_comp = 0;

  /// Free final time (nosnoc: time_optimal_problem): the time is scaled by a speed of time s > 0,
  /// dt = s dtau on the nominal horizon tau in [0, T]: the dynamics become s f(x, u, p) and the
  /// Lagrange term s f_q; the final time T_final = integral of s dtau is added to the cost.
  bool time_optimal_problem = false;
  /// One speed of time per control interval instead of one for the whole horizon (nosnoc:
  /// local_speed_of_time_variable).
  bool local_speed_of_time_variable = false;
  double s_sot_min = 0.04;  ///< lower bound of s, > 0 (nosnoc: s_sot_min)
  double s_sot_max = 25;    ///< upper bound of s (nosnoc: s_sot_max)
  double s_sot0 = 1;        ///< initial guess of s, within the bounds (nosnoc: s_sot0)
  /// Weight of the penalty rho_sot sum_k (s_k - 1)^2 on the speed of time (one term per speed
  /// variable: per control interval, or once for a global speed), >= 0 (MATLAB nosnoc: rho_sot
  /// with S_sot_nominal = 1). Part of the objective. With time_optimal_problem or time_freezing.
  double rho_sot = 0;
  /// Bounds of the final time T_final = sum_k s_k T / N_stages of a time-optimal problem
  /// (nosnoc: T_final_min, T_final_max); 0 <= T_final_min <= T_final_max.
  double T_final_min = 0;
  double T_final_max = std::numeric_limits<double>::infinity();

  /// Time freezing (nosnoc: time_freezing): the model has a clock state x[clock_state] that
  /// reads the physical time (t' = 1 where time runs, t' = 0 in the auxiliary regions of a state
  /// jump). The dynamics are scaled by a speed of time s (as for time_optimal_problem: one
  /// variable, or one per control interval with local_speed_of_time_variable) on the numerical
  /// horizon tau in [0, T], the Lagrange term becomes s f_q, and at the end of every control
  /// interval k = 1..N_stages the clock is tied to the physical time:
  ///   |t(tau_k) - t(0) - k T / N_stages| <= time_freezing_tolerance.
  /// The final time is not free: the physical horizon is T. Not with time_optimal_problem.
  bool time_freezing = false;
  int clock_state = -1;  ///< index of the clock state in x (nosnoc: t_var)
  /// With time_freezing: false leaves out fesd's speed of time (nosnoc_py's
  /// SpeedOfTimeVariableMode NONE; MATLAB nosnoc: use_speed_of_time_variables): the model
  /// scales its dynamics itself, e.g. by a control. Must be true with time_optimal_problem.
  bool use_speed_of_time_variables = true;
  double time_freezing_tolerance = 0;  ///< >= 0 (nosnoc_py: time_freezing_tolerance)
};

/// An optimal control problem of a piecewise smooth system (Filippov paper, Sect. 5).
struct Ocp : OcpData {
  Pss model;
};

/// An optimal control problem of a projected dynamical system (papers/fesd-pds.txt Sect. II-D,
/// III-D; docs/pds.md "Optimal control"): the same costs, bounds and constraints, each control
/// interval one PDS FESD interval (src/discretization/pds_interval.hpp).
struct PdsOcp : OcpData {
  Pds model;
  PdsOptions pds;  ///< big_M and h_penalty of the PDS step equilibration
};

/// Initial guess of the states (nosnoc: initialization).
enum class OcpInitialization {
  Constant,    ///< x0 at every point, algebraic variables from LP(x0) (the paper's Sect. 5.2)
  Simulation,  ///< a forward simulation from x0 with u_guess on the same grid (Sect. 4.5)
  /// Ocp::x_guess, linear in t between the control grid points; per control interval the
  /// algebraic variables from LP(x) at its midpoint (nosnoc: EXTERNAL). Picks a branch where
  /// solutions are not unique, or starts from a known trajectory.
  External,
};
/// Problem-file key `initialization`: "constant", "simulation", "external".
std::string_view to_string(OcpInitialization v);
bool parse(std::string_view name, OcpInitialization& out);

struct OcpOptions {
  /// Default step equilibration for OCPs: l2_relaxed, not the integrator's heuristic_mean, whose
  /// pull of every h_n towards T / N_FE biases an OCP's switching times (measured on (56):
  /// x0* off by 3e-2 with rho_h = 1; docs/formulation.md).
  DiscretizationOptions discretization{.step_eq = StepEq::L2Relaxed};
  HomotopyOptions homotopy;
  NlpOptions nlp;
  OcpInitialization initialization = OcpInitialization::Constant;
  /// `initial_theta` (nosnoc's initial_theta): every Stewart weight theta of the first NLP's guess
  /// (all intervals, elements and stage points) set to this value in [0, 1], whatever the
  /// initialization; lambda and mu stay the LP's. -1 (default): theta from the LP (8) at the
  /// guessed states. Stewart's form only (the step form's variables are alpha).
  double initial_theta = -1;
  /// Evaluate path constraints and state bounds at the RK stage points too, not only at the
  /// element boundaries.
  bool constraints_at_stages = false;
  /// Called after every NLP of the homotopy, the pinned re-solve included (the CLI prints
  /// format_homotopy_row() of it); the library itself never prints.
  HomotopyCallback on_homotopy_row;
  /// Called from inside an NLP after an IPOPT iteration, at most every nlp_progress_every_s
  /// seconds of wall time (0: after every iteration), so that a long NLP shows what it is doing
  /// (the CLI prints format_nlp_progress() of it under the table, every 30 s); must not throw.
  NlpProgressCallback on_nlp_progress;
  double nlp_progress_every_s = 30;  ///< >= 0
};

/// Empty if valid, else one line per broken rule.
std::vector<std::string> validate(const OcpOptions& o);

/// Warnings about the formulation of a valid `ocp` (empty if none; solve() adds them to the
/// summary). time_freezing whose clock state has the same rate in every region at x0 and the first
/// control guess (within lbu, ubu): no region freezes it, and the clock constraints then fix that
/// rate on every control interval (nosnoc_py's discs, docs/nosnoc-examples.md row 22).
std::vector<std::string> warnings(const Ocp& ocp);

/// The solution of an OCP. Grid = all finite-element boundaries of all control intervals.
struct OcpResult {
  Status status = Status::NotRun;
  std::string message;
  double objective = 0;      ///< the OCP's own cost (59a): no penalty terms of the MPCC method
  double comp_residual = 0;  ///< final complementarity residual (largest product of a pair)
  MpccMode mpcc_mode = MpccMode::ScholtesIneq;

  std::vector<double> t;                     ///< element boundaries, t.front() = 0, t.back() = T
  std::vector<Eigen::VectorXd> x;            ///< states at t
  std::vector<double> h;                     ///< h_{k,n} of every element, interval by interval
  std::vector<int> interval;                 ///< control interval k of every element
  std::vector<double> t_ctrl;                ///< control grid, N_stages + 1 points
  std::vector<Eigen::VectorXd> u;            ///< control of each interval
  std::vector<std::vector<int>> active_set;  ///< active regions per element
  std::vector<SwitchEvent> switches;         ///< element boundaries where the active set changes
  /// eta of (31) at every interior element boundary of an interval (NaN at interval starts):
  /// zero where a switch happens. One entry per element.
  std::vector<double> eta;
  std::vector<double> t_stage;           ///< stage times
  std::vector<Eigen::VectorXd> x_stage;  ///< stage states
  std::vector<Eigen::VectorXd> theta, lambda;
  /// The step form's stage values (dcs_mode = step, else empty): alpha, lambda_p, lambda_n (n_c
  /// each); theta is then theta(alpha), lambda per region as in IntegratorResult.
  std::vector<Eigen::VectorXd> alpha, lambda_p, lambda_n;
  /// The algebraic variables z at the stage points (models with z, else empty).
  std::vector<Eigen::VectorXd> z;

  /// Values of the global decision variables (OcpData::v_global, in its order) and their
  /// parameter names.
  Eigen::VectorXd v_global;
  std::vector<std::string> v_global_names;
  /// The final time (time_optimal_problem: T_final = sum_k s_k T / N_stages; else T), and the
  /// speed of time of every control interval (empty without time_optimal_problem and
  /// time_freezing). With time_optimal_problem t, h, t_ctrl, t_stage and the switch times are
  /// physical times; with time_freezing they are the numerical time tau in [0, T] (h the steps
  /// in tau) and the physical time is the clock state.
  double T_final = 0;
  std::vector<double> s_sot;

  std::vector<HomotopyRow> homotopy;  ///< one row per NLP (a pinned re-solve last)
  Summary summary;                    ///< work and time; n_variables, n_constraints: the NLP

  Eigen::VectorXd x0() const { return x.empty() ? Eigen::VectorXd() : x.front(); }
  Eigen::VectorXd x_final() const { return x.empty() ? Eigen::VectorXd() : x.back(); }
  /// One line: status, objective, x(0), number of switches, time.
  std::string brief_report() const;
  /// A multi-line human summary: status, objective, switches, the homotopy table (unless
  /// with_homotopy_table is false, e.g. when it was already shown as progress), work and timing.
  std::string full_report(bool with_homotopy_table = true) const;
};

/// Solves the OCP. Throws fesd::InvalidModel / InvalidOption for bad input (dimensions, NaN,
/// options out of range); a solver failure is a status in the result.
OcpResult solve(const Ocp& ocp, const OcpOptions& options);

/// Solves an OCP of a projected dynamical system: per control interval the FESD discretization of
/// papers/fesd-pds.txt (6), (8) and Sect. III-C (Radau IIA with n_s >= 2 or the standard method),
/// the MPCC homotopy of `options.homotopy`, then one re-solve with the active set of every element
/// fixed (HomotopyOptions::fix_active_set). The result: `lambda` holds the PDS multipliers (n_c
/// per stage), `theta` and `eta` stay empty, `active_set` lists the active constraints per
/// element, `switches` are contact and leaving events. Not used for PDS: the Stewart-specific
/// post-processing (sliding-exit pins, the allocation search, active_set_sigma).
/// initialization = simulation integrates each control interval with its u_guess (docs/pds.md).
/// Throws like solve(const Ocp&, ...).
OcpResult solve(const PdsOcp& ocp, const OcpOptions& options);

namespace detail {
template <class F>
class OcpFunctionsFor final : public OcpFunctions {
 public:
  explicit OcpFunctionsFor(F f) : f_(std::move(f)) {}
  bool has_f_q() const override {
    return requires(const double* v) {
      f_.f_q(v, v, v);
    };
  }
  bool has_f_q_T() const override {
    return requires(const double* v) {
      f_.f_q_T(v, v);
    };
  }
#define FESD_IMPLEMENT_OCP_FUNCTIONS(T)                                                       \
  T f_q(const T* x, const T* u, const T* p) const override {                                  \
    if constexpr (requires { f_.f_q(x, u, p); })                                              \
      return f_.f_q(x, u, p);                                                                 \
    else                                                                                      \
      return T(0.0);                                                                          \
  }                                                                                           \
  T f_q_T(const T* x, const T* p) const override {                                            \
    if constexpr (requires { f_.f_q_T(x, p); })                                               \
      return f_.f_q_T(x, p);                                                                  \
    else                                                                                      \
      return T(0.0);                                                                          \
  }                                                                                           \
  void g_path(const T* x, const T* u, const T* p, T* out) const override {                    \
    if constexpr (requires { f_.g_path(x, u, p, out); }) f_.g_path(x, u, p, out);             \
  }                                                                                           \
  void g_terminal(const T* x, const T* p, T* out) const override {                            \
    if constexpr (requires { f_.g_terminal(x, p, out); }) f_.g_terminal(x, p, out);           \
  }                                                                                           \
  void g_path_comp(const T* x, const T* u, const T* p, T* out) const override {               \
    if constexpr (requires { f_.g_path_comp(x, u, p, out); }) f_.g_path_comp(x, u, p, out);   \
  }                                                                                           \
  void g_rk_comp(const T* x, const T* u, const T* p, const T* y, T* out) const override {     \
    if constexpr (requires { f_.g_rk_comp(x, u, p, y, out); }) f_.g_rk_comp(x, u, p, y, out); \
  }
  FESD_FOR_EACH_SCALAR(FESD_IMPLEMENT_OCP_FUNCTIONS)
#undef FESD_IMPLEMENT_OCP_FUNCTIONS
 private:
  F f_;
};
}  // namespace detail

/// Wraps C++ cost/constraint functions (see the top of this file) into OcpFunctions.
template <class F>
std::shared_ptr<const OcpFunctions> make_ocp_functions(F f) {
  return std::make_shared<detail::OcpFunctionsFor<F>>(std::move(f));
}

}  // namespace fesd
