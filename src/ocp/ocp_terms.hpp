// src/ocp/ocp_terms.hpp: the parts of a discretized OCP that do not depend on the dynamics, shared
// by the piecewise smooth OCP (ocp.cpp, FesdInterval) and the projected one (pds_ocp.cpp,
// PdsInterval): the cost and constraint blocks, the decision variables s0, p and q_k, and
// add_ocp_terms(), which writes the state bounds, the Lagrange term, the path constraints and the
// terminal cost and constraints of (59) for any interval type with the layout x(n, j),
// X(n, i, j), h(n), N_FE(), n_s().
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "core/util.hpp"
#include "fesd/ocp.hpp"
#include "fesd/tableau.hpp"
#include "mpcc/problem.hpp"
#include "nlp/block.hpp"
#include "nlp/block_nlp.hpp"
#include "nlp/sum_block.hpp"

namespace fesd::ocp_detail {

inline std::vector<int> range(int first, int n) {
  std::vector<int> r(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) r[i] = first + i;
  return r;
}

// ---- bounds (empty: unbounded) -----------------------------------------------------------------
inline double lower(const Eigen::VectorXd& lb, Eigen::Index i) {
  return lb.size() == 0 ? -nlp::kInf : std::max(lb[i], -nlp::kInf);
}
inline double upper(const Eigen::VectorXd& ub, Eigen::Index i) {
  return ub.size() == 0 ? nlp::kInf : std::min(ub[i], nlp::kInf);
}

// ---- cost and constraint blocks ----------------------------------------------------------------

/// h * sum_j b_j f_q(X_j, q, p): the Lagrange term of one element with the RK quadrature.
/// inputs: h, X_1 .. X_{n_s} (n_x each), q (n_u), p (n_p)
struct LagrangeTerm {
  const OcpFunctions* f;
  std::vector<double> b;
  int n_x, n_u, n_p;
  int num_inputs() const { return 1 + static_cast<int>(b.size()) * n_x + n_u + n_p; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    const int n_s = static_cast<int>(b.size());
    const T* q = w + 1 + n_s * n_x;
    const T* p = q + n_u;
    T s(0.0);
    for (int j = 0; j < n_s; ++j) s = s + b[j] * f->f_q(w + 1 + j * n_x, q, p);
    c[0] = w[0] * s;
  }
};

/// f_q_T(x, p).  inputs: x (n_x), p (n_p)
struct MayerTerm {
  const OcpFunctions* f;
  int n_x, n_p;
  int num_inputs() const { return n_x + n_p; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    c[0] = f->f_q_T(w, w + n_x);
  }
};

/// g_path(x, q, p).  inputs: x (n_x), q (n_u), p (n_p)
struct PathConstraint {
  const OcpFunctions* f;
  int n_x, n_u, n_p, n_g;
  int num_inputs() const { return n_x + n_u + n_p; }
  int num_outputs() const { return n_g; }
  template <class T>
  void operator()(const T* w, T* c) const {
    f->g_path(w, w + n_x, w + n_x + n_u, c);
  }
};

/// g_terminal(x, p) (soft = false), or with slacks s (soft = true): outputs g - s (<= ub) and
/// g + s (>= lb).  inputs: x (n_x), p (n_p)[, s (n_g)]
struct TerminalConstraintEq {
  const OcpFunctions* f;
  int n_x, n_p, n_g;
  bool soft = false;
  int num_inputs() const { return n_x + n_p + (soft ? n_g : 0); }
  int num_outputs() const { return soft ? 2 * n_g : n_g; }
  template <class T>
  void operator()(const T* w, T* c) const {
    f->g_terminal(w, w + n_x, c);
    if (!soft) return;
    const T* s = w + n_x + n_p;
    for (int i = 0; i < n_g; ++i) {
      c[n_g + i] = c[i] + s[i];
      c[i] = c[i] - s[i];
    }
  }
};

/// The path complementarity functions at one point with their lifted variables A, B >= 0:
/// outputs a(x, q, p) - A and b(x, q, p) - B (= 0).  inputs: x (n_x), q (n_u), p (n_p), A (n),
/// B (n)
struct PathCompEq {
  const OcpFunctions* f;
  int n_x, n_u, n_p, n;
  int num_inputs() const { return n_x + n_u + n_p + 2 * n; }
  int num_outputs() const { return 2 * n; }
  template <class T>
  void operator()(const T* w, T* c) const {
    f->g_path_comp(w, w + n_x, w + n_x + n_u, c);
    const T* lifted = w + n_x + n_u + n_p;
    for (int i = 0; i < 2 * n; ++i) c[i] = c[i] - lifted[i];
  }
};

/// The stage complementarity functions at one RK stage point with their lifted variables A, B >= 0:
/// outputs a(x, q, p, y) - A and b(x, q, p, y) - B (= 0), y the stage's DCS algebraic variables
/// (RkAlgebraic, `y_size` entries) of which the block reads `entries` (the others are 0).
/// inputs: x (n_x), q (n_u), p (n_p), y[entries] (entries.size()), A (n), B (n)
struct RkCompEq {
  const OcpFunctions* f;
  int n_x, n_u, n_p, n, y_size;
  std::vector<int> entries;
  int num_inputs() const { return n_x + n_u + n_p + static_cast<int>(entries.size()) + 2 * n; }
  int num_outputs() const { return 2 * n; }
  template <class T>
  void operator()(const T* w, T* c) const {
    thread_local std::vector<T> y;
    y.assign(static_cast<std::size_t>(y_size), T(0.0));
    const T* ye = w + n_x + n_u + n_p;
    for (std::size_t l = 0; l < entries.size(); ++l)
      y[static_cast<std::size_t>(entries[l])] = ye[l];
    f->g_rk_comp(w, w + n_x, w + n_x + n_u, y.data(), c);
    const T* lifted = ye + entries.size();
    for (int i = 0; i < 2 * n; ++i) c[i] = c[i] - lifted[i];
  }
};

/// The stage variable layout of a piecewise smooth model: its regions and switching functions.
inline RkAlgebraic rk_algebraic(const Pss& m) {
  return {m.n_theta(), m.n_c()};
}

/// The entries of the RkAlgebraic layout the stage complementarity pairs read: those
/// OcpFunctions::g_rk_comp_inputs() names, or (empty) every entry of the form (step: the Heaviside
/// step form). Entries the form lacks are left out (check_input reports them).
inline std::vector<int> rk_comp_entries(const OcpFunctions& f, const RkAlgebraic& layout,
                                        bool step) {
  std::vector<int> out;
  std::vector<int> named = f.g_rk_comp_inputs();
  if (named.empty()) named = range(0, layout.size());
  for (int i : named)
    if (i >= 0 && i < layout.size() && layout.exists(i, step)) out.push_back(i);
  return out;
}

/// The messages of the cost and constraint blocks with more than ad::kMaxInputs inputs (each
/// starts with the problem-file key to change).
std::vector<std::string> cost_block_size_errors(const OcpData& ocp, int n_x, int n_u, int n_p,
                                                int n_s);

// ---- per control interval ----------------------------------------------------------------------

/// The parameter values of every control interval (OcpData::p_stage, or p in each).
using StageParameters = std::vector<Eigen::VectorXd>;

/// OcpData::p_stage, or N_stages copies of p (model_p_default if p is empty).
inline StageParameters stage_parameters(const OcpData& ocp, const Eigen::VectorXd& p_default) {
  if (!ocp.p_stage.empty()) return ocp.p_stage;
  return StageParameters(static_cast<std::size_t>(ocp.N_stages),
                         ocp.p.size() > 0 ? ocp.p : p_default);
}

/// The control guess of interval k: OcpData::u_guess_stage, u_guess, or 0.
inline Eigen::VectorXd control_guess(const OcpData& ocp, int k, int n_u) {
  if (!ocp.u_guess_stage.empty()) return ocp.u_guess_stage[static_cast<std::size_t>(k)];
  return ocp.u_guess.size() > 0 ? ocp.u_guess : Eigen::VectorXd::Zero(n_u);
}

// ---- the NLP -----------------------------------------------------------------------------------

/// The MPCC of an OCP and where its pieces live, for one interval type (FesdInterval,
/// PdsInterval).
template <class Interval>
struct OcpNlpParts {
  mpcc::Problem mpcc;
  Tableau tab;
  std::vector<int> s0, p;
  std::vector<std::vector<int>> p_k;  // per interval: p, or its own fixed values (p_stage)
  std::vector<std::vector<int>> q;    // per interval
  std::vector<std::unique_ptr<Interval>> iv;
  std::vector<int> terminal_slacks;
  /// Path complementarity points: the inputs x, q, p of PathCompEq and the first of its lifted
  /// variables (A then B, 2 n_g_path_comp).
  /// Stage complementarity points (OcpData::n_g_rk_comp) also have `y`: the NLP variables of the
  /// entries of the RkAlgebraic layout they read (rk_entries).
  struct CompPoint {
    std::vector<int> inputs;
    int lifted = -1;
    bool rk = false;
    std::vector<int> y;
  };
  std::vector<int> rk_entries;
  RkAlgebraic rk_layout;
  std::vector<CompPoint> comp_points;
};

// ---- decision variables ------------------------------------------------------------------------

/// A parameter the optimizer chooses: a global variable (OcpData::v_global; one NLP variable), or
/// (per_interval) the speed of time of a time-optimal problem with local speeds (one per control
/// interval).
struct FreeParameter {
  int index;
  double lb, ub;
  bool per_interval;
};

/// The free parameters of an OCP with n_p parameters; with time_optimal_problem or time_freezing
/// the speed of time is the last parameter (the OCP is the one with_speed_of_time() made).
inline std::vector<FreeParameter> free_parameters(const OcpData& ocp, int n_p) {
  std::vector<FreeParameter> f;
  for (const GlobalVariable& v : ocp.v_global) f.push_back({v.index, v.lb, v.ub, false});
  if (ocp.time_optimal_problem || (ocp.time_freezing && ocp.use_speed_of_time_variables))
    f.push_back({n_p - 1, ocp.s_sot_min, ocp.s_sot_max, ocp.local_speed_of_time_variable});
  return f;
}

// ---- decision variables ------------------------------------------------------------------------

/// s0 (fixed to x0, or free within [lbx0, ubx0] intersected with [lbx, ubx]), p (fixed to the
/// first interval's values) and per interval its parameters p_k: p, or (p_stage) their own fixed
/// variables from interval 1 on.
inline void add_start_and_parameters(mpcc::Problem& mp, const OcpData& ocp,
                                     const StageParameters& p_stage, std::vector<int>& s0,
                                     std::vector<int>& p_vars, std::vector<std::vector<int>>& p_k) {
  const Eigen::VectorXd& p = p_stage.front();
  nlp::BlockNlp& nlp = mp.nlp();
  const int n_x = static_cast<int>(ocp.x0.size());
  s0 = range(nlp.add_variables(n_x, 0.0, 0.0, 0.0), n_x);
  mp.fix(s0, ocp.x0);
  if (ocp.lbx0.size() > 0)
    for (int i = 0; i < n_x; ++i)
      mp.bound(s0[i], std::max(lower(ocp.lbx0, i), lower(ocp.lbx, i)),
               std::min(upper(ocp.ubx0, i), upper(ocp.ubx, i)));
  const int n_p = static_cast<int>(p.size());
  p_vars = range(nlp.add_variables(n_p, 0.0, 0.0, 0.0), n_p);
  mp.fix(p_vars, p);
  const std::vector<FreeParameter> free = free_parameters(ocp, n_p);
  auto make_free = [&](int var, const FreeParameter& f) {
    mp.bound(var, std::max(f.lb, -nlp::kInf), std::min(f.ub, nlp::kInf));
    mp.guess()[var] = std::clamp(mp.guess()[var], mp.lower(var), mp.upper(var));
  };
  for (const FreeParameter& f : free) make_free(p_vars[f.index], f);
  p_k.assign(1, p_vars);
  const bool local =
      std::any_of(free.begin(), free.end(), [](const FreeParameter& f) { return f.per_interval; });
  for (std::size_t k = 1; k < p_stage.size(); ++k) {
    if (ocp.p_stage.empty() && !local) {
      p_k.push_back(p_vars);
      continue;
    }
    std::vector<int> pk = p_vars;
    if (!ocp.p_stage.empty()) {  // own values, fixed
      pk = range(nlp.add_variables(n_p, 0.0, 0.0, 0.0), n_p);
      mp.fix(pk, p_stage[k]);
    }
    for (const FreeParameter& f : free) {
      if (!f.per_interval) {
        pk[f.index] = p_vars[f.index];  // one variable for every interval
      } else {
        pk[f.index] = nlp.add_variables(1, 0.0, 0.0, p[f.index]);
        make_free(pk[f.index], f);
      }
    }
    p_k.push_back(std::move(pk));
  }
}

/// The constraints of the speed of time (the OCP with_speed_of_time() made; p_k[k].back() is the
/// speed of control interval k):
/// * time_optimal_problem with finite T_final bounds: T_final_min <= sum_k s_k T / N_stages <=
///   T_final_max (one row over the distinct speed variables);
/// * time_freezing: the clock at the end of control interval k (`clock_end[k]`, an NLP variable)
///   within t(0) + (k + 1) T / N_stages +- time_freezing_tolerance, as bounds of that variable.
inline void add_speed_of_time_constraints(mpcc::Problem& mp, const OcpData& ocp,
                                          const std::vector<std::vector<int>>& p_k,
                                          const std::vector<int>& clock_end) {
  const double T_k = ocp.T / ocp.N_stages;
  if (ocp.time_optimal_problem && (ocp.T_final_min > 0 || std::isfinite(ocp.T_final_max))) {
    // The speed variables are p_k[k].back(): one per control interval with local speeds, else
    // one for all (add_start_and_parameters).
    if (!ocp.local_speed_of_time_variable || p_k.size() == 1) {  // a bound of the one speed
      const double n = static_cast<double>(p_k.size()) * T_k;
      const int v = p_k.front().back();
      mp.bound(
          v, std::max(mp.lower(v), ocp.T_final_min / n),
          std::min(mp.upper(v), std::isfinite(ocp.T_final_max) ? ocp.T_final_max / n : nlp::kInf));
    } else {  // one speed per interval: sum_k s_k = T_final / T_k
      std::vector<int> speeds;
      for (const std::vector<int>& pk : p_k) speeds.push_back(pk.back());
      mp.nlp().add_constraint(nlp::make_block(nlp::Sum{static_cast<int>(speeds.size())}), speeds,
                              ocp.T_final_min / T_k,
                              std::isfinite(ocp.T_final_max) ? ocp.T_final_max / T_k : nlp::kInf);
    }
  }
  if (ocp.time_freezing) {
    const double t0 = ocp.x0[ocp.clock_state];
    const double tol = ocp.time_freezing_tolerance;
    for (std::size_t k = 0; k < clock_end.size(); ++k) {
      const double t_k = t0 + static_cast<double>(k + 1) * T_k;
      const int v = clock_end[k];
      mp.bound(v, std::max(mp.lower(v), t_k - tol), std::min(mp.upper(v), t_k + tol));
    }
  }
}

/// q_k of control interval k within [lbu, ubu], its guess control_guess() (clamped).
inline std::vector<int> add_control(mpcc::Problem& mp, const OcpData& ocp, int n_u, int k) {
  std::vector<int> q = range(mp.nlp().add_variables(n_u, 0.0, 0.0, 0.0), n_u);
  const Eigen::VectorXd g = control_guess(ocp, k, n_u);
  for (int i = 0; i < n_u; ++i) {
    mp.bound(q[i], lower(ocp.lbu, i), upper(ocp.ubu, i));
    mp.guess()[q[i]] = std::clamp(g[i], mp.lower(q[i]), mp.upper(q[i]));
  }
  return q;
}

// ---- the terms of (59) -------------------------------------------------------------------------

/// State bounds at every element boundary (and stage point with constraints_at_stages), path
/// constraints there and at s0, the Lagrange term with the RK quadrature per element, the Mayer
/// term and the terminal constraints at the end of the last interval (hard, or l1 with the slacks
/// returned in terminal_slacks). `iv[k]` is the interval of control interval k, `q[k]` its control,
/// `p_k[k]` its parameters (the terminal terms use the last interval's).
template <class Interval>
void add_ocp_terms(mpcc::Problem& mp, const OcpData& ocp, const OcpOptions& o, const Tableau& tab,
                   int n_x, int n_u, const std::vector<int>& s0,
                   const std::vector<std::vector<int>>& p_k, const std::vector<std::vector<int>>& q,
                   const std::vector<std::unique_ptr<Interval>>& iv,
                   std::vector<int>& terminal_slacks,
                   std::vector<typename OcpNlpParts<Interval>::CompPoint>& comp_points) {
  nlp::BlockNlp& nlp = mp.nlp();
  const int n_p = static_cast<int>(p_k.front().size());
  const OcpFunctions* f = ocp.functions.get();
  std::vector<double> bw;
  for (int j = 0; j < tab.n_s; ++j) bw.push_back(tab.b(j));
  auto lagrange = f && f->has_f_q() ? nlp::make_block(LagrangeTerm{f, bw, n_x, n_u, n_p}) : nullptr;
  auto path =
      ocp.n_g_path > 0 ? nlp::make_block(PathConstraint{f, n_x, n_u, n_p, ocp.n_g_path}) : nullptr;
  std::vector<double> path_lb(ocp.n_g_path), path_ub(ocp.n_g_path);
  for (int i = 0; i < ocp.n_g_path; ++i) {
    path_lb[i] = lower(ocp.lbg_path, i);
    path_ub[i] = upper(ocp.ubg_path, i);
  }
  auto bound_state = [&](int first) {
    for (int i = 0; i < n_x; ++i)
      mp.bound(first + i, std::max(mp.lower(first + i), lower(ocp.lbx, i)),
               std::min(mp.upper(first + i), upper(ocp.ubx, i)));
  };
  const int n_comp = ocp.n_g_path_comp;
  auto comp = n_comp > 0 ? nlp::make_block(PathCompEq{f, n_x, n_u, n_p, n_comp}) : nullptr;
  std::vector<discretization::CompGroup> comp_groups;
  std::vector<discretization::CompPair> comp_pairs;
  auto add_path = [&](int x_first, const std::vector<int>& qk, const std::vector<int>& pk) {
    std::vector<int> vars = range(x_first, n_x);
    vars.insert(vars.end(), qk.begin(), qk.end());
    vars.insert(vars.end(), pk.begin(), pk.end());
    if (path) nlp.add_constraint(path, vars, path_lb, path_ub);
    if (!comp) return;
    // 0 <= A perp B >= 0 with A = a(x, q, p), B = b(x, q, p): lifted, so that the relaxation
    // sees products of variables with sign bounds as FESD's own pairs.
    const int lifted = nlp.add_variables(2 * n_comp, 0.0, nlp::kInf, 0.0);
    comp_points.push_back({vars, lifted, false, {}});
    for (int i = 0; i < 2 * n_comp; ++i) vars.push_back(lifted + i);
    nlp.add_constraint(comp, vars, std::vector<double>(2 * n_comp, 0.0),
                       std::vector<double>(2 * n_comp, 0.0));
    for (int i = 0; i < n_comp; ++i) {
      const discretization::CompPair pair{lifted + i, lifted + n_comp + i};
      comp_groups.push_back({{pair}, false});
      comp_pairs.push_back(pair);
    }
  };
  add_path(s0[0], q[0], p_k[0]);
  for (std::size_t k = 0; k < iv.size(); ++k) {
    const Interval& v = *iv[k];
    for (int n = 0; n < v.N_FE(); ++n) {
      bound_state(v.x(n + 1, 0));
      add_path(v.x(n + 1, 0), q[k], p_k[k]);
      if (o.constraints_at_stages)
        for (int s = 0; s < v.n_s(); ++s) {
          bound_state(v.X(n, s, 0));
          add_path(v.X(n, s, 0), q[k], p_k[k]);
        }
      if (lagrange) {
        std::vector<int> vars{v.h(n)};
        for (int s = 0; s < v.n_s(); ++s)
          for (int i = 0; i < n_x; ++i) vars.push_back(v.X(n, s, i));
        vars.insert(vars.end(), q[k].begin(), q[k].end());
        vars.insert(vars.end(), p_k[k].begin(), p_k[k].end());
        nlp.add_objective(lagrange, vars);
      }
    }
  }

  if (comp) mp.add_complementarity(comp_groups, comp_pairs);

  // ---- terminal cost and constraints at s_N ----
  const Interval& last = *iv.back();
  std::vector<int> xp = range(last.x(last.N_FE(), 0), n_x);
  xp.insert(xp.end(), p_k.back().begin(), p_k.back().end());
  if (f && f->has_f_q_T()) nlp.add_objective(nlp::make_block(MayerTerm{f, n_x, n_p}), xp);
  if (ocp.n_g_terminal > 0) {
    const int n_g = ocp.n_g_terminal;
    std::vector<double> lb(n_g), ub(n_g);
    for (int i = 0; i < n_g; ++i) {
      lb[i] = lower(ocp.lbg_terminal, i);
      ub[i] = upper(ocp.ubg_terminal, i);
    }
    if (ocp.terminal_constraint == TerminalConstraint::Hard) {
      nlp.add_constraint(nlp::make_block(TerminalConstraintEq{f, n_x, n_p, n_g, false}), xp, lb,
                         ub);
    } else {  // l1: g - s <= ub, g + s >= lb, rho * sum s
      terminal_slacks = range(nlp.add_variables(n_g, 0.0, nlp::kInf, 0.0), n_g);
      std::vector<int> vars = xp;
      vars.insert(vars.end(), terminal_slacks.begin(), terminal_slacks.end());
      std::vector<double> lb2(2 * n_g, -nlp::kInf), ub2(2 * n_g, nlp::kInf);
      for (int i = 0; i < n_g; ++i) {
        ub2[i] = ub[i];
        lb2[n_g + i] = lb[i];
      }
      nlp.add_constraint(nlp::make_block(TerminalConstraintEq{f, n_x, n_p, n_g, true}), vars, lb2,
                         ub2);
      nlp.add_objective(nlp::make_block(nlp::Sum{n_g}), terminal_slacks, ocp.rho_terminal);
    }
  }
}

/// The stage complementarity pairs (OcpData::n_g_rk_comp): at every RK stage point X_{n,m} of every
/// element of every control interval, a(X_{n,m}, q_k, p_k, y_{n,m}) and b(...) lifted into
/// variables A, B >= 0 (as the path complementarity pairs), y_{n,m} the stage's theta, lambda,
/// alpha, lambda_n, lambda_p (RkAlgebraic; `step`: the Heaviside step form). For FesdInterval.
template <class Parts>
void add_rk_comp(Parts& b, const OcpData& ocp, const RkAlgebraic& layout, bool step, int n_x) {
  const int n_comp = ocp.n_g_rk_comp;
  if (n_comp <= 0) return;
  mpcc::Problem& mp = b.mpcc;
  nlp::BlockNlp& nlp = mp.nlp();
  const OcpFunctions* f = ocp.functions.get();
  const int n_u = static_cast<int>(b.q.front().size());
  const int n_p = static_cast<int>(b.p_k.front().size());
  b.rk_layout = layout;
  b.rk_entries = rk_comp_entries(*f, layout, step);
  auto block = nlp::make_block(RkCompEq{f, n_x, n_u, n_p, n_comp, layout.size(), b.rk_entries});
  std::vector<discretization::CompGroup> groups;
  std::vector<discretization::CompPair> pairs;
  for (std::size_t k = 0; k < b.iv.size(); ++k) {
    const auto& v = *b.iv[k];
    for (int n = 0; n < v.N_FE(); ++n)
      for (int m = 0; m < v.n_s(); ++m) {
        std::vector<int> vars = range(v.X(n, m, 0), n_x);
        vars.insert(vars.end(), b.q[k].begin(), b.q[k].end());
        vars.insert(vars.end(), b.p_k[k].begin(), b.p_k[k].end());
        const std::vector<int> xqp = vars;
        std::vector<int> y;
        for (int i : b.rk_entries) {
          const auto [kind, j] = layout.entry(i);
          switch (kind) {
            case RkAlgebraic::Kind::Theta:
              y.push_back(v.theta(n, m, j));
              break;
            case RkAlgebraic::Kind::Lambda:   // Stewart's lambda
            case RkAlgebraic::Kind::LambdaN:  // the step form's lambda_n: its first n_c
              y.push_back(v.lambda(n, m, j));
              break;
            case RkAlgebraic::Kind::Alpha:
              y.push_back(v.alpha(n, m, j));
              break;
            case RkAlgebraic::Kind::LambdaP:
              y.push_back(v.lambda(n, m, layout.n_c + j));
              break;
          }
        }
        vars.insert(vars.end(), y.begin(), y.end());
        const int lifted = nlp.add_variables(2 * n_comp, 0.0, nlp::kInf, 0.0);
        for (int i = 0; i < 2 * n_comp; ++i) vars.push_back(lifted + i);
        nlp.add_constraint(block, vars, std::vector<double>(2 * n_comp, 0.0),
                           std::vector<double>(2 * n_comp, 0.0));
        b.comp_points.push_back({xqp, lifted, true, std::move(y)});
        for (int i = 0; i < n_comp; ++i) {
          const discretization::CompPair pair{lifted + i, lifted + n_comp + i};
          groups.push_back({{pair}, false});
          pairs.push_back(pair);
        }
      }
  }
  mp.add_complementarity(groups, pairs);
}

/// The OCP's own cost at a solution: the Lagrange term with the RK quadrature of each element
/// (h_n, its stage states, the interval's control and parameters), the Mayer term at x_final (the
/// last interval's parameters), the l1 penalty.
class CostSum {
 public:
  CostSum(const OcpData& ocp, const Tableau& tab, const StageParameters& p)
      : ocp_(ocp), tab_(tab), p_(p) {}
  /// One element of control interval k: h_n sum_j b_j f_q(X_j, q, p_k).
  void element(double h, const std::vector<Eigen::VectorXd>& X, const Eigen::VectorXd& q,
               std::size_t k) {
    const OcpFunctions* f = ocp_.functions.get();
    if (!f || !f->has_f_q()) return;
    double quad = 0;
    for (int s = 0; s < tab_.n_s; ++s)
      quad += tab_.b(s) * f->f_q(X[s].data(), q.data(), p_[k].data());
    sum_ += h * quad;
  }
  double total(const Eigen::VectorXd& x_final, const std::vector<double>& w,
               const std::vector<int>& terminal_slacks) const {
    const OcpFunctions* f = ocp_.functions.get();
    double s = sum_;
    if (f && f->has_f_q_T()) s += f->f_q_T(x_final.data(), p_.back().data());
    for (int v : terminal_slacks) s += ocp_.rho_terminal * w[v];
    return s;
  }

