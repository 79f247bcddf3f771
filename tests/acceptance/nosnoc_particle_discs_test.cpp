// nosnoc_py's particle exercise and discs exercise (docs/nosnoc-examples.md rows 13 and 22):
// examples/nosnoc/particle.toml and examples/nosnoc/disc_switch_places.toml, both in the
// Heaviside step form with a general inclusion f(x, alpha) and time freezing, each run as
// written and checked against what is known about its solution.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "fesd/ocp.hpp"
#include "fesd/problem_file.hpp"

namespace {

std::string example_path(const std::string& file) {
  return std::string(FESD_SOURCE_DIR) + "/examples/nosnoc/" + file;
}

// The state at the element boundary tau (the numerical time), which must be a boundary.
Eigen::VectorXd state_at(const fesd::OcpResult& r, double tau) {
  for (std::size_t i = 0; i < r.t.size(); ++i)
    if (std::abs(r.t[i] - tau) < 1e-9) return r.x[i];
  ADD_FAILURE() << "no element boundary at tau = " << tau;
  return Eigen::VectorXd::Constant(r.x.front().size(), NAN);
}

// The particle's exact motion (derived in the file's header) in the physical time t: thrown
// from (0, 1) with (3, 0), g = 10; impact at t_i = 1/sqrt(5) with vy = -2 sqrt(5), which the
// Coulomb impulse (mu = 0.2) turns into vy = 0, vx = 3 - 2/sqrt(5); sliding with dvx/dt =
// -mu g = -2 until rest at t = 1.5, x = 2.45. Returns (qx, qy, vx, vy).
Eigen::Vector4d particle_exact(double t) {
  const double ti = 1.0 / std::sqrt(5.0);
  if (t <= ti) return {3 * t, 1 - 5 * t * t, 3.0, -10 * t};
  const double vx_i = 3.0 - 2.0 / std::sqrt(5.0);
  if (t <= 1.5) {
    const double dt = t - ti;
    return {3 * ti + vx_i * dt - dt * dt, 0.0, vx_i - 2 * dt, 0.0};
  }
  return {2.45, 0.0, 0.0, 0.0};
}

// 20 control intervals of 0.125 (nosnoc_py's 20 simulation steps), 5 elements each, one speed of
// time per interval. Exact: the clock reads k/8 at every interval end; the speeds are 1 in
// flight, 3 on the impact interval [0.375, 0.5] (flight 1/sqrt5 - 3/8, impulse sqrt5/10 with the
// clock frozen, sliding at th1 = 2/3: s * 0.125 = 0.375 exactly), 1.5 while sliding (th1 = 2/3)
// and 2 at rest (th1 = 1/2). Measured: the states at every interval end before the impact to
// 1.2e-8, vx, vy, qy after it to 2e-7; the speeds to 3e-7; the stop at tau = 1.5 to 1e-12.
// One element, the last of the impact interval, holds both the end of the impulse and the start
// of sliding (its right end point carries the sliding weights), so qx is off by 2.1e-4 from
// there on: qx(2.5) = 2.449790 against 2.45; the increments of qx after tau = 0.5 are exact to
// 1e-8.
TEST(NosnocParticleDiscs, ParticleFollowsTheExactThrowImpactSlideRest) {
  const fesd::OcpProblem p = fesd::load_ocp_problem(example_path("particle.toml"));
  const fesd::OcpResult r = fesd::solve(p.ocp, p.options);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_EQ(r.s_sot.size(), 20u);
  for (int k = 0; k < 20; ++k) {
    const double s_exact = k < 3 ? 1.0 : k == 3 ? 3.0 : k < 12 ? 1.5 : 2.0;
    EXPECT_NEAR(r.s_sot[k], s_exact, 1e-5) << "interval " << k;
  }
  const Eigen::VectorXd x_half = state_at(r, 0.5);
  for (int k = 0; k <= 20; ++k) {
    const double tau = k * 0.125;
    const Eigen::VectorXd x = state_at(r, tau);
    EXPECT_NEAR(x[4], tau, 1e-9) << "clock at interval end " << k;
    const Eigen::Vector4d e = particle_exact(x[4]);
    if (k <= 3) {
      for (int i = 0; i < 4; ++i) EXPECT_NEAR(x[i], e[i], 1e-6) << "k " << k << " i " << i;
    } else {
      EXPECT_NEAR(x[1], 0.0, 1e-6) << k;
      EXPECT_NEAR(x[2], e[2], 1e-5) << k;
      EXPECT_NEAR(x[3], 0.0, 1e-5) << k;
      EXPECT_NEAR(x[0] - x_half[0], e[0] - particle_exact(0.5)[0], 1e-6) << k;
    }
  }
  EXPECT_NEAR(r.x_final()[0], 2.45, 5e-4);
  // The impact enters the contact region at tau = 3/8 + (1/sqrt5 - 3/8)/3; the particle comes to
  // rest (vx = 0: every region active) at tau = t = 1.5.
  ASSERT_GE(r.switches.size(), 2u);
  EXPECT_NEAR(r.switches.front().t, 0.375 + (1.0 / std::sqrt(5.0) - 0.375) / 3.0, 1e-6);
  EXPECT_NEAR(r.switches.back().t, 1.5, 1e-6);
  EXPECT_EQ(r.switches.back().after.size(), 8u);
}

// The discs OCP as written takes minutes (docs/nosnoc-examples.md, row 22), so this checks what
// decides its physics, on the file's own f_alpha: in the contact region (gap f_c < 0 and
// approaching, v_n < 0: alpha = (0, 0)) positions stand still, the total momentum
// m1 v1 + m2 v2 does not change and the kinetic energy falls at the rate sot a_n v_n < 0 (an
// inelastic normal impulse); the clock runs at sot in every region (not frozen, so the clock
// constraints force sot = 1); apart (alpha_1 = 1) the field is the free motion under u and drag.
TEST(NosnocParticleDiscs, DiscsContactFieldConservesMomentumAndDissipates) {
  const fesd::OcpProblem p = fesd::load_ocp_problem(example_path("disc_switch_places.toml"));
  const fesd::Pss& m = p.ocp.model;
  ASSERT_TRUE(m.has_f_alpha());
  ASSERT_EQ(m.n_x(), 9);
  ASSERT_EQ(m.n_c(), 2);
  EXPECT_TRUE(p.ocp.time_freezing);
  EXPECT_FALSE(p.ocp.use_speed_of_time_variables);
  EXPECT_EQ(p.ocp.clock_state, 8);
  const double m1 = 2, m2 = 1, a_n = 10;
  // Overlapping by a little, disc 1 moving into disc 2 (d = q1 - q2 = (0.45, 0.1)).
  const Eigen::VectorXd x =
      (Eigen::VectorXd(9) << 0.2, 0.3, -0.25, 0.2, -1.5, 0.4, 0.3, -0.2, 1.7).finished();
  const Eigen::Vector3d u(4.0, -3.0, 1.3);
  const Eigen::VectorXd& par = m.p_default;
  const double dx = x[0] - x[2], dy = x[1] - x[3];
  const double f_c = dx * dx + dy * dy - 0.25;
  const double v_n = 2 * dx * (x[4] - x[6]) + 2 * dy * (x[5] - x[7]);
  ASSERT_LT(f_c, 0.0);
  ASSERT_LT(v_n, 0.0);
  Eigen::VectorXd f(9);
  const Eigen::Vector2d contact(0.0, 0.0);
  m.functions().f_alpha(x.data(), contact.data(), u.data(), par.data(), f.data());
  for (int i = 0; i < 4; ++i) EXPECT_EQ(f[i], 0.0) << i;
  EXPECT_NEAR(m1 * f[4] + m2 * f[6], 0.0, 1e-14);
  EXPECT_NEAR(m1 * f[5] + m2 * f[7], 0.0, 1e-14);
  const double dKE = m1 * (x[4] * f[4] + x[5] * f[5]) + m2 * (x[6] * f[6] + x[7] * f[7]);
  EXPECT_NEAR(dKE, u[2] * a_n * v_n, 1e-12);
  EXPECT_LT(dKE, 0.0);
  EXPECT_EQ(f[8], u[2]);  // the clock is not frozen
  // Apart: free motion, drag cv v / |v + eps| (eps added to each component), clock at sot.
  const Eigen::Vector2d apart(1.0, 0.0);
  m.functions().f_alpha(x.data(), apart.data(), u.data(), par.data(), f.data());
  const double n1 = std::hypot(x[4] + 0.1, x[5] + 0.1);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(f[i], u[2] * x[4 + i], 1e-14) << i;
  EXPECT_NEAR(f[4], u[2] * (u[0] - 2 * x[4] / n1) / m1, 1e-14);
  EXPECT_EQ(f[8], u[2]);
}

// The discs file with its control fixed (an impact test of the discretized model, cheap enough
// for the suite; the OCP itself is in docs/nosnoc-examples.md): disc 1 pushed straight at disc 2
// by ux = -4 (sot = 1, uy = 0) for 2.5 s, 10 intervals. Exact properties: disc 2 rests at (-1, 0)
// until disc 1 touches it (only contact moves it); the discs never overlap (f_c >= 0); during
// the impact (the contact region alone: th2 = 1) positions stand still, the total momentum is
// conserved and the kinetic energy falls (inelastic: the normal impulse ends at v_n = 0); after
// it the two move together along the x axis (v_n = 0: equal x velocities); the clock reads
// k T / N_stages at every interval end. Measured: touch at tau = 1.928, f_c >= -2.5e-8, momentum
// over the pure-contact element to 3e-8 (-3.1688), positions there to 9e-8, kinetic energy
// 2.510 -> 1.760; disc 2 before the touch at rest to 2e-8 (the relaxed products th lambda <=
// sigma_N = 1e-8 leave a contact weight of that order); v1x = v2x = -1.003747 at T.
TEST(NosnocParticleDiscs, DiscsImpactIsInelasticAndConservesMomentum) {
  fesd::OcpProblem p = fesd::load_ocp_problem(example_path("disc_switch_places.toml"));
  fesd::apply_override(p, "T", "2.5");
  fesd::apply_override(p, "N_stages", "10");
  fesd::apply_override(p, "N_homotopy", "0");
  p.ocp.lbu = Eigen::Vector3d(-4.0, 0.0, 1.0);
  p.ocp.ubu = p.ocp.lbu;
  p.ocp.u_guess = p.ocp.lbu;
  const fesd::OcpResult r = fesd::solve(p.ocp, p.options);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  auto gap = [](const Eigen::VectorXd& x) {
    return std::pow(x[0] - x[2], 2) + std::pow(x[1] - x[3], 2) - 0.25;
  };
  auto momentum = [](const Eigen::VectorXd& x) {
    return Eigen::Vector2d(2 * x[4] + x[6], 2 * x[5] + x[7]);
  };
  auto kinetic = [](const Eigen::VectorXd& x) {
    return x[4] * x[4] + x[5] * x[5] + 0.5 * (x[6] * x[6] + x[7] * x[7]);
  };
  bool touched = false;
  int contact_elements = 0;
  for (std::size_t i = 0; i < r.x.size(); ++i) {
    const Eigen::VectorXd& x = r.x[i];
    EXPECT_GE(gap(x), -1e-6) << i;
    if (gap(x) < 1e-6) touched = true;
    if (!touched) {
      EXPECT_NEAR(x[2], -1.0, 1e-6) << i;
      EXPECT_NEAR(x[6], 0.0, 1e-6) << i;
    }
    EXPECT_NEAR(x[1], 0.0, 1e-9) << i;
    EXPECT_NEAR(x[3], 0.0, 1e-9) << i;
  }
  for (const Eigen::VectorXd& x : r.x_stage) EXPECT_GE(gap(x), -1e-6);
  ASSERT_TRUE(touched);
  for (std::size_t n = 0; n < r.h.size(); ++n) {
    const Eigen::VectorXd& a = r.alpha[n];  // n_s = 1: one stage per element
    const double th2 = (1 - a[0]) * (1 - a[1]);
    if (th2 < 1 - 1e-6 || r.h[n] < 1e-6) continue;
    ++contact_elements;
    const Eigen::VectorXd& x0 = r.x[n];
    const Eigen::VectorXd& x1 = r.x[n + 1];
    EXPECT_NEAR((x1.head(4) - x0.head(4)).norm(), 0.0, 1e-6) << n;
    EXPECT_NEAR((momentum(x1) - momentum(x0)).norm(), 0.0, 1e-6) << n;
    EXPECT_LT(kinetic(x1), kinetic(x0)) << n;
  }
  EXPECT_GE(contact_elements, 1);
  EXPECT_NEAR(r.x_final()[4], r.x_final()[6], 1e-6);
  EXPECT_LT(r.x_final()[4], -0.5);
  for (int k = 0; k <= 10; ++k) EXPECT_NEAR(state_at(r, 0.25 * k)[8], 0.25 * k, 1e-9) << k;
}

}  // namespace
