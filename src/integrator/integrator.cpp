// The FESD integrator: one FesdInterval NLP, built once and re-solved for every step with the new
// start state (fixed variables) and a shifted initial guess.
#include "fesd/integrator.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "dcs/stewart.hpp"
#include "discretization/fesd_interval.hpp"
#include "fesd/error.hpp"
#include "mpcc/homotopy.hpp"
#include "nlp/ipopt_solver.hpp"

namespace fesd {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kActiveThetaTol = 1e-6;
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

Eigen::VectorXd gather(const std::vector<double>& w, int first, int n) {
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = w[first + i];
  return v;
}

/// The NLP of one integration step: built once, re-solved for every step with new fixed inputs.
struct StepNlp {
  nlp::BlockNlp nlp;
  discretization::IntervalInputs in;
  std::unique_ptr<discretization::FesdInterval> iv;
  std::vector<int> comp_rows;
};

std::unique_ptr<StepNlp> build_step_nlp(const Pss& model, const Tableau& tab,
                                        const DiscretizationOptions& d, double T_step) {
  auto s = std::make_unique<StepNlp>();
  s->in.s0 = fixed_vars(s->nlp, model.n_x());
  s->in.q = fixed_vars(s->nlp, model.n_u());
  s->in.p = fixed_vars(s->nlp, model.n_p());
  s->in.lambda_start = fixed_vars(s->nlp, model.n_theta());
  s->in.mu_start = fixed_vars(s->nlp, model.n_sys());
  s->in.T = T_step;
  // Non-stiffly-accurate schemes: boundary values (33) at the step end too, so that a switch
  // cannot hide between the last stage and the end of the step.
  s->in.boundary_at_end = true;
  s->iv = std::make_unique<discretization::FesdInterval>(model, tab, d);
  s->iv->build(s->nlp, s->in);
  s->comp_rows = mpcc::add_scholtes_rows(s->nlp, s->iv->groups());
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
  if (!std::isfinite(T_sim) || T_sim <= 0)
    throw InvalidOption(fmt::format("T_sim = {}: must be finite and > 0", T_sim));
  if (N_sim < 1) throw InvalidOption(fmt::format("N_sim = {}: must be >= 1", N_sim));
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
  const int N_FE = d.N_FE, n_s = d.n_s;
  const double T_step = T_sim / N_sim;

  // ---- the NLP of one step ----
  const std::unique_ptr<StepNlp> primary = build_step_nlp(model, tab, d, T_step);
  nlp::BlockNlp& nlp = primary->nlp;
  const discretization::IntervalInputs& in = primary->in;
  const discretization::FesdInterval& iv = *primary->iv;
  // Built on first need: the same step with the sparse cross complementarity (28), which the
  // homotopy follows more reliably (docs/benchmarks.md). Same variable layout, other rows.
  std::unique_ptr<StepNlp> fallback;
  const bool can_fall_back = d.use_fesd && d.cross_comp != CrossComp::Sparse;

  auto xdot_at = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& theta) {
    Eigen::VectorXd xd(n_x);
    dcs::eval_F_theta<double>(model, x.data(), u.data(), p.data(), theta.data(), xd.data());
    return xd;
  };
  Eigen::VectorXd x = x0_in;
  dcs::LpSolution lp = dcs::solve_lp(model, x, p);
  fix(nlp, in.s0, x);
  fix(nlp, in.q, u);
  fix(nlp, in.p, p);
  fix(nlp, in.lambda_start, lp.lambda);
  fix(nlp, in.mu_start, lp.mu);
  iv.set_guess(nlp, x, lp, xdot_at(x, lp.theta));
  nlp.finalize();

  IntegratorResult res;
  res.summary.setup_s = seconds_since(t_start);
  nlp::IpoptSolver solver(options.nlp);

