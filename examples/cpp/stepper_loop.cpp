// examples/cpp/stepper_loop.cpp: the stepping API (fesd::Stepper) in a control loop, as in a
// hardware-in-the-loop or MPC plant simulation: a block with Coulomb friction driven by a
// proportional velocity controller that tracks v_ref(t) = sin(t), with a new control every step.
//
//   position' = v,   v' = u - F_c sign(v),   u = K (v_ref - v)    (F_c = 0.5, K = 4, h = 10 ms)
//
// Where v_ref turns, |u| < F_c: the block sticks (a sliding mode on v = 0) until the controller
// pushes hard enough. The Stepper is created once (all memory sized there); each step() writes
// x(t + h) into the caller's vector, without heap allocation once the active-set shapes met have
// been seen (docs/active-set.md, "Stepping API"). Builds against the installed package.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <fesd/stepper.hpp>

struct FrictionBlock {
  // x = (position, v); one switching function c = v; region 0: v > 0, region 1: v < 0.
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[1];
  }
  template <class T>
  void f(int region, const T* x, const T* u, const T* p, T* f) const {
    f[0] = x[1];
    f[1] = u[0] - (region == 0 ? 1.0 : -1.0) * p[0];  // u - F_c sign(v)
  }
};

int main() {
  fesd::Pss model = fesd::make_pss(
      FrictionBlock{},
      fesd::PssDims{.n_x = 2, .n_u = 1, .n_p = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
  model.p_default = Eigen::VectorXd::Constant(1, 0.5);  // F_c
  const double h = 0.01, K = 4.0;
  fesd::Stepper stepper(model, h);  // Radau IIA n_s = 2, N_FE = 2 per step (the defaults)

  Eigen::VectorXd x = Eigen::Vector2d(0.0, 0.0), u(1);
  const Eigen::VectorXd p;  // empty: the model's p_default
  double worst_us = 0, total_us = 0;
  const int N = 1000;
  std::printf("%8s %12s %12s %10s  %s\n", "t", "position", "v", "u", "step");
  for (int k = 0; k < N; ++k) {
    const double t = k * h;
    u[0] = K * (std::sin(t) - x[1]);  // the controller: a new u every step
    const auto t0 = std::chrono::steady_clock::now();
    const fesd::Status s = stepper.step(x, u, p, x);  // x(t + h) into x
    const double us =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    if (s != fesd::Status::Success) {
      std::printf("step %d failed: %s\n", k, stepper.last_step().message.c_str());
      return 1;
    }
    worst_us = std::max(worst_us, us);
    total_us += us;
    if (k % 100 == 99 || stepper.last_step().switched)
      std::printf("%8.3f %12.6f %12.6f %10.4f  %s\n", t + h, x[0], x[1], u[0],
                  stepper.last_step().switched ? "switch" : "");
  }
  const fesd::StepperStats& st = stepper.stats();
  std::printf(
      "%ld steps: %ld on the active-set path, %ld by the homotopy fallback; %.1f us per "
      "step on average, %.1f us the slowest (a step meeting a new shape, or the OS taking the "
      "core)\n",
      st.steps, st.active_set_steps, st.homotopy_steps, total_us / N, worst_us);
  return 0;
}
