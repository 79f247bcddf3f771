// The FESD integrator: one FesdInterval NLP, built once and re-solved for every step with the new
// start state (fixed variables) and a shifted initial guess.
#include "fesd/integrator.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/option_registry.hpp"
#include "core/report.hpp"
#include "dcs/stewart.hpp"
#include "discretization/fesd_interval.hpp"
#include "fesd/error.hpp"
#include "mpcc/homotopy.hpp"
#include "nlp/ipopt_solver.hpp"

namespace fesd {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kMaxSplit = 2;  // a failed step is retried as halves, then quarters
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void check_finite(const Eigen::VectorXd& v, const char* name) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw InvalidModel(fmt::format("{}[{}] = {}: must be finite", name, i, v[i]));
}

void fix(nlp::BlockNlp& nlp, const std::vector<int>& vars, const Eigen::VectorXd& values) {
  for (std::size_t i = 0; i < vars.size(); ++i) {
    nlp.x_lb[vars[i]] = nlp.x_ub[vars[i]] = values[static_cast<Eigen::Index>(i)];
    nlp.x_init[vars[i]] = values[static_cast<Eigen::Index>(i)];
  }
}

std::vector<int> fixed_vars(nlp::BlockNlp& nlp, int n) {
  std::vector<int> v;
  const int first = nlp.add_variables(n, 0.0, 0.0, 0.0);
  for (int i = 0; i < n; ++i) v.push_back(first + i);
  return v;
}

std::vector<int> range_of(int first, int n) {
  std::vector<int> v;
  for (int i = 0; i < n; ++i) v.push_back(first + i);
  return v;
}

/// Fixes the variables to the values, or only uses them as the initial guess.
void fix_or_guess(nlp::BlockNlp& nlp, const std::vector<int>& vars, const Eigen::VectorXd& values,
                  bool guess_only) {
  if (!guess_only) return fix(nlp, vars, values);
  for (std::size_t i = 0; i < vars.size(); ++i)
    nlp.x_init[vars[i]] = values[static_cast<Eigen::Index>(i)];
}

Eigen::VectorXd gather(const std::vector<double>& w, int first, int n) {
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = w[first + i];
  return v;
}