  res.t.push_back(0.0);
  res.x.push_back(x);
  double t = 0.0;
  res.status = Status::Success;
  res.message = "";
  for (int step = 0; step < N_sim; ++step) {
    if (step > 0) {  // new start state; guess: continue the last stage of the previous step
      lp = dcs::solve_lp(model, x, p);
      fix(nlp, in.s0, x);
      fix(nlp, in.lambda_start, lp.lambda);
      fix(nlp, in.mu_start, lp.mu);
      dcs::LpSolution last;
      last.theta = gather(nlp.x_init, iv.theta(N_FE - 1, n_s - 1, 0), n_th);
      last.lambda = gather(nlp.x_init, iv.lambda(N_FE - 1, n_s - 1, 0), n_th);
      last.mu = gather(nlp.x_init, iv.mu(N_FE - 1, n_s - 1, 0), n_sys);
      const Eigen::VectorXd xdot = gather(nlp.x_init, iv.V(N_FE - 1, n_s - 1, 0), n_x);
      iv.set_guess(nlp, x, last, xdot);
    }
    nlp::Iterate it;
    it.x = nlp.x_init;
    mpcc::HomotopyResult hr = mpcc::solve_homotopy(nlp, primary->comp_rows, iv.residual_pairs(),
                                                   solver, it, options.homotopy);
    std::vector<HomotopyRow> rows = hr.rows;
    auto account = [&](const mpcc::HomotopyResult& h) {
      res.summary.homotopy_steps += static_cast<int>(h.rows.size());
      res.summary.nlp_iterations += h.nlp_iterations;
      res.summary.derivative_s += h.eval_s;
      res.summary.solver_s += h.solver_s;
    };
    account(hr);
    if (hr.status != Status::Success && can_fall_back) {  // same start, sparse form (28)
      if (!fallback) {
        DiscretizationOptions sparse = d;
        sparse.cross_comp = CrossComp::Sparse;
        fallback = build_step_nlp(model, tab, sparse, T_step);
      }
      fallback->nlp.x_lb = nlp.x_lb;  // same layout: fixed inputs and bounds carry over
      fallback->nlp.x_ub = nlp.x_ub;
      fallback->nlp.x_init = nlp.x_init;
      if (!fallback->nlp.finalized()) fallback->nlp.finalize();
      nlp::Iterate retry;
      retry.x = nlp.x_init;
      hr = mpcc::solve_homotopy(fallback->nlp, fallback->comp_rows, fallback->iv->residual_pairs(),
                                solver, retry, options.homotopy);
      account(hr);
      rows.insert(rows.end(), hr.rows.begin(), hr.rows.end());
      ++res.summary.fallback_steps;
      it = std::move(retry);
    }
    nlp.x_init = it.x;  // the solution: read below and the base of the next guess
    const std::vector<double>& w = it.x;
    res.homotopy.push_back(std::move(rows));
    res.summary.max_comp_residual = std::max(res.summary.max_comp_residual, hr.comp_residual);

    for (int n = 0; n < N_FE; ++n) {
      const double hn = w[iv.h(n)];
      // Active regions of the element: theta_{n,m,r} > 1e-6 at some stage. theta is a convex
      // weight in [0, 1]; inactive regions have theta ~ sigma / lambda at the solution, and
      // lambda alone cannot decide (it vanishes for every region at a switching boundary).
      std::vector<int> active;
      for (int r = 0; r < n_th; ++r) {
        double th = 0;
        for (int s = 0; s < n_s; ++s) th = std::max(th, w[iv.theta(n, s, r)]);
        if (th > kActiveThetaTol) active.push_back(r);
      }
      for (int s = 0; s < n_s; ++s) {
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
    x = res.x.back();
    if (options.progress)
      std::fprintf(stderr, "  step %4d/%d  t = %-10.6g  NLPs %2zu  iter %4d  comp %.1e  %s\n",
                   step + 1, N_sim, t, hr.rows.size(), hr.nlp_iterations, hr.comp_residual,
                   std::string(to_string(hr.status)).c_str());
    if (hr.status != Status::Success) {
      res.status = hr.status;
      res.message = fmt::format(
          "step {} of {} (t = {:.6g}): {} (last IPOPT status {}, "
          "complementarity residual {:.2e})",
          step + 1, N_sim, t, describe(hr.status), hr.last_nlp_status, hr.comp_residual);
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
  for (const auto& s : switches) {
    auto set = [](const std::vector<int>& a) {
      std::vector<int> one_based(a.begin(), a.end());
      for (int& v : one_based) ++v;
      return fmt::format("{{{}}}", fmt::join(one_based, ","));
    };
    os << fmt::format("    t_s = {:.12g}   active regions {} -> {}\n", s.t, set(s.before),
                      set(s.after));
  }
  const double steps = homotopy.empty() ? 1.0 : static_cast<double>(homotopy.size());
  os << fmt::format("  integration steps    {}  ({} finite elements)\n", homotopy.size(), h.size());
  os << fmt::format("  NLPs solved          {}  ({:.1f} per step)\n", summary.homotopy_steps,
                    summary.homotopy_steps / steps);
  os << fmt::format("  IPOPT iterations     {}  ({:.1f} per step)\n", summary.nlp_iterations,
                    summary.nlp_iterations / steps);
  os << fmt::format("  max comp. residual   {:.2e}\n", summary.max_comp_residual);
  if (summary.fallback_steps > 0)
    os << fmt::format("  retried steps        {}  (sparse cross complementarity (28))\n",
                      summary.fallback_steps);
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
