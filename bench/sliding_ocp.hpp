// bench/sliding_ocp.hpp: the sliding-mode OCP (61) of papers/fesd-filippov.txt (Sect. 5.3),
//
//   min  int_0^4 u'u + v'v dt + rho ||q(4) - q_final||_1
//   s.t. x = (q, v), x(0) = (2 pi / 3, pi / 3, 0, 0),
//        q' = -sign(c(x)) + v (componentwise), v' = u,  |v_i| <= 2,  |u_i| <= 10,
//        c(x) = (phi_1, phi_2), phi_1 = q1 + 0.15 q2^2, phi_2 = -0.05 q1^3 + q2,
//
// with rho = 1e3 and q_final = (-pi/6, -pi/4); and nosnoc_py's variant of it (PEERS.md, its
// examples/sliding_mode_ocp/sliding_mode_ocp.py): cost int v'v dt, terminal equality
// q(4) = q_final, |u| <= 10, no bound on v, v' = 2u, heuristic_mean step equilibration with
// rho_h = 10. Shared by bench/sliding_ocp.cpp, the tests and the examples.
//
// Cartesian product (Sect. 2.3), n_sys = 2: subsystem k switches on phi_k. x' = sum of the two
// subsystems' convex combinations. The paper's model writes the smooth part (v in q', u in v')
// once, into both regions of subsystem 1 (its theta sums to one). nosnoc_py's example gives
// subsystem k the fields (-+1 + v_k in q_k', u in v') in both its regions, so u enters v' once
// per subsystem: v' = 2u.
#pragma once
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

#include <fesd/model.hpp>
#include <fesd/ocp.hpp>

namespace fesd_bench {

struct SlidingModel {
  bool nosnoc = false;  ///< nosnoc_py's layout: v' = 2u (u in both subsystems)
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0] + 0.15 * x[1] * x[1];
    c[1] = -0.05 * x[0] * x[0] * x[0] + x[1];
  }
  // Regions (default sign matrix, S = [[1], [-1]] per subsystem): 0: phi_1 > 0, 1: phi_1 < 0,
  // 2: phi_2 > 0, 3: phi_2 < 0.
  template <class T>
  void f(int region, const T* x, const T* u, const T*, T* f) const {
    for (int i = 0; i < 4; ++i) f[i] = T(0.0);
    if (nosnoc) {  // region 2k: phi_k > 0, q_k' = -1 + v_k; region 2k + 1: q_k' = 1 + v_k
      const int k = region / 2;
      f[k] = (region % 2 == 0 ? -1.0 : 1.0) + x[2 + k];
      f[2] = u[0];
      f[3] = u[1];
      return;
    }
    switch (region) {
      case 0:
      case 1:
        f[0] = (region == 0 ? -1.0 : 1.0) + x[2];
        f[1] = x[3];
        f[2] = u[0];
        f[3] = u[1];
        break;
      default:
        f[1] = T(region == 2 ? -1.0 : 1.0);
        break;
    }
  }
};

inline fesd::Pss sliding_model(bool nosnoc = false) {
  return fesd::make_pss(
      SlidingModel{nosnoc},
      fesd::PssDims{.n_x = 4,
                    .n_u = 2,
                    .subsystems = {fesd::Subsystem::from_c(1), fesd::Subsystem::from_c(1)}});
}

inline Eigen::Vector2d sliding_q_final() {
  return {-std::numbers::pi / 6, -std::numbers::pi / 4};
}

/// int u'u + v'v dt (paper) or int v'v dt (nosnoc_py); g_terminal = q(4).
struct SlidingCost {
  bool with_u = true;
  template <class T>
  T f_q(const T* x, const T* u, const T*) const {
    T s = x[2] * x[2] + x[3] * x[3];
    if (with_u) s = s + u[0] * u[0] + u[1] * u[1];
    return s;
  }
  template <class T>
  void g_terminal(const T* x, const T*, T* g) const {
    g[0] = x[0];
    g[1] = x[1];
  }
};

/// The paper's (61): l1 terminal penalty rho = 1e3, |v| <= 2, |u| <= 10; N_stages = 6.
inline fesd::Ocp sliding_ocp_paper() {
  fesd::Ocp ocp;
  ocp.model = sliding_model();
  ocp.functions = fesd::make_ocp_functions(SlidingCost{true});
  ocp.T = 4.0;
  ocp.N_stages = 6;
  ocp.x0 = Eigen::Vector4d(2 * std::numbers::pi / 3, std::numbers::pi / 3, 0, 0);
  ocp.lbx = Eigen::Vector4d(-INFINITY, -INFINITY, -2, -2);
  ocp.ubx = Eigen::Vector4d(INFINITY, INFINITY, 2, 2);
  ocp.lbu = Eigen::Vector2d(-10, -10);
  ocp.ubu = Eigen::Vector2d(10, 10);
  ocp.n_g_terminal = 2;
  ocp.lbg_terminal = sliding_q_final();
  ocp.ubg_terminal = sliding_q_final();
  ocp.terminal_constraint = fesd::TerminalConstraint::L1;
  ocp.rho_terminal = 1e3;
  return ocp;
}

/// nosnoc_py's example (PEERS.md): cost int v'v, q(4) = q_final exactly, |u| <= 10, v free,
/// v' = 2u.
inline fesd::Ocp sliding_ocp_nosnoc() {
  fesd::Ocp ocp = sliding_ocp_paper();
  ocp.model = sliding_model(/*nosnoc=*/true);
  ocp.functions = fesd::make_ocp_functions(SlidingCost{false});
  ocp.lbx.resize(0);
  ocp.ubx.resize(0);
  ocp.terminal_constraint = fesd::TerminalConstraint::Hard;
  return ocp;
}

/// Radau IIA n_s = 2, N_FE = 6 per interval (the paper's Sect. 5.3 and nosnoc_py's settings).
inline fesd::OcpOptions sliding_options() {
  fesd::OcpOptions o;
  o.discretization.rk_scheme = fesd::RkScheme::RadauIIA;
  o.discretization.n_s = 2;
  o.discretization.N_FE = 6;
  o.discretization.step_eq = fesd::StepEq::HeuristicMean;
  o.discretization.rho_h = 10;
  o.homotopy.complementarity_tol = 1e-9;
  return o;
}

}  // namespace fesd_bench