/// Appends the N_FE elements of a step (NLP point w) to the result; advances t.
void append_step(IntegratorResult& res, const Pss& model, const discretization::FesdInterval& iv,
                 const Tableau& tab, const std::vector<double>& w, double& t) {
  const int n_x = model.n_x(), n_th = model.n_theta(), n_sys = model.n_sys();
  for (int n = 0; n < iv.N_FE(); ++n) {
    const double hn = w[iv.h(n)];
    const std::vector<int> active = iv.active_set(w.data(), n);
    for (int s = 0; s < iv.n_s(); ++s) {
      res.t_stage.push_back(t + tab.c(s) * hn);
      res.x_stage.push_back(gather(w, iv.X(n, s, 0), n_x));
      res.theta.push_back(gather(w, iv.theta(n, s, 0), n_th));
      res.lambda.push_back(gather(w, iv.lambda(n, s, 0), n_th));
      res.mu.push_back(gather(w, iv.mu(n, s, 0), n_sys));
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

/// The NLP of one integration step: built once, re-solved for every step with new fixed inputs.
struct StepNlp {
  nlp::BlockNlp nlp;
  discretization::IntervalInputs in;
  std::unique_ptr<discretization::FesdInterval> iv;
  std::optional<mpcc::Relaxation> relaxation;  // of iv->groups(), in the homotopy's mpcc_mode
};

std::unique_ptr<StepNlp> build_step_nlp(const Pss& model, const Tableau& tab,
                                        const DiscretizationOptions& d, double T_step,
                                        MpccMode mpcc_mode) {
  auto s = std::make_unique<StepNlp>();
  s->in.s0 = fixed_vars(s->nlp, model.n_x());
  s->in.q = fixed_vars(s->nlp, model.n_u());
  s->in.p = fixed_vars(s->nlp, model.n_p());
  // FESD: lambda_{0,0}, mu_{0,0} are variables tied to s0 by the LP equation (9), not fixed
  // numbers, so that a step starting on a switching surface (c(s0) = O(1e-13)) is not made
  // infeasible by the round-off sign of a fixed lambda_{0,0}. The standard method does not use
  // them (no cross complementarity): fixed.
  const int n_th = model.n_theta(), n_sys = model.n_sys();
  if (d.use_fesd) {
    s->in.lambda_start = range_of(s->nlp.add_variables(n_th, 0.0, nlp::kInf, 0.0), n_th);
    s->in.mu_start = range_of(s->nlp.add_variables(n_sys, -nlp::kInf, nlp::kInf, 0.0), n_sys);
    s->in.lp_at_start = true;
  } else {
    s->in.lambda_start = fixed_vars(s->nlp, n_th);
    s->in.mu_start = fixed_vars(s->nlp, n_sys);
  }
  s->in.T = T_step;
  // Non-stiffly-accurate schemes: boundary values (33) at the step end too, so that a switch
  // cannot hide between the last stage and the end of the step.
  s->in.boundary_at_end = true;
  s->iv = std::make_unique<discretization::FesdInterval>(model, tab, d);
  s->iv->build(s->nlp, s->in);
  s->relaxation.emplace(s->nlp, s->iv->groups(), mpcc_mode);
  return s;
}

}  // namespace

std::vector<double> IntegratorResult::switch_times() const {
  std::vector<double> ts;
  for (const auto& s : switches) ts.push_back(s.t);
  return ts;
}

IntegratorResult integrate(const Pss& model, const Eigen::VectorXd& x0_in, double T_sim, int N_sim,
                           const IntegratorOptions& options, const Eigen::VectorXd& u_in,
                           const Eigen::VectorXd& p_in) {
  const auto t_start = Clock::now();
  // ---- input checks: throw before computing ----
  check(options);
  if (model.n_x() < 1) throw InvalidModel("model: empty (n_x = 0)");
  if (x0_in.size() != model.n_x())
    throw InvalidModel(
        fmt::format("x0 has {} entries, expected n_x = {}", x0_in.size(), model.n_x()));
  check_finite(x0_in, "x0");
  if (const auto e = registry::validate_simulation(T_sim, N_sim); !e.empty())
    throw InvalidOption(registry::join(e));
  const Eigen::VectorXd u = u_in.size() == 0 ? Eigen::VectorXd::Zero(model.n_u()) : u_in;
  const Eigen::VectorXd p = p_in.size() == 0 ? model.p_default : p_in;
  if (u.size() != model.n_u())
    throw InvalidModel(fmt::format("u has {} entries, expected n_u = {}", u.size(), model.n_u()));
  if (p.size() != model.n_p())
    throw InvalidModel(fmt::format("p has {} entries, expected n_p = {}", p.size(), model.n_p()));
  check_finite(u, "u");
  check_finite(p, "p");

  const DiscretizationOptions& d = options.discretization;
  const Tableau tab = make_tableau(d.rk_scheme, d.n_s);
  const int n_x = model.n_x(), n_th = model.n_theta(), n_sys = model.n_sys();
  const int n_s = d.n_s;
  const double T_step = T_sim / N_sim;

  // ---- the NLPs of one step ----
  // Level (k, r) solves a step of length T_step / 2^k with N_FE (r = 0) or 2 N_FE (r = 1)
  // elements. A step whose homotopy fails (also in the sparse form) is retried with 2 N_FE
  // elements (two switches closer than a step need two free element boundaries between them),
  // then as two half steps, up to kMaxSplit times (docs/benchmarks.md). Each level's NLP is
  // built on first need and re-solved with new fixed inputs.
  struct Level {
    std::unique_ptr<StepNlp> primary;
    // The same step with the sparse cross complementarity (28), which the homotopy follows more
    // reliably (docs/benchmarks.md). Same variable layout, other rows. Built on first need.
    std::unique_ptr<StepNlp> fallback;
  };
  std::vector<std::array<Level, 2>> levels(kMaxSplit + 1);
  // scholtes_eq and fischer_burmeister impose one equation per pair: with the sparse form (28)
  // a theta gets more equations than it has freedom (IPOPT: Not_Enough_Degrees_Of_Freedom), so
  // the sparse retry is useless for them.
  const MpccMode mode = options.homotopy.mpcc_mode;
  const bool can_fall_back = d.use_fesd && d.cross_comp != CrossComp::Sparse &&
                             mode != MpccMode::ScholtesEq && mode != MpccMode::FischerBurmeister;
  auto level_options = [&](int r) {
    DiscretizationOptions dr = d;
    dr.N_FE = r == 0 ? d.N_FE : 2 * d.N_FE;
    return dr;
  };
  auto level_nlp = [&](int k, int r) -> StepNlp& {
    Level& level = levels[k][r];
    if (!level.primary) {
      level.primary = build_step_nlp(model, tab, level_options(r), T_step / std::ldexp(1.0, k),
                                     options.homotopy.mpcc_mode);
      StepNlp& sn = *level.primary;
      fix(sn.nlp, sn.in.q, u);
      fix(sn.nlp, sn.in.p, p);
    }
    return *level.primary;
  };

  auto xdot_at = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& theta) {
    Eigen::VectorXd xd(n_x);
    dcs::eval_F_theta<double>(model, x.data(), u.data(), p.data(), theta.data(), xd.data());
    return xd;
  };
  // Initial guess of the next step: the LP at x0 first, then the last stage of the last step.
  dcs::LpSolution guess = dcs::solve_lp(model, x0_in, p);
  Eigen::VectorXd guess_xdot = xdot_at(x0_in, guess.theta);

  IntegratorResult res;
  level_nlp(0, 0).nlp.finalize();
  res.summary.setup_s = seconds_since(t_start);
  nlp::IpoptSolver solver(options.nlp);
  auto account = [&](const mpcc::HomotopyResult& h) {
    res.summary.homotopy_steps += static_cast<int>(h.rows.size());
    res.summary.nlp_iterations += h.nlp_iterations;
    res.summary.derivative_s += h.eval_s;
    res.summary.solver_s += h.solver_s;
  };

  res.t.push_back(0.0);
  res.x.push_back(x0_in);
  double t = 0.0;
  Eigen::VectorXd x = x0_in;
  mpcc::HomotopyResult last_hr;
  std::vector<double> failed_w;  // last iterate of a failed step, reported with the failure
  const discretization::FesdInterval* failed_iv = nullptr;

  // Sliding exits of a solved step (docs/formulation.md): the exits inside it
  // (FesdInterval::exits_to_pin), and an exit at its start where the previous step ended with
  // theta > kExitThetaTol of the leaving region, are pinned and the last NLP solved again; if
  // that fails, the unpinned solution stays. On success hr's complementarity residual becomes
  // the pinned solution's.
  auto pin_exits = [&](StepNlp& sn, nlp::Iterate& it, mpcc::HomotopyResult& hr,
                       std::vector<HomotopyRow>& rows) {
    const double sigma = hr.rows.back().sigma;
    const int k = static_cast<int>(rows.size());
    const discretization::FesdInterval& iv = *sn.iv;
    const std::vector<double>& w = it.x;
    std::vector<discretization::FesdInterval::ExitPin> pins =
        iv.exits_to_pin(w.data(), /*control_jump_at_end=*/false);
    // The previous step ended sliding with theta_r > 0 (guess.theta: its last stage), and this
    // one starts without r: an early exit at the step start. Element 0 is pinned: it stays on
    // the surface until theta_r reaches 0. Its length gets a lower bound, half the time theta_r
    // takes to reach 0 at its rate in the previous element: a pinned element of length ~0 would
    // meet theta_r = 0 only within the tolerance (the stage equations lose their hold on theta
    // as h -> 0), without moving the exit.
    double h0_min = 0;
    if (!res.active_set.empty()) {
      const std::vector<int> first = iv.active_set(w.data(), 0);
      for (int r :
           discretization::FesdInterval::exit_regions(model, res.active_set.back(), first)) {
        const double th_end = guess.theta[r];
        if (th_end <= discretization::FesdInterval::kExitThetaTol) continue;
        // theta_r at the first and last stage of the previous element (res.theta, res.t_stage).
        const std::size_t last = res.theta.size() - 1, first_stage = last + 1 - n_s;
        const double dt = res.t_stage[last] - res.t_stage[first_stage];
        const double rate = dt > 0 ? (th_end - res.theta[first_stage][r]) / dt : 0.0;
        if (rate >= 0) continue;  // theta_r not falling: no exit to expect near the step start
        pins.push_back({0, r, true});
        h0_min = std::max(h0_min, 0.5 * th_end / -rate);
      }
    }
    if (pins.empty()) return;
    const mpcc::HomotopyResult again = mpcc::solve_again(
        sn.nlp, *sn.relaxation, iv.residual_pairs(), solver, it, sigma, k, options.homotopy,
        [&](nlp::BlockNlp& problem, std::vector<double>& point) {
          for (const auto& pin : pins) iv.pin_exit(problem, point, pin);
          const int h0 = iv.h(0);
          if (h0_min > 0 && h0_min < problem.x_ub[h0]) {
            problem.x_lb[h0] = std::max(problem.x_lb[h0], h0_min);
            point[h0] = std::max(point[h0], h0_min);
          }
        });
    account(again);
    rows.insert(rows.end(), again.rows.begin(), again.rows.end());
    if (again.status == Status::Success) {
      res.summary.pinned_exits += static_cast<int>(pins.size());
      hr.comp_residual = again.comp_residual;
    } else {
      ++res.summary.pin_failures;
    }
  };

  bool careful = false;  // an attempt of the current step failed (see solve_step)
  // Solves one step of level (k, r) from x; on success appends it to res and advances t, x,
  // guess.
  auto solve_step = [&](int k, int r) -> bool {
    StepNlp& sn = level_nlp(k, r);
    Level& level = levels[k][r];
    nlp::BlockNlp& nlp = sn.nlp;
    const discretization::FesdInterval& iv = *sn.iv;
    const dcs::LpSolution lp = dcs::solve_lp(model, x, p);
    fix(nlp, sn.in.s0, x);
    fix_or_guess(nlp, sn.in.lambda_start, lp.lambda, d.use_fesd);
    fix_or_guess(nlp, sn.in.mu_start, lp.mu, d.use_fesd);
    iv.set_guess(nlp, x, guess, guess_xdot);
    if (!nlp.finalized()) nlp.finalize();
    nlp::Iterate it;
    it.x = nlp.x_init;
    // Once an attempt of this step has failed, every retry solves all its NLPs to ipopt.tol:
    // loosely solved early NLPs (intermediate_tol) can lead the homotopy astray in hard steps,
    // e.g. one starting on the co-dimension-2 sliding set of OCP (61) (docs/formulation.md).
    HomotopyOptions hopt = options.homotopy;
    if (careful) hopt.intermediate_tol = 0;
    mpcc::HomotopyResult hr =
        mpcc::solve_homotopy(nlp, *sn.relaxation, iv.residual_pairs(), solver, it, hopt);
    std::vector<HomotopyRow> rows = hr.rows;
    account(hr);
    auto restart = [&] {
      it.x = nlp.x_init;
      it.z_L.clear();
      it.z_U.clear();
      it.lambda.clear();
    };
    if (hr.status != Status::Success && hopt.intermediate_tol > 0) {  // same NLP, tight
      careful = true;
      hopt.intermediate_tol = 0;
      restart();
      hr = mpcc::solve_homotopy(nlp, *sn.relaxation, iv.residual_pairs(), solver, it, hopt);
      account(hr);
      rows.insert(rows.end(), hr.rows.begin(), hr.rows.end());
    }
    if (hr.status != Status::Success) careful = true;
    StepNlp* solved = &sn;                                // the NLP whose solution `it` is
    if (hr.status != Status::Success && can_fall_back) {  // same start, sparse form (28)
      if (!level.fallback) {
        DiscretizationOptions sparse = level_options(r);
        sparse.cross_comp = CrossComp::Sparse;
        level.fallback = build_step_nlp(model, tab, sparse, T_step / std::ldexp(1.0, k),
                                        options.homotopy.mpcc_mode);
      }
      StepNlp& fb = *level.fallback;
      fb.nlp.x_lb = nlp.x_lb;  // same layout: fixed inputs and bounds carry over
      fb.nlp.x_ub = nlp.x_ub;
      fb.nlp.x_init = nlp.x_init;
      if (!fb.nlp.finalized()) fb.nlp.finalize();
      restart();
      hr = mpcc::solve_homotopy(fb.nlp, *fb.relaxation, fb.iv->residual_pairs(), solver, it, hopt);
      account(hr);
      rows.insert(rows.end(), hr.rows.begin(), hr.rows.end());
      ++res.summary.fallback_steps;
      solved = &fb;
    }
    if (hr.status == Status::Success && d.pin_sliding_exits && iv.can_pin_exits())
      pin_exits(*solved, it, hr, rows);
    res.homotopy.push_back(std::move(rows));
    last_hr = hr;
    const std::vector<double>& w = it.x;
    if (hr.status != Status::Success) {
      failed_w = w;
      failed_iv = &iv;
      return false;
    }
    res.summary.max_comp_residual = std::max(res.summary.max_comp_residual, hr.comp_residual);
    append_step(res, model, iv, tab, w, t);
    x = res.x.back();
    const int last = iv.N_FE() - 1;
    guess.theta = gather(w, iv.theta(last, n_s - 1, 0), n_th);
    guess.lambda = gather(w, iv.lambda(last, n_s - 1, 0), n_th);
    guess.mu = gather(w, iv.mu(last, n_s - 1, 0), n_sys);
    guess_xdot = gather(w, iv.V(last, n_s - 1, 0), n_x);
    return true;
  };
  // Advances over one step of level k: retried with 2 N_FE elements where it fails, then split
  // into halves.
  std::function<bool(int)> advance = [&](int k) -> bool {
    if (solve_step(k, 0)) return true;
    if (!d.use_fesd) return false;
    ++res.summary.refine_attempts;
    if (solve_step(k, 1)) {
      ++res.summary.refined_steps;
      return true;
    }
    if (k == kMaxSplit) return false;
    ++res.summary.split_steps;
    return advance(k + 1) && advance(k + 1);
  };

  res.status = Status::Success;
  res.message = "";
  for (int step = 0; step < N_sim; ++step) {
    careful = false;
    const bool ok = advance(0);
    if (options.progress)
      std::fprintf(stderr, "  step %4d/%d  t = %-10.6g  NLPs %2zu  iter %4d  comp %.1e  %s\n",
                   step + 1, N_sim, t, last_hr.rows.size(), last_hr.nlp_iterations,
                   last_hr.comp_residual, std::string(to_string(last_hr.status)).c_str());
    if (!ok) {
      // Report the failed step's last iterate too, so the user sees where it went wrong.
      if (failed_iv) append_step(res, model, *failed_iv, tab, failed_w, t);
      res.status = last_hr.status;
      res.message = fmt::format(
          "step {} of {} (t = {:.6g}): {} (last IPOPT status {}, "
          "complementarity residual {:.2e})",
          step + 1, N_sim, t, describe(last_hr.status), last_hr.last_nlp_status,
          last_hr.comp_residual);
      break;
    }
  }
  if (res.status == Status::Success) res.message = std::string(describe(Status::Success));
  res.summary.wall_s = seconds_since(t_start);
  return res;
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
  for (const auto& s : switches) os << detail::format_switch(s);
  // homotopy has one entry per solve attempt: a refinement follows a failed attempt, a split a
  // failed refinement.
  const std::size_t n_steps = homotopy.size() - static_cast<std::size_t>(summary.refine_attempts) -
                              static_cast<std::size_t>(summary.split_steps);
  const double steps = n_steps == 0 ? 1.0 : static_cast<double>(n_steps);
  os << fmt::format("  integration steps    {}  ({} finite elements)\n", n_steps, h.size());
  os << fmt::format("  NLPs solved          {}  ({:.1f} per step)\n", summary.homotopy_steps,
                    summary.homotopy_steps / steps);
  os << fmt::format("  IPOPT iterations     {}  ({:.1f} per step)\n", summary.nlp_iterations,
                    summary.nlp_iterations / steps);
  os << fmt::format("  max comp. residual   {:.2e}\n", summary.max_comp_residual);
  if (summary.fallback_steps > 0)
    os << fmt::format("  retried steps        {}  (sparse cross complementarity (28))\n",
                      summary.fallback_steps);
  if (summary.refined_steps > 0)
    os << fmt::format("  refined steps        {}  (solved again with 2 N_FE elements)\n",
                      summary.refined_steps);
  if (summary.split_steps > 0)
    os << fmt::format("  split steps          {}  (retried as two half steps)\n",
                      summary.split_steps);
  if (summary.pinned_exits > 0 || summary.pin_failures > 0)
    os << fmt::format("  pinned sliding exits {}  ({} re-solves failed, unpinned)\n",
                      summary.pinned_exits, summary.pin_failures);
  os << fmt::format("  wall time            {:.3f} s  ({:.2f} ms per step)\n", summary.wall_s,
                    1e3 * summary.wall_s / steps);
  const double busy = summary.derivative_s + summary.solver_s;
  os << fmt::format("    derivatives        {:.3f} s  ({:.0f} %)\n", summary.derivative_s,
                    busy > 0 ? 100 * summary.derivative_s / busy : 0.0);
  os << fmt::format("    IPOPT + MUMPS      {:.3f} s  ({:.0f} %)\n", summary.solver_s,
                    busy > 0 ? 100 * summary.solver_s / busy : 0.0);
  os << fmt::format("    setup              {:.3f} s\n", summary.setup_s);
  return os.str();
}

}  // namespace fesd
