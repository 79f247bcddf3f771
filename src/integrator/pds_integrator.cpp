// integrate() for projected dynamical systems (include/fesd/pds.hpp, docs/pds.md): one
// PdsInterval NLP, built once and re-solved for every step with the new start state, by the MPCC
// homotopy (there is no active-set path for PDS).
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/option_registry.hpp"
#include "core/util.hpp"
#include "discretization/pds_interval.hpp"
#include "fesd/error.hpp"
#include "fesd/pds.hpp"
#include "mpcc/problem.hpp"
#include "nlp/nlp_solver.hpp"

namespace fesd {
namespace {

using util::check_finite;
using util::gather;
using util::range_of;
using util::seconds_since;

using Clock = std::chrono::steady_clock;
/// grad c_k(x) (n_x) of one constraint.
Eigen::VectorXd grad_c(const Pds& m, const Eigen::VectorXd& x, const Eigen::VectorXd& p, int k) {
  Eigen::VectorXd e = Eigen::VectorXd::Zero(m.n_c()), g(m.n_x());
  e[k] = 1.0;
  m.functions().grad_c_lambda(x.data(), p.data(), e.data(), g.data());
  return g;
}

/// The guess of a step: explicit Euler on f with 16 substeps per element, after each substep
/// the violated constraints corrected by a Gauss-Newton step along grad c_k; lambda from the
/// closed form (5) where c_k(x) ~ 0.
struct StepGuess {
  std::vector<Eigen::VectorXd> X, lambda;
};
StepGuess projected_euler(const Pds& m, const Tableau& tab, int N_FE, double T,
                          const Eigen::VectorXd& x0, const Eigen::VectorXd& u,
                          const Eigen::VectorXd& p) {
  const int n_x = m.n_x(), n_c = m.n_c(), sub = 16;
  const double h0 = T / N_FE;
  StepGuess g;
  Eigen::VectorXd x = x0, f(n_x), c(n_c);
  auto project = [&](Eigen::VectorXd& y) {
    for (int it = 0; it < 3; ++it) {
      m.functions().c(y.data(), p.data(), c.data());
      for (int k = 0; k < n_c; ++k)
        if (c[k] < 0) {
          const Eigen::VectorXd gk = grad_c(m, y, p, k);
          const double nn = gk.squaredNorm();
          if (nn > 0) y -= (c[k] / nn) * gk;
        }
    }
  };
  auto advance = [&](double dt) {
    const int steps = std::max(1, static_cast<int>(std::ceil(sub * dt / h0)));
    for (int s = 0; s < steps; ++s) {
      m.functions().f(x.data(), u.data(), p.data(), f.data());
      x += (dt / steps) * f;
      project(x);
    }
  };
  double t_now = 0;
  for (int n = 0; n < N_FE; ++n)
    for (int i = 0; i < tab.n_s; ++i) {
      const double t_stage = (n + tab.c[i]) * h0;
      if (t_stage > t_now) advance(t_stage - t_now);
      t_now = t_stage;
      g.X.push_back(x);
      Eigen::VectorXd lam = Eigen::VectorXd::Zero(n_c);
      m.functions().c(x.data(), p.data(), c.data());
      m.functions().f(x.data(), u.data(), p.data(), f.data());
      for (int k = 0; k < n_c; ++k)
        if (c[k] <= 1e-6 * std::max(1.0, x.norm())) {
          const Eigen::VectorXd gk = grad_c(m, x, p, k);
          const double nn = gk.squaredNorm();
          if (nn > 0) lam[k] = std::max(0.0, -gk.dot(f) / nn);  // (5)
        }
      g.lambda.push_back(lam);
    }
  return g;
}

void check_input(const Pds& model, const Eigen::VectorXd& x0, double T_sim, int N_sim,
                 const IntegratorOptions& options, const Eigen::VectorXd& u,
                 const Eigen::VectorXd& p, const PdsOptions& pds) {
  check(options);
  if (x0.size() != model.n_x())
    throw InvalidModel(fmt::format("x0 has {} entries, expected n_x = {}", x0.size(), model.n_x()));
  check_finite(x0, "x0");
  if (const auto e = registry::validate_simulation(T_sim, N_sim); !e.empty())
    throw InvalidOption(registry::join(e));
  if (u.size() != model.n_u())
    throw InvalidModel(fmt::format("u has {} entries, expected n_u = {}", u.size(), model.n_u()));
  if (p.size() != model.n_p())
    throw InvalidModel(fmt::format("p has {} entries, expected n_p = {}", p.size(), model.n_p()));
  check_finite(u, "u");
  check_finite(p, "p");
  const Tableau tab = make_tableau(options.discretization.rk_scheme, options.discretization.n_s);
  if (auto e = discretization::PdsInterval::errors(tab, options.discretization, pds); !e.empty())
    throw InvalidOption(registry::join(e));
  if (!(model.x0_tol >= 0))
    throw InvalidModel(fmt::format("model: x0_tol = {}: must be >= 0", model.x0_tol));
  Eigen::VectorXd c(model.n_c());
  model.functions().c(x0.data(), p.data(), c.data());
  for (int k = 0; k < model.n_c(); ++k) {
    if (!std::isfinite(c[k]))
      throw InvalidModel(fmt::format("c{}(x0) = {}: must be finite", k + 1, c[k]));
    if (c[k] < -model.x0_tol)
      throw InvalidModel(
          fmt::format("x0 lies outside C = {{x : c(x) >= 0}}: c{}(x0) = {:.6g} < -x0_tol = {:.3g}",
                      k + 1, c[k], -model.x0_tol));
  }
}

/// LICQ at x0: the gradients of the active constraints (c_k(x0) <= x0_tol) linearly independent.
std::vector<std::string> licq_warnings(const Pds& m, const Eigen::VectorXd& x0,
                                       const Eigen::VectorXd& p) {
  Eigen::VectorXd c(m.n_c());
  m.functions().c(x0.data(), p.data(), c.data());
  std::vector<int> active;
  for (int k = 0; k < m.n_c(); ++k)
    if (c[k] <= m.x0_tol) active.push_back(k);
  if (active.empty()) return {};
  Eigen::MatrixXd G(m.n_x(), static_cast<Eigen::Index>(active.size()));
  for (std::size_t a = 0; a < active.size(); ++a)
    G.col(static_cast<Eigen::Index>(a)) = grad_c(m, x0, p, active[a]);
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(G);
  qr.setThreshold(1e-10);
  if (qr.rank() == static_cast<Eigen::Index>(active.size())) return {};
  std::vector<int> one_based;
  for (int k : active) one_based.push_back(k + 1);
  return {fmt::format(
      "LICQ fails at x0: the gradients of the active constraints c{} are linearly dependent "
      "(rank {} of {}); lambda is not unique and the NLPs may converge slowly",
      fmt::join(one_based, ", c"), qr.rank(), active.size())};
}

}  // namespace

IntegratorResult integrate(const Pds& model, const Eigen::VectorXd& x0, double T_sim, int N_sim,
                           const IntegratorOptions& options, const Eigen::VectorXd& u_in,
                           const Eigen::VectorXd& p_in, const PdsOptions& pds) {
  const auto t_start = Clock::now();
  const Eigen::VectorXd u = u_in.size() == 0 ? Eigen::VectorXd::Zero(model.n_u()) : u_in;
  const Eigen::VectorXd p = p_in.size() == 0 ? model.p_default : p_in;
  check_input(model, x0, T_sim, N_sim, options, u, p, pds);
  const DiscretizationOptions& d = options.discretization;
  const Tableau tab = make_tableau(d.rk_scheme, d.n_s);
  const double T_step = T_sim / N_sim;
  const int n_x = model.n_x(), n_c = model.n_c();

  IntegratorResult res;
  res.summary.warnings = warnings(options.homotopy);
  for (auto& w : licq_warnings(model, x0, p)) res.summary.warnings.push_back(std::move(w));
  for (auto& w : nlp::warnings(options.nlp)) res.summary.warnings.push_back(std::move(w));

  // ---- the step problem ----
  mpcc::Problem mpcc;
  nlp::BlockNlp& nlp = mpcc.nlp();
  discretization::PdsIntervalInputs in;
  in.s0 = range_of(nlp.add_variables(n_x, 0.0, 0.0, 0.0), n_x);
  in.q = range_of(nlp.add_variables(model.n_u(), 0.0, 0.0, 0.0), model.n_u());
  in.p = range_of(nlp.add_variables(model.n_p(), 0.0, 0.0, 0.0), model.n_p());
  in.T = T_step;
  discretization::PdsInterval iv(model, tab, d, pds);
  iv.build(nlp, in);
  mpcc.add_complementarity(iv.groups(), iv.residual_pairs());
  mpcc.relax(options.homotopy.mpcc_mode);
  mpcc.fix(in.q, u);
  mpcc.fix(in.p, p);
  // Warm starts with the small pushes of pds_nlp_options(); a step whose homotopy fails is solved
  // once more from the same guess with IPOPT's own pushes (Summary::fallback_steps).
  std::unique_ptr<nlp::NlpSolver> solver =
      nlp::make_solver(discretization::pds_nlp_options(options.nlp));
  std::unique_ptr<nlp::NlpSolver> fallback_solver;

  res.t.push_back(0.0);
  res.x.push_back(x0);
  Eigen::VectorXd x = x0;
  double t = 0;
  // A failed step goes to the fallback solver, not through the OCP's rungs.
  const HomotopyOptions step_homotopy = mpcc::step_homotopy_options(options.homotopy);
  for (int step = 0; step < N_sim; ++step) {
    mpcc.fix(in.s0, x);
    const StepGuess g = projected_euler(model, tab, iv.N_FE(), T_step, x, u, p);
    iv.set_guess(mpcc.guess(), x, g.X, g.lambda, u, p);
    if (!mpcc.finalized()) {
      mpcc.finalize();
      res.summary.n_variables = mpcc.num_variables();
      res.summary.n_constraints = mpcc.num_constraints();
      res.summary.setup_s = seconds_since(t_start);
    }
    mpcc::HomotopyResult hr = mpcc.solve_homotopy(*solver, step_homotopy);
    nlp::NlpSolver* step_nlp_solver = solver.get();
    if (hr.status != Status::Success) {
      if (!fallback_solver) fallback_solver = nlp::make_solver(options.nlp);
      mpcc::HomotopyResult again = mpcc.solve_homotopy(*fallback_solver, step_homotopy);
      if (again.status == Status::Success) ++res.summary.fallback_steps;
      mpcc::append(hr, again);
      hr.status = again.status;
      step_nlp_solver = fallback_solver.get();
    }
    // The re-solve with the active set of every element fixed (PdsInterval::active_set_bounds);
    // if it fails, the homotopy's solution stays.
    if (hr.status == Status::Success && d.use_fesd && options.homotopy.fix_active_set) {
      mpcc::HomotopyResult again = mpcc.solve_again(*step_nlp_solver, options.homotopy,
                                                    iv.active_set_bounds(mpcc.solution().data()));
      if (again.status == Status::Success) {
        mpcc::append(hr, again);
        ++res.summary.active_set_solves;
        hr.active_set_fixed = true;
      } else {
        mpcc::append_discarded(hr, again);  // the homotopy's point, residual and status stay
        ++res.summary.active_set_failures;
      }
    }
    ++res.summary.homotopy_path_steps;
    res.homotopy.emplace_back();
    mpcc::add_to_summary(hr, res.summary, res.homotopy.back());
    res.summary.max_comp_residual = std::max(res.summary.max_comp_residual, hr.comp_residual);
    if (options.on_step)
      options.on_step({step + 1, N_sim, t, static_cast<int>(hr.rows.size()), hr.nlp_iterations,
                       hr.comp_residual, hr.status});
    if (hr.status != Status::Success) {
      res.status = hr.status;
      res.message = fmt::format(
          "step {} of {} (t = {:.6g}): {} (last NLP: {}, complementarity "
          "residual {:.2e})",
          step + 1, N_sim, t, describe(hr.status), hr.last_nlp_status, hr.comp_residual);
      break;
    }
    // ---- append the step's elements ----
    const std::vector<double>& w = mpcc.solution();
    for (int n = 0; n < iv.N_FE(); ++n) {
      const double hn = w[iv.h(n)];
      const std::vector<int> active = iv.active_set(w.data(), n);
      for (int i = 0; i < iv.n_s(); ++i) {
        res.t_stage.push_back(t + tab.c[i] * hn);
        res.x_stage.push_back(gather(w, iv.X(n, i, 0), n_x));
        res.lambda.push_back(gather(w, iv.lambda(n, i, 0), n_c));
      }
      if (!res.active_set.empty() && res.active_set.back() != active)
        res.switches.push_back(
            {t, static_cast<int>(res.h.size()) - 1, res.active_set.back(), active});
      res.active_set.push_back(active);
      res.h.push_back(hn);
      t += hn;
      res.t.push_back(t);
      res.x.push_back(gather(w, iv.x(n + 1, 0), n_x));
    }
    x = res.x.back();
  }
  if (res.status == Status::NotRun) {
    res.status = Status::Success;
    res.message = std::string(describe(Status::Success));
  }
  res.summary.wall_s = seconds_since(t_start);
  return res;
}

}  // namespace fesd
