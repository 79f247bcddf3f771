// bench/sensitivity_ocp.hpp: the sensitivity OCP (56) of papers/fesd-filippov.txt (Sect. 4.5),
//
//   min_{x0}  int_0^2 x(t)^2 dt + (x(2) - 5/3)^2   s.t.  x(0) = x0,  x' in 2 - sign(x),
//
// shared by bench/sensitivity_ocp.cpp and the tests. Exact solution (REFERENCE.md): the only
// local minimizer is x0* = (9 - sqrt(417)) / 8 with V* = 1.5237727753749571.
#pragma once
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include <fesd/model.hpp>
#include <fesd/ocp.hpp>

namespace fesd_bench {

inline const double kSensitivityX0Star = (9.0 - std::sqrt(417.0)) / 8.0;
inline constexpr double kSensitivityVStar = 1.5237727753749571;

/// The initial guesses of Fig. 9 (right): n values of x0 spread evenly over [-3, 3] (0.5 for n =
/// 1).
inline std::vector<double> sensitivity_guesses(int n) {
  std::vector<double> g;
  for (int k = 0; k < n; ++k) g.push_back(n == 1 ? 0.5 : -3.0 + 6.0 * k / (n - 1));
  return g;
}

/// x' in 2 - sign(x): region 0 (c = x > 0): x' = 1, region 1 (x < 0): x' = 3.
struct SensitivityModel {
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int region, const T*, const T*, const T*, T* f) const {
    f[0] = T(region == 0 ? 1.0 : 3.0);
  }
};

struct SensitivityCost {
  template <class T>
  T f_q(const T* x, const T*, const T*) const {
    return x[0] * x[0];
  }
  template <class T>
  T f_q_T(const T* x, const T*) const {
    return (x[0] - 5.0 / 3.0) * (x[0] - 5.0 / 3.0);
  }
};

/// (56) with x0 free (unbounded) and initial guess x0_guess; one control interval of length 2.
inline fesd::Ocp sensitivity_ocp(double x0_guess) {
  fesd::Ocp ocp;
  ocp.model = fesd::make_pss(SensitivityModel{},
                             fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
  ocp.functions = fesd::make_ocp_functions(SensitivityCost{});
  ocp.T = 2.0;
  ocp.N_stages = 1;
  ocp.x0 = Eigen::VectorXd::Constant(1, x0_guess);
  ocp.lbx0 = Eigen::VectorXd::Constant(1, -INFINITY);
  ocp.ubx0 = Eigen::VectorXd::Constant(1, INFINITY);
  return ocp;
}

/// The paper's settings: Gauss-Legendre n_s = 2, N_FE = 25, initialization by a simulation from
/// x0_guess on the same grid; sigma from sigma_0 to 1e-15 (homotopy) or fixed at 1e-15; step
/// equilibration l2_relaxed (the OCP default).
inline fesd::OcpOptions sensitivity_options(
    bool use_fesd, bool homotopy, fesd::MpccMode mode = fesd::MpccMode::ScholtesIneq,
    fesd::CrossComp cross_comp = fesd::CrossComp::StageSum) {
  fesd::OcpOptions o;
  o.discretization.rk_scheme = fesd::RkScheme::GaussLegendre;
  o.discretization.n_s = 2;
  o.discretization.N_FE = 25;
  o.discretization.use_fesd = use_fesd;
  o.discretization.cross_comp = cross_comp;
  o.initialization = fesd::OcpInitialization::Simulation;
  o.homotopy.mpcc_mode = mode;
  o.homotopy.sigma_N = 1e-15;
  o.homotopy.complementarity_tol = 1e-12;
  if (!homotopy) o.homotopy.sigma_0 = 1e-15;  // one NLP with a fixed sigma
  return o;
}

}  // namespace fesd_bench
