// src/ocp/ocp.cpp: the discretized OCP (59): control intervals chained by their boundary states
// s_k (multiple-shooting type, Sect. 5.1), one FesdInterval per interval, costs and constraints as
// blocks, the MPCC solved by a homotopy (Sect. 5.2).
#include "fesd/ocp.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/report.hpp"
#include "dcs/stewart.hpp"
#include "discretization/fesd_interval.hpp"
#include "fesd/error.hpp"
#include "mpcc/homotopy.hpp"
#include "nlp/block.hpp"
#include "nlp/block_nlp.hpp"
#include "nlp/ipopt_solver.hpp"
#include "nlp/sum_block.hpp"
#include "ocp/ocp_input.hpp"

namespace fesd {
namespace {

using Clock = std::chrono::steady_clock;
using discretization::FesdInterval;
using discretization::IntervalInputs;
using nlp::kInf;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::vector<int> range(int first, int n) {
  std::vector<int> r(n);
  for (int i = 0; i < n; ++i) r[i] = first + i;
  return r;
}

Eigen::VectorXd gather(const std::vector<double>& w, int first, int n) {
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = w[first + i];
  return v;
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

// ---- input checks ------------------------------------------------------------------------------

double lower(const Eigen::VectorXd& lb, Eigen::Index i) {
  return lb.size() == 0 ? -kInf : std::max(lb[i], -kInf);
}
double upper(const Eigen::VectorXd& ub, Eigen::Index i) {
  return ub.size() == 0 ? kInf : std::min(ub[i], kInf);
}

std::vector<int> intervals_N_FE(const Ocp& ocp, const OcpOptions& o) {
  if (ocp.N_FE.empty()) return std::vector<int>(ocp.N_stages, o.discretization.N_FE);
  return ocp.N_FE;
}

void check_input(const Ocp& ocp, const OcpOptions& o) {
  ocp_detail::require_valid_input(ocp, o);  // src/ocp/ocp_input.cpp, shared with problem files
}

// ---- the NLP -----------------------------------------------------------------------------------

struct OcpNlp {
  nlp::BlockNlp nlp;
  Tableau tab;
  std::vector<int> s0, p;
  std::vector<std::vector<int>> q;  // per interval
  std::vector<std::unique_ptr<FesdInterval>> iv;
  std::vector<IntervalInputs> in;
  std::vector<discretization::CompGroup> groups;
  std::vector<discretization::CompPair> residual_pairs;
  std::vector<int> terminal_slacks;
};

std::unique_ptr<OcpNlp> build(const Ocp& ocp, const OcpOptions& o, const Eigen::VectorXd& p) {
  const Pss& m = ocp.model;
  const DiscretizationOptions& d = o.discretization;
  const int n_x = m.n_x(), n_u = m.n_u(), n_p = m.n_p(), n_th = m.n_theta(), n_sys = m.n_sys();
  auto b = std::make_unique<OcpNlp>();
  b->tab = make_tableau(d.rk_scheme, d.n_s);
  nlp::BlockNlp& nlp = b->nlp;
  const bool x0_free = ocp.lbx0.size() > 0;

  // s0: fixed to x0, or free within [lbx0, ubx0] intersected with [lbx, ubx].
  b->s0 = range(nlp.add_variables(n_x, 0.0, 0.0, 0.0), n_x);
  for (int i = 0; i < n_x; ++i) {
    nlp.x_init[b->s0[i]] = ocp.x0[i];
    nlp.x_lb[b->s0[i]] = x0_free ? std::max(lower(ocp.lbx0, i), lower(ocp.lbx, i)) : ocp.x0[i];
    nlp.x_ub[b->s0[i]] = x0_free ? std::min(upper(ocp.ubx0, i), upper(ocp.ubx, i)) : ocp.x0[i];
  }
  b->p = range(nlp.add_variables(n_p, 0.0, 0.0, 0.0), n_p);
  for (int i = 0; i < n_p; ++i) nlp.x_lb[b->p[i]] = nlp.x_ub[b->p[i]] = nlp.x_init[b->p[i]] = p[i];
  // The standard method does not use lambda_{0,0}: fixed dummies.
  std::vector<int> dummy_lambda, dummy_mu;
  if (!d.use_fesd) {
    dummy_lambda = range(nlp.add_variables(n_th, 0.0, 0.0, 0.0), n_th);
    dummy_mu = range(nlp.add_variables(n_sys, 0.0, 0.0, 0.0), n_sys);
  }

  const std::vector<int> N_FE = intervals_N_FE(ocp, o);
  const double T_k = ocp.T / ocp.N_stages;
  for (int k = 0; k < ocp.N_stages; ++k) {
    std::vector<int> q = range(nlp.add_variables(n_u, 0.0, 0.0, 0.0), n_u);
    for (int i = 0; i < n_u; ++i) {
      nlp.x_lb[q[i]] = lower(ocp.lbu, i);
      nlp.x_ub[q[i]] = upper(ocp.ubu, i);
      const double g = ocp.u_guess.size() > 0 ? ocp.u_guess[i] : 0.0;
      nlp.x_init[q[i]] = std::clamp(g, nlp.x_lb[q[i]], nlp.x_ub[q[i]]);
    }
    b->q.push_back(q);
    IntervalInputs in;
    in.q = q;
    in.p = b->p;
    in.T = T_k;
    in.boundary_at_end = true;  // non-stiffly-accurate schemes: lambda at s_{k+1} for the next
    if (k == 0) {
      in.s0 = b->s0;
      if (d.use_fesd) {  // lambda_{0,0}, mu_{0,0} tied to s0 by the LP (9): s0 may be free
        in.lambda_start = range(nlp.add_variables(n_th, 0.0, kInf, 0.0), n_th);
        in.mu_start = range(nlp.add_variables(n_sys, -kInf, kInf, 0.0), n_sys);
        in.lp_at_start = true;
      } else {
        in.lambda_start = dummy_lambda;
        in.mu_start = dummy_mu;
      }
    } else {
      const FesdInterval& prev = *b->iv.back();
      in.s0 = range(prev.x(prev.N_FE(), 0), n_x);
      if (d.use_fesd) {  // continuity of lambda, mu across the interval boundary (27)
        for (int r = 0; r < n_th; ++r)
          in.lambda_start.push_back(prev.lambda_end(prev.N_FE() - 1, r));
        for (int j = 0; j < n_sys; ++j) in.mu_start.push_back(prev.mu_end(prev.N_FE() - 1, j));
      } else {
        in.lambda_start = dummy_lambda;
        in.mu_start = dummy_mu;
      }
    }
    DiscretizationOptions dk = d;
    dk.N_FE = N_FE[k];
    b->iv.push_back(std::make_unique<FesdInterval>(m, b->tab, dk));
    b->iv.back()->build(nlp, in);
    b->in.push_back(in);
  }

  // ---- state bounds, costs, path constraints per element ----
  const OcpFunctions* f = ocp.functions.get();
  std::vector<double> bw;
  for (int j = 0; j < b->tab.n_s; ++j) bw.push_back(b->tab.b(j));
  auto lagrange = f && f->has_f_q() ? nlp::make_block(LagrangeTerm{f, bw, n_x, n_u, n_p}) : nullptr;
  auto path =
      ocp.n_g_path > 0 ? nlp::make_block(PathConstraint{f, n_x, n_u, n_p, ocp.n_g_path}) : nullptr;
  std::vector<double> path_lb(ocp.n_g_path), path_ub(ocp.n_g_path);
  for (int i = 0; i < ocp.n_g_path; ++i) {
    path_lb[i] = lower(ocp.lbg_path, i);
    path_ub[i] = upper(ocp.ubg_path, i);
  }
  auto bound_state = [&](int first) {
    for (int i = 0; i < n_x; ++i) {
      nlp.x_lb[first + i] = std::max(nlp.x_lb[first + i], lower(ocp.lbx, i));
      nlp.x_ub[first + i] = std::min(nlp.x_ub[first + i], upper(ocp.ubx, i));
    }
  };
  auto add_path = [&](int x_first, const std::vector<int>& q) {
    if (!path) return;
    std::vector<int> vars = range(x_first, n_x);
    vars.insert(vars.end(), q.begin(), q.end());
    vars.insert(vars.end(), b->p.begin(), b->p.end());
    nlp.add_constraint(path, vars, path_lb, path_ub);
  };
  add_path(b->s0[0], b->q[0]);
  for (int k = 0; k < ocp.N_stages; ++k) {
    const FesdInterval& iv = *b->iv[k];
    for (int n = 0; n < iv.N_FE(); ++n) {
      bound_state(iv.x(n + 1, 0));
      add_path(iv.x(n + 1, 0), b->q[k]);
      if (o.constraints_at_stages)
        for (int s = 0; s < iv.n_s(); ++s) {
          bound_state(iv.X(n, s, 0));
          add_path(iv.X(n, s, 0), b->q[k]);
        }
      if (lagrange) {
        std::vector<int> vars{iv.h(n)};
        for (int s = 0; s < iv.n_s(); ++s)
          for (int i = 0; i < n_x; ++i) vars.push_back(iv.X(n, s, i));
        vars.insert(vars.end(), b->q[k].begin(), b->q[k].end());
        vars.insert(vars.end(), b->p.begin(), b->p.end());
        nlp.add_objective(lagrange, vars);
      }
    }
  }

  // ---- terminal cost and constraints at s_N ----
  const FesdInterval& last = *b->iv.back();
  std::vector<int> xp = range(last.x(last.N_FE(), 0), n_x);
  xp.insert(xp.end(), b->p.begin(), b->p.end());
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
      b->terminal_slacks = range(nlp.add_variables(n_g, 0.0, kInf, 0.0), n_g);
      std::vector<int> vars = xp;
      vars.insert(vars.end(), b->terminal_slacks.begin(), b->terminal_slacks.end());
      std::vector<double> lb2(2 * n_g, -kInf), ub2(2 * n_g, kInf);
      for (int i = 0; i < n_g; ++i) {
        ub2[i] = ub[i];
        lb2[n_g + i] = lb[i];
      }
      nlp.add_constraint(nlp::make_block(TerminalConstraintEq{f, n_x, n_p, n_g, true}), vars, lb2,
                         ub2);
      nlp.add_objective(nlp::make_block(nlp::Sum{n_g}), b->terminal_slacks, ocp.rho_terminal);
    }
  }

