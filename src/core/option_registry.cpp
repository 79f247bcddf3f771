// The option registry (option_registry.hpp): every key of the option tables, declared once, and
// the range checks and messages generated from it. docs/problem-files.md's tables are checked
// against this file by tests/core/option_registry_test.cpp.
#include "core/option_registry.hpp"

#include "core/limits.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <tuple>
#include <type_traits>

#include <fmt/format.h>

#include "fesd/ocp.hpp"
#include "fesd/options.hpp"

namespace fesd::registry {
namespace {

using T = OptionTarget;

// ---- building entries from the C++ members ----------------------------------------------------

/// The member an option lives in: (t.*Part)->*Member, or *(t.*Part) without a Member.
template <auto Part, auto Member>
decltype(auto) ref(const T& t) {
  if constexpr (std::is_null_pointer_v<decltype(Member)>)
    return *(t.*Part);
  else
    return ((t.*Part)->*Member);
}

template <class M>
constexpr Kind kind_of() {
  if constexpr (std::is_enum_v<M>)
    return Kind::Enum;
  else if constexpr (std::is_same_v<M, bool>)
    return Kind::Bool;
  else if constexpr (std::is_integral_v<M>)
    return Kind::Int;
  else
    return Kind::Double;
}

template <auto Part, auto Member>
double get_value(const T& t) {
  const auto v = ref<Part, Member>(t);
  if constexpr (std::is_enum_v<decltype(v)>)
    return static_cast<double>(static_cast<int>(v));
  else
    return static_cast<double>(v);
}

template <auto Part, auto Member>
void set_value(const T& t, double v) {
  auto& r = ref<Part, Member>(t);
  using M = std::remove_reference_t<decltype(r)>;
  if constexpr (std::is_enum_v<M>)
    r = static_cast<M>(static_cast<int>(v));
  else if constexpr (std::is_same_v<M, bool>)
    r = v != 0;
  else
    r = static_cast<M>(v);
}

template <class E>
int parse_index(std::string_view name) {
  E v{};
  return parse(name, v) ? static_cast<int>(v) : -1;
}

/// A scalar option stored in (t.*Part)->*Member (or *(t.*Part)); its kind, value names, getter
/// and setter follow from the member's type.
template <auto Part, auto Member = nullptr>
Option scalar(Table table, std::string_view key, Use use, std::string_view doc,
              std::string_view nosnoc, Range range = {}) {
  using M = std::remove_cvref_t<decltype(ref<Part, Member>(std::declval<const T&>()))>;
  Option o{.table = table,
           .key = key,
           .kind = kind_of<M>(),
           .use = use,
           .doc = doc,
           .nosnoc = nosnoc,
           .range = range};
  if constexpr (std::is_enum_v<M>) {
    o.names = enum_names<M>();
    o.parse_name = parse_index<M>;
  }
  o.present = [](const T& t) { return t.*Part != nullptr; };
  o.get = get_value<Part, Member>;
  o.set = set_value<Part, Member>;
  return o;
}

/// A key the loader reads itself (arrays, expressions).
Option input(Table table, std::string_view key, Use use, std::string_view doc,
             std::string_view nosnoc, bool overridable = false) {
  return Option{.table = table,
                .key = key,
                .kind = Kind::Input,
                .use = use,
                .doc = doc,
                .nosnoc = nosnoc,
                .overridable = overridable};
}

// ---- ranges and the named rules between options -----------------------------------------------

constexpr Range kPositive{.min = 0, .min_open = true};
constexpr Range at_least(double min, std::string_view note = {}) {
  return Range{.min = min, .note = note};
}
constexpr Range between(double min, double max, std::string_view note = {}) {
  return Range{.min = min, .max = max, .note = note};
}

/// n_s by scheme: Lobatto needs two stages, explicit RK has tableaus up to four.
std::pair<Range, std::string_view> n_s_for_scheme(const T& t) {
  const RkScheme s = t.discretization->rk_scheme;
  const bool lobatto = s == RkScheme::LobattoIIIA || s == RkScheme::LobattoIIIC;
  return {between(lobatto ? 2 : 1, s == RkScheme::ExplicitRK ? 4 : 9), to_string(s)};
}

std::string fesd_needs_two_elements(const T& t, double N_FE) {
  if (!t.discretization->use_fesd || N_FE >= 2) return {};
  return "FESD needs >= 2 finite elements (with one there is no step size to move); use 2 or "
         "use_fesd = false";
}

std::string initial_theta_rule(const T& t, double v) {
  if (v == -1) return {};
  if (!(v >= 0 && v <= 1)) return "must be in [0, 1], or -1 (theta from the LP)";
  if (t.discretization->dcs_mode == DcsMode::Step)
    return "needs dcs_mode = \"stewart\" (the step form's variables are alpha, not theta)";
  return {};
}

std::string s_elastic_0_at_most_max(const T& t, double s0) {
  const double s_max = t.homotopy->s_elastic_max;
  if (!(std::isfinite(s_max) && s_max > 0) || s0 <= s_max) return {};
  return fmt::format("must be <= s_elastic_max = {}", s_max);
}

std::string sigma_N_at_most_sigma_0(const T& t, double sigma_N) {
  const double sigma_0 = t.homotopy->sigma_0;
  if (!(std::isfinite(sigma_0) && sigma_0 > 0) || sigma_N <= sigma_0) return {};
  return fmt::format("must be <= sigma_0 = {}", sigma_0);
}

/// With a target, a given N_sim is the first step count tried: it must not exceed the cap.
std::string N_sim_at_most_N_sim_max(const T& t, double N_sim) {
  if (t.tol_sim == nullptr || t.N_sim_max == nullptr || !(*t.tol_sim > 0) || N_sim <= *t.N_sim_max)
    return {};
  return fmt::format(
      "must be <= N_sim_max = {} (with tol_sim, N_sim is the first step count tried)",
      *t.N_sim_max);
}

/// Without the estimate there is nothing to choose N_sim by: it must be given, without tol_sim.
std::string no_estimate_needs_N_sim(const T& t, double error_estimate) {
  if (error_estimate != 0 || t.N_sim == nullptr || t.tol_sim == nullptr ||
      (*t.N_sim > 0 && !(*t.tol_sim > 0)))
    return {};
  return "needs N_sim and no tol_sim (N_sim is otherwise chosen from error estimates)";
}

/// Thm 15's square system has the element lengths as unknowns: FESD only.
std::string ell_1_needs_terminal_constraints(const T& t, double mode) {
  if (static_cast<TerminalConstraint>(static_cast<int>(mode)) != TerminalConstraint::L1 ||
      t.ocp->n_g_terminal > 0)
    return {};
  return "there are no terminal constraints to relax (expected g_terminal, or "
         "relax_terminal_constraint = \"none\")";
}

// ---- the registry -------------------------------------------------------------------------------

std::vector<Option> build() {
  using D = DiscretizationOptions;
  using H = HomotopyOptions;
  using N = NlpOptions;
  constexpr Table kSim = Table::Simulation, kOcp = Table::Ocp, kDisc = Table::Discretization,
                  kHom = Table::Homotopy, kIpopt = Table::Ipopt;
  constexpr Use kBoth = Use::Both;
  std::vector<Option> o;
  const auto with = [&](Option opt, auto&& edit) {
    edit(opt);
    o.push_back(opt);
  };

  // [simulation]: integrate()'s inputs.
  with(scalar<&T::T_sim>(kSim, "T_sim", Use::Simulation, "the length of the time interval", "T_sim",
                         kPositive),
       [](Option& x) { x.required = true; });
  with(
      scalar<&T::N_sim>(kSim, "N_sim", Use::Simulation, "integration steps of length T_sim / N_sim",
                        "N_sim", at_least(0, "(0: chosen by tol_sim)")),
      [](Option& x) { x.rule = N_sim_at_most_N_sim_max; });
  o.push_back(scalar<&T::tol_sim>(
      kSim, "tol_sim", Use::Simulation,
      "target for the estimated error ||x(T_sim) - x_exact(T_sim)||, chooses N_sim", "",
      at_least(0, "(0: 1e-6 if N_sim is not given, else no target)")));
  o.push_back(scalar<&T::N_sim_max>(kSim, "N_sim_max", Use::Simulation,
                                    "the largest N_sim tried to reach tol_sim", "", at_least(1)));
  with(scalar<&T::error_estimate>(
           kSim, "error_estimate", Use::Simulation,
           "with N_sim given, estimate the error from two companion runs (false: one run)", ""),
       [](Option& x) { x.rule = no_estimate_needs_N_sim; });
  o.push_back(scalar<&T::step_solver>(
      kSim, "step_solver", Use::Simulation,
      "per step: Newton on the active set's square system (homotopy fallback), or the MPCC "
      "homotopy (IPOPT); the standard method (use_fesd = false) always uses the homotopy",
      ""));
  o.push_back(input(kSim, "u", Use::Simulation,
                    "constant control values, one per control (comma-separated)", "", true));
  o.push_back(input(kSim, "t0", Use::Simulation,
                    "initial value of the clock state (only used if t appears)", "", true));
  o.push_back(
      input(kSim, "theta_guess", Use::Simulation,
            "guess of the Stewart weights theta of the first step (n_theta values in [0, "
            "1]) instead of the LP's at x0: picks the branch where solutions are not unique",
            "", true));
  o.push_back(scalar<&T::sensitivities>(
      kSim, "sensitivities", Use::Simulation,
      "compute dx(T)/dx0, dx(T)/du, dx(T)/dp (implicit function theorem per step, chained)", ""));

  // [ocp]: the horizon, costs, constraints, bounds and guesses (include/fesd/ocp.hpp).
  const Use ocp = Use::Ocp;
  with(scalar<&T::ocp, &Ocp::T>(kOcp, "T", ocp, "the length of the horizon", "T", kPositive),
       [](Option& x) { x.required = true; });
  o.push_back(scalar<&T::ocp, &Ocp::N_stages>(kOcp, "N_stages", ocp, "number of control intervals",
                                              "N_stages", at_least(1)));
  o.push_back(input(kOcp, "f_q", ocp, "Lagrange term", "f_q"));
  o.push_back(input(kOcp, "f_q_T", ocp, "Mayer term", "f_q_T"));
  o.push_back(input(kOcp, "g_path", ocp, "path constraints", "g_path"));
  o.push_back(input(kOcp, "lbg_path", ocp, "lower bounds of g_path", "g_path_lb"));
  o.push_back(input(kOcp, "ubg_path", ocp, "upper bounds of g_path", "g_path_ub"));
  o.push_back(input(kOcp, "g_terminal", ocp, "terminal constraints", "g_terminal"));
  o.push_back(input(kOcp, "lbg_terminal", ocp, "lower bounds of g_terminal", "g_terminal_lb"));
  o.push_back(input(kOcp, "ubg_terminal", ocp, "upper bounds of g_terminal", "g_terminal_ub"));
  o.push_back(input(kOcp, "lbx", ocp, "state lower bounds", "lbx"));
  o.push_back(input(kOcp, "ubx", ocp, "state upper bounds", "ubx"));
  o.push_back(input(kOcp, "lbu", ocp, "control lower bounds", "lbu"));
  o.push_back(input(kOcp, "ubu", ocp, "control upper bounds", "ubu"));
  o.push_back(input(kOcp, "u_guess", ocp,
                    "initial guess of the controls: one per control (comma-separated), or in a "
                    "file N_stages rows, one per control interval",
                    "u0", true));
  o.push_back(input(kOcp, "x_guess", ocp,
                    "initial guess of the states at the control grid points t_k = k T / "
                    "N_stages (N_stages + 1 rows); implies initialization = external",
                    ""));
  o.push_back(input(kOcp, "p_time_var", ocp,
                    "parameters per control interval: {name = [N_stages values]}", "p_time_var"));
  o.push_back(input(kOcp, "lbx0", ocp, "lower bounds of a free initial state", ""));
  o.push_back(input(kOcp, "ubx0", ocp, "upper bounds of a free initial state", ""));
  with(scalar<&T::ocp, &Ocp::terminal_constraint>(
           kOcp, "relax_terminal_constraint", ocp,
           "terminal constraints exactly (none) or as a penalty rho_terminal * |violation|_1",
           "relax_terminal_constraint"),
       [](Option& x) { x.rule = ell_1_needs_terminal_constraints; });
  o.push_back(scalar<&T::ocp, &Ocp::rho_terminal>(kOcp, "rho_terminal", ocp,
                                                  "weight of the ell_1 terminal penalty",
                                                  "rho_terminal", kPositive));
  o.push_back(input(kOcp, "v_global", ocp,
                    "global decision variables: parameters of [model] p chosen by the optimizer",
                    "v_global"));
  o.push_back(input(kOcp, "g_path_comp", ocp,
                    "path complementarity pairs 0 <= a perp b >= 0 of expressions", "g_path_comp"));
  o.push_back(scalar<&T::ocp, &Ocp::time_optimal_problem>(
      kOcp, "time_optimal_problem", ocp,
      "free final time: a speed of time s scales the dynamics, T_final is added to the cost",
      "time_optimal_problem"));
  o.push_back(scalar<&T::ocp, &Ocp::local_speed_of_time_variable>(
      kOcp, "local_speed_of_time_variable", ocp, "one speed of time per control interval",
      "local_speed_of_time_variable"));
  o.push_back(scalar<&T::ocp, &Ocp::s_sot_min>(
      kOcp, "s_sot_min", ocp, "lower bound of the speed of time", "s_sot_min", kPositive));
  o.push_back(scalar<&T::ocp, &Ocp::s_sot_max>(
      kOcp, "s_sot_max", ocp, "upper bound of the speed of time", "s_sot_max", kPositive));
  o.push_back(scalar<&T::ocp, &Ocp::s_sot0>(
      kOcp, "s_sot0", ocp, "initial guess of the speed of time", "s_sot0", kPositive));
  o.push_back(scalar<&T::ocp, &Ocp::rho_sot>(
      kOcp, "rho_sot", ocp, "weight of the penalty rho_sot (s - 1)^2 per speed of time variable",
      "rho_sot", at_least(0)));
  o.push_back(input(kOcp, "T_final_min", ocp,
                    "lower bound of the final time of a time-optimal problem", "T_final_min"));
  o.push_back(input(kOcp, "T_final_max", ocp,
                    "upper bound of the final time of a time-optimal problem", "T_final_max"));
  o.push_back(scalar<&T::ocp, &Ocp::time_freezing>(
      kOcp, "time_freezing", ocp,
      "time freezing: a speed of time scales the dynamics, the clock state reads k T / N_stages "
      "at every control interval end",
      "time_freezing"));
  o.push_back(input(kOcp, "clock_state", ocp,
                    "the state of model.x that is the clock of time freezing (a name)", "t_var"));
  o.push_back(scalar<&T::ocp, &Ocp::use_speed_of_time_variables>(
      kOcp, "use_speed_of_time_variables", ocp,
      "time freezing with fesd's speed of time (false: the model scales its dynamics itself)",
      "use_speed_of_time_variables"));
  o.push_back(scalar<&T::ocp, &Ocp::time_freezing_tolerance>(
      kOcp, "time_freezing_tolerance", ocp, "tolerance of the clock constraints of time freezing",
      "time_freezing_tolerance", at_least(0)));
  o.push_back(scalar<&T::ocp_options, &OcpOptions::initialization>(kOcp, "initialization", ocp,
                                                                   "initial guess of the NLP", ""));
  with(scalar<&T::ocp_options, &OcpOptions::initial_theta>(
           kOcp, "initial_theta", ocp,
           "every theta of the first guess set to this value (-1: the LP's)", "initial_theta"),
       [](Option& x) { x.rule = initial_theta_rule; });
  o.push_back(scalar<&T::ocp_options, &OcpOptions::constraints_at_stages>(
      kOcp, "constraints_at_stages", ocp,
      "also impose g_path, lbx, ubx at the Runge-Kutta stage points", "g_path_at_stg"));

  // [discretization]: FESD (32).
  o.push_back(scalar<&T::discretization, &D::rk_scheme>(
      kDisc, "rk_scheme", kBoth, "Runge-Kutta scheme in every finite element", "rk_scheme"));
  with(scalar<&T::discretization, &D::n_s>(
           kDisc, "n_s", kBoth, "Runge-Kutta stages per finite element", "n_s", between(1, 9)),
       [](Option& x) { x.range_for = n_s_for_scheme; });
  with(scalar<&T::discretization, &D::N_FE>(
           kDisc, "N_finite_elements", kBoth,
           "finite elements per integration step (per control interval in an OCP)",
           "N_finite_elements", between(1, 1000)),
       [](Option& x) {
         x.alias = "N_FE";
         x.rule = fesd_needs_two_elements;
       });
  o.push_back(scalar<&T::discretization, &D::use_fesd>(
      kDisc, "use_fesd", kBoth, "FESD (32); false: standard time-stepping with fixed h (26)",
      "use_fesd"));
  o.push_back(scalar<&T::discretization, &D::cross_comp>(
      kDisc, "cross_comp_mode", kBoth, "form of the cross complementarity (28)-(29)",
      "cross_comp_mode"));
  o.push_back(scalar<&T::discretization, &D::step_eq>(
      kDisc, "step_equilibration", kBoth, "removal of the spurious degrees of freedom of h_n (31)",
      "step_equilibration"));
  o.push_back(scalar<&T::discretization, &D::stage_lambda_sign>(
      kDisc, "stage_lambda_sign", kBoth,
      "where lambda >= 0 holds: every stage, element boundaries, or by scheme", ""));
  o.push_back(scalar<&T::discretization, &D::gamma_h>(
      kDisc, "gamma_h", kBoth, "step size freedom: h_n in [(1 - gamma_h) h, (1 + gamma_h) h]",
      "gamma_h", Range{.min = 0, .max = 1, .min_open = true}));
  o.push_back(scalar<&T::discretization, &D::rho_h>(
      kDisc, "rho_h", kBoth,
      "weight of the step-equilibration penalty (heuristic_mean, heuristic_delta, l2_relaxed)",
      "rho_h", kPositive));
  o.push_back(scalar<&T::discretization, &D::dcs_mode>(
      kDisc, "dcs_mode", kBoth,
      "stewart: theta per region (8); step: alpha per switching function (Heaviside step form)",
      "dcs_mode"));
  o.push_back(scalar<&T::discretization, &D::pin_sliding_exits>(
      kDisc, "pin_sliding_exits", kBoth,
      "solve once more with sliding exits pinned where theta has not reached 0", ""));

  // [homotopy]: the MPCC homotopy.
  o.push_back(scalar<&T::homotopy, &H::mpcc_mode>(
      kHom, "mpcc_mode", kBoth, "how the complementarity constraints enter the NLPs", "mpcc_mode"));
  o.push_back(scalar<&T::homotopy, &H::sigma_0>(kHom, "sigma_0", kBoth, "first homotopy relaxation",
                                                "sigma_0", kPositive));
  o.push_back(scalar<&T::homotopy, &H::homotopy_update_slope>(
      kHom, "homotopy_update_slope", kBoth, "sigma_{k+1} = slope * sigma_k",
      "homotopy_update_slope", Range{.min = 0, .max = 1, .min_open = true, .max_open = true}));
  o.push_back(scalar<&T::homotopy, &H::homotopy_update_rule>(
      kHom, "homotopy_update_rule", kBoth,
      "linear: slope * sigma_k; superlinear: min(slope * sigma_k, sigma_k^exponent)",
      "homotopy_update_rule"));
  o.push_back(scalar<&T::homotopy, &H::homotopy_update_exponent>(
      kHom, "homotopy_update_exponent", kBoth, "exponent of the superlinear rule",
      "homotopy_update_exponent", Range{.min = 1, .max = 10, .min_open = true}));
  with(scalar<&T::homotopy, &H::sigma_N>(kHom, "sigma_N", kBoth, "smallest sigma", "sigma_N",
                                         kPositive),
       [](Option& x) { x.rule = sigma_N_at_most_sigma_0; });
  o.push_back(scalar<&T::homotopy, &H::complementarity_tol>(
      kHom, "complementarity_tol", kBoth, "stop when the complementarity residual is <= this",
      "comp_tol", kPositive));
  o.push_back(scalar<&T::homotopy, &H::max_homotopy_steps>(
      kHom, "N_homotopy", kBoth, "maximum number of NLPs per step or OCP", "N_homotopy",
      between(0, 1000, "(0: automatic)")));
  o.push_back(scalar<&T::homotopy, &H::homotopy_retries>(
      kHom, "homotopy_retries", Use::Ocp,
      "failed NLPs retried from the last converged one with a smaller sigma step", "",
      between(0, 100, "(0: go on from the failed point)")));
  o.push_back(scalar<&T::homotopy, &H::homotopy_cold_restart>(
      kHom, "homotopy_cold_restart", Use::Ocp,
      "once the retries are used up, solve a failed (or stalled penalty) NLP again from the "
      "initial guess",
      ""));
  o.push_back(scalar<&T::homotopy, &H::intermediate_tol>(
      kHom, "intermediate_tol", kBoth, "IPOPT tol of the NLPs with sigma > 10 complementarity_tol",
      "", Range{.min = 0, .note = "(0: ipopt.tol everywhere)"}));
  o.push_back(scalar<&T::homotopy, &H::active_set_sigma>(
      kHom, "active_set_sigma", kBoth,
      "end the homotopy with the active set fixed once it is stable at sigma <= this", "",
      Range{.min = 0, .note = "(0: off)"}));
  o.push_back(scalar<&T::homotopy, &H::s_elastic_max>(
      kHom, "s_elastic_max", Use::Ocp,
      "upper bound of the elastic variable s (elastic_ineq, elastic_two_sided; 1e20: none)",
      "s_elastic_max", kPositive));
  with(scalar<&T::homotopy, &H::s_elastic_0>(
           kHom, "s_elastic_0", Use::Ocp,
           "first guess of the elastic variable s (elastic_ineq, elastic_two_sided)", "s_elastic_0",
           Range{.min = 0}),
       [](Option& x) { x.rule = s_elastic_0_at_most_max; });
  o.push_back(scalar<&T::homotopy, &H::objective_scaling_direct>(
      kHom, "objective_scaling_direct", Use::Ocp,
      "penalty modes: objective J + (1/sigma) P (true) or sigma J + P (false)",
      "objective_scaling_direct"));
  o.push_back(scalar<&T::homotopy, &H::fix_active_set>(
      kHom, "fix_active_set", Use::Simulation,
      "solve each step's last NLP once more with its active set fixed (exact complementarity)",
      ""));

  // [ipopt]: IPOPT's own options that fesd sets; any other key goes to IPOPT by name.
  o.push_back(scalar<&T::nlp, &N::tol>(kIpopt, "tol", kBoth, "IPOPT tol", "", kPositive));
  o.push_back(scalar<&T::nlp, &N::acceptable_tol>(kIpopt, "acceptable_tol", kBoth,
                                                  "IPOPT acceptable_tol", "", kPositive));
  o.push_back(scalar<&T::nlp, &N::max_iter>(kIpopt, "max_iter", kBoth, "IPOPT iterations per NLP",
                                            "", at_least(1)));
  o.push_back(scalar<&T::nlp, &N::print_level>(kIpopt, "print_level", kBoth, "IPOPT's own output",
                                               "", between(0, 12)));
  o.push_back(scalar<&T::nlp, &N::kkt_solver>(kIpopt, "kkt_solver", kBoth,
                                              "linear solver of IPOPT's KKT systems", ""));
  o.push_back(scalar<&T::nlp, &N::kkt_scaling>(
      kIpopt, "kkt_scaling", kBoth,
      "scaling of the sparse LDL' (warm: from the last factorization's)", ""));
  return o;
}

const std::vector<Option>& registry() {
  static const std::vector<Option> options = build();
  return options;
}

bool inside(const Range& r, double v) {
  if (r.min_open ? !(v > r.min) : !(v >= r.min)) return false;
  if (r.max_open ? !(v < r.max) : !(v <= r.max)) return false;
  return true;
}

bool bounded_below(const Range& r) {
  return r.min > -Range::kNone;
}
bool bounded_above(const Range& r) {
  return r.max < Range::kNone;
}

std::string text_of(const Range& r, Kind kind) {
  const bool lo = bounded_below(r), hi = bounded_above(r);
  if (kind == Kind::Int) {
    const auto i = [](double v) { return static_cast<long long>(v); };
    if (lo && hi) return fmt::format("{}..{}", i(r.min), i(r.max));
    if (lo) return fmt::format(">= {}", i(r.min));
    if (hi) return fmt::format("<= {}", i(r.max));
    return {};
  }
  if (lo && hi)
    return fmt::format("{}{}, {}{}", r.min_open ? '(' : '[', r.min, r.max, r.max_open ? ')' : ']');
  if (lo) return fmt::format("{} {}", r.min_open ? ">" : ">=", r.min);
  if (hi) return fmt::format("{} {}", r.max_open ? "<" : "<=", r.max);
  return {};
}

/// "in 1..9", "> 0": what follows "must be".
std::string must_be(const Range& r, Kind kind) {
  const std::string text = text_of(r, kind);
  return bounded_below(r) && bounded_above(r) ? "in " + text : text;
}

std::string list(std::span<const std::string_view> names, std::string_view last_sep) {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) s += i + 1 == names.size() ? last_sep : ", ";
    s += names[i];
  }
  return s;
}

}  // namespace

