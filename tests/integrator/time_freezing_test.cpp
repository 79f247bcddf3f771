// Time freezing (issue 17): a state jump written as a Filippov system with a clock state that
// stands still during the jump. examples/time_freezing_bouncing_ball.toml: a ball dropped from
// q = 1 bounces elastically; the impact v+ = -v- is an auxiliary spring q'' = -k q below the
// ground (k = 100) during which the clock t is frozen. Closed form (g = 9.81, h0 = 1):
// t1 = sqrt(2 h0 / g); in the numerical time tau the j-th impact starts at
// (2j - 1) t1 + (j - 1) pi / sqrt(k) and ends pi / sqrt(k) later; the clock reads (2j - 1) t1
// at both ends, and the ball leaves with v = +sqrt(2 g h0). Measured largest errors over the
// three impacts of tau in [0, 3] (entry/exit times, clock, exit speed), Radau IIA 3:
// 1.2e-5 at N_sim = 60 and 2.2e-7 at N_sim = 120 (order 5.8; the scheme has 2 n_s - 1 = 5).
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "fesd/integrator.hpp"
#include "fesd/problem_file.hpp"

namespace {

double max_impact_error(int N_sim) {
  fesd::SimulationProblem p = fesd::load_simulation_problem(
      std::string(FESD_SOURCE_DIR) + "/examples/time_freezing_bouncing_ball.toml");
  p.N_sim = N_sim;
  const fesd::IntegratorResult r =
      fesd::integrate(p.model, p.x0, p.T_sim, p.N_sim, p.options, p.u, p.p);
  EXPECT_EQ(r.status, fesd::Status::Success) << r.message;
  const double g = 9.81, k = 100.0, h0 = 1.0;
  const double t1 = std::sqrt(2 * h0 / g), frozen = M_PI / std::sqrt(k);
  const double speed = std::sqrt(2 * g * h0);
  // tau in [0, 3]: three entries (0.45, 1.67, 2.89) and two exits (0.77, 1.98).
  EXPECT_EQ(r.switches.size(), 5u);
  if (r.switches.size() != 5u) return INFINITY;
  auto state_at = [&](double tau) {
    for (std::size_t i = 0; i < r.t.size(); ++i)
      if (std::abs(r.t[i] - tau) < 1e-12) return r.x[i];
    ADD_FAILURE() << "no element boundary at tau = " << tau;
    return Eigen::VectorXd(Eigen::VectorXd::Constant(3, NAN));
  };
  double err = 0;
  for (int j = 1; j <= 3; ++j) {
    const fesd::SwitchEvent& entry = r.switches[static_cast<std::size_t>(2 * (j - 1))];
    EXPECT_EQ(entry.after, std::vector<int>{1}) << j;
    const double clock = (2 * j - 1) * t1;
    err = std::max(err, std::abs(entry.t - (clock + (j - 1) * frozen)));
    err = std::max(err, std::abs(state_at(entry.t)[2] - clock));
    err = std::max(err, std::abs(state_at(entry.t)[1] + speed));
    if (j == 3) break;
    const fesd::SwitchEvent& exit = r.switches[static_cast<std::size_t>(2 * j - 1)];
    EXPECT_EQ(exit.after, std::vector<int>{0}) << j;
    err = std::max(err, std::abs(exit.t - (clock + j * frozen)));
    err = std::max(err, std::abs(state_at(exit.t)[2] - clock));
    err = std::max(err, std::abs(state_at(exit.t)[1] - speed));
  }
  return err;
}

TEST(TimeFreezing, BouncingBallImpactsInClosedForm) {
  const double e60 = max_impact_error(60);
  const double e120 = max_impact_error(120);
  EXPECT_LT(e60, 3e-5);
  EXPECT_LT(e120, 5e-7);
  // Fifth order (2 n_s - 1 for Radau IIA 3): halving h divides the error by at least 2^4.
  EXPECT_GT(e60 / e120, 16.0);
}

}  // namespace
