#include "dcs/stewart.hpp"

#include <cmath>

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

}  // namespace fesd::dcs