  for (const auto& iv : b->iv) {
    b->groups.insert(b->groups.end(), iv->groups().begin(), iv->groups().end());
    b->residual_pairs.insert(b->residual_pairs.end(), iv->residual_pairs().begin(),
                             iv->residual_pairs().end());
  }
  return b;
}

// ---- initial guess -----------------------------------------------------------------------------

/// Constant: x0 everywhere, algebraic variables from LP(x0) (Sect. 5.2).
void guess_constant(OcpNlp& b, const Ocp& ocp, const Eigen::VectorXd& p) {
  const dcs::LpSolution lp = dcs::solve_lp(ocp.model, ocp.x0, p);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(ocp.model.n_x());
  for (const auto& iv : b.iv) iv->set_guess(b.nlp, ocp.x0, lp, zero);
  auto& w = b.nlp.x_init;
  const auto& in0 = b.in.front();
  if (in0.lp_at_start) {
    for (int r = 0; r < ocp.model.n_theta(); ++r) w[in0.lambda_start[r]] = lp.lambda[r];
    for (int j = 0; j < ocp.model.n_sys(); ++j) w[in0.mu_start[j]] = lp.mu[j];
  }
  for (int i = 0; i < ocp.model.n_x(); ++i) w[b.s0[i]] = ocp.x0[i];
}

/// Simulation: the FESD integrator from x0 with u_guess on the same grid (one integration step
/// per control interval). Falls back to the constant guess (returns false) if the integrator
/// fails or its grid differs (split steps, different N_FE per interval).
bool guess_simulation(OcpNlp& b, const Ocp& ocp, const OcpOptions& o, const Eigen::VectorXd& p) {
  const Pss& m = ocp.model;
  const std::vector<int> N_FE = intervals_N_FE(ocp, o);
  for (int n : N_FE)
    if (n != N_FE.front()) return false;
  IntegratorOptions io;
  io.discretization = o.discretization;
  io.discretization.N_FE = N_FE.front();
  // A near-uniform grid: the simulation's h_n are not unique without step equilibration, and a
  // guess with elements at their bounds traps a switch at its element boundary.
  io.discretization.step_eq = StepEq::HeuristicMean;
  // The simulation gets its own homotopy from sigma = 1 (the OCP's may start at a tiny fixed
  // sigma, from which a simulation without a guess does not converge), to the OCP's tolerance.
  io.homotopy = HomotopyOptions{};
  io.homotopy.sigma_N = std::min(o.homotopy.sigma_N, io.homotopy.sigma_0);
  io.homotopy.complementarity_tol = o.homotopy.complementarity_tol;
  io.nlp = o.nlp;
  io.nlp.print_level = 0;
  const Eigen::VectorXd u = ocp.u_guess.size() > 0 ? ocp.u_guess : Eigen::VectorXd::Zero(m.n_u());
  const IntegratorResult r = integrate(m, ocp.x0, ocp.T, ocp.N_stages, io, u, p);
  const int n_s = b.tab.n_s, n_x = m.n_x(), n_th = m.n_theta(), n_sys = m.n_sys();
  const std::size_t elements = static_cast<std::size_t>(N_FE.front() * ocp.N_stages);
  if (r.status != Status::Success || r.h.size() != elements) return false;
  guess_constant(b, ocp, p);  // everything the simulation does not give
  auto& w = b.nlp.x_init;
  int e = 0;
  for (const auto& ivp : b.iv) {
    const FesdInterval& iv = *ivp;
    for (int n = 0; n < iv.N_FE(); ++n, ++e) {
      w[iv.h(n)] = std::clamp(r.h[e], b.nlp.x_lb[iv.h(n)], b.nlp.x_ub[iv.h(n)]);
      for (int i = 0; i < n_x; ++i) w[iv.x(n + 1, i)] = r.x[e + 1][i];
      for (int s = 0; s < n_s; ++s) {
        const std::size_t st = static_cast<std::size_t>(e * n_s + s);
        Eigen::VectorXd V(n_x);
        dcs::eval_F_theta<double>(m, r.x_stage[st].data(), u.data(), p.data(), r.theta[st].data(),
                                  V.data());
        for (int i = 0; i < n_x; ++i) {
          w[iv.X(n, s, i)] = r.x_stage[st][i];
          w[iv.V(n, s, i)] = V[i];
        }
        for (int k = 0; k < n_th; ++k) {
          w[iv.theta(n, s, k)] = r.theta[st][k];
          w[iv.lambda(n, s, k)] = r.lambda[st][k];
        }
        for (int j = 0; j < n_sys; ++j) w[iv.mu(n, s, j)] = r.mu[st][j];
      }
      if (iv.lambda_end(n, 0) >= 0 && !(iv.lambda_end(n, 0) == iv.lambda(n, n_s - 1, 0))) {
        const dcs::LpSolution lp = dcs::solve_lp(m, r.x[e + 1], p);
        for (int k = 0; k < n_th; ++k) w[iv.lambda_end(n, k)] = lp.lambda[k];
        for (int j = 0; j < n_sys; ++j) w[iv.mu_end(n, j)] = lp.mu[j];
      }
    }
    iv.update_lifted_guess(b.nlp);
  }
  return true;
}

// ---- results -----------------------------------------------------------------------------------

void extract(const OcpNlp& b, const Ocp& ocp, const std::vector<double>& w,
             const Eigen::VectorXd& p, OcpResult& res) {
  const Pss& m = ocp.model;
  const int n_x = m.n_x(), n_th = m.n_theta(), n_u = m.n_u();
  const double T_k = ocp.T / ocp.N_stages;
  double t = 0;
  res.t = {0.0};
  res.x = {gather(w, b.s0[0], n_x)};
  double objective = 0;
  const OcpFunctions* f = ocp.functions.get();
  for (int k = 0; k < ocp.N_stages; ++k) {
    const FesdInterval& iv = *b.iv[k];
    const Eigen::VectorXd q = gather(w, b.q[k].empty() ? 0 : b.q[k][0], n_u);
    res.u.push_back(q);
    res.t_ctrl.push_back(k * T_k);
    const std::vector<double> eta = iv.eta(w.data());
    for (int n = 0; n < iv.N_FE(); ++n) {
      const double hn = w[iv.h(n)];
      const std::vector<int> active = iv.active_set(w.data(), n);
      double quad = 0;
      for (int s = 0; s < iv.n_s(); ++s) {
        res.t_stage.push_back(t + b.tab.c(s) * hn);
        const Eigen::VectorXd X = gather(w, iv.X(n, s, 0), n_x);
        res.x_stage.push_back(X);
        res.theta.push_back(gather(w, iv.theta(n, s, 0), n_th));
        res.lambda.push_back(gather(w, iv.lambda(n, s, 0), n_th));
        if (f && f->has_f_q()) quad += b.tab.b(s) * f->f_q(X.data(), q.data(), p.data());
      }
      objective += hn * quad;
      if (!res.active_set.empty() && res.active_set.back() != active)
        res.switches.push_back(
            {t, static_cast<int>(res.h.size()) - 1, res.active_set.back(), active});
      res.active_set.push_back(active);
      res.h.push_back(hn);
      res.interval.push_back(k);
      res.eta.push_back(eta[n]);
      t += hn;
      res.t.push_back(t);
      res.x.push_back(gather(w, iv.x(n + 1, 0), n_x));
    }
  }
  res.t_ctrl.push_back(ocp.T);
  if (f && f->has_f_q_T()) objective += f->f_q_T(res.x.back().data(), p.data());
  for (int s : b.terminal_slacks) objective += ocp.rho_terminal * w[s];
  res.objective = objective;
}

}  // namespace

