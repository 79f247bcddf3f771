// src/ocp/speed_of_time.hpp: time-optimal problems (OcpData::time_optimal_problem) as an OCP on
// the nominal horizon tau in [0, T] with one more parameter, the speed of time s = dt / dtau:
//
//   dx/dtau = s f_i(x, u, p) in every region i,   Lagrange term s (1 + f_q(x, u, p)),
//
// so that the integral of the Lagrange term is T_final + int_0^T_final f_q dt with
// T_final = int_0^T s dtau. The switching functions c(x, p), the Mayer term and the constraints
// do not change. s is a free parameter (ocp_terms.hpp, free_parameters): one NLP variable, or one
// per control interval (local_speed_of_time_variable); within [s_sot_min, s_sot_max], guess s_sot0.
// Nothing of the discretization changes: FesdInterval integrates the scaled model.
#pragma once
#include <memory>
#include <utility>

#include <Eigen/Dense>

#include "fesd/ocp.hpp"

namespace fesd::ocp_detail {

/// The model's functions with f multiplied by the last parameter.
class SpeedOfTimePss final : public PssFunctions {
 public:
  SpeedOfTimePss(const Pss& model) : model_(model), n_p_(model.n_p()), n_x_(model.n_x()) {}
#define FESD_SPEED_OF_TIME_PSS(T)                                                 \
  void c(const T* x, const T* p, T* out) const override {                         \
    model_.functions().c(x, p, out);                                              \
  }                                                                               \
  void g(const T* x, const T* p, T* out) const override {                         \
    model_.functions().g(x, p, out);                                              \
  }                                                                               \
  void f(int region, const T* x, const T* u, const T* p, T* out) const override { \
    model_.functions().f(region, x, u, p, out);                                   \
    for (int i = 0; i < n_x_; ++i) out[i] = p[n_p_] * out[i];                     \
  }
  FESD_FOR_EACH_SCALAR(FESD_SPEED_OF_TIME_PSS)
#undef FESD_SPEED_OF_TIME_PSS
  int n_z() const override {
    return model_.n_z();
  }
  void algebraic(const double* x, const double* u, const double* p, double* z) const override {
    model_.functions().algebraic(x, u, p, z);
  }

 private:
  Pss model_;  // shares the user's functions
  int n_p_, n_x_;
};

/// The OCP's functions with the Lagrange term s (1 + f_q) (s the last parameter).
class SpeedOfTimeCosts final : public OcpFunctions {
 public:
  SpeedOfTimeCosts(std::shared_ptr<const OcpFunctions> f, int n_p) : f_(std::move(f)), n_p_(n_p) {}
  bool has_f_q() const override { return true; }
  bool has_f_q_T() const override { return f_ && f_->has_f_q_T(); }
#define FESD_SPEED_OF_TIME_COSTS(T)                                             \
  T f_q(const T* x, const T* u, const T* p) const override {                    \
    if (f_ && f_->has_f_q()) return p[n_p_] * (1.0 + f_->f_q(x, u, p));         \
    return p[n_p_] * 1.0;                                                       \
  }                                                                             \
  T f_q_T(const T* x, const T* p) const override {                              \
    return f_ ? f_->f_q_T(x, p) : T(0.0);                                       \
  }                                                                             \
  void g_path(const T* x, const T* u, const T* p, T* out) const override {      \
    if (f_) f_->g_path(x, u, p, out);                                           \
  }                                                                             \
  void g_terminal(const T* x, const T* p, T* out) const override {              \
    if (f_) f_->g_terminal(x, p, out);                                          \
  }                                                                             \
  void g_path_comp(const T* x, const T* u, const T* p, T* out) const override { \
    if (f_) f_->g_path_comp(x, u, p, out);                                      \
  }
  FESD_FOR_EACH_SCALAR(FESD_SPEED_OF_TIME_COSTS)
#undef FESD_SPEED_OF_TIME_COSTS
 private:
  std::shared_ptr<const OcpFunctions> f_;
  int n_p_;
};

inline Eigen::VectorXd with_entry(const Eigen::VectorXd& v, double value) {
  Eigen::VectorXd out(v.size() + 1);
  out << v, value;
  return out;
}

/// The OCP on the nominal horizon with the speed of time as its last parameter (guess s_sot0);
/// the OCP itself if it is not time-optimal.
inline Ocp with_speed_of_time(const Ocp& ocp) {
  if (!ocp.time_optimal_problem) return ocp;
  Ocp out = ocp;
  const Pss& m = ocp.model;
  PssDims dims = m.dims();
  ++dims.n_p;
  out.model = Pss(dims, std::make_shared<const SpeedOfTimePss>(m));
  out.model.state_names = m.state_names;
  out.model.control_names = m.control_names;
  out.model.parameter_names = m.parameter_names;
  if (!out.model.parameter_names.empty()) out.model.parameter_names.push_back("s_sot");
  out.model.p_default = with_entry(m.p_default, ocp.s_sot0);
  if (ocp.p.size() > 0) out.p = with_entry(ocp.p, ocp.s_sot0);
  for (Eigen::VectorXd& row : out.p_stage) row = with_entry(row, ocp.s_sot0);
  out.functions = std::make_shared<const SpeedOfTimeCosts>(ocp.functions, m.n_p());
  return out;
}

}  // namespace fesd::ocp_detail