 private:
  const OcpData& ocp_;
  const Tableau& tab_;
  const StageParameters& p_;
  double sum_ = 0;
};

/// The result of the NLP point w: grid, states, controls, stage points, active sets, switches,
/// the OCP's own objective. For any interval type with active_set(w, n); `per_stage(v, n, s)`
/// appends the interval kind's algebraic variables of one stage, `eta_of(v)` gives one entry per
/// element of OcpResult::eta.
template <class Interval, class PerStage, class EtaOf>
void extract_result(const OcpData& ocp, const Tableau& tab, int n_x, int n_u,
                    const std::vector<int>& s0, const std::vector<std::vector<int>>& q,
                    const std::vector<std::unique_ptr<Interval>>& iv,
                    const std::vector<int>& terminal_slacks, const std::vector<double>& w,
                    const StageParameters& p, OcpResult& res, const PerStage& per_stage,
                    const EtaOf& eta_of) {
  const double T_k = ocp.T / ocp.N_stages;
  double t = 0;
  res.t = {0.0};
  res.x = {util::gather(w, s0[0], n_x)};
  CostSum objective(ocp, tab, p);
  for (std::size_t k = 0; k < iv.size(); ++k) {
    const Interval& v = *iv[k];
    const Eigen::VectorXd qk = util::gather(w, q[k].empty() ? 0 : q[k][0], n_u);
    res.u.push_back(qk);
    res.t_ctrl.push_back(static_cast<double>(k) * T_k);
    const std::vector<double> eta = eta_of(v);
    for (int n = 0; n < v.N_FE(); ++n) {
      const double hn = w[v.h(n)];
      const std::vector<int> active = v.active_set(w.data(), n);
      std::vector<Eigen::VectorXd> X;
      for (int s = 0; s < v.n_s(); ++s) {
        res.t_stage.push_back(t + tab.c(s) * hn);
        X.push_back(util::gather(w, v.X(n, s, 0), n_x));
        res.x_stage.push_back(X.back());
        per_stage(v, n, s);
      }
      objective.element(hn, X, qk, k);
      if (!res.active_set.empty() && res.active_set.back() != active)
        res.switches.push_back(
            {t, static_cast<int>(res.h.size()) - 1, res.active_set.back(), active});
      res.active_set.push_back(active);
      res.h.push_back(hn);
      res.interval.push_back(static_cast<int>(k));
      res.eta.push_back(eta[static_cast<std::size_t>(n)]);
      t += hn;
      res.t.push_back(t);
      res.x.push_back(util::gather(w, v.x(n + 1, 0), n_x));
    }
  }
  res.t_ctrl.push_back(ocp.T);
  res.objective = objective.total(res.x.back(), w, terminal_slacks);
}

/// The guess of the lifted path complementarity variables: a(x, q, p) and b(x, q, p) at the
/// guess of their inputs, clamped to >= 0. After the guess of everything else.
template <class Parts>
void guess_path_comp(Parts& b, const OcpData& ocp, int n_x, int n_u) {
  std::vector<double>& w = b.mpcc.guess();
  for (const auto& point : b.comp_points) {
    const int n = point.rk ? ocp.n_g_rk_comp : ocp.n_g_path_comp;
    std::vector<double> out(static_cast<std::size_t>(2 * n));
    std::vector<double> in;
    for (int v : point.inputs) in.push_back(w[v]);
    if (point.rk) {
      std::vector<double> y(static_cast<std::size_t>(b.rk_layout.size()), 0.0);
      for (std::size_t l = 0; l < point.y.size(); ++l) y[b.rk_entries[l]] = w[point.y[l]];
      ocp.functions->g_rk_comp(in.data(), in.data() + n_x, in.data() + n_x + n_u, y.data(),
                               out.data());
    } else {
      ocp.functions->g_path_comp(in.data(), in.data() + n_x, in.data() + n_x + n_u, out.data());
    }
    for (int i = 0; i < 2 * n; ++i)
      w[point.lifted + i] = std::isfinite(out[i]) ? std::max(out[i], 0.0) : 0.0;
  }
}

/// The parameter values of every control interval at the NLP point w (free parameters included).
inline StageParameters solution_parameters(const std::vector<std::vector<int>>& p_k,
                                           const std::vector<double>& w) {
  StageParameters out;
  for (const std::vector<int>& vars : p_k) {
    Eigen::VectorXd v(static_cast<Eigen::Index>(vars.size()));
    for (std::size_t i = 0; i < vars.size(); ++i) v[static_cast<Eigen::Index>(i)] = w[vars[i]];
    out.push_back(std::move(v));
  }
  return out;
}

/// The values and names of the global variables at w (p_vars: the parameters' NLP variables).
inline void extract_globals(const OcpData& ocp, const std::vector<std::string>& p_names,
                            const std::vector<int>& p_vars, const std::vector<double>& w,
                            OcpResult& res) {
  res.v_global.resize(static_cast<Eigen::Index>(ocp.v_global.size()));
  res.v_global_names.clear();
  for (std::size_t i = 0; i < ocp.v_global.size(); ++i) {
    const int k = ocp.v_global[i].index;
    res.v_global[static_cast<Eigen::Index>(i)] = w[p_vars[k]];
    res.v_global_names.push_back(
        static_cast<std::size_t>(k) < p_names.size() ? p_names[k] : fmt::format("p{}", k + 1));
  }
}

/// The times of a result on the nominal grid (tau in [0, T], control intervals of length T_k)
/// mapped to physical time t = sum_{j < k} s_j T_k + s_k (tau - k T_k) with the speeds s_k of
/// the control intervals; T_final and s_sot set.
inline void to_physical_time(OcpResult& res, const std::vector<double>& s, double T_k) {
  std::vector<double> start(s.size() + 1, 0.0);  // physical start of each interval
  for (std::size_t k = 0; k < s.size(); ++k) start[k + 1] = start[k] + s[k] * T_k;
  const auto phys = [&](double tau) {
    const double kk = std::floor(tau / T_k);
    const std::size_t k =
        static_cast<std::size_t>(std::clamp(kk, 0.0, static_cast<double>(s.size() - 1)));
    return start[k] + s[k] * (tau - static_cast<double>(k) * T_k);
  };
  for (double& t : res.t) t = phys(t);
  for (double& t : res.t_stage) t = phys(t);
  for (double& t : res.t_ctrl) t = phys(t);
  for (SwitchEvent& e : res.switches) e.t = phys(e.t);
  for (std::size_t e = 0; e < res.h.size(); ++e)
    res.h[e] *= s[static_cast<std::size_t>(res.interval[e])];
  res.s_sot = s;
  res.T_final = start.back();
}

/// The outcome of the homotopy in the result: status, complementarity residual, message.
inline void set_outcome(const mpcc::HomotopyResult& hr, OcpResult& res) {
  res.status = hr.status;
  res.comp_residual = hr.comp_residual;
  res.summary.max_comp_residual = hr.comp_residual;
  res.message = res.status == Status::Success
                    ? std::string(describe(Status::Success))
                    : fmt::format("{} (last IPOPT status {}, complementarity residual {:.2e})",
                                  describe(hr.status), hr.last_nlp_status, hr.comp_residual);
}

}  // namespace fesd::ocp_detail
