// bench/gene_network_exact.hpp: the exact solution of a piecewise-affine gene network
// (Acary, de Jong, Brogliato 2014) whose trajectories cross the thresholds transversally, by
// event location in closed form. Shared by bench/irma_order.cpp and
// tests/acceptance/nosnoc_gene_networks_test.cpp.
//
//   x_i' = b_i(alpha) - gamma_i x_i,   alpha = (H(x_i - theta_ik))_{i,k} (Heaviside steps),
//
// b constant between threshold crossings. There x_i(t) = x*_i + (x_i(t0) - x*_i) e^{-gamma_i (t -
// t0)} with the focal point x*_i = b_i / gamma_i, and x_i reaches a threshold theta between x_i(t0)
// and x*_i at t0 + ln((x_i(t0) - x*_i) / (theta - x*_i)) / gamma_i. The next event is the earliest
// of these; at it alpha flips and b changes. A crossing after which x_i's own focal point lies
// back across its threshold would start a sliding mode (a self-regulating gene): not handled,
// exact_solution throws.
#pragma once
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <vector>

namespace fesd_bench {

struct GeneNetwork {
  std::vector<double> gamma;                    // degradation rates, one per state
  std::vector<std::vector<double>> thresholds;  // per state, the thresholds theta_ik
  /// Synthesis b(alpha), alpha in the order of the switching functions: state by state, each
  /// state's thresholds in the order given (nosnoc's order of c).
  std::function<std::vector<double>(const std::vector<double>& alpha)> b;
};

struct GeneEvent {
  double t = 0;
  int state = 0;      // i
  int threshold = 0;  // k
  int alpha = 0;      // index of the switching function (alpha_{alpha + 1} in a problem file)
  bool up = false;    // x_i crosses theta_ik upwards (alpha 0 -> 1)
};

struct GeneSolution {
  std::vector<double> x_T;
  std::vector<GeneEvent> events;
};

/// x(T) and the crossings of a trajectory from x0 at t = 0 (no state exactly on a threshold).
inline GeneSolution exact_solution(const GeneNetwork& net, std::vector<double> x, double T) {
  const int n = static_cast<int>(x.size());
  std::vector<double> alpha;
  std::vector<std::vector<int>> slot(n);  // slot[i][k]: index of alpha of theta_ik
  for (int i = 0; i < n; ++i)
    for (double th : net.thresholds[i]) {
      if (x[i] == th) throw std::invalid_argument("exact_solution: x0 on a threshold");
      slot[i].push_back(static_cast<int>(alpha.size()));
      alpha.push_back(x[i] > th ? 1.0 : 0.0);
    }
  GeneSolution sol;
  double t = 0;
  for (;;) {
    const std::vector<double> b = net.b(alpha);
    std::vector<double> xs(n);
    for (int i = 0; i < n; ++i) xs[i] = b[i] / net.gamma[i];
    double dt = T - t;
    int ei = -1, ek = -1;
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < static_cast<int>(net.thresholds[i].size()); ++k) {
        const double th = net.thresholds[i][k];
        const bool above = alpha[slot[i][k]] > 0.5;
        if (above ? !(xs[i] < th) : !(xs[i] > th)) continue;  // x_i moves away from theta_ik
        const double d = std::log((x[i] - xs[i]) / (th - xs[i])) / net.gamma[i];
        if (d < dt) {
          dt = d;
          ei = i;
          ek = k;
        }
      }
    for (int i = 0; i < n; ++i) x[i] = xs[i] + (x[i] - xs[i]) * std::exp(-net.gamma[i] * dt);
    t += dt;
    if (ei < 0) break;
    const int a = slot[ei][ek];
    x[ei] = net.thresholds[ei][ek];
    alpha[a] = 1.0 - alpha[a];
    sol.events.push_back({t, ei, ek, a, alpha[a] > 0.5});
    const double xs_new = net.b(alpha)[ei] / net.gamma[ei];
    if ((alpha[a] > 0.5) != (xs_new > x[ei]))
      throw std::runtime_error("exact_solution: sliding on a threshold (not handled)");
    if (sol.events.size() > 100000) throw std::runtime_error("exact_solution: too many events");
  }
  sol.x_T = x;
  return sol;
}

/// The IRMA network of Acary et al. (2014) as nosnoc_py's examples/Acary2014/irma.py defines
/// it, galactose switched on (SWITCH_ON = 1): x = (CBF1, GAL4, SWI5, GAL80, ASH1), thresholds
/// x1: 0.01; x2: 0.01, 0.06, 0.08; x3: 0.035; x4: 0.04; x5: 0.01 (alpha_1 .. alpha_7 in this
/// order), as examples/nosnoc/irma.toml:
///
///   x1' = 1.1e-4 + 9e-4 a6 - 0.05 x1,        x2' = 3e-4 + 0.15 a1 - 0.04 x2,
///   x3' = 6e-4 + 0.018 a3 - 0.05 x3,         x4' = 5e-4 a2 + 0.03 a2 (1 - a5) - 0.02 x4,
///   x5' = 7.5e-4 + 0.015 a4 - 0.6 x5.
inline GeneNetwork irma_network() {
  GeneNetwork net;
  net.gamma = {0.05, 0.04, 0.05, 0.02, 0.6};
  net.thresholds = {{0.01}, {0.01, 0.06, 0.08}, {0.035}, {0.04}, {0.01}};
  net.b = [](const std::vector<double>& a) {
    return std::vector<double>{1.1e-4 + 9e-4 * a[5], 3e-4 + 0.15 * a[0], 6e-4 + 0.018 * a[2],
                               5e-4 * a[1] + 0.03 * a[1] * (1 - a[4]), 7.5e-4 + 0.015 * a[3]};
  };
  return net;
}

inline std::vector<double> irma_x0() {
  return {0.011, 0.09, 0.04, 0.05, 0.015};
}

}  // namespace fesd_bench
