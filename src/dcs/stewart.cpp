#include "dcs/stewart.hpp"

#include <cmath>

#include <fmt/format.h>

#include "dcs/step.hpp"

namespace fesd::dcs {

LpSolution solve_lp(const Pss& m, const Eigen::VectorXd& x, const Eigen::VectorXd& p,
                    double tie_tol) {
  LpSolution s;
  std::vector<double> c, gd;
  solve_lp(m, x.data(), p.data(), s, c, gd, tie_tol);
  return s;
}

void solve_lp(const Pss& m, const double* x, const double* p, LpSolution& s, std::vector<double>& c,
              std::vector<double>& gd, double tie_tol) {
  s.g.resize(m.n_theta());
  eval_g<double>(m, x, p, s.g.data(), c, gd);
  s.lambda.resize(m.n_theta());
  s.mu.resize(m.n_sys());
  s.theta.setZero(m.n_theta());
  for (int k = 0; k < m.n_sys(); ++k) {
    const int r0 = m.region_offset(k), r1 = m.region_offset(k + 1);
    const double mu = s.g.segment(r0, r1 - r0).minCoeff();
    s.mu[k] = mu;
    const double scale = std::max(1.0, std::abs(mu));
    int ties = 0;
    for (int r = r0; r < r1; ++r) {
      s.lambda[r] = s.g[r] - mu;
      if (s.lambda[r] <= tie_tol * scale) ++ties;
    }
    for (int r = r0; r < r1; ++r)
      if (s.lambda[r] <= tie_tol * scale) s.theta[r] = 1.0 / ties;
  }
}

LpSolution solve_step(const Pss& m, const Eigen::VectorXd& x, const Eigen::VectorXd& p,
                      double tie_tol) {
  LpSolution s;
  const int n_c = m.n_c();
  s.g.resize(n_c);
  if (n_c > 0) m.functions().c(x.data(), p.data(), s.g.data());
  s.alpha.resize(n_c);
  s.lambda.resize(2 * n_c);
  for (int j = 0; j < n_c; ++j) {
    const double c = s.g[j];
    const double tol = tie_tol * std::max(1.0, std::abs(c));
    s.alpha[j] = c > tol ? 1.0 : (c < -tol ? 0.0 : 0.5);
    s.lambda[j] = std::max(-c, 0.0);       // lambda_n
    s.lambda[n_c + j] = std::max(c, 0.0);  // lambda_p
  }
  s.mu.resize(0);
  s.theta.resize(m.n_theta());
  eval_theta_of_alpha<double>(m, s.alpha.data(), s.theta.data());
  return s;
}

LpSolution solve_start(const Pss& m, DcsMode mode, const Eigen::VectorXd& x,
                       const Eigen::VectorXd& p) {
  return mode == DcsMode::Step ? solve_step(m, x, p) : solve_lp(m, x, p);
}

std::string step_mode_error(const Pss& m) {
  for (int k = 0; k < m.n_sys(); ++k)
    if (m.dims().subsystems[k].n_c == 0)
      return fmt::format(
          "discretization.dcs_mode = step: subsystem {} is given by indicator functions g "
          "(g-form); the Heaviside step form needs switching functions c with a sign matrix S "
          "(use dcs_mode = stewart, or write the subsystem with c and S)",
          k);
  return {};
}

}  // namespace fesd::dcs
