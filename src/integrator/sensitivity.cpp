// Sensitivities of one integration step by the implicit function theorem (sensitivity.hpp,
// docs/sensitivities.md).
#include "integrator/sensitivity.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "fesd/error.hpp"
#include "integrator/active_set.hpp"

namespace fesd::integrator {

SquareSystem::SquareSystem(const nlp::BlockNlp& nlp, std::vector<int> free,
                           std::vector<std::pair<int, int>> equal)
    : nlp_(nlp), free_(std::move(free)), equal_(std::move(equal)) {
  col_of_.assign(nlp_.num_variables(), -1);
  for (std::size_t i = 0; i < free_.size(); ++i) col_of_[free_[i]] = static_cast<int>(i);
  g_.resize(nlp_.num_constraints());
  jac_.resize(nlp_.jac_nnz());
}

bool SquareSystem::square() const {
  return nlp_.num_constraints() + equal_.size() == free_.size();
}

bool SquareSystem::factor(const std::vector<double>& w, std::string& why) {
  const int n = static_cast<int>(free_.size()), m = nlp_.num_constraints();
  if (!nlp_.eval_jac_g(w.data(), jac_.data())) {
    why = "the Jacobian could not be evaluated";
    return false;
  }
  J_.setZero(n, n);
  const std::vector<int>& rows = nlp_.jac_rows();
  const std::vector<int>& cols = nlp_.jac_cols();
  for (std::size_t e = 0; e < jac_.size(); ++e)
    if (const int c = col_of_[cols[e]]; c >= 0) J_(rows[e], c) += jac_[e];
  for (std::size_t e = 0; e < equal_.size(); ++e) {
    J_(m + static_cast<int>(e), col_of_[equal_[e].first]) = 1;
    J_(m + static_cast<int>(e), col_of_[equal_[e].second]) = -1;
  }
  lu_.compute(J_);
  const auto pivots = lu_.matrixLU().diagonal().cwiseAbs();
  if (!J_.allFinite() || !(pivots.minCoeff() > 1e-14 * pivots.maxCoeff())) {
    why = "the square system is singular at the solution";
    return false;
  }
  return true;
}

bool SquareSystem::newton(std::vector<double>& w, int max_it, std::string& why) {
  if (!square()) {
    why = fmt::format(
        "the system with the solution's active set is not square ({} rows, {} "
        "unknowns)",
        nlp_.num_constraints() + equal_.size(), free_.size());
    return false;
  }
  const int n = static_cast<int>(free_.size()), m = nlp_.num_constraints();
  Eigen::VectorXd F(n);
  for (int it = 0; it <= max_it; ++it) {
    if (!nlp_.eval_g(w.data(), g_.data())) {
      why = "the equations could not be evaluated";
      return false;
    }
    for (int i = 0; i < m; ++i) F[i] = g_[i] - nlp_.g_lb[i];
    for (std::size_t e = 0; e < equal_.size(); ++e)
      F[m + static_cast<int>(e)] = w[equal_[e].first] - w[equal_[e].second];
    double w_max = 1;
    for (int j : free_) w_max = std::max(w_max, std::abs(w[j]));
    if (F.lpNorm<Eigen::Infinity>() <= 1e-12 * w_max) return true;
    if (it == max_it || !factor(w, why)) break;
    const Eigen::VectorXd dz = lu_.solve(-F);
    if (!dz.allFinite()) break;
    for (int i = 0; i < n; ++i) w[free_[i]] += dz[i];
  }
  if (why.empty()) why = "Newton's method on the square system did not converge";
  return false;
}

bool SquareSystem::ift(const std::vector<double>& w, const std::vector<int>& inputs,
                       const std::vector<int>& x_end, Eigen::MatrixXd& out, std::string& why) {
  if (!square()) {
    why = "the system is not square";
    return false;
  }
  if (!factor(w, why)) return false;
  // F_inputs: the Jacobian entries in the input columns (fixed variables s0, q, p)
  std::vector<int> input_of(nlp_.num_variables(), -1);
  for (std::size_t i = 0; i < inputs.size(); ++i) input_of[inputs[i]] = static_cast<int>(i);
  const int n = static_cast<int>(free_.size());
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(inputs.size()));
  const std::vector<int>& rows = nlp_.jac_rows();
  const std::vector<int>& cols = nlp_.jac_cols();
  for (std::size_t e = 0; e < jac_.size(); ++e)
    if (const int c = input_of[cols[e]]; c >= 0) B(rows[e], c) += jac_[e];
  const Eigen::MatrixXd dw = lu_.solve(-B);
  out.resize(static_cast<Eigen::Index>(x_end.size()), B.cols());
  for (std::size_t i = 0; i < x_end.size(); ++i) {
    const int c = col_of_[x_end[i]];
    if (c < 0) {
      why = "the end state is not an unknown of the square system";
      return false;
    }
    out.row(static_cast<Eigen::Index>(i)) = dw.row(c);
  }
  if (!out.allFinite()) {
    why = "the sensitivity is not finite";
    return false;
  }
  return true;
}

StepSensitivity split_inputs(const Eigen::MatrixXd& d, int n_x, int n_u, int n_p) {
  StepSensitivity s;
  s.x0 = d.leftCols(n_x);
  s.u = d.middleCols(n_x, n_u);
  s.p = d.middleCols(n_x + n_u, n_p);
  return s;
}