bool user_sets(const NlpOptions& o, std::string_view name) {
  return std::any_of(o.extra.begin(), o.extra.end(),
                     [&](const auto& kv) { return kv.first == name; });
}

std::string_view to_string(Table t) {
  switch (t) {
    case Table::Simulation:
      return "simulation";
    case Table::Ocp:
      return "ocp";
    case Table::Discretization:
      return "discretization";
    case Table::Homotopy:
      return "homotopy";
    case Table::Ipopt:
      return "ipopt";
  }
  return "unknown";
}

OptionTarget target_of(const DiscretizationOptions& o) {
  return {.discretization = const_cast<DiscretizationOptions*>(&o)};
}
OptionTarget target_of(const HomotopyOptions& o) {
  return {.homotopy = const_cast<HomotopyOptions*>(&o)};
}
OptionTarget target_of(const NlpOptions& o) {
  return {.nlp = const_cast<NlpOptions*>(&o)};
}
OptionTarget target_of(const IntegratorOptions& o) {
  return {.discretization = const_cast<DiscretizationOptions*>(&o.discretization),
          .homotopy = const_cast<HomotopyOptions*>(&o.homotopy),
          .nlp = const_cast<NlpOptions*>(&o.nlp),
          .step_solver = const_cast<StepSolver*>(&o.step_solver),
          .sensitivities = const_cast<bool*>(&o.sensitivities)};
}
OptionTarget target_of(const OcpOptions& o) {
  return {.discretization = const_cast<DiscretizationOptions*>(&o.discretization),
          .homotopy = const_cast<HomotopyOptions*>(&o.homotopy),
          .nlp = const_cast<NlpOptions*>(&o.nlp),
          .ocp_options = const_cast<OcpOptions*>(&o)};
}

