// src/ocp/ocp.cpp: the discretized OCP (59): control intervals chained by their boundary states
// s_k (multiple-shooting type, Sect. 5.1), one FesdInterval per interval, costs and constraints as
// blocks, the MPCC solved by a homotopy (Sect. 5.2).
#include "fesd/ocp.hpp"
#include "core/util.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <tuple>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/limits.hpp"
#include "dcs/step.hpp"
#include "dcs/stewart.hpp"
#include "discretization/fesd_interval.hpp"
#include "fesd/error.hpp"
#include "mpcc/problem.hpp"
#include "nlp/block.hpp"
#include "nlp/block_nlp.hpp"
#include "nlp/nlp_solver.hpp"
#include "nlp/sum_block.hpp"
#include "ocp/allocation.hpp"
#include "ocp/ocp_checks.hpp"
#include "ocp/ocp_input.hpp"
#include "ocp/ocp_terms.hpp"
#include "ocp/resolve_account.hpp"
#include "ocp/speed_of_time.hpp"

namespace fesd {
namespace {

using util::gather;
using util::seconds_since;

using Clock = std::chrono::steady_clock;
using discretization::FesdInterval;
using discretization::IntervalInputs;
using nlp::kInf;
using ocp_detail::control_guess;
using ocp_detail::LagrangeTerm;
using ocp_detail::MayerTerm;
using ocp_detail::range;
using ocp_detail::ResolveAccount;
using ocp_detail::StageParameters;
using ocp_detail::TerminalConstraintEq;

std::vector<int> intervals_N_FE(const Ocp& ocp, const OcpOptions& o) {
  if (ocp.N_FE.empty()) return std::vector<int>(ocp.N_stages, o.discretization.N_FE);
  return ocp.N_FE;
}

// ---- the NLP -----------------------------------------------------------------------------------

/// The MPCC of the OCP (59)-(60) and where its pieces live.
struct OcpNlp : ocp_detail::OcpNlpParts<FesdInterval> {
  std::vector<IntervalInputs> in;
  DcsMode mode = DcsMode::Stewart;
};

std::unique_ptr<OcpNlp> build(const Ocp& ocp, const OcpOptions& o, const StageParameters& p) {
  const Pss& m = ocp.model;
  const DiscretizationOptions& d = o.discretization;
  const int n_x = m.n_x(), n_u = m.n_u();
  // multipliers per point: Stewart lambda (n_theta), mu (n_sys); step (lambda_n, lambda_p)
  const int n_th = dcs::n_lambda(m, d.dcs_mode), n_sys = dcs::n_mu(m, d.dcs_mode);
  auto b = std::make_unique<OcpNlp>();
  b->mode = d.dcs_mode;
  b->tab = make_tableau(d.rk_scheme, d.n_s);
  mpcc::Problem& mp = b->mpcc;
  nlp::BlockNlp& nlp = mp.nlp();

  ocp_detail::add_start_and_parameters(mp, ocp, p, b->s0, b->p, b->p_k);
  // The standard method does not use lambda_{0,0}: fixed dummies.
  std::vector<int> dummy_lambda, dummy_mu;
  if (!d.use_fesd) {
    dummy_lambda = range(nlp.add_variables(n_th, 0.0, 0.0, 0.0), n_th);
    dummy_mu = range(nlp.add_variables(n_sys, 0.0, 0.0, 0.0), n_sys);
  }

  const std::vector<int> N_FE = intervals_N_FE(ocp, o);
  const double T_k = ocp.T / ocp.N_stages;
  for (int k = 0; k < ocp.N_stages; ++k) {
    std::vector<int> q = ocp_detail::add_control(mp, ocp, n_u, k);
    b->q.push_back(q);
    IntervalInputs in;
    in.q = q;
    in.p = b->p_k[static_cast<std::size_t>(k)];
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

  ocp_detail::add_ocp_terms(mp, ocp, o, b->tab, n_x, n_u, b->s0, b->p_k, b->q, b->iv,
                            b->terminal_slacks, b->comp_points);
  ocp_detail::add_rk_comp(*b, ocp, ocp_detail::rk_algebraic(m), d.dcs_mode == DcsMode::Step, n_x);
  std::vector<int> clock_end;  // time freezing: the clock at every control interval's end
  if (ocp.time_freezing)
    for (const auto& iv : b->iv) clock_end.push_back(iv->x(iv->N_FE(), ocp.clock_state));
  ocp_detail::add_speed_of_time_constraints(mp, ocp, b->p_k, clock_end);
  for (const auto& iv : b->iv) mp.add_complementarity(iv->groups(), iv->residual_pairs());
  mp.relax(o.homotopy);
  return b;
}

// ---- initial guess -----------------------------------------------------------------------------

/// Constant: x0 everywhere, algebraic variables from LP(x0) (Sect. 5.2), with each interval's
/// parameters.
void guess_constant(OcpNlp& b, const Ocp& ocp, const StageParameters& p) {
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(ocp.model.n_x());
  auto& w = b.mpcc.guess();
  for (std::size_t k = 0; k < b.iv.size(); ++k)
    b.iv[k]->set_guess(w, ocp.x0, dcs::solve_start(ocp.model, b.mode, ocp.x0, p[k]), zero);
  const dcs::LpSolution lp = dcs::solve_start(ocp.model, b.mode, ocp.x0, p.front());
  const auto& in0 = b.in.front();
  if (in0.lp_at_start) {
    for (std::size_t r = 0; r < in0.lambda_start.size(); ++r) w[in0.lambda_start[r]] = lp.lambda[r];
    for (std::size_t j = 0; j < in0.mu_start.size(); ++j) w[in0.mu_start[j]] = lp.mu[j];
  }
  for (int i = 0; i < ocp.model.n_x(); ++i) w[b.s0[i]] = ocp.x0[i];
}

/// External: Ocp::x_guess, linear in t on each control interval, the algebraic variables of
/// interval k from LP at its midpoint with its parameters. x0 keeps its value unless it is free.
void guess_external(OcpNlp& b, const Ocp& ocp, const StageParameters& p) {
  const Pss& m = ocp.model;
  auto& w = b.mpcc.guess();
  const double T_k = ocp.T / ocp.N_stages;
  for (std::size_t k = 0; k < b.iv.size(); ++k) {
    const Eigen::VectorXd& a = ocp.x_guess[k];
    const Eigen::VectorXd& e = ocp.x_guess[k + 1];
    b.iv[k]->set_guess(w, a, dcs::solve_start(m, b.mode, 0.5 * (a + e), p[k]), (e - a) / T_k);
  }
  const Eigen::VectorXd start = ocp.lbx0.size() > 0 ? ocp.x_guess.front() : ocp.x0;
  for (int i = 0; i < m.n_x(); ++i)
    w[b.s0[i]] = std::clamp(start[i], b.mpcc.lower(b.s0[i]), b.mpcc.upper(b.s0[i]));
  const auto& in0 = b.in.front();
  if (in0.lp_at_start) {
    const dcs::LpSolution lp = dcs::solve_start(m, b.mode, start, p.front());
    for (std::size_t r = 0; r < in0.lambda_start.size(); ++r) w[in0.lambda_start[r]] = lp.lambda[r];
    for (std::size_t j = 0; j < in0.mu_start.size(); ++j) w[in0.mu_start[j]] = lp.mu[j];
  }
  for (const auto& iv : b.iv) iv->update_lifted_guess(w);
}

/// OcpOptions::initial_theta: every theta of the guess = value (Stewart's form, validated).
void guess_theta(OcpNlp& b, double value) {
  auto& w = b.mpcc.guess();
  for (const auto& iv : b.iv) {
    for (int n = 0; n < iv->N_FE(); ++n)
      for (int m = 0; m < iv->n_s(); ++m)
        for (int r = 0; r < iv->n_comp(); ++r) w[iv->theta(n, m, r)] = value;
    iv->update_lifted_guess(w);
  }
}

/// Time freezing: the clock state of the guess, where it violates the clock constraints (a
/// constant guess), linear in tau from t(0) to t(0) + T, as if time never froze; with
/// time_freezing_tolerance the guess at every interval end is then within the bounds.
void guess_clock(OcpNlp& b, const Ocp& ocp) {
  auto& w = b.mpcc.guess();
  const int c = ocp.clock_state;
  const double t0 = ocp.x0[c], T_k = ocp.T / ocp.N_stages;
  for (std::size_t k = 0; k < b.iv.size(); ++k) {
    const FesdInterval& iv = *b.iv[k];
    const int end = iv.x(iv.N_FE(), c);
    if (w[end] >= b.mpcc.lower(end) && w[end] <= b.mpcc.upper(end)) continue;
    const double start = t0 + static_cast<double>(k) * T_k, h = T_k / iv.N_FE();
    for (int n = 0; n < iv.N_FE(); ++n) {
      for (int s = 0; s < iv.n_s(); ++s) w[iv.X(n, s, c)] = start + (n + b.tab.c(s)) * h;
      w[iv.x(n + 1, c)] = start + (n + 1) * h;
    }
  }
}

/// Simulation: the FESD integrator from x0 with u_guess on the same grid (one integration step
/// per control interval). Falls back to the constant guess (returns false) if the integrator
/// fails or its grid differs (split steps, different N_FE per interval).
bool guess_simulation(OcpNlp& b, const Ocp& ocp, const OcpOptions& o, const StageParameters& p) {
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
  // One integration step per control interval: in one run when every interval has the same
  // control guess and parameters, else interval by interval (each from the previous end).
  IntegratorResult r;
  if (ocp.p_stage.empty() && ocp.u_guess_stage.empty()) {
    r = integrate(m, ocp.x0, ocp.T, ocp.N_stages, io, control_guess(ocp, 0, m.n_u()), p.front());
  } else {
    r.x = {ocp.x0};
    r.status = Status::Success;
    for (int k = 0; k < ocp.N_stages && r.status == Status::Success; ++k) {
      const IntegratorResult rk =
          integrate(m, r.x.back(), ocp.T / ocp.N_stages, 1, io, control_guess(ocp, k, m.n_u()),
                    p[static_cast<std::size_t>(k)]);
      r.status = rk.status;
      if (rk.status != Status::Success || rk.x.empty()) break;
      r.h.insert(r.h.end(), rk.h.begin(), rk.h.end());
      r.x.insert(r.x.end(), rk.x.begin() + 1, rk.x.end());
      for (auto [to, from] : {std::pair{&r.x_stage, &rk.x_stage}, std::pair{&r.theta, &rk.theta},
                              std::pair{&r.lambda, &rk.lambda}, std::pair{&r.mu, &rk.mu},
                              std::pair{&r.alpha, &rk.alpha}, std::pair{&r.lambda_n, &rk.lambda_n},
                              std::pair{&r.lambda_p, &rk.lambda_p}})
        to->insert(to->end(), from->begin(), from->end());
    }
  }
  const int n_s = b.tab.n_s, n_x = m.n_x(), n_th = m.n_theta(), n_sys = m.n_sys();
  const std::size_t elements = static_cast<std::size_t>(N_FE.front() * ocp.N_stages);
  if (r.status != Status::Success || r.h.size() != elements) return false;
  guess_constant(b, ocp, p);  // everything the simulation does not give
  auto& w = b.mpcc.guess();
  int e = 0;
  for (std::size_t iv_k = 0; iv_k < b.iv.size(); ++iv_k) {
    const FesdInterval& iv = *b.iv[iv_k];
    const Eigen::VectorXd u = control_guess(ocp, static_cast<int>(iv_k), m.n_u());
    const Eigen::VectorXd& pk = p[iv_k];
    for (int n = 0; n < iv.N_FE(); ++n, ++e) {
      w[iv.h(n)] = std::clamp(r.h[e], b.mpcc.lower(iv.h(n)), b.mpcc.upper(iv.h(n)));
      for (int i = 0; i < n_x; ++i) w[iv.x(n + 1, i)] = r.x[e + 1][i];
      for (int s = 0; s < n_s; ++s) {
        const std::size_t st = static_cast<std::size_t>(e * n_s + s);
        Eigen::VectorXd V(n_x);
        dcs::eval_F_theta<double>(m, r.x_stage[st].data(), u.data(), pk.data(), r.theta[st].data(),
                                  V.data());
        for (int i = 0; i < n_x; ++i) {
          w[iv.X(n, s, i)] = r.x_stage[st][i];
          w[iv.V(n, s, i)] = V[i];
        }
        for (int k = 0; k < n_th; ++k) w[iv.theta(n, s, k)] = r.theta[st][k];
        if (iv.step_mode()) {
          const int n_c = m.n_c();
          for (int j = 0; j < n_c; ++j) {
            w[iv.alpha(n, s, j)] = r.alpha[st][j];
            w[iv.alpha(n, s, n_c + j)] = 1.0 - r.alpha[st][j];
            w[iv.lambda(n, s, j)] = r.lambda_n[st][j];
            w[iv.lambda(n, s, n_c + j)] = r.lambda_p[st][j];
          }
        } else {
          for (int k = 0; k < n_th; ++k) w[iv.lambda(n, s, k)] = r.lambda[st][k];
          for (int j = 0; j < n_sys; ++j) w[iv.mu(n, s, j)] = r.mu[st][j];
        }
      }
      if (iv.lambda_end(n, 0) >= 0 && !(iv.lambda_end(n, 0) == iv.lambda(n, n_s - 1, 0))) {
        const dcs::LpSolution lp = dcs::solve_start(m, b.mode, r.x[e + 1], pk);
        for (int k = 0; k < iv.n_lambda(); ++k) w[iv.lambda_end(n, k)] = lp.lambda[k];
        for (int j = 0; j < iv.n_mu(); ++j) w[iv.mu_end(n, j)] = lp.mu[j];
      }
    }
    iv.update_lifted_guess(w);
  }
  return true;
}

// ---- results -----------------------------------------------------------------------------------

void extract(const OcpNlp& b, const Ocp& ocp, const std::vector<double>& w,
             const StageParameters& /*fixed*/, OcpResult& res) {
  const Pss& m = ocp.model;
  const StageParameters p = ocp_detail::solution_parameters(b.p_k, w);  // free ones included
  const int n_th = m.n_theta();
  ocp_detail::extract_result(
      ocp, b.tab, m.n_x(), m.n_u(), b.s0, b.q, b.iv, b.terminal_slacks, w, p, res,
      [&](const FesdInterval& iv, int n, int s) {
        res.theta.push_back(gather(w, iv.theta(n, s, 0), n_th));
        discretization::append_stage_multipliers(iv, m, w, n, s, res);
      },
      [&](const FesdInterval& iv) { return iv.eta(w.data()); });
}

/// The OCP's own cost (59a) at the NLP point w.
double cost(const OcpNlp& b, const Ocp& ocp, const std::vector<double>& w,
            const StageParameters& p) {
  OcpResult r;
  extract(b, ocp, w, p, r);
  return r.objective;
}

/// The bounds that fix the active set of every element (FesdInterval::pin_bounds) at w, with the
/// sliding exits of each interval pinned when `pin` (and its scheme can pin). Intervals without
/// an exit to pin are fixed only if `every_interval`; interval `skip` not at all (the caller
/// gives its bounds). Returns the number of pinned exits.
int fix_active_sets(const OcpNlp& b, const std::vector<double>& w, bool pin, bool every_interval,
                    std::vector<nlp::Bound>& bounds,
                    std::size_t skip = std::numeric_limits<std::size_t>::max()) {
  int n_pins = 0;
  for (std::size_t k = 0; k < b.iv.size(); ++k) {
    const FesdInterval& iv = *b.iv[k];
    std::vector<FesdInterval::ExitPin> pins;
    if (pin && iv.can_pin_exits()) pins = iv.exits_to_pin(w.data(), /*control_jump_at_end=*/true);
    if (k == skip || (pins.empty() && !every_interval)) continue;
    n_pins += static_cast<int>(pins.size());
    for (const nlp::Bound& bd : iv.pin_bounds(w.data(), pins)) bounds.push_back(bd);
  }
  return n_pins;
}

/// The early end of the homotopy (HomotopyOptions::active_set_sigma) as a finish hook of
/// solve_homotopy(): after an NLP with sigma <= active_set_sigma whose active sets (every element
/// of every interval) equal those of the NLP before, solve once more with them fixed and the
/// sliding exits pinned; a converged solve ends the homotopy (`finished` set), a failed one lets
/// it go on from where it was.
std::function<bool(mpcc::HomotopyResult&)> early_active_set_finish(OcpNlp& b, const OcpOptions& o,
                                                                   nlp::NlpSolver& solver,
                                                                   Summary& summary,
                                                                   bool& finished) {
  if (!(o.homotopy.active_set_sigma > 0) || !b.iv.front()->can_pin_exits()) return {};
  using ActiveSets = std::vector<std::vector<std::vector<int>>>;  // interval, element, regions
  struct Seen {
    ActiveSets before, failed;
  };
  auto seen = std::make_shared<Seen>();
  return [&b, &o, &solver, &summary, &finished, seen](mpcc::HomotopyResult& h) {
    mpcc::Problem& mp = b.mpcc;
    ActiveSets now;
    for (const auto& iv : b.iv) now.push_back(iv->active_sets(mp.solution().data()));
    const bool stable = now == seen->before;
    seen->before = now;
    // Active sets whose fixed NLP failed are not tried again.
    if (!stable || now == seen->failed || !(h.rows.back().sigma <= o.homotopy.active_set_sigma))
      return false;
    std::vector<nlp::Bound> bounds;
    const int n_pins = fix_active_sets(b, mp.solution(), o.discretization.pin_sliding_exits,
                                       /*every_interval=*/true, bounds);
    const mpcc::HomotopyResult again = mp.solve_again(solver, o.homotopy, bounds, n_pins);
    if (o.on_homotopy_row) o.on_homotopy_row(again.rows.back());
    // A failed re-solve is discarded (solve_again keeps the point before): counted, but the
    // residual and status stay the kept point's (else it would end the homotopy as a success
    // when this was its last NLP).
    if (again.status != Status::Success) {
      mpcc::append_discarded(h, again);
      ++summary.active_set_failures;
      seen->failed = std::move(now);
      return false;
    }
    mpcc::append(h, again);
    ++summary.active_set_solves;
    summary.pinned_exits = n_pins;
    finished = true;
    return true;
  };
}

/// Solves the last NLP once more from `start` with `bounds` (active sets fixed). The result is
/// kept if it converges and keep(its cost) holds; else the point before is restored. Nothing is
/// solved (false) once the account is exhausted.
template <class Keep>
bool try_resolve(OcpNlp& b, const Ocp& ocp, const OcpOptions& o, const StageParameters& p,
                 nlp::NlpSolver& solver, ResolveAccount& account, mpcc::HomotopyResult& hr,
                 const std::vector<double>& start, const std::vector<nlp::Bound>& bounds,
                 int n_pins, const Keep& keep) {
  if (account.skip()) return false;
  mpcc::Problem& mp = b.mpcc;
  const nlp::Iterate before = mp.iterate();
  const mpcc::HomotopyResult again = mp.solve_again(solver, o.homotopy, bounds, n_pins, &start);
  if (o.on_homotopy_row) o.on_homotopy_row(again.rows.back());
  account(again);
  if (again.status == Status::Success && keep(cost(b, ocp, mp.solution(), p))) {
    hr.comp_residual = again.comp_residual;
    return true;
  }
  mp.restore(before);
  return false;
}

/// Switches held by the grid (docs/formulation.md, "Switches held by the grid"): while the
/// solution has a switch on an element boundary whose neighbouring elements sit at an h bound,
/// re-place the boundaries of those intervals (FesdInterval::regrid) and solve the last NLP from
/// there with every element's active set fixed (a smooth problem in which the switch moves
/// freely again). A round is kept if it converges and does not raise the cost; at most
/// kMaxGridMoves rounds (each one at least doubles how far a held switch can go). Switches still
/// held at the end are counted and named in a warning.
void move_held_switches(OcpNlp& b, const Ocp& ocp, const OcpOptions& o, const StageParameters& p,
                        nlp::NlpSolver& solver, ResolveAccount& account, mpcc::HomotopyResult& hr,
                        Summary& summary) {
  constexpr int kMaxGridMoves = 8;
  for (int round = 0; round < kMaxGridMoves; ++round) {
    const std::vector<double> w = b.mpcc.solution();
    std::vector<double> moved = w;
    bool any = false;  // some interval had a held switch and could be re-gridded
    for (const auto& iv : b.iv)
      if (!iv->held_switches(w.data()).empty()) any = iv->regrid(w.data(), moved) || any;
    if (!any) break;
    std::vector<nlp::Bound> bounds;
    const int n_pins = fix_active_sets(b, moved, o.discretization.pin_sliding_exits,
                                       /*every_interval=*/true, bounds);
    const double cost_before = cost(b, ocp, w, p);
    const double slack = 1e-9 * std::max(1.0, std::abs(cost_before));
    if (!try_resolve(b, ocp, o, p, solver, account, hr, moved, bounds, n_pins,
                     [&](double c) { return c <= cost_before + slack; }))
      break;
    ++summary.grid_moves;
  }
}

/// Switches born at a touch (docs/formulation.md, "Switches held by the grid"): where the
/// solution touches a switching surface at an element boundary without switching (an OCP's free
/// x0 on the surface, a trajectory grazing it), the MPCC's stationarity conditions do not see the
/// switch that could be born there, and the homotopy stops at the kink. Each touch
/// (FesdInterval::touches) is probed: the element after it in the other region, solved with
/// every active set fixed; kept if the cost falls, then held switches are moved again. At most
/// kMaxProbes NLPs.
void probe_touches(OcpNlp& b, const Ocp& ocp, const OcpOptions& o, const StageParameters& p,
                   nlp::NlpSolver& solver, ResolveAccount& account, mpcc::HomotopyResult& hr,
                   Summary& summary) {
  constexpr int kMaxProbes = 4;
  mpcc::Problem& mp = b.mpcc;
  int probes = 0;
  bool improved = true;
  while (improved && probes < kMaxProbes) {
    improved = false;
    const std::vector<double> w = mp.solution();
    const double cost_before = cost(b, ocp, w, p);
    for (std::size_t k = 0; k < b.iv.size() && !improved && probes < kMaxProbes; ++k) {
      for (const FesdInterval::Touch& t : b.iv[k]->touches(w.data())) {
        if (probes >= kMaxProbes) break;
        ++probes;
        std::vector<double> start = w;
        const auto active = b.iv[k]->probe(w.data(), t, start);
        std::vector<nlp::Bound> bounds = b.iv[k]->active_set_bounds(active);
        fix_active_sets(b, start, /*pin=*/false, /*every_interval=*/true, bounds, /*skip=*/k);
        const double slack = 1e-9 * std::max(1.0, std::abs(cost_before));
        if (try_resolve(b, ocp, o, p, solver, account, hr, start, bounds, 0,
                        [&](double c) { return c < cost_before - slack; })) {
          ++summary.born_switches;
          improved = true;
          break;
        }
      }
    }
    if (improved) move_held_switches(b, ocp, o, p, solver, account, hr, summary);
  }
}

/// One move of the allocation search: interval k re-gridded with `count` elements per segment
/// (the current counts with one moved across switch j, or as they are), equal lengths on each
/// segment (FesdInterval::regrid with explicit counts), and the last NLP is solved from there with
/// every active set fixed. The re-gridded point is the old solution on each segment, so its cost
/// (the new quadrature of the old trajectory) predicts the move: it is solved only if that cost is
/// lower, or if the regrid had to move the switch (an h bound). Kept (true) if it converges and
/// lowers the cost.
bool try_allocation_move(OcpNlp& b, const Ocp& ocp, const OcpOptions& o, const StageParameters& p,
                         nlp::NlpSolver& solver, ResolveAccount& account, mpcc::HomotopyResult& hr,
                         std::size_t k, std::size_t j, const std::vector<int>& count,
                         Summary& summary) {
  const FesdInterval& iv = *b.iv[k];
  const std::vector<double> w = b.mpcc.solution();
  if (j >= count.size()) return false;
  std::vector<double> start = w;
  if (!iv.regrid(w.data(), start, count)) return false;
  const double cost_before = cost(b, ocp, w, p);
  const double slack = 1e-9 * std::max(1.0, std::abs(cost_before));
  auto switch_time = [&](const std::vector<double>& v) {
    double t = 0;
    const int n_end = iv.segment_boundaries(v.data())[j];
    for (int n = 0; n < n_end; ++n) t += v[iv.h(n)];
    return t;
  };
  const bool moved = std::abs(switch_time(w) - switch_time(start)) > 1e-9 * ocp.T;
  if (!moved && cost(b, ocp, start, p) >= cost_before - slack) return false;
  if (account.skip()) return false;
  std::vector<nlp::Bound> bounds;
  const int n_pins = fix_active_sets(b, start, o.discretization.pin_sliding_exits,
                                     /*every_interval=*/true, bounds);
  ++summary.allocation_solves;
  return try_resolve(b, ocp, o, p, solver, account, hr, start, bounds, n_pins,
                     [&](double c) { return c < cost_before - slack; });
}

/// The allocation search (docs/formulation.md, "Switches held by the grid"): how many elements
/// each segment between two switches gets is a discrete choice the NLP does not make, and with
/// l2_relaxed (zero on every grid uniform between switches) the cost depends on it wherever the
/// scheme's quadrature is not exact. A coordinate descent: for each switch of each interval,
/// move one element from one neighbouring segment to the other and re-solve; keep the move if
/// the cost falls and go on in that direction while it falls; repeat until no single move
/// improves. At most 2 N_FE re-solves per switch; a move is solved only where the cost of the
/// re-gridded point predicts a gain (try_allocation_move), so a scheme whose quadrature is exact
/// for the problem costs none. Only with step_eq = l2_relaxed: the other penalties pull every h_n
/// to h0 (heuristic_*) and so decide the allocation themselves, or are not the default.
void search_allocation(OcpNlp& b, const Ocp& ocp, const OcpOptions& o, const StageParameters& p,
                       nlp::NlpSolver& solver, ResolveAccount& account, mpcc::HomotopyResult& hr,
                       Summary& summary) {
  if (o.discretization.step_eq != StepEq::L2Relaxed) return;
  int budget = 0, n_switches = 0;
  {
    const std::vector<double> w = b.mpcc.solution();
    for (const auto& iv : b.iv) {
      const int n = static_cast<int>(iv->segment_counts(w.data()).size()) - 1;
      n_switches += n;
      budget += 2 * iv->N_FE() * n;
    }
  }
  const int solves_end = summary.allocation_solves + budget;
  // Re-solves that did not lower the cost, by interval, kind (dir 0 or not) and allocation: not
  // tried again in a later pass.
  std::set<std::tuple<std::size_t, bool, std::vector<int>>> failed;
  auto step = [&](std::size_t k, std::size_t j, int dir) {
    if (summary.allocation_solves >= solves_end) return false;
    std::vector<int> count = b.iv[k]->segment_counts(b.mpcc.solution().data());
    if (j >= count.size()) return false;
    count[j - 1] += dir;
    count[j] -= dir;
    auto key = std::make_tuple(k, dir == 0, std::move(count));
    if (failed.contains(key)) return false;
    const int solves = summary.allocation_solves;
    if (try_allocation_move(b, ocp, o, p, solver, account, hr, k, j, std::get<2>(key), summary)) {
      ++summary.allocation_moves;
      return true;
    }
    if (summary.allocation_solves > solves) failed.insert(std::move(key));
    return false;
  };
  // The grid uniform on each segment with the counts as they are (dir 0): the re-solve after a
  // move can end at a grid that is not, next to a switch.
  auto even_out = [&](std::size_t k) {
    while (step(k, 1, 0)) {
    }
  };
  bool improved = false;
  do {
    improved = false;
    for (std::size_t k = 0; k < b.iv.size(); ++k) {
      even_out(k);
      for (std::size_t j = 1; j < b.iv[k]->segment_counts(b.mpcc.solution().data()).size(); ++j)
        for (int dir : {1, -1})
          while (step(k, j, dir)) {
            improved = true;
            even_out(k);
          }
    }
  } while (improved && n_switches > 0);
}

/// The allocation `count` in every interval (ocp_detail::solve_allocation): re-grid, then solve
/// the last NLP with every active set fixed; the result kept whatever its cost. False (the point
/// before restored) if an interval cannot be re-gridded or the re-solve fails.
bool force_allocation(OcpNlp& b, const Ocp& ocp, const OcpOptions& o, const StageParameters& p,
                      nlp::NlpSolver& solver, ResolveAccount& account, mpcc::HomotopyResult& hr,
                      const std::vector<int>& count, Summary& summary) {
  const std::vector<double> w = b.mpcc.solution();
  std::vector<double> start = w;
  for (const auto& iv : b.iv)
    if (!iv->regrid(w.data(), start, count)) return false;
  std::vector<nlp::Bound> bounds;
  const int n_pins = fix_active_sets(b, start, o.discretization.pin_sliding_exits,
                                     /*every_interval=*/true, bounds);
  if (!try_resolve(b, ocp, o, p, solver, account, hr, start, bounds, n_pins,
                   [](double) { return true; }))
    return false;
  // Then uniform on each segment again while that lowers the cost (the allocation search's
  // first step).
  for (std::size_t k = 0; k < b.iv.size(); ++k)
    for (int n = 0;
         n < 8 && try_allocation_move(b, ocp, o, p, solver, account, hr, k, 1,
                                      b.iv[k]->segment_counts(b.mpcc.solution().data()), summary);
         ++n) {
    }
  return true;
}

/// Counts the switches still held by the grid and names each in a warning.
void report_held_switches(const OcpNlp& b, const std::vector<double>& w, Summary& summary) {
  double t0 = 0;
  for (const auto& iv : b.iv) {
    for (double t : iv->held_switch_times(w.data(), t0)) {
      ++summary.held_switches;
      summary.warnings.push_back(fmt::format(
          "the switch at t = {:.6g} is held by the grid: the element lengths next to it are at "
          "their bounds (1 +- gamma_h) h, so the optimizer may have stopped it short of the "
          "optimum (use more finite elements, or a larger gamma_h)",
          t));
    }
    for (int e = 0; e < iv->N_FE(); ++e) t0 += w[iv->h(e)];
  }
}

}  // namespace

namespace ocp_detail {

std::vector<std::string> block_size_errors(const Ocp& ocp, const OcpOptions& o) {
  DiscretizationOptions d = o.discretization;
  if (!ocp.N_FE.empty()) d.N_FE = *std::max_element(ocp.N_FE.begin(), ocp.N_FE.end());
  std::vector<std::string> errors = FesdInterval::block_size_errors(ocp.model, d);
  const Pss& m = ocp.model;
  for (std::string& e : cost_block_size_errors(ocp, m.n_x(), m.n_u(), m.n_p(), d.n_s))
    errors.push_back(std::move(e));
  if (ocp.n_g_rk_comp > 0 && ocp.functions) {
    const RkAlgebraic layout = rk_algebraic(m);
    const bool step = d.dcs_mode == DcsMode::Step;
    // Entries the form lacks: every one the functions name (an empty list means "all").
    for (int i : ocp.functions->g_rk_comp_inputs())
      if (i < 0 || i >= layout.size())
        errors.push_back(fmt::format(
            "ocp.g_path_comp: reads stage entry {}, out of range (the RK stage variables of this "
            "model are {} entries: theta_1 .. theta_{}, lambda, alpha, lambda_n, lambda_p)",
            i, layout.size(), layout.n_theta));
      else if (!layout.exists(i, step))
        errors.push_back(fmt::format(
            "ocp.g_path_comp: reads {}, which the {} form does not have (Stewart's form: theta_i, "
            "lambda_i; the step form (dcs_mode = step): theta_i, alpha_j, lambda_n_j, lambda_p_j)",
            layout.name(i), step ? "step" : "Stewart"));
    const RkCompEq block{ocp.functions.get(),
                         m.n_x(),
                         m.n_u(),
                         m.n_p() + (has_speed_of_time(ocp) ? 1 : 0),
                         ocp.n_g_rk_comp,
                         layout.size(),
                         rk_comp_entries(*ocp.functions, layout, step)};
    if (block.num_inputs() > ad::kMaxInputs)
      errors.push_back(fmt::format(
          "ocp.g_path_comp = {} pairs at the RK stages: one block of n_x + n_u + n_p + (stage "
          "variables read) + 2 n = {} inputs per stage point; at most {} inputs per block are "
          "supported (use fewer pairs or stage variables)",
          ocp.n_g_rk_comp, block.num_inputs(), ad::kMaxInputs));
  }
  return errors;
}

std::vector<std::string> cost_block_size_errors(const OcpData& ocp, int n_x, int n_u, int n_p,
                                                int n_s) {
  std::vector<std::string> errors;
  const int limit = ad::kMaxInputs;
  const OcpFunctions* f = ocp.functions.get();
  // The blocks add_ocp_terms() adds, with the same functors (their input counts need no
  // function). The path constraints (n_x + n_u + n_p inputs) are smaller than the dynamics block.
  if (f != nullptr && f->has_f_q()) {
    const int k = LagrangeTerm{f, std::vector<double>(n_s), n_x, n_u, n_p}.num_inputs();
    if (k > limit)
      errors.push_back(fmt::format(
          "ocp.f_q = Lagrange term: integrated over one element it is one block of 1 + n_s n_x + "
          "n_u + n_p = {} inputs (n_s = {}, n_x = {}); at most {} inputs per block are supported "
          "(use fewer stages n_s or fewer states)",
          k, n_s, n_x, limit));
  }
  if (f != nullptr && f->has_f_q_T() && MayerTerm{f, n_x, n_p}.num_inputs() > limit)
    errors.push_back(fmt::format(
        "ocp.f_q_T = Mayer term: one block of n_x + n_p = {} inputs; at most {} inputs per block "
        "are supported (use fewer states)",
        n_x + n_p, limit));
  if (ocp.n_g_terminal > 0) {
    const bool soft = ocp.terminal_constraint == TerminalConstraint::L1;
    const int k = TerminalConstraintEq{f, n_x, n_p, ocp.n_g_terminal, soft}.num_inputs();
    if (k > limit)
      errors.push_back(fmt::format(
          "ocp.g_terminal = {} terminal constraints: one block of n_x + n_p{} = {} inputs; at "
          "most {} inputs per block are supported (use fewer states{})",
          ocp.n_g_terminal, soft ? " + n_g_terminal (l1 slacks)" : "", k, limit,
          soft ? " or terminal constraints, or relax_terminal_constraint = none" : ""));
  }
  return errors;
}

std::string step_length_error(const OcpData& ocp) {
  return core::step_length_error("ocp.T", ocp.T, "ocp.N_stages", ocp.N_stages);
}

}  // namespace ocp_detail

std::vector<std::string> validate(const OcpOptions& o) {
  std::vector<std::string> errors = validate(o.discretization, o.homotopy, o.nlp);
  if (!(o.nlp_progress_every_s >= 0) || !std::isfinite(o.nlp_progress_every_s))
    errors.push_back(fmt::format("nlp_progress_every_s = {}: must be a finite number >= 0",
                                 o.nlp_progress_every_s));
  return errors;
}

namespace {

/// solve() with the allocation `count` forced after the homotopy (ocp_detail::solve_allocation)
/// when `count` is not null; `applied` tells whether it could be.
OcpResult solve_impl(const Ocp& user, const OcpOptions& options, const std::vector<int>* count,
                     bool* applied) {
  const auto t_start = Clock::now();
  ocp_detail::require_valid_input(user, options);  // src/ocp/ocp_input.cpp, shared with files
  // A time-optimal problem is solved on the nominal horizon with the speed of time as one more
  // parameter (speed_of_time.hpp); otherwise ocp is a copy of user.
  const Ocp ocp = ocp_detail::with_speed_of_time(user);
  const StageParameters p = ocp_detail::stage_parameters(ocp, ocp.model.p_default);  // checked

  std::unique_ptr<OcpNlp> b = build(ocp, options, p);
  mpcc::Problem& mp = b->mpcc;
  OcpResult res;
  res.mpcc_mode = options.homotopy.mpcc_mode;
  bool simulated = false;
  if (options.initialization == OcpInitialization::Simulation)
    simulated = guess_simulation(*b, ocp, options, p);
  if (options.initialization == OcpInitialization::External)
    guess_external(*b, ocp, p);
  else if (!simulated)
    guess_constant(*b, ocp, p);
  if (options.initial_theta >= 0) guess_theta(*b, options.initial_theta);
  ocp_detail::guess_path_comp(*b, ocp, ocp.model.n_x(), ocp.model.n_u());
  if (ocp.time_freezing) guess_clock(*b, ocp);
  mp.finalize();
  res.summary.warnings = warnings(options.homotopy);
  for (auto& w : nlp::warnings(options.nlp)) res.summary.warnings.push_back(std::move(w));
  for (auto& w : warnings(user)) res.summary.warnings.push_back(std::move(w));
  res.summary.n_variables = mp.num_variables();
  res.summary.n_constraints = mp.num_constraints();
  res.summary.setup_s = seconds_since(t_start);

  const std::unique_ptr<nlp::NlpSolver> solver = nlp::make_solver(options.nlp);
  solver->set_progress(options.on_nlp_progress, options.nlp_progress_every_s);
  ResolveAccount account{res.summary, res.homotopy};
  bool finished_early = false;
  const auto finish = early_active_set_finish(*b, options, *solver, res.summary, finished_early);
  mpcc::HomotopyResult hr = mp.solve_homotopy(*solver, options.homotopy, options.on_homotopy_row,
                                              /*warm_max_iter=*/0, finish);
  account(hr);
  if (std::string w = mpcc::cold_restart_warning(hr); !w.empty())
    res.summary.warnings.push_back(std::move(w));
  // Sliding exits left early (docs/formulation.md): pin them and solve the last NLP once more;
  // if that fails, the unpinned solution stays. (Pinned already if the homotopy ended early.)
  if (hr.status == Status::Success && !finished_early && options.discretization.pin_sliding_exits &&
      b->iv.front()->can_pin_exits()) {
    // Per control interval: at their boundaries the control jumps, and with it the sliding
    // vector field, so a mode may end there with theta > 0; one that ends inside the last
    // element of an interval is kept on the surface up to the boundary instead.
    std::vector<nlp::Bound> bounds;
    const int n_pins =
        fix_active_sets(*b, mp.solution(), /*pin=*/true, /*every_interval=*/false, bounds);
    if (n_pins > 0) {
      const mpcc::HomotopyResult again = mp.solve_again(*solver, options.homotopy, bounds, n_pins);
      if (options.on_homotopy_row) options.on_homotopy_row(again.rows.back());
      account(again);
      if (again.status == Status::Success) {
        ++res.summary.active_set_solves;
        res.summary.pinned_exits = n_pins;
        hr.comp_residual = again.comp_residual;
      } else {
        ++res.summary.pin_failures;
        res.summary.warnings.push_back(fmt::format(
            "{} sliding exit{} could not be pinned (the re-solve failed): {} switch time{} may be "
            "off by up to one element",
            n_pins, n_pins == 1 ? "" : "s", n_pins == 1 ? "its" : "their", n_pins == 1 ? "" : "s"));
      }
    }
  }
  if (hr.status == Status::Success && options.discretization.use_fesd) {
    move_held_switches(*b, ocp, options, p, *solver, account, hr, res.summary);
    probe_touches(*b, ocp, options, p, *solver, account, hr, res.summary);
    search_allocation(*b, ocp, options, p, *solver, account, hr, res.summary);
    if (account.skipped > 0)
      res.summary.warnings.push_back(fmt::format(
          "{} re-solves with the active set fixed in a row did not converge; {} more (held "
          "switches, touches, the allocation search) were skipped",
          ResolveAccount::kMaxFailedInARow, account.skipped));
    account.failed_in_a_row = 0;  // an allocation asked for is always tried
    if (count != nullptr)
      *applied = force_allocation(*b, ocp, options, p, *solver, account, hr, *count, res.summary);
    report_held_switches(*b, mp.solution(), res.summary);
  }
  ocp_detail::set_outcome(hr, res);
  extract(*b, ocp, mp.solution(), p, res);
  ocp_detail::extract_globals(user, user.model.parameter_names, b->p, mp.solution(), res);
  res.T_final = ocp.T;
  if (ocp_detail::has_speed_of_time(ocp)) {
    std::vector<double> s;
    const int i_s = ocp.model.n_p() - 1;
    for (const std::vector<int>& pk : b->p_k) s.push_back(mp.solution()[pk[i_s]]);
    if (ocp.time_optimal_problem)
      ocp_detail::to_physical_time(res, s, ocp.T / ocp.N_stages);
    else
      res.s_sot = s;  // time freezing: the grid stays in tau, the clock is the physical time
  }
  if (options.initialization == OcpInitialization::Simulation && !simulated)
    res.message += " [the initializing simulation failed or used another grid: constant guess]";
  res.summary.wall_s = seconds_since(t_start);
  return res;
}

}  // namespace

OcpResult solve(const Ocp& ocp, const OcpOptions& options) {
  return solve_impl(ocp, options, nullptr, nullptr);
}

std::optional<OcpResult> ocp_detail::solve_allocation(const Ocp& ocp, const OcpOptions& options,
                                                      const std::vector<int>& count) {
  bool applied = false;
  OcpResult res = solve_impl(ocp, options, &count, &applied);
  if (!applied) return std::nullopt;
  return res;
}

std::string OcpResult::brief_report() const {
  std::string x0s;
  if (!x.empty())
    for (Eigen::Index i = 0; i < x.front().size(); ++i)
      x0s += fmt::format("{}{:.10g}", i ? ", " : "", x.front()[i]);
  std::string extra;
  if (!s_sot.empty()) extra += fmt::format(", T_final = {:.10g}", T_final);
  for (Eigen::Index i = 0; i < v_global.size(); ++i)
    extra +=
        fmt::format(", {} = {:.10g}", v_global_names[static_cast<std::size_t>(i)], v_global[i]);
  return fmt::format(
      "{}: objective {:.10g}, x(0) = [{}]{}, {} switch{}, {} NLPs, {} IPOPT "
      "iterations, {:.3f} s",
      to_string(status), objective, x0s, extra, switches.size(), switches.size() == 1 ? "" : "es",
      summary.homotopy_steps, summary.nlp_iterations, summary.wall_s);
}

std::string OcpResult::full_report(bool with_homotopy_table) const {
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
  if (!s_sot.empty())
    os << fmt::format("  T_final              {:.12g} (speed of time {})\n", T_final,
                      vec(Eigen::Map<const Eigen::VectorXd>(
                          s_sot.data(), static_cast<Eigen::Index>(s_sot.size()))));
  for (Eigen::Index i = 0; i < v_global.size(); ++i)
    os << fmt::format("  v_global             {} = {:.12g}\n",
                      v_global_names[static_cast<std::size_t>(i)], v_global[i]);
  os << fmt::format("  switches             {}\n", switches.size());
  for (const auto& s : switches) os << format_switch(s);
  os << fmt::format("  NLP size             {} variables, {} constraints\n", summary.n_variables,
                    summary.n_constraints);
  if (with_homotopy_table) {
    os << "  homotopy\n" << homotopy_table_header();
    for (const auto& r : homotopy) os << format_homotopy_row(r);
  }
  os << format_warnings(summary);
  os << format_work(summary);
  return os.str();
}

}  // namespace fesd