std::vector<std::string> validate(const OcpOptions& o) {
  std::vector<std::string> e = validate(o.discretization);
  for (auto& s : validate(o.homotopy)) e.push_back(std::move(s));
  for (auto& s : validate(o.nlp)) e.push_back(std::move(s));
  return e;
}

OcpResult solve(const Ocp& ocp, const OcpOptions& options) {
  const auto t_start = Clock::now();
  check_input(ocp, options);
  const Eigen::VectorXd p = ocp.p.size() > 0 ? ocp.p : ocp.model.p_default;
  if (p.size() != ocp.model.n_p())
    throw InvalidModel(
        fmt::format("ocp.p has {} entries, expected n_p = {}", p.size(), ocp.model.n_p()));

  std::unique_ptr<OcpNlp> b = build(ocp, options, p);
  OcpResult res;
  res.mpcc_mode = options.homotopy.mpcc_mode;
  bool simulated = false;
  if (options.initialization == OcpInitialization::Simulation)
    simulated = guess_simulation(*b, ocp, options, p);
  if (!simulated) guess_constant(*b, ocp, p);
  const mpcc::Relaxation relaxation(b->nlp, b->groups, options.homotopy.mpcc_mode);
  b->nlp.finalize();
  res.n_variables = b->nlp.num_variables();
  res.n_constraints = b->nlp.num_constraints();
  res.setup_s = seconds_since(t_start);

  nlp::IpoptSolver solver(options.nlp);
  nlp::Iterate it;
  it.x = b->nlp.x_init;
  if (options.progress)
    std::fprintf(stderr, "%4s %9s %10s %14s %9s %5s  %-26s %8s\n", "k", "sigma", "comp",
                 "objective", "inf_pr", "iter", "IPOPT status", "time s");
  auto on_row = [&](const HomotopyRow& r) {
    if (options.progress)
      std::fprintf(stderr, "%4d %9.1e %10.2e %14.7e %9.1e %5d  %-26s %8.3f\n", r.k, r.sigma,
                   r.comp_residual, r.objective, r.inf_pr, r.nlp_iterations, r.nlp_status.c_str(),
                   r.cpu_s);
  };
  mpcc::HomotopyResult hr = mpcc::solve_homotopy(b->nlp, relaxation, b->residual_pairs, solver, it,
                                                 options.homotopy, on_row);
  res.homotopy = hr.rows;
  res.nlp_iterations = hr.nlp_iterations;
  res.derivative_s = hr.eval_s;
  res.solver_s = hr.solver_s;
  // Sliding exits left early (docs/formulation.md): pin them and solve the last NLP once more;
  // if that fails, the unpinned solution stays.
  if (hr.status == Status::Success && options.discretization.pin_sliding_exits &&
      b->iv.front()->can_pin_exits()) {
    // Per control interval: at their boundaries the control jumps, and with it the sliding
    // vector field, so a mode may end there with theta > 0; one that ends inside the last
    // element of an interval is kept on the surface up to the boundary instead.
    std::vector<std::pair<int, FesdInterval::ExitPin>> pins;  // (interval, pin)
    for (int k = 0; k < ocp.N_stages; ++k)
      for (const auto& pin : b->iv[k]->exits_to_pin(it.x.data(), /*control_jump_at_end=*/true))
        pins.emplace_back(k, pin);
    if (!pins.empty()) {
      const mpcc::HomotopyResult again =
          mpcc::solve_again(b->nlp, relaxation, b->residual_pairs, solver, it, hr.rows.back().sigma,
                            static_cast<int>(hr.rows.size()), options.homotopy,
                            [&](nlp::BlockNlp& problem, std::vector<double>& point) {
                              for (const auto& [k, pin] : pins)
                                b->iv[k]->pin_exit(problem, point, pin);
                            });
      on_row(again.rows.back());
      if (options.progress)
        std::fprintf(stderr, "%4s (row %d: the last NLP again, %zu sliding exit%s pinned%s)\n", "",
                     again.rows.back().k, pins.size(), pins.size() == 1 ? "" : "s",
                     again.status == Status::Success ? "" : "; failed, unpinned solution kept");
      res.homotopy.push_back(again.rows.back());
      res.nlp_iterations += again.nlp_iterations;
      res.derivative_s += again.eval_s;
      res.solver_s += again.solver_s;
      if (again.status == Status::Success) {
        res.pinned_exits = static_cast<int>(pins.size());
        hr.comp_residual = again.comp_residual;
      } else {
        res.pin_failed = true;
      }
    }
  }
  res.status = hr.status;
  res.comp_residual = hr.comp_residual;
  extract(*b, ocp, it.x, p, res);
  res.message = res.status == Status::Success
                    ? std::string(describe(Status::Success))
                    : fmt::format("{} (last IPOPT status {}, complementarity residual {:.2e})",
                                  describe(hr.status), hr.last_nlp_status, hr.comp_residual);
  if (options.initialization == OcpInitialization::Simulation && !simulated)
    res.message += " [the initializing simulation failed or used another grid: constant guess]";
  res.wall_s = seconds_since(t_start);
  return res;
}