std::span<const Option> all() {
  return registry();
}

std::span<const Table> tables(Use kind) {
  static constexpr std::array<Table, 4> kSimulation{Table::Simulation, Table::Discretization,
                                                    Table::Homotopy, Table::Ipopt};
  static constexpr std::array<Table, 4> kOcpTables{Table::Ocp, Table::Discretization,
                                                   Table::Homotopy, Table::Ipopt};
  static constexpr std::array<Table, 5> kAll{Table::Simulation, Table::Ocp, Table::Discretization,
                                             Table::Homotopy, Table::Ipopt};
  if (kind == Use::Simulation) return kSimulation;
  if (kind == Use::Ocp) return kOcpTables;
  return kAll;
}

bool has(const Option& o, Use kind) {
  return o.use == Use::Both || kind == Use::Both || o.use == kind;
}

const Option* find(Table table, std::string_view key) {
  for (const Option& o : registry())
    if (o.table == table && o.key == key) return &o;
  return nullptr;
}

std::vector<std::string_view> keys(Table table, Use kind) {
  std::vector<std::string_view> out;
  for (const Option& o : registry())
    if (o.table == table && has(o, kind)) out.push_back(o.key);
  return out;
}

const Option* required_option(Table table) {
  for (const Option& o : registry())
    if (o.table == table && o.required) return &o;
  return nullptr;
}