void copy_interval(const Pss& model, const discretization::FesdInterval& from,
                   const std::vector<double>& w_from, const discretization::FesdInterval& to,
                   std::vector<double>& w_to) {
  if (from.N_FE() != to.N_FE() || from.n_s() != to.n_s())
    throw InternalError("copy_interval: the intervals differ in N_FE or n_s");
  const int n_x = model.n_x(), n_th = model.n_theta(), n_sys = model.n_sys();
  for (int n = 0; n < from.N_FE(); ++n) {
    w_to[to.h(n)] = w_from[from.h(n)];
    for (int s = 0; s < from.n_s(); ++s) {
      for (int i = 0; i < n_x; ++i) {
        w_to[to.V(n, s, i)] = w_from[from.V(n, s, i)];
        w_to[to.X(n, s, i)] = w_from[from.X(n, s, i)];
      }
      for (int r = 0; r < n_th; ++r) {
        w_to[to.theta(n, s, r)] = w_from[from.theta(n, s, r)];
        w_to[to.lambda(n, s, r)] = w_from[from.lambda(n, s, r)];
      }
      for (int k = 0; k < n_sys; ++k) w_to[to.mu(n, s, k)] = w_from[from.mu(n, s, k)];
    }
    for (int i = 0; i < n_x; ++i) w_to[to.x(n + 1, i)] = w_from[from.x(n + 1, i)];
    if (from.lambda_end(n, 0) >= 0 && to.lambda_end(n, 0) >= 0) {
      for (int r = 0; r < n_th; ++r) w_to[to.lambda_end(n, r)] = w_from[from.lambda_end(n, r)];
      for (int k = 0; k < n_sys; ++k) w_to[to.mu_end(n, k)] = w_from[from.mu_end(n, k)];
    }
  }
}

StandardStepSensitivity::StandardStepSensitivity(const Pss& model, const Tableau& tab,
                                                 const DiscretizationOptions& d, double T_step,
                                                 const Eigen::VectorXd& u, const Eigen::VectorXd& p)
    : model_(model), tab_(tab), d_(d) {
  if (d.use_fesd) throw InternalError("StandardStepSensitivity is for use_fesd = false");
  in_ = add_step_inputs(nlp_, model, false, T_step);
  iv_ = std::make_unique<discretization::FesdInterval>(model, tab_, d_);
  iv_->build(nlp_, in_);
  for (std::size_t i = 0; i < in_.q.size(); ++i)
    nlp_.x_lb[in_.q[i]] = nlp_.x_ub[in_.q[i]] = u[static_cast<Eigen::Index>(i)];
  for (std::size_t i = 0; i < in_.p.size(); ++i)
    nlp_.x_lb[in_.p[i]] = nlp_.x_ub[in_.p[i]] = p[static_cast<Eigen::Index>(i)];
  for (int i = 0; i < nlp_.num_constraints(); ++i)
    if (nlp_.g_lb[i] != nlp_.g_ub[i])
      throw InternalError("StandardStepSensitivity: the equations of a step must be equalities");
  nlp_.finalize();
}

bool StandardStepSensitivity::compute(const Eigen::VectorXd& x0,
                                      const discretization::FesdInterval& other,
                                      const std::vector<double>& w_other, StepSensitivity& out,
                                      std::string& why) {
  const discretization::FesdInterval& iv = *iv_;
  std::vector<double> w(nlp_.x_lb.size(), 0.0);
  std::vector<double> lb = nlp_.x_lb, ub = nlp_.x_ub;
  for (std::size_t j = 0; j < lb.size(); ++j)
    if (lb[j] == ub[j]) w[j] = lb[j];
  for (int i = 0; i < model_.n_x(); ++i) w[in_.s0[i]] = lb[in_.s0[i]] = ub[in_.s0[i]] = x0[i];
  copy_interval(model_, other, w_other, iv, w);
  // the active set of each stage: lambda_r = 0 where theta_r outweighs it, else theta_r = 0
  for (int n = 0; n < iv.N_FE(); ++n)
    for (int s = 0; s < iv.n_s(); ++s)
      for (int r = 0; r < model_.n_theta(); ++r) {
        const int th = iv.theta(n, s, r), la = iv.lambda(n, s, r);
        const int pinned = w[th] > std::abs(w[la]) ? la : th;
        lb[pinned] = ub[pinned] = w[pinned] = 0.0;
      }
  std::vector<int> free;
  for (std::size_t j = 0; j < lb.size(); ++j)
    if (lb[j] < ub[j]) free.push_back(static_cast<int>(j));
  SquareSystem sys(nlp_, free, {});
  if (!sys.newton(w, 10, why)) return false;
  std::vector<int> inputs = in_.s0, x_end;
  inputs.insert(inputs.end(), in_.q.begin(), in_.q.end());
  inputs.insert(inputs.end(), in_.p.begin(), in_.p.end());
  for (int i = 0; i < model_.n_x(); ++i) x_end.push_back(iv.x(iv.N_FE(), i));
  Eigen::MatrixXd d;
  if (!sys.ift(w, inputs, x_end, d, why)) return false;
  out = split_inputs(d, model_.n_x(), model_.n_u(), model_.n_p());
  return true;
}

}  // namespace fesd::integrator
