// tests/nlp/fesd_nlp_fixture.hpp: what the derivative tests of tests/nlp share: a two-subsystem
// model with nonlinear c and f, a control and a parameter, and one FESD interval built into a
// BlockNlp with free start state, controls and multipliers (the OCP case: every input has
// derivatives) and its complementarity rows.
#pragma once
#include <cmath>
#include <vector>

#include "discretization/fesd_interval.hpp"
#include "fesd/model.hpp"
#include "mpcc/relaxation.hpp"

namespace fesd_test {

// Two subsystems (Cartesian product, eq. 21) with nonlinear g and f, a control and a parameter:
// subsystem 0 from c0 = x1 - p0 x2^2 (default S), subsystem 1 from two switching functions.
struct Nonlinear {
  template <class T>
  void c(const T* x, const T* p, T* c) const {
    using std::sin;
    c[0] = x[0] - p[0] * x[1] * x[1];
    c[1] = sin(x[1]) + 0.3 * x[0];
    c[2] = x[0] * x[1] - 0.1;
  }
  template <class T>
  void f(int r, const T* x, const T* u, const T* p, T* f) const {
    using std::cos;
    using std::exp;
    const double s = 1.0 + r;
    f[0] = -s * x[1] + u[0] * cos(x[0]) + p[0];
    f[1] = s * x[0] * x[1] - exp(0.1 * x[1]) * (r % 2 ? 1.0 : -1.0);
  }
};

inline fesd::Pss nonlinear_model() {
  return fesd::make_pss(Nonlinear{}, fesd::PssDims{.n_x = 2,
                                                   .n_u = 1,
                                                   .n_p = 1,
                                                   .subsystems = {fesd::Subsystem::from_c(1),
                                                                  fesd::Subsystem::from_c(2)}});
}

/// One interval of `model` with N_FE = 3 and T = 0.3 (boundary LP at the end) into `nlp`, with
/// its Scholtes rows; not finalized. `iv` must outlive `nlp`'s evaluations.
inline void build_interval(const fesd::Pss& model, fesd::discretization::FesdInterval& iv,
                           fesd::nlp::BlockNlp& nlp) {
  auto vars = [&](int n) {
    std::vector<int> v;
    const int first = nlp.add_variables(n, -1e20, 1e20, 0.0);
    for (int i = 0; i < n; ++i) v.push_back(first + i);
    return v;
  };
  fesd::discretization::IntervalInputs in;
  in.s0 = vars(model.n_x());
  in.q = vars(model.n_u());
  in.p = vars(model.n_p());
  in.lambda_start = vars(model.n_theta());
  in.mu_start = vars(model.n_sys());
  in.T = 0.3;
  in.boundary_at_end = true;
  iv.build(nlp, in);
  fesd::mpcc::add_scholtes_rows(nlp, iv.groups());
}

inline fesd::DiscretizationOptions options(fesd::RkScheme scheme, int n_s, fesd::StepEq step_eq,
                                           fesd::CrossComp cross) {
  fesd::DiscretizationOptions d;
  d.rk_scheme = scheme;
  d.n_s = n_s;
  d.N_FE = 3;
  d.step_eq = step_eq;
  d.cross_comp = cross;
  return d;
}

}  // namespace fesd_test
