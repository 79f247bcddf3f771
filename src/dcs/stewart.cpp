#include "dcs/stewart.hpp"

#include <cmath>

namespace fesd::dcs {

LpSolution solve_lp(const Pss& m, const Eigen::VectorXd& x, const Eigen::VectorXd& p,
                    double tie_tol) {
  LpSolution s;
  s.g.resize(m.n_theta());
  eval_g<double>(m, x.data(), p.data(), s.g.data());
  s.lambda.resize(m.n_theta());
  s.mu.resize(m.n_sys());
  s.theta = Eigen::VectorXd::Zero(m.n_theta());
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
  return s;
}

}  // namespace fesd::dcs
