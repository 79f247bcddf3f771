// bench/value_function.hpp: V(x0) and V'(x0) of the OCP (56) of papers/fesd-filippov.txt by
// simulation (Fig. 9, left): shared by bench/fig9_value_function.cpp and
// tests/acceptance/value_function_test.cpp.
//
//   V(x0) = int_0^2 x(t)^2 dt + (x(2) - 5/3)^2,   x' in 2 - sign(x),   x(0) = x0        (56)
//
// The integral is a second state q' = x^2, q(0) = 0, integrated by the same scheme on the same
// grid (the quadrature of the discretized OCP's cost), so V = q(2) + (x(2) - 5/3)^2 and, from the
// integrator's sensitivities dz(2)/dz0 of z = (x, q) (docs/sensitivities.md; first column: d/dx0),
// V'(x0) = dq(2)/dx0 + 2 (x(2) - 5/3) dx(2)/dx0. The derivative of the quadrature thus includes the
// motion of the switch time, as the IFT of the step's square system does for x.
#pragma once
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include <fesd/integrator.hpp>
#include <fesd/model.hpp>

namespace fesd_bench {

/// x' in 2 - sign(x) (region 0: x > 0, x' = 1; region 1: x < 0, x' = 3), q' = x^2.
struct ValueModel {
  template <class T>
  void c(const T* z, const T*, T* c) const {
    c[0] = z[0];
  }
  template <class T>
  void f(int region, const T* z, const T*, const T*, T* f) const {
    f[0] = T(region == 0 ? 1.0 : 3.0);
    f[1] = z[0] * z[0];
  }
};

inline fesd::Pss value_model() {
  return fesd::make_pss(ValueModel{},
                        fesd::PssDims{.n_x = 2, .subsystems = {fesd::Subsystem::from_c(1)}});
}

inline constexpr double kValueT = 2.0;
inline constexpr double kValueTarget = 5.0 / 3.0;

/// The exact V and V' (REFERENCE.md): for x0 >= 0, x = x0 + t, V = ((x0 + 2)^3 - x0^3) / 3 +
/// (x0 + 1/3)^2, V' = 6 x0 + 14/3 (the right derivative at the kink x0 = 0); for -6 < x0 < 0, x
/// reaches 0 at t_s = -x0 / 3 and then x = t - t_s, V = -x0^3 / 9 + (2 + x0/3)^3 / 3 + (1/3 +
/// x0/3)^2, V' = -x0^2 / 3 + (2 + x0/3)^2 / 3 + 2 (1 + x0) / 9, zero at x0* = (9 - sqrt 417) / 8.
struct ExactValue {
  double V = 0, dV = 0;
};
inline ExactValue exact_value(double x0) {
  if (x0 >= 0)
    return {(std::pow(x0 + 2, 3) - std::pow(x0, 3)) / 3 + std::pow(x0 + 1.0 / 3.0, 2),
            6 * x0 + 14.0 / 3.0};
  return {-std::pow(x0, 3) / 9 + std::pow(2 + x0 / 3, 3) / 3 + std::pow((1 + x0) / 3, 2),
          -x0 * x0 / 3 + std::pow(2 + x0 / 3, 2) / 3 + 2 * (1 + x0) / 9};
}

/// V and V' from one simulation (N_sim steps) with sensitivities; NaN where the run failed or
/// the sensitivities are not available (`why` then says so).
struct SimulatedValue {
  double V = std::numeric_limits<double>::quiet_NaN();
  double dV = std::numeric_limits<double>::quiet_NaN();
  fesd::Status status = fesd::Status::NotRun;
  std::string why;
  double cpu_s = 0;
};
inline SimulatedValue simulated_value(const fesd::Pss& model, double x0, int N_sim,
                                      fesd::IntegratorOptions o) {
  o.sensitivities = true;
  const fesd::IntegratorResult r =
      fesd::integrate(model, Eigen::Vector2d(x0, 0.0), kValueT, N_sim, o);
  SimulatedValue v;
  v.status = r.status;
  v.cpu_s = r.summary.wall_s;
  if (r.status != fesd::Status::Success) {
    v.why = r.message;
    return v;
  }
  const Eigen::VectorXd z = r.x_final();
  v.V = z[1] + (z[0] - kValueTarget) * (z[0] - kValueTarget);
  if (!r.sensitivities.available) {
    v.why = r.sensitivities.message;
    return v;
  }
  const Eigen::MatrixXd& S = r.sensitivities.x0;
  v.dV = S(1, 0) + 2 * (z[0] - kValueTarget) * S(0, 0);
  return v;
}

/// The paper's discretization of Fig. 9: Gauss-Legendre n_s = 2, N_FE = 25 on [0, 2] (one
/// control interval: N_sim = 1); FESD or the standard method (26).
inline fesd::IntegratorOptions fig9_options(bool use_fesd) {
  fesd::IntegratorOptions o;
  o.discretization.rk_scheme = fesd::RkScheme::GaussLegendre;
  o.discretization.n_s = 2;
  o.discretization.N_FE = 25;
  o.discretization.use_fesd = use_fesd;
  return o;
}

}  // namespace fesd_bench
