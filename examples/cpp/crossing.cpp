// examples/cpp/crossing.cpp: Example 3(a) of the FESD paper in C++, x' in 2 - sign(x), x(0) = -1.
// The trajectory crosses x = 0 at t_s = 1/3, then x(t) = t - 1/3 (REFERENCE.md).
// Builds against the installed package: find_package(fesd) + target_link_libraries(... fesd::fesd).
#include <cmath>
#include <cstdio>

#include <fesd/integrator.hpp>
#include <fesd/model.hpp>

struct TwoSided {
  // One switching function c(x) = x; default sign matrix S = [[1], [-1]]: region 0 is x > 0.
  template <class T>
  void c(const T* x, const T*, T* c) const {
    c[0] = x[0];
  }
  template <class T>
  void f(int region, const T*, const T*, const T*, T* f) const {
    f[0] = T(region == 0 ? 1.0 : 3.0);  // 2 - sign(x)
  }
};

int main() {
  fesd::Pss model =
      fesd::make_pss(TwoSided{}, fesd::PssDims{.n_x = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
  fesd::IntegratorOptions opt;
  opt.discretization.n_s = 2;
  Eigen::VectorXd x0(1);
  x0 << -1.0;
  const double T = 2.0;
  const fesd::IntegratorResult r = fesd::integrate(model, x0, T, 10, opt);
  std::printf("%s\n", r.brief_report().c_str());
  const double err = std::abs(r.x_final()[0] - (T - 1.0 / 3.0));
  const bool ok = r.status == fesd::Status::Success && r.switches.size() == 1 &&
                  std::abs(r.switches[0].t - 1.0 / 3.0) < 1e-8 && err < 1e-8;
  std::printf("switch at t = %.12f (exact 1/3), |x(T) - (T - 1/3)| = %.2e: %s\n",
              r.switches.empty() ? -1.0 : r.switches[0].t, err, ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}