std::string OcpResult::report() const {
  std::ostringstream os;
  auto vec = [](const Eigen::VectorXd& v) {
    std::string s;
    for (Eigen::Index i = 0; i < v.size(); ++i) s += fmt::format("{}{:.10g}", i ? ", " : "", v[i]);
    return "[" + s + "]";
  };
  os << fmt::format("fesd optimal control: {}\n", to_string(status));
  os << fmt::format("  status               {} ({})\n", to_string(status), message);
  os << fmt::format("  objective            {:.12g}\n", objective);
  os << fmt::format("  MPCC method          {}, final complementarity residual {:.2e}\n",
                    to_string(mpcc_mode), comp_residual);
  if (!x.empty()) {
    os << fmt::format("  x(0)                 {}\n", vec(x.front()));
    os << fmt::format("  x(T)                 {}\n", vec(x.back()));
  }
  os << fmt::format("  switches             {}\n", switches.size());
  for (const auto& s : switches) os << detail::format_switch(s);
  os << fmt::format("  NLP size             {} variables, {} constraints\n", n_variables,
                    n_constraints);
  os << fmt::format("  homotopy             {} NLPs, {} IPOPT iterations\n", homotopy.size(),
                    nlp_iterations);
  if (pinned_exits > 0 || pin_failed)
    os << fmt::format("  sliding exits        {}\n",
                      pin_failed
                          ? "pinning failed (unpinned solution kept)"
                          : fmt::format("{} pinned (last row: the pinned NLP)", pinned_exits));
  os << fmt::format("    {:>3} {:>9} {:>10} {:>14} {:>9} {:>5}  {:<26} {:>8}\n", "k", "sigma",
                    "comp", "objective", "inf_pr", "iter", "IPOPT status", "time s");
  for (const auto& r : homotopy)
    os << fmt::format("    {:>3} {:>9.1e} {:>10.2e} {:>14.7e} {:>9.1e} {:>5}  {:<26} {:>8.3f}\n",
                      r.k, r.sigma, r.comp_residual, r.objective, r.inf_pr, r.nlp_iterations,
                      r.nlp_status, r.cpu_s);
  const double busy = derivative_s + solver_s;
  os << fmt::format("  wall time            {:.3f} s\n", wall_s);
  os << fmt::format("    derivatives        {:.3f} s  ({:.0f} %)\n", derivative_s,
                    busy > 0 ? 100 * derivative_s / busy : 0.0);
  os << fmt::format("    IPOPT + MUMPS      {:.3f} s  ({:.0f} %)\n", solver_s,
                    busy > 0 ? 100 * solver_s / busy : 0.0);
  os << fmt::format("    setup              {:.3f} s\n", setup_s);
  return os.str();
}

}  // namespace fesd