std::string path_of(const Option& o) {
  return fmt::format("{}.{}", to_string(o.table), o.key);
}

std::string format_value(const Option& o, double v) {
  switch (o.kind) {
    case Kind::Int:
      return fmt::format("{}", static_cast<long long>(v));
    case Kind::Bool:
      return v != 0 ? "true" : "false";
    case Kind::Enum: {
      const auto i = static_cast<std::size_t>(v);
      return v >= 0 && i < o.names.size() ? std::string(o.names[i]) : fmt::format("{}", v);
    }
    default:
      return fmt::format("{}", v);
  }
}

std::string range_text(const Option& o) {
  if (o.kind == Kind::Enum) return list(o.names, ", ");
  if (o.kind == Kind::Int || o.kind == Kind::Double) return text_of(o.range, o.kind);
  return {};
}

std::string expected_text(const Option& o) {
  const std::string range = must_be(o.range, o.kind);
  const auto with_range = [&](std::string_view what) {
    return range.empty() ? std::string(what) : fmt::format("{} {}", what, range);
  };
  switch (o.kind) {
    case Kind::Int:
      return with_range("an integer");
    case Kind::Double:
      return with_range("a number");
    case Kind::Bool:
      return "a boolean (true or false)";
    case Kind::Enum:
      return "one of " + list(o.names, ", ");
    default:
      return {};
  }
}

