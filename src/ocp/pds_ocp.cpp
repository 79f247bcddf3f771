// src/ocp/pds_ocp.cpp: optimal control of projected dynamical systems, papers/fesd-pds.txt
// Sect. III-D (docs/pds.md, "Optimal control"): N_stages control intervals chained by their
// boundary states, each one PdsInterval (the FESD discretization (6), (8) with the step
// equilibration of Sect. III-C over T / N_stages), the costs and constraints of the piecewise
// smooth OCP (ocp_terms.hpp), the MPCC solved by the homotopy of src/mpcc, then once more with
// the active set of every element fixed.
#include <chrono>
#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "core/util.hpp"
#include "discretization/pds_interval.hpp"
#include "fesd/error.hpp"
#include "fesd/ocp.hpp"
#include "fesd/pds.hpp"
#include "mpcc/problem.hpp"
#include "nlp/nlp_solver.hpp"
#include "ocp/ocp_input.hpp"
#include "ocp/ocp_terms.hpp"

namespace fesd {
namespace {

using discretization::PdsInterval;
using discretization::PdsIntervalInputs;
using util::gather;
using util::seconds_since;
using Clock = std::chrono::steady_clock;

/// The MPCC of a PDS OCP and where its pieces live.
using PdsOcpNlp = ocp_detail::OcpNlpParts<PdsInterval>;

std::unique_ptr<PdsOcpNlp> build(const PdsOcp& ocp, const OcpOptions& o,
                                 const ocp_detail::StageParameters& p) {
  const Pds& m = ocp.model;
  const DiscretizationOptions& d = o.discretization;
  auto b = std::make_unique<PdsOcpNlp>();
  b->tab = make_tableau(d.rk_scheme, d.n_s);
  mpcc::Problem& mp = b->mpcc;
  ocp_detail::add_start_and_parameters(mp, ocp, p, b->s0, b->p, b->p_k);
  const double T_k = ocp.T / ocp.N_stages;
  for (int k = 0; k < ocp.N_stages; ++k) {
    b->q.push_back(ocp_detail::add_control(mp, ocp, m.n_u(), k));
    PdsIntervalInputs in;
    in.s0 = k == 0 ? b->s0 : ocp_detail::range(b->iv.back()->x(b->iv.back()->N_FE(), 0), m.n_x());
    in.q = b->q.back();
    in.p = b->p_k[static_cast<std::size_t>(k)];
    in.T = T_k;
    DiscretizationOptions dk = d;
    if (!ocp.N_FE.empty()) dk.N_FE = ocp.N_FE[k];
    b->iv.push_back(std::make_unique<PdsInterval>(m, b->tab, dk, ocp.pds));
    b->iv.back()->build(mp.nlp(), in);
  }
  ocp_detail::add_ocp_terms(mp, ocp, o, b->tab, m.n_x(), m.n_u(), b->s0, b->p_k, b->q, b->iv,
                            b->terminal_slacks, b->comp_points);
  for (const auto& iv : b->iv) mp.add_complementarity(iv->groups(), iv->residual_pairs());
  mp.relax(o.homotopy);
  return b;
}

/// x0 at every stage point, lambda = 0 (nothing in contact is assumed), the control guesses.
void guess_constant(PdsOcpNlp& b, const PdsOcp& ocp, const ocp_detail::StageParameters& p) {
  auto& w = b.mpcc.guess();
  for (std::size_t k = 0; k < b.iv.size(); ++k) {
    const PdsInterval& iv = *b.iv[k];
    const std::size_t stages = static_cast<std::size_t>(iv.N_FE() * iv.n_s());
    const std::vector<Eigen::VectorXd> X(stages, ocp.x0);
    const std::vector<Eigen::VectorXd> lambda(stages, Eigen::VectorXd::Zero(ocp.model.n_c()));
    iv.set_guess(w, ocp.x0, X, lambda, gather(w, b.q[k].empty() ? 0 : b.q[k][0], ocp.model.n_u()),
                 p[k]);
  }
  for (int i = 0; i < ocp.model.n_x(); ++i) w[b.s0[i]] = ocp.x0[i];
}

/// initialization = simulation: interval after interval, integrate() of the PDS from the state
/// reached (x0 first) with the interval's control guess, its N_FE and the same scheme and
/// homotopy; the guess is the simulated stage states, multipliers and element lengths. An interval
/// whose simulation fails keeps the constant guess from there on (returned as a warning).
std::string guess_simulation(PdsOcpNlp& b, const PdsOcp& ocp, const OcpOptions& o,
                             const ocp_detail::StageParameters& p) {
  auto& w = b.mpcc.guess();
  Eigen::VectorXd x = ocp.x0;
  const double T_k = ocp.T / ocp.N_stages;
  for (std::size_t k = 0; k < b.iv.size(); ++k) {
    const PdsInterval& iv = *b.iv[k];
    const Eigen::VectorXd u = gather(w, b.q[k].empty() ? 0 : b.q[k][0], ocp.model.n_u());
    IntegratorOptions io;
    io.discretization = o.discretization;
    io.discretization.N_FE = iv.N_FE();
    io.homotopy = o.homotopy;
    io.nlp = o.nlp;
    IntegratorResult r;
    try {
      r = integrate(ocp.model, x, T_k, 1, io, u, p[k], ocp.pds);
    } catch (const Error& e) {
      r.status = Status::NlpFailed;
      r.message = e.what();
    }
    if (r.status != Status::Success)
      return fmt::format(
          "initialization = simulation: the simulation of control interval {} failed ({}); the "
          "constant guess x0 from there on",
          k + 1, r.message);
    iv.set_guess(w, x, r.x_stage, r.lambda, u, p[k]);
    for (int n = 0; n < iv.N_FE(); ++n) w[iv.h(n)] = r.h[static_cast<std::size_t>(n)];
    x = r.x_final();
  }
  return "";
}

void extract(const PdsOcpNlp& b, const PdsOcp& ocp, const std::vector<double>& w,
             const ocp_detail::StageParameters& /*fixed*/, OcpResult& res) {
  const int n_c = ocp.model.n_c();
  const ocp_detail::StageParameters p = ocp_detail::solution_parameters(b.p_k, w);
  ocp_detail::extract_result(
      ocp, b.tab, ocp.model.n_x(), ocp.model.n_u(), b.s0, b.q, b.iv, b.terminal_slacks, w, p, res,
      [&](const PdsInterval& iv, int n, int s) {
        res.lambda.push_back(gather(w, iv.lambda(n, s, 0), n_c));
      },
      [](const PdsInterval& iv) {  // PDS: no eta of (31)
        return std::vector<double>(static_cast<std::size_t>(iv.N_FE()), std::nan(""));
      });
}

}  // namespace

OcpResult solve(const PdsOcp& ocp, const OcpOptions& options) {
  const auto t_start = Clock::now();
  ocp_detail::require_valid_input(ocp, options);
  const ocp_detail::StageParameters p = ocp_detail::stage_parameters(ocp, ocp.model.p_default);
  std::unique_ptr<PdsOcpNlp> b = build(ocp, options, p);
  mpcc::Problem& mp = b->mpcc;
  OcpResult res;
  res.mpcc_mode = options.homotopy.mpcc_mode;
  guess_constant(*b, ocp, p);
  res.summary.warnings = warnings(options.homotopy);
  if (options.initialization == OcpInitialization::Simulation)
    if (std::string w = guess_simulation(*b, ocp, options, p); !w.empty())
      res.summary.warnings.push_back(std::move(w));
  mp.finalize();
  res.summary.n_variables = mp.num_variables();
  res.summary.n_constraints = mp.num_constraints();
  res.summary.setup_s = seconds_since(t_start);

  const std::unique_ptr<nlp::NlpSolver> solver = nlp::make_solver(options.nlp);
  solver->set_progress(options.on_nlp_progress, options.nlp_progress_every_s);
  mpcc::HomotopyResult hr = mp.solve_homotopy(*solver, options.homotopy, options.on_homotopy_row);
  mpcc::add_to_summary(hr, res.summary, res.homotopy);
  if (std::string w = mpcc::cold_restart_warning(hr); !w.empty())
    res.summary.warnings.push_back(std::move(w));
  // The re-solve with the active set of every element fixed (PdsInterval::active_set_bounds):
  // complementarity then holds exactly; if it fails, the homotopy's solution stays.
  if (hr.status == Status::Success && options.discretization.use_fesd &&
      options.homotopy.fix_active_set) {
    std::vector<nlp::Bound> bounds;
    for (const auto& iv : b->iv)
      for (const nlp::Bound& bd : iv->active_set_bounds(mp.solution().data())) bounds.push_back(bd);
    const mpcc::HomotopyResult again = mp.solve_again(*solver, options.homotopy, bounds);
    if (options.on_homotopy_row) options.on_homotopy_row(again.rows.back());
    mpcc::add_to_summary(again, res.summary, res.homotopy);
    if (again.status == Status::Success) {
      ++res.summary.active_set_solves;
      hr.comp_residual = again.comp_residual;
    } else {
      ++res.summary.active_set_failures;
      res.summary.warnings.push_back(
          "the re-solve with the active sets fixed failed: the homotopy's solution stays");
    }
  }
  ocp_detail::set_outcome(hr, res);
  extract(*b, ocp, mp.solution(), p, res);
  ocp_detail::extract_globals(ocp, ocp.model.parameter_names, b->p, mp.solution(), res);
  res.T_final = ocp.T;
  res.summary.wall_s = seconds_since(t_start);
  return res;
}

}  // namespace fesd
