#include "discretization/fesd_interval.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <unordered_map>

#include <fmt/format.h>

#include "dcs/step.hpp"
#include "discretization/dynamics_block.hpp"
#include "discretization/dynamics_eq.hpp"
#include "discretization/stage_state_block.hpp"
#include "discretization/step_equilibration_block.hpp"
#include "fesd/ad.hpp"
#include "fesd/error.hpp"
#include "nlp/sum_block.hpp"

namespace fesd::discretization {
namespace {

using nlp::kInf;
using nlp::make_block;

/// Builds a block's variable list: distinct NLP indices, each with its local position.
class VarList {
 public:
  int add(int global) {
    auto [it, fresh] = local_.emplace(global, static_cast<int>(vars_.size()));
    if (fresh) vars_.push_back(global);
    return it->second;
  }
  std::vector<int> add(const std::vector<int>& globals) {
    std::vector<int> r;
    for (int g : globals) r.push_back(add(g));
    return r;
  }
  const std::vector<int>& vars() const { return vars_; }

 private:
  std::unordered_map<int, int> local_;
  std::vector<int> vars_;
};

std::vector<int> range(int first, int n) {
  std::vector<int> r(n);
  for (int i = 0; i < n; ++i) r[i] = first + i;
  return r;
}

// ---- the equations as functors on local inputs w ------------------------------------------

/// g(X) - lambda - mu_{k(r)} = 0.  inputs: X (n_x), lambda (n_theta), mu (n_sys), p
struct LpEq {
  const Pss* m;
  std::vector<int> owner;  // subsystem of each region
  int num_inputs() const { return m->n_x() + m->n_theta() + m->n_sys() + m->n_p(); }
  int num_outputs() const { return m->n_theta(); }
  template <class T>
  void operator()(const T* w, T* c) const {
    const T* X = w;
    const T* lambda = X + m->n_x();
    const T* mu = lambda + m->n_theta();
    const T* p = mu + m->n_sys();
    dcs::eval_g(*m, X, p, c);
    for (int r = 0; r < m->n_theta(); ++r) c[r] = c[r] - lambda[r] - mu[owner[r]];
  }
};

/// e' theta^k = 1 per subsystem.  inputs: theta (n_theta)
struct SimplexEq {
  std::vector<int> offsets;  // region_offset(0..n_sys)
  int num_inputs() const { return offsets.back(); }
  int num_outputs() const { return static_cast<int>(offsets.size()) - 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    for (int k = 0; k + 1 < static_cast<int>(offsets.size()); ++k) {
      T s(0.0);
      for (int r = offsets[k]; r < offsets[k + 1]; ++r) s = s + w[r];
      c[k] = s;
    }
  }
};

/// The step form's c(X) - lambda_p + lambda_n = 0.  inputs: X (n_x), lambda_n (n_c),
/// lambda_p (n_c), p
struct StepCEq {
  const Pss* m;
  int num_inputs() const { return m->n_x() + 2 * m->n_c() + m->n_p(); }
  int num_outputs() const { return m->n_c(); }
  template <class T>
  void operator()(const T* w, T* c) const {
    const int n_c = m->n_c();
    const T* X = w;
    const T* ln = X + m->n_x();
    const T* lp = ln + n_c;
    const T* p = lp + n_c;
    m->functions().c(X, p, c);
    for (int j = 0; j < n_c; ++j) c[j] = c[j] - lp[j] + ln[j];
  }
};

/// The step form's theta - theta(alpha) = 0.  inputs: theta (n_theta), alpha (n_c)
struct StepThetaEq {
  const Pss* m;
  int num_inputs() const { return m->n_theta() + m->n_c(); }
  int num_outputs() const { return m->n_theta(); }
  template <class T>
  void operator()(const T* w, T* c) const {
    dcs::eval_theta_of_alpha(*m, w + m->n_theta(), c);
    for (int r = 0; r < m->n_theta(); ++r) c[r] = w[r] - c[r];
  }
};

/// The step form's general inclusion f_alpha(X, alpha, q, p) (PssFunctions::f_alpha): y = alpha
/// (n_c).
struct AlphaRhs {
  const Pss* m;
  int n_y() const { return m->n_c(); }
  template <class T>
  void operator()(const T* X, const T* alpha, const T* q, const T* p, T* out) const {
    m->functions().f_alpha(X, alpha, q, p, out);
  }
};

/// The step form's dynamics of a general inclusion: V - f_alpha(X, alpha, q, p) = 0.
/// inputs: V (n_x), X (n_x), alpha (n_c), q (n_u), p (n_p)
using AlphaDynamicsEq = StageDynamicsEq<AlphaRhs>;

/// alpha_j + beta_j = 1 (beta = 1 - alpha as a variable).  inputs: alpha (n_c), beta (n_c)
struct AlphaBetaEq {
  int n_c;
  int num_inputs() const { return 2 * n_c; }
  int num_outputs() const { return n_c; }
  template <class T>
  void operator()(const T* w, T* c) const {
    for (int j = 0; j < n_c; ++j) c[j] = w[j] + w[n_c + j];
  }
};

/// (h - h0)^2, the heuristic_mean penalty term.
struct SquaredDeviation {
  double h0;
  int num_inputs() const { return 1; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    const T d = w[0] - h0;
    c[0] = d * d;
  }
};

/// (h_n - h_{n-1})^2, the heuristic_delta penalty term.  inputs: h_{n-1}, h_n
struct SquaredDifference {
  int num_inputs() const { return 2; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    const T d = w[1] - w[0];
    c[0] = d * d;
  }
};

}  // namespace

FesdInterval::FesdInterval(const Pss& model, const Tableau& tableau,
                           const DiscretizationOptions& options)
    : model_(model), tab_(tableau), opt_(options), N_FE_(options.N_FE), n_s_(tableau.n_s) {
  stiffly_accurate_ = tab_.stiffly_accurate;
  step_ = options.dcs_mode == DcsMode::Step;
  n_lam_ = dcs::n_lambda(model, options.dcs_mode);
  n_mu_ = dcs::n_mu(model, options.dcs_mode);
  owner_ = dcs::region_subsystem(model);
  const StageLambdaSign sign = options.stage_lambda_sign;
  boundary_sign_ =
      options.use_fesd && (sign == StageLambdaSign::Boundary ||
                           (sign == StageLambdaSign::Auto &&
                            (options.rk_scheme == RkScheme::LobattoIIIC || tab_.is_explicit)));
}

std::vector<std::string> FesdInterval::block_size_errors(const Pss& m,
                                                         const DiscretizationOptions& options) {
  std::vector<std::string> errors;
  if (options.dcs_mode == DcsMode::Step)
    if (std::string e = dcs::step_mode_error(m); !e.empty()) return {e};
  if (m.has_f_alpha() && options.dcs_mode != DcsMode::Step)
    return {
        "model.f_alpha needs discretization.dcs_mode = \"step\" (the general inclusion f(x, "
        "alpha) is written in the Heaviside step form; Stewart's form needs region-wise F)"};
  const int limit = ad::kMaxInputs;
  const int n_x = m.n_x(), n_th = m.n_theta();
  // The model's blocks, as build() creates them (the same functors, so the counts cannot drift).
  const int dynamics = DynamicsEq{&m}.num_inputs();  // 2 n_x + n_theta + n_u + n_p
  const int lp = LpEq{&m, {}}.num_inputs();          // n_x + n_theta + n_sys + n_p
  if (std::max(dynamics, lp) > limit) {
    const bool states = 2 * n_x >= n_th;  // name what dominates
    const std::string key =
        states
            ? fmt::format("model.x = {} states", n_x)
            : fmt::format("{} = {} regions", m.n_sys() > 1 ? "model.subsystem" : "model.F", n_th);
    const std::string block =
        dynamics >= lp
            ? fmt::format(
                  "the dynamics (25) of one stage are one block of 2 n_x + n_theta + n_u "
                  "+ n_p = {} inputs",
                  dynamics)
            : fmt::format(
                  "the LP (9) of one stage is one block of n_x + n_theta + n_sys + n_p = "
                  "{} inputs",
                  lp);
    errors.push_back(fmt::format(
        "{}: {} (n_x = {}, n_theta = {}, n_u = {}, n_p = {}); at most {} inputs per block are "
        "supported ({})",
        key, block, n_x, n_th, m.n_u(), m.n_p(), limit,
        states ? "use fewer states"
               : "give S with only the regions that can occur, or fewer switching functions"));
  }
  const StepEq se = options.step_eq;
  if (options.use_fesd && options.N_FE >= 2 &&
      (se == StepEq::Eta || se == StepEq::EtaTanh || se == StepEq::L2Relaxed)) {
    // h_{n-1}, h_n and 4 lifted sums per region (step form: per entry of (alpha, beta))
    const int step_eq = 2 + 4 * (options.dcs_mode == DcsMode::Step ? 2 * m.n_c() : n_th);
    if (step_eq > limit)
      errors.push_back(fmt::format(
          "discretization.step_equilibration = {}: the step equilibration (31) of two neighbouring "
          "elements is one block of 2 + 4 n_theta = {} inputs with n_theta = {} regions; at most "
          "{} inputs per block are supported, i.e. n_theta <= {} (use heuristic_mean, "
          "heuristic_delta or none, or fewer regions)",
          to_string(se), step_eq, n_th, limit, (limit - 2) / 4));
  }
  return errors;
}

void FesdInterval::build(nlp::BlockNlp& nlp, const IntervalInputs& in) {
  in_ = in;
  const Pss& m = model_;
  const int n_x = m.n_x(), n_th = m.n_theta(), n_sys = m.n_sys(), n_c = m.n_c();
  const int n_lam = n_lam_, n_mu = n_mu_, n_cp = n_comp();
  if (static_cast<int>(in.s0.size()) != n_x || static_cast<int>(in.q.size()) != m.n_u() ||
      static_cast<int>(in.p.size()) != m.n_p() ||
      static_cast<int>(in.lambda_start.size()) != n_lam_ ||
      static_cast<int>(in.mu_start.size()) != n_mu_)
    throw InternalError("internal: FesdInterval inputs do not match the model dimensions");
  const bool fesd = opt_.use_fesd;
  const double h0 = in.T / N_FE_;

  // ---- variables ----
  h_.assign(N_FE_, -1);
  V_.assign(N_FE_ * n_s_, -1);
  X_.assign(N_FE_ * n_s_, -1);
  theta_.assign(N_FE_ * n_s_, -1);
  lambda_.assign(N_FE_ * n_s_, -1);
  mu_.assign(N_FE_ * n_s_, -1);
  alpha_.assign(N_FE_ * n_s_, -1);
  x_.assign(N_FE_ + 1, {});
  x_[0] = in.s0;
  lambda_end_.assign(N_FE_, {});
  boundary_vars_.assign(N_FE_, false);
  mu_end_.assign(N_FE_, {});
  stage_signed_.assign(N_FE_ * n_s_, true);
  for (int n = 0; n < N_FE_; ++n) {
    const double h_lb = fesd ? (1.0 - opt_.gamma_h) * h0 : h0;
    const double h_ub = fesd ? (1.0 + opt_.gamma_h) * h0 : h0;
    h_[n] = nlp.add_variables(1, h_lb, h_ub, h0);
    for (int s = 0; s < n_s_; ++s) {
      V_[idx(n, s)] = nlp.add_variables(n_x, -kInf, kInf, 0.0);
      X_[idx(n, s)] = nlp.add_variables(n_x, -kInf, kInf, 0.0);
      // (step form: theta = theta(alpha) is a lifted variable, alpha and beta = 1 - alpha in
      // [0, 1] the complementarity variables)
      theta_[idx(n, s)] = nlp.add_variables(n_th, step_ ? -kInf : 0.0, kInf, 0.0);
      if (step_) alpha_[idx(n, s)] = nlp.add_variables(2 * n_c, 0.0, 1.0, 0.5);
      // Boundary sign: lambda >= 0 only where the stage is the element's end point.
      stage_signed_[idx(n, s)] = !boundary_sign_ || (stiffly_accurate_ && s == n_s_ - 1);
      lambda_[idx(n, s)] =
          nlp.add_variables(n_lam, stage_signed_[idx(n, s)] ? 0.0 : -kInf, kInf, 0.0);
      mu_[idx(n, s)] = nlp.add_variables(n_mu, -kInf, kInf, 0.0);
    }
    if (stiffly_accurate_) {
      x_[n + 1] = range(X_[idx(n, n_s_ - 1)], n_x);  // x_{n+1} = X_{n,n_s}: last row of A is b
      lambda_end_[n] = range(lambda_[idx(n, n_s_ - 1)], n_lam);
      mu_end_[n] = range(mu_[idx(n, n_s_ - 1)], n_mu);
    } else {
      x_[n + 1] = range(nlp.add_variables(n_x, -kInf, kInf, 0.0), n_x);
      // With free stage lambdas every element end needs its signed boundary point.
      const bool boundary = fesd && (n < N_FE_ - 1 || in.boundary_at_end || boundary_sign_);
      if (boundary) {
        boundary_vars_[n] =
            true;  // (33): lambda, mu at t_{n+1} from LP(x_{n+1}); theta discarded (39)
        lambda_end_[n] = range(nlp.add_variables(n_lam, 0.0, kInf, 0.0), n_lam);
        mu_end_[n] = range(nlp.add_variables(n_mu, -kInf, kInf, 0.0), n_mu);
      }
    }
  }

  // ---- shared blocks ----
  const auto owner = dcs::region_subsystem(m);
  std::vector<int> offsets;
  for (int k = 0; k <= n_sys; ++k) offsets.push_back(m.region_offset(k));
  const bool by_alpha = step_ && m.has_f_alpha();  // V = f_alpha(X, alpha) instead of (25)
  const std::shared_ptr<const nlp::Block> dynamics =
      by_alpha ? make_block(AlphaDynamicsEq{&m})
               : std::shared_ptr<const nlp::Block>(std::make_shared<DynamicsBlock>(m));
  // The multiplier equation of a point: Stewart's LP (9), or the step form's c = lambda_p -
  // lambda_n; inputs X, lambda (n_lam), mu (n_mu), p either way.
  auto lp = step_ ? make_block(StepCEq{&m}) : make_block(LpEq{&m, owner});
  auto theta_of_alpha = make_block(StepThetaEq{&m});
  auto alpha_beta = make_block(AlphaBetaEq{n_c});
  auto simplex = make_block(SimplexEq{offsets});
  std::vector<std::shared_ptr<const nlp::Block>> stage_state(n_s_);
  std::vector<std::vector<int>> stage_cols(n_s_);
  for (int s = 0; s < n_s_; ++s) {
    std::vector<double> a;
    for (int j = 0; j < n_s_; ++j)
      if (tab_.A(s, j) != 0.0) {
        a.push_back(tab_.A(s, j));
        stage_cols[s].push_back(j);
      }
    stage_state[s] = std::make_shared<StageStateBlock>(StageStateEq{a});
  }
  std::vector<double> b;
  std::vector<int> b_cols;
  for (int j = 0; j < n_s_; ++j)
    if (tab_.b(j) != 0.0) {
      b.push_back(tab_.b(j));
      b_cols.push_back(j);
    }
  const std::shared_ptr<const nlp::Block> continuity =
      std::make_shared<StageStateBlock>(StageStateEq{b});

  for (int n = 0; n < N_FE_; ++n) {
    for (int s = 0; s < n_s_; ++s) {
      for (int i = 0; i < n_x; ++i) {  // X_{n,s} = x_n + h_n sum_j a_sj V_{n,j}
        std::vector<int> vars{X(n, s, i), x(n, i), h(n)};
        for (int j : stage_cols[s]) vars.push_back(V(n, j, i));
        nlp.add_constraint(stage_state[s], vars, 0.0, 0.0);
      }
      std::vector<int> dv = range(V(n, s, 0), n_x);  // (25): V = F(X) theta
      for (int i = 0; i < n_x; ++i) dv.push_back(X(n, s, i));
      if (by_alpha)
        for (int j = 0; j < n_c; ++j) dv.push_back(alpha(n, s, j));
      else
        for (int r = 0; r < n_th; ++r) dv.push_back(theta(n, s, r));
      dv.insert(dv.end(), in.q.begin(), in.q.end());
      dv.insert(dv.end(), in.p.begin(), in.p.end());
      nlp.add_constraint(dynamics, dv, 0.0, 0.0);
      std::vector<int> lv = range(X(n, s, 0), n_x);  // (9): g(X) - lambda - mu e = 0
      for (int r = 0; r < n_lam; ++r) lv.push_back(lambda(n, s, r));
      for (int k = 0; k < n_mu; ++k) lv.push_back(mu(n, s, k));
      lv.insert(lv.end(), in.p.begin(), in.p.end());
      nlp.add_constraint(lp, lv, 0.0, 0.0);
      if (step_) {  // theta = theta(alpha), alpha + beta = 1
        std::vector<int> tv = range(theta(n, s, 0), n_th);
        for (int j = 0; j < n_c; ++j) tv.push_back(alpha(n, s, j));
        nlp.add_constraint(theta_of_alpha, tv, 0.0, 0.0);
        nlp.add_constraint(alpha_beta, range(alpha(n, s, 0), 2 * n_c), 1.0, 1.0);
      } else {
        nlp.add_constraint(simplex, range(theta(n, s, 0), n_th), 1.0, 1.0);  // e' theta = 1
      }
    }
    if (!stiffly_accurate_) {
      for (int i = 0; i < n_x; ++i) {  // x_{n+1} = x_n + h_n sum b_m V_{n,m}
        std::vector<int> vars{x(n + 1, i), x(n, i), h(n)};
        for (int j : b_cols) vars.push_back(V(n, j, i));
        nlp.add_constraint(continuity, vars, 0.0, 0.0);
      }
      if (boundary_vars_[n]) {  // (33) at x_{n+1}
        std::vector<int> lv = x_[n + 1];
        lv.insert(lv.end(), lambda_end_[n].begin(), lambda_end_[n].end());
        lv.insert(lv.end(), mu_end_[n].begin(), mu_end_[n].end());
        lv.insert(lv.end(), in.p.begin(), in.p.end());
        nlp.add_constraint(lp, lv, 0.0, 0.0);
      }
    }
  }

  if (in.lp_at_start) {  // (9) at s0 for lambda_{0,0}, mu_{0,0}
    std::vector<int> lv = in.s0;
    lv.insert(lv.end(), in.lambda_start.begin(), in.lambda_start.end());
    lv.insert(lv.end(), in.mu_start.begin(), in.mu_start.end());
    lv.insert(lv.end(), in.p.begin(), in.p.end());
    nlp.add_constraint(lp, lv, 0.0, 0.0);
  }

  // ---- lambda points per element: start, stages, end boundary (27), (34) ----
  points_.assign(N_FE_, {});
  point_signed_.assign(N_FE_, {});
  for (int n = 0; n < N_FE_; ++n) {
    std::vector<int> start = n == 0 ? in.lambda_start : lambda_end_[n - 1];
    if (!start.empty()) {
      points_[n].push_back(start);
      point_signed_[n].push_back(true);
    }
    for (int s = 0; s < n_s_; ++s) {
      points_[n].push_back(range(lambda(n, s, 0), n_lam));
      point_signed_[n].push_back(stage_signed_[idx(n, s)]);
    }
    if (boundary_vars_[n]) {
      points_[n].push_back(lambda_end_[n]);
      point_signed_[n].push_back(true);
    }
  }

  step_eq_rows_.clear();
  if (fesd) {
    nlp.add_constraint(make_block(nlp::Sum{N_FE_}), h_, in.T, in.T);  // sum h_n = T
    if (opt_.step_eq == StepEq::Eta || opt_.step_eq == StepEq::EtaTanh ||
        opt_.step_eq == StepEq::L2Relaxed) {
      // Lifted per-element sums: sigma^lambda_{n,r} over the signed points, sigma^theta_{n,r}
      // over the stages (step form: r over the entries of (lambda_n, lambda_p) and of
      // (alpha, beta), docs/formulation.md). Each (31) block then has 2 + 4 n_theta inputs instead
      // of 2 + n_theta (2 (n_s + 2) + 2 n_s) (docs/derivatives.md).
      lam_sum_.assign(N_FE_, std::vector<int>(n_cp, -1));
      th_sum_.assign(N_FE_, std::vector<int>(n_cp, -1));
      std::map<int, std::shared_ptr<const nlp::Block>> sum_blocks;
      auto sum_block = [&](int k) {
        auto& block = sum_blocks[k];
        if (!block) block = make_block(nlp::Sum{k, /*minus_first=*/true});
        return block;
      };
      for (int n = 0; n < N_FE_; ++n)
        for (int r = 0; r < n_cp; ++r) {
          lam_sum_[n][r] = nlp.add_variables(1, -kInf, kInf, 0.0);
          std::vector<int> lv{lam_sum_[n][r]};
          for (std::size_t q = 0; q < points_[n].size(); ++q)
            if (point_signed_[n][q]) lv.push_back(points_[n][q][r]);
          nlp.add_constraint(sum_block(static_cast<int>(lv.size())), lv, 0.0, 0.0);
          th_sum_[n][r] = nlp.add_variables(1, -kInf, kInf, 0.0);
          std::vector<int> tv{th_sum_[n][r]};
          for (int st = 0; st < n_s_; ++st) tv.push_back(comp_var(n, st, r));
          nlp.add_constraint(sum_block(static_cast<int>(tv.size())), tv, 0.0, 0.0);
        }
      for (int n = 1; n < N_FE_; ++n) {  // (31)
        VarList vl;
        StepEquilibrationEq f;
        f.use_tanh = opt_.step_eq == StepEq::EtaTanh;
        f.penalty = opt_.step_eq == StepEq::L2Relaxed;
        f.h_scale = h0;
        f.h_prev = vl.add(h(n - 1));
        f.h_cur = vl.add(h(n));
        f.lam_B.assign(n_cp, {});
        f.lam_F.assign(n_cp, {});
        f.th_B.assign(n_cp, {});
        f.th_F.assign(n_cp, {});
        for (int r = 0; r < n_cp; ++r) {
          f.lam_B[r].push_back(vl.add(lam_sum_[n - 1][r]));
          f.lam_F[r].push_back(vl.add(lam_sum_[n][r]));
          f.th_B[r].push_back(vl.add(th_sum_[n - 1][r]));
          f.th_F[r].push_back(vl.add(th_sum_[n][r]));
        }
        f.k = static_cast<int>(vl.vars().size());
        if (f.penalty)
          nlp.add_objective(std::make_shared<StepEquilibrationBlock>(f), vl.vars(), opt_.rho_h);
        else
          step_eq_rows_.push_back(
              nlp.add_constraint(std::make_shared<StepEquilibrationBlock>(f), vl.vars(), 0.0, 0.0));
      }
    } else if (opt_.step_eq == StepEq::HeuristicMean) {
      auto pen = make_block(SquaredDeviation{h0});
      for (int n = 0; n < N_FE_; ++n) nlp.add_objective(pen, {h(n)}, opt_.rho_h);
    } else if (opt_.step_eq == StepEq::HeuristicDelta) {
      // Neighbours inside this interval only: nothing ties h_0 to the previous interval's last h.
      auto pen = make_block(SquaredDifference{});
      for (int n = 1; n < N_FE_; ++n) nlp.add_objective(pen, {h(n - 1), h(n)}, opt_.rho_h);
    }
  }
  build_complementarity();
}

void FesdInterval::build_complementarity() {
  // Pairs (theta_r, lambda_r), or in the step form (alpha_j, lambda_n_j) and (beta_j,
  // lambda_p_j): comp_var(n, s, i) with the entry i of a multiplier point.
  const int n_th = n_comp();
  residual_pairs_.clear();
  groups_.clear();
  const bool fesd = opt_.use_fesd;
  // Position of stage s among the points of element n (the start point shifts stages by one).
  auto stage_point = [&](int n, int s) {
    return (n == 0 ? !in_.lambda_start.empty() : !lambda_end_[n - 1].empty()) ? s + 1 : s;
  };
  std::vector<std::vector<CompPair>> cross_by_element;
  for (int n = 0; n < N_FE_; ++n) {
    CompGroup element;
    std::vector<CompPair> cross;  // pairs with m' != m
    const auto& pts = points_[n];
    for (int s = 0; s < n_s_; ++s) {
      const int own = stage_point(n, s);
      for (int r = 0; r < n_th; ++r) {
        CompGroup stage_sum;
        for (int q = 0; q < static_cast<int>(pts.size()); ++q) {
          if (!fesd && q != own) continue;  // standard method: no cross complementarity
          const CompPair pair{comp_var(n, s, r), pts[q][r]};
          if (!point_signed_[n][q]) {  // free lambda: only its own stage's product, two-sided
            if (q == own) {
              residual_pairs_.push_back(pair);
              groups_.push_back({{pair}, /*two_sided=*/true});
            }
            continue;
          }
          residual_pairs_.push_back(pair);
          stage_sum.pairs.push_back(pair);
          element.pairs.push_back(pair);
          if (q != own) cross.push_back(pair);
          if (!fesd || opt_.cross_comp == CrossComp::Sparse ||
              (opt_.cross_comp == CrossComp::Neighbor && q == own))
            groups_.push_back({{pair}});
        }
        if (fesd && opt_.cross_comp == CrossComp::StageSum && !stage_sum.pairs.empty())
          groups_.push_back(std::move(stage_sum));
      }
    }
    if (fesd && opt_.cross_comp == CrossComp::Element) groups_.push_back(std::move(element));
    cross_by_element.push_back(std::move(cross));
  }
  if (fesd && opt_.cross_comp == CrossComp::Neighbor) {  // (29): elements n and n+1 together
    for (int n = 0; n + 1 < N_FE_ || n == 0; ++n) {
      CompGroup g{cross_by_element[n]};
      if (n + 1 < N_FE_)
        g.pairs.insert(g.pairs.end(), cross_by_element[n + 1].begin(),
                       cross_by_element[n + 1].end());
      groups_.push_back(std::move(g));
    }
  }
}

void FesdInterval::set_guess(std::vector<double>& w, const Eigen::VectorXd& x0,
                             const dcs::LpSolution& lp, const Eigen::VectorXd& xdot) const {
  const int n_x = model_.n_x(), n_th = model_.n_theta(), n_sys = n_mu_, n_c = model_.n_c();
  const double h0 = in_.T / N_FE_;
  for (int n = 0; n <= N_FE_; ++n)
    for (int i = 0; i < n_x; ++i) w[x(n, i)] = x0[i] + n * h0 * xdot[i];
  for (int n = 0; n < N_FE_; ++n) {
    w[h(n)] = h0;
    for (int s = 0; s < n_s_; ++s) {
      for (int i = 0; i < n_x; ++i) {
        w[V(n, s, i)] = xdot[i];
        w[X(n, s, i)] = x0[i] + (n + tab_.c(s)) * h0 * xdot[i];
      }
      for (int r = 0; r < n_th; ++r) w[theta(n, s, r)] = lp.theta[r];
      for (int r = 0; r < n_lam_; ++r) w[lambda(n, s, r)] = lp.lambda[r];
      for (int k = 0; k < n_sys; ++k) w[mu(n, s, k)] = lp.mu[k];
      if (step_)
        for (int j = 0; j < n_c; ++j) {
          w[alpha(n, s, j)] = lp.alpha[j];
          w[alpha(n, s, n_c + j)] = 1.0 - lp.alpha[j];
        }
    }
    if (boundary_vars_[n]) {
      for (int r = 0; r < n_lam_; ++r) w[lambda_end_[n][r]] = lp.lambda[r];
      for (int k = 0; k < n_sys; ++k) w[mu_end_[n][k]] = lp.mu[k];
    }
  }
  update_lifted_guess(w);
}

namespace {
// The activity rule, for one stage or summed over an element's stages: theta outweighs |lambda|
// and is above noise somewhere (kActiveThetaTol).
bool theta_outweighs(double theta_sum, double abs_lambda_sum, double theta_max) {
  return theta_sum > abs_lambda_sum && theta_max > FesdInterval::kActiveThetaTol;
}
}  // namespace

bool FesdInterval::stage_active(const double* w, int n, int m, int r) const {
  const double th = w[theta(n, m, r)];
  return theta_outweighs(th, std::abs(region_lambda(w, n, m, r)), th);
}

std::vector<int> FesdInterval::active_set(const double* w, int n) const {
  std::vector<int> active;
  active_set(w, n, active);
  return active;
}

void FesdInterval::active_set(const double* w, int n, std::vector<int>& active) const {
  active.clear();
  for (int r = 0; r < model_.n_theta(); ++r) {
    double th = 0, th_max = 0, la = 0;
    for (int s = 0; s < n_s_; ++s) {
      th += w[theta(n, s, r)];
      th_max = std::max(th_max, w[theta(n, s, r)]);
      la += std::abs(region_lambda(w, n, s, r));
    }
    if (theta_outweighs(th, la, th_max)) active.push_back(r);
  }
}

double FesdInterval::region_lambda(const double* w, int n, int m, int r) const {
  if (!step_) return w[lambda(n, m, r)];
  thread_local std::vector<double> mult;
  mult.resize(static_cast<std::size_t>(n_lam_));
  for (int i = 0; i < n_lam_; ++i) mult[i] = w[lambda(n, m, i)];
  return dcs::region_multiplier(model_, owner_, r, mult.data());
}

std::vector<std::vector<int>> FesdInterval::active_sets(const double* w) const {
  std::vector<std::vector<int>> active(N_FE_);
  for (int n = 0; n < N_FE_; ++n) active[n] = active_set(w, n);
  return active;
}

std::vector<int> FesdInterval::exit_regions(const Pss& model, const std::vector<int>& before,
                                            const std::vector<int>& after) {
  std::vector<int> exits;
  for (int k = 0; k < model.n_sys(); ++k) {
    const int first = model.region_offset(k), last = model.region_offset(k + 1);
    bool stays = false;
    for (int r = first; r < last; ++r) stays = stays || (has(before, r) && has(after, r));
    if (!stays) continue;
    for (int r = first; r < last; ++r)
      if (has(before, r) && !has(after, r)) exits.push_back(r);
  }
  return exits;
}

std::vector<FesdInterval::ExitPin> FesdInterval::exits_to_pin(const double* w,
                                                              bool control_jump_at_end) const {
  std::vector<ExitPin> pins;
  std::vector<std::vector<int>> active = active_sets(w);
  for (int n = 0; n + 1 < N_FE_; ++n)
    // (an element of length ~0 with both regions active is a crossing, not a sliding mode)
    if (!collapsed(w, n))
      for (int r : exit_regions(model_, active[n], active[n + 1])) pins.push_back({n, r, true});
  // An exit inside the last element: r slides there and has left the surface by its end.
  const int last = N_FE_ - 1;
  for (int k = 0; k < model_.n_sys(); ++k) {
    const int first = model_.region_offset(k), end = model_.region_offset(k + 1);
    auto slides = [&](const std::vector<int>& a, int r) {
      if (!has(a, r)) return false;
      for (int j = first; j < end; ++j)
        if (j != r && has(a, j)) return true;
      return false;
    };
    for (int r = first; r < end; ++r) {
      if (!slides(active[last], r) || stage_active(w, last, n_s_ - 1, r)) continue;
      if (control_jump_at_end)
        pins.push_back({last, r, false});
      else if (last >= 1 && slides(active[last - 1], r))
        pins.push_back({last - 1, r, true});
    }
  }
  return pins;
}

std::vector<nlp::Bound> FesdInterval::pin_bounds(const double* w,
                                                 const std::vector<ExitPin>& pins) const {
  if (!opt_.use_fesd || (!pins.empty() && !can_pin_exits()))
    throw InternalError(
        "FesdInterval::pin_bounds needs FESD (and a stiffly accurate scheme to pin exits)");
  // The active sets to fix: the solution's, with each pinned exit's region kept in its element
  // and (theta_zero) removed from the next.
  std::vector<std::vector<int>> active = active_sets(w);
  for (const ExitPin& pin : pins) {
    if (!has(active[pin.n], pin.r)) {
      active[pin.n].push_back(pin.r);
      std::sort(active[pin.n].begin(), active[pin.n].end());
    }
    if (pin.theta_zero && pin.n + 1 < N_FE_) std::erase(active[pin.n + 1], pin.r);
  }
  std::vector<nlp::Bound> bounds = active_set_bounds(active);
  for (const ExitPin& pin : pins)
    if (pin.theta_zero) bounds.push_back({theta(pin.n, n_s_ - 1, pin.r), 0.0, 0.0});
  return bounds;
}

std::vector<nlp::Bound> FesdInterval::active_set_bounds(
    const std::vector<std::vector<int>>& active) const {
  if (!opt_.use_fesd || static_cast<int>(active.size()) != N_FE_)
    throw InternalError("FesdInterval::active_set_bounds needs FESD and one set per element");
  // The interval's own lambda_{0,0} (lp_at_start) is tied to the fixed start state s0 by the LP
  // (9). With every region of a sliding mode fixed to lambda = 0 there, g_r(s0) - mu = 0 for
  // each of them repeats c(s0) = 0, an equation too many (s0 is given): the Jacobian loses rank
  // and IPOPT crawls to its acceptable level. One active region per subsystem keeps a free
  // lambda_{0,0} instead, without its sign bound (it equals g_r(s0) - mu = O(1e-16) of either
  // sign; with lambda >= 0 the bound would become active and the problem degenerate again).
  auto free_at_start = [&](const std::vector<int>& a0, int r) {
    if (!in_.lp_at_start) return false;
    for (int k = 0; k < model_.n_sys(); ++k) {
      const int first = model_.region_offset(k), end = model_.region_offset(k + 1);
      if (r < first || r >= end) continue;
      int n_active = 0, last = -1;
      for (int j = first; j < end; ++j)
        if (has(a0, j)) ++n_active, last = j;
      return n_active > 1 && r == last;
    }
    return false;
  };
  std::vector<nlp::Bound> bounds;
  if (step_) return step_active_set_bounds(active);
  for (int n = 0; n < N_FE_; ++n)
    for (int r = 0; r < model_.n_theta(); ++r) {
      // theta = 0 off the active set; lambda = 0 on it at every point of the element: its start
      // (the end of the element before: a crossing or sliding entry there puts the state on the
      // boundary of r), its stages and its end boundary.
      if (!has(active[n], r)) {
        for (int s = 0; s < n_s_; ++s) bounds.push_back({theta(n, s, r), 0.0, 0.0});
        continue;
      }
      // (a free-sign stage lambda too: theta lambda = 0 with theta > 0)
      for (std::size_t q = 0; q < points_[n].size(); ++q) {
        if (n == 0 && q == 0 && free_at_start(active[0], r))
          bounds.push_back({points_[n][q][r], -nlp::kInf, nlp::kInf});
        else
          bounds.push_back({points_[n][q][r], 0.0, 0.0});
      }
    }
  return bounds;
}

std::vector<nlp::Bound> FesdInterval::step_active_set_bounds(
    const std::vector<std::vector<int>>& active) const {
  // Per element and switching function j, the signs S_rj of its active regions: only +1 (the
  // element lies in c_j >= 0): alpha_j = 1 at the stages, lambda_n_j = 0 at every point of the
  // element; only -1: alpha_j = 0, lambda_p_j = 0; both (sliding on c_j = 0): lambda_n_j =
  // lambda_p_j = 0 at every point, alpha_j free. At the start point of a sliding j (lp_at_start)
  // lambda_n_j stays free of its sign bound instead (as active_set_bounds() keeps one lambda of
  // Stewart's form): c_j(s0) = lambda_p_j - lambda_n_j with both fixed would repeat c_j(s0) = 0.
  const int n_c = model_.n_c();
  std::vector<nlp::Bound> bounds;
  for (int n = 0; n < N_FE_; ++n) {
    int c_off = 0;
    for (int k = 0; k < model_.n_sys(); ++k) {
      const Eigen::MatrixXd& S = model_.S(k);
      const int r0 = model_.region_offset(k), r1 = model_.region_offset(k + 1);
      for (int j = 0; j < model_.dims().subsystems[k].n_c; ++j) {
        const int jj = c_off + j;
        bool plus = false, minus = false;
        for (int r = r0; r < r1; ++r)
          if (has(active[n], r)) (S(r - r0, j) > 0 ? plus : minus) = true;
        if (!plus && !minus) continue;
        auto fix_points = [&](int i) {  // multiplier entry i = 0 at every point of element n
          for (std::size_t q = 0; q < points_[n].size(); ++q) {
            if (n == 0 && q == 0 && in_.lp_at_start && plus && minus && i == jj)
              bounds.push_back({points_[n][q][i], -nlp::kInf, nlp::kInf});
            else
              bounds.push_back({points_[n][q][i], 0.0, 0.0});
          }
        };
        if (plus) fix_points(jj);         // lambda_n_j = 0
        if (minus) fix_points(n_c + jj);  // lambda_p_j = 0
        if (plus != minus)
          for (int s = 0; s < n_s_; ++s) {
            bounds.push_back({alpha(n, s, jj), plus ? 1.0 : 0.0, plus ? 1.0 : 0.0});
            bounds.push_back({alpha(n, s, n_c + jj), plus ? 0.0 : 1.0, plus ? 0.0 : 1.0});
          }
      }
      c_off += model_.dims().subsystems[k].n_c;
    }
  }
  return bounds;
}

void FesdInterval::update_lifted_guess(std::vector<double>& w) const {
  for (std::size_t n = 0; n < lam_sum_.size(); ++n)
    for (std::size_t r = 0; r < lam_sum_[n].size(); ++r) {
      double sl = 0, st = 0;
      for (std::size_t q = 0; q < points_[n].size(); ++q)
        if (point_signed_[n][q]) sl += w[points_[n][q][r]];
      for (int s = 0; s < n_s_; ++s) st += w[comp_var(static_cast<int>(n), s, static_cast<int>(r))];
      w[lam_sum_[n][r]] = sl;
      w[th_sum_[n][r]] = st;
    }
}

std::vector<double> FesdInterval::eta(const double* w) const {
  const int n_th = n_comp();
  std::vector<double> out(N_FE_, std::numeric_limits<double>::quiet_NaN());
  for (int n = 1; n < N_FE_; ++n) {
    double e = 1.0;
    for (int r = 0; r < n_th; ++r) {
      double lb = 0, lf = 0, tb = 0, tf = 0;
      for (std::size_t q = 0; q < points_[n - 1].size(); ++q)
        if (point_signed_[n - 1][q]) lb += w[points_[n - 1][q][r]];
      for (std::size_t q = 0; q < points_[n].size(); ++q)
        if (point_signed_[n][q]) lf += w[points_[n][q][r]];
      for (int s = 0; s < n_s_; ++s) {
        tb += w[comp_var(n - 1, s, r)];
        tf += w[comp_var(n, s, r)];
      }
      e *= lb * lf + tb * tf;
    }
    out[n] = e;
  }
  return out;
}

}  // namespace fesd::discretization