std::string help_text(const Option& o) {
  switch (o.kind) {
    case Kind::Enum:
      return fmt::format("{}: {}", o.doc, list(o.names, " or "));
    case Kind::Bool:
      return fmt::format("{}; 1/0 or true/false", o.doc);
    case Kind::Int:
    case Kind::Double: {
      std::string range = must_be(o.range, o.kind);
      if (!o.range.note.empty()) range += fmt::format(" {}", o.range.note);
      return range.empty() ? std::string(o.doc) : fmt::format("{}; {}", o.doc, range);
    }
    default:
      return std::string(o.doc);
  }
}

std::string unknown_name(const Option& o, std::string_view got) {
  // At most 60 characters of what was given (a 9 KB value must not make a 9 KB message).
  constexpr std::size_t kShown = 60;
  std::string shown;
  std::size_t chars = 0;
  for (char ch : got) {
    const bool continuation = (static_cast<unsigned char>(ch) & 0xC0) == 0x80;
    if (!continuation && chars++ == kShown) {
      shown += "...";
      break;
    }
    shown += ch;
  }
  return fmt::format("unknown name (expected one of {}; got \"{}\")", list(o.names, ", "), shown);
}

std::string check(const Option& o, const OptionTarget& t, double value, std::string_view path) {
  const std::string where =
      fmt::format("{} = {}", path.empty() ? path_of(o) : std::string(path), format_value(o, value));
  if (o.kind == Kind::Int || o.kind == Kind::Double) {
    Range range = o.range;
    std::string_view context;
    if (o.range_for != nullptr) std::tie(range, context) = o.range_for(t);
    const bool finite = std::isfinite(value);
    if (!finite || !inside(range, value)) {
      std::string what = must_be(range, o.kind);
      if (!finite) what = what.empty() ? "finite" : "finite and " + what;
      if (!context.empty()) what += fmt::format(" for {}", context);
      if (!range.note.empty()) what += fmt::format(" {}", range.note);
      return fmt::format("{}: must be {}", where, what);
    }
  }
  if (o.rule != nullptr)
    if (std::string what = o.rule(t, value); !what.empty())
      return fmt::format("{}: {}", where, what);
  return {};
}

