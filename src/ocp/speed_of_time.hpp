// src/ocp/speed_of_time.hpp: time-optimal problems (OcpData::time_optimal_problem) and time
// freezing (OcpData::time_freezing) as an OCP on the nominal horizon tau in [0, T] with one more
// parameter, the speed of time s = dt / dtau:
//
//   dx/dtau = s f_i(x, u, p) in every region i,
//   Lagrange term s (1 + f_q(x, u, p)) (time-optimal) or s f_q(x, u, p) (time freezing),
//                 plus rho_sot (s - 1)^2 / T_s (T_s = T / N_stages per local speed, T global),
//
// so that the integral of the Lagrange term is T_final + int_0^T_final f_q dt with
// T_final = int_0^T s dtau (time-optimal), and the quadrature of the penalty is rho_sot (s - 1)^2
// per speed variable (the h_n of a control interval sum to T / N_stages). The switching
// functions c(x, p), the Mayer term and the constraints do not change. s is a free parameter
// (ocp_terms.hpp, free_parameters): one NLP variable, or one per control interval
// (local_speed_of_time_variable); within [s_sot_min, s_sot_max], guess s_sot0. Nothing of the
// discretization changes: FesdInterval integrates the scaled model.
#pragma once
#include <memory>
#include <utility>
#include <vector>

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

/// The OCP's functions with the Lagrange term s (1 + f_q) (time-optimal; `add_one`) or s f_q,
/// plus rho_sot (s - 1)^2 / T_s (s the last parameter).
class SpeedOfTimeCosts final : public OcpFunctions {
 public:
  SpeedOfTimeCosts(std::shared_ptr<const OcpFunctions> f, int n_p, bool add_one, double rho_sot,
                   double T_s)
      : f_(std::move(f)), n_p_(n_p), add_one_(add_one), weight_(rho_sot / T_s) {}
  bool has_f_q() const override { return add_one_ || weight_ > 0 || (f_ && f_->has_f_q()); }
  bool has_f_q_T() const override { return f_ && f_->has_f_q_T(); }
#define FESD_SPEED_OF_TIME_COSTS(T)                                                       \
  T f_q(const T* x, const T* u, const T* p) const override {                              \
    const T& s = p[n_p_];                                                                 \
    T q(add_one_ ? 1.0 : 0.0);                                                            \
    if (f_ && f_->has_f_q()) q = q + f_->f_q(x, u, p);                                    \
    T out = s * q;                                                                        \
    if (weight_ > 0) out = out + weight_ * (s - 1.0) * (s - 1.0);                         \
    return out;                                                                           \
  }                                                                                       \
  T f_q_T(const T* x, const T* p) const override {                                        \
    return f_ ? f_->f_q_T(x, p) : T(0.0);                                                 \
  }                                                                                       \
  void g_path(const T* x, const T* u, const T* p, T* out) const override {                \
    if (f_) f_->g_path(x, u, p, out);                                                     \
  }                                                                                       \
  void g_terminal(const T* x, const T* p, T* out) const override {                        \
    if (f_) f_->g_terminal(x, p, out);                                                    \
  }                                                                                       \
  void g_path_comp(const T* x, const T* u, const T* p, T* out) const override {           \
    if (f_) f_->g_path_comp(x, u, p, out);                                                \
  }                                                                                       \
  void g_rk_comp(const T* x, const T* u, const T* p, const T* y, T* out) const override { \
    if (f_) f_->g_rk_comp(x, u, p, y, out);                                               \
  }
  FESD_FOR_EACH_SCALAR(FESD_SPEED_OF_TIME_COSTS)
#undef FESD_SPEED_OF_TIME_COSTS
  std::vector<int> g_rk_comp_inputs() const override {
    return f_ ? f_->g_rk_comp_inputs() : std::vector<int>{};
  }

 private:
  std::shared_ptr<const OcpFunctions> f_;
  int n_p_;
  bool add_one_;
  double weight_;
};

inline Eigen::VectorXd with_entry(const Eigen::VectorXd& v, double value) {
  Eigen::VectorXd out(v.size() + 1);
  out << v, value;
  return out;
}

/// True if the OCP has a speed of time (time-optimal or time freezing).
inline bool has_speed_of_time(const OcpData& ocp) {
  return ocp.time_optimal_problem || (ocp.time_freezing && ocp.use_speed_of_time_variables);
}

/// The OCP on the nominal horizon with the speed of time as its last parameter (guess s_sot0);
/// the OCP itself if it has no speed of time.
inline Ocp with_speed_of_time(const Ocp& ocp) {
  if (!has_speed_of_time(ocp)) return ocp;
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
  const double T_s = ocp.local_speed_of_time_variable ? ocp.T / ocp.N_stages : ocp.T;
  out.functions = std::make_shared<const SpeedOfTimeCosts>(
      ocp.functions, m.n_p(), ocp.time_optimal_problem, ocp.rho_sot, T_s);
  return out;
}

}  // namespace fesd::ocp_detail