std::vector<std::string> check(Table table, const OptionTarget& t) {
  std::vector<std::string> errors;
  for (const Option& o : registry()) {
    if (o.table != table || o.get == nullptr || !o.present(t)) continue;
    if (std::string e = check(o, t, o.get(t)); !e.empty()) errors.push_back(std::move(e));
  }
  return errors;
}

std::vector<std::string> validate_simulation(double T_sim, int N_sim, double t0) {
  // integrate() takes a step count (the registry's N_sim = 0 means "chosen by simulate()").
  std::vector<std::string> e = check(Table::Simulation, OptionTarget{.T_sim = &T_sim});
  if (N_sim < 1) e.push_back(fmt::format("simulation.N_sim = {}: must be >= 1", N_sim));
  if (e.empty())  // the smallest step, docs/problem-files.md "Limits"
    if (std::string s =
            core::step_length_error("simulation.T_sim", T_sim, "simulation.N_sim", N_sim, t0);
        !s.empty())
      e.push_back(std::move(s));
  return e;
}

std::vector<std::string> validate_simulation(double T_sim, int N_sim, double tol_sim, int N_sim_max,
                                             double t0, bool error_estimate) {
  std::vector<std::string> e =
      check(Table::Simulation, OptionTarget{.T_sim = &T_sim,
                                            .N_sim = &N_sim,
                                            .tol_sim = &tol_sim,
                                            .N_sim_max = &N_sim_max,
                                            .error_estimate = &error_estimate});
  // The smallest step, docs/problem-files.md "Limits": of N_sim if given, else of one step (a
  // search for tol_sim stops where the step would become shorter).
  if (e.empty())
    if (std::string s = core::step_length_error("simulation.T_sim", T_sim, "simulation.N_sim",
                                                std::max(N_sim, 1), t0);
        !s.empty())
      e.push_back(std::move(s));
  return e;
}

std::string join(const std::vector<std::string>& messages) {
  std::string all;
  for (const std::string& m : messages) all += (all.empty() ? "" : "; ") + m;
  return all;
}

}  // namespace fesd::registry
