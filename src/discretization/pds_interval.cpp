#include "discretization/pds_interval.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include <fmt/format.h>

#include "core/option_registry.hpp"
#include "discretization/dynamics_eq.hpp"
#include "discretization/stage_state_block.hpp"
#include "fesd/error.hpp"
#include "nlp/block.hpp"
#include "nlp/sum_block.hpp"

namespace fesd::discretization {
namespace {

using nlp::kInf;

/// f(X, q, p) + grad c(X, p) lambda, the right-hand side of (6a): y = lambda (n_c).
struct PdsRhs {
  const Pds* m;
  int n_y() const { return m->n_c(); }
  template <class T>
  void operator()(const T* X, const T* /*lambda*/, const T* q, const T* p, T* out) const {
    m->functions().f(X, q, p, out);
  }
  template <class T>
  void second(const T* X, const T* lambda, const T* /*q*/, const T* p, T* out) const {
    m->functions().grad_c_lambda(X, p, lambda, out);
  }
};

/// V - f(X, q, p) - grad c(X, p) lambda = 0 (6a).  inputs: V (n_x), X (n_x), lambda (n_c), q, p
using PdsDynamicsEq = StageDynamicsEq<PdsRhs>;

/// C - c(X, p) = 0 (the lifted constraint values of (6b)).  inputs: C (n_c), X (n_x), p
struct ConstraintEq {
  const Pds* m;
  int num_inputs() const { return m->n_c() + m->n_x() + m->n_p(); }
  int num_outputs() const { return m->n_c(); }
  template <class T>
  void operator()(const T* w, T* c) const {
    const int n_c = m->n_c();
    m->functions().c(w + n_c, w + n_c + m->n_x(), c);
    for (int k = 0; k < n_c; ++k) c[k] = w[k] - c[k];
  }
};

/// sum_i a_i w_i (the linear rows of the step equilibration).
struct LinearEq {
  std::vector<double> a;
  int num_inputs() const { return static_cast<int>(a.size()); }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    T s(0.0);
    for (std::size_t i = 0; i < a.size(); ++i) s = s + a[i] * w[i];
    c[0] = s;
  }
};

/// (h - h0)^2 / h0^2: the tie-break objective of the relaxed NLPs (PdsOptions::h_penalty).
struct RelativeDeviation {
  double h0;
  int num_inputs() const { return 1; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    const T d = (w[0] - h0) / h0;
    c[0] = d * d;
  }
};

std::vector<int> range(int first, int n) {
  std::vector<int> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) v[i] = first + i;
  return v;
}

}  // namespace

NlpOptions pds_nlp_options(const NlpOptions& o) {
  NlpOptions out = o;
  for (const char* name :
       {"warm_start_bound_push", "warm_start_slack_bound_push", "warm_start_mult_bound_push"}) {
    const bool given = std::any_of(out.extra.begin(), out.extra.end(),
                                   [&](const auto& kv) { return kv.first == name; });
    if (!given) out.extra.emplace_back(name, fmt::format("{:g}", kPdsWarmStartPush));
  }
  return out;
}

std::vector<std::string> PdsInterval::errors(const Tableau& tab, const DiscretizationOptions& o,
                                             const PdsOptions& pds) {
  std::vector<std::string> e;
  if (tab.scheme != RkScheme::RadauIIA && tab.scheme != RkScheme::LobattoIIIC)
    e.push_back(fmt::format(
        "rk_scheme = {}: projected dynamical systems support only schemes with c_n_s = 1 whose "
        "last stage is the element end (radau_iia, lobatto_iiic), papers/fesd-pds.txt Sect. III-A",
        to_string(tab.scheme)));
  if (o.use_fesd && o.N_FE < 2)
    e.push_back(fmt::format("N_finite_elements = {}: FESD needs >= 2", o.N_FE));
  if (!(pds.M > 0) || !std::isfinite(pds.M))
    e.push_back(fmt::format("step equilibration M = {}: must be finite and > 0", pds.M));
  return e;
}

PdsInterval::PdsInterval(const Pds& model, const Tableau& tableau,
                         const DiscretizationOptions& options, const PdsOptions& pds_options)
    : model_(model), tab_(tableau), opt_(options), pds_(pds_options) {
  if (auto e = errors(tab_, opt_, pds_); !e.empty()) throw InvalidOption(registry::join(e));
  N_FE_ = opt_.N_FE;
  n_s_ = tab_.n_s;
  free_first_ = opt_.use_fesd && tab_.scheme == RkScheme::LobattoIIIC;
}

void PdsInterval::build(nlp::BlockNlp& nlp, const PdsIntervalInputs& in) {
  in_ = in;
  const Pds& m = model_;
  const int n_x = m.n_x(), n_c = m.n_c();
  const bool fesd = opt_.use_fesd;
  const double h0 = in.T / N_FE_;
  // ---- variables ----
  h_.clear();
  X_.clear();
  V_.clear();
  lambda_.clear();
  C_.clear();
  for (int n = 0; n < N_FE_; ++n) {
    if (fesd)
      h_.push_back(nlp.add_variables(1, (1.0 - opt_.gamma_h) * h0, (1.0 + opt_.gamma_h) * h0, h0));
    else
      h_.push_back(nlp.add_variables(1, h0, h0, h0));
    for (int i = 0; i < n_s_; ++i) {
      X_.push_back(nlp.add_variables(n_x, -kInf, kInf, 0.0));
      V_.push_back(nlp.add_variables(n_x, -kInf, kInf, 0.0));
      lambda_.push_back(nlp.add_variables(n_c, 0.0, kInf, 0.0));
      C_.push_back(nlp.add_variables(n_c, i == 0 && free_first_ ? -kInf : 0.0, kInf, 0.0));
    }
  }
  // ---- (6a), (6b) ----
  auto dynamics = nlp::make_block(PdsDynamicsEq{&m});
  auto constraint = nlp::make_block(ConstraintEq{&m});
  std::vector<std::shared_ptr<const nlp::Block>> stage_state(n_s_);
  std::vector<std::vector<int>> stage_cols(n_s_);
  for (int i = 0; i < n_s_; ++i) {
    std::vector<double> a;
    for (int j = 0; j < n_s_; ++j)
      if (tab_.A(i, j) != 0.0) {
        a.push_back(tab_.A(i, j));
        stage_cols[i].push_back(j);
      }
    stage_state[i] = std::make_shared<StageStateBlock>(StageStateEq{a});
  }
  for (int n = 0; n < N_FE_; ++n)
    for (int i = 0; i < n_s_; ++i) {
      std::vector<int> dv = range(V(n, i, 0), n_x);
      for (int j = 0; j < n_x; ++j) dv.push_back(X(n, i, j));
      for (int k = 0; k < n_c; ++k) dv.push_back(lambda(n, i, k));
      dv.insert(dv.end(), in.q.begin(), in.q.end());
      dv.insert(dv.end(), in.p.begin(), in.p.end());
      nlp.add_constraint(dynamics, dv, 0.0, 0.0);
      std::vector<int> cv = range(C(n, i, 0), n_c);
      for (int j = 0; j < n_x; ++j) cv.push_back(X(n, i, j));
      cv.insert(cv.end(), in.p.begin(), in.p.end());
      nlp.add_constraint(constraint, cv, 0.0, 0.0);
      for (int j = 0; j < n_x; ++j) {
        std::vector<int> sv{X(n, i, j), x(n, j), h(n)};
        for (int col : stage_cols[i]) sv.push_back(V(n, col, j));
        nlp.add_constraint(stage_state[i], sv, 0.0, 0.0);
      }
    }
  // ---- FESD: sum h_n = T and the step equilibration of Sect. III-C ----
  nu_.assign(N_FE_, -1);
  auto per_boundary = [&] {
    return std::vector<std::vector<int>>(N_FE_, std::vector<int>(n_c, -1));
  };
  pi_c_ = per_boundary(), pi_l_ = per_boundary(), max_ = per_boundary(), nu_k_ = per_boundary();
  s1_ = per_boundary(), s2_ = per_boundary(), mu1_ = per_boundary(), mu2_ = per_boundary();
  std::vector<CompPair> lp_pairs;
  if (fesd) {
    nlp.add_constraint(make_block(nlp::Sum{N_FE_}), h_, in.T, in.T);
    if (pds_.h_penalty) {
      auto pen = nlp::make_block(RelativeDeviation{h0});
      for (int n = 0; n < N_FE_; ++n) nlp.add_objective(pen, {h(n)}, opt_.rho_h / N_FE_);
    }
    auto row = [&](std::vector<int> vars, std::vector<double> a, double lb, double ub) {
      nlp.add_constraint(nlp::make_block(LinearEq{std::move(a)}), std::move(vars), lb, ub);
    };
    // n_s = 1: c at the step start (the backward sum of boundary 1, see backward_extra); Lobatto
    // IIIC: c at the start point of element 0 (sums (10), the pairs of (8b) for n = 0).
    C0_.clear();
    if (n_s_ == 1 || free_first_) {
      const int c0 = nlp.add_variables(n_c, -kInf, kInf, 0.0);
      std::vector<int> cv = range(c0, n_c);
      cv.insert(cv.end(), in.s0.begin(), in.s0.end());
      cv.insert(cv.end(), in.p.begin(), in.p.end());
      nlp.add_constraint(constraint, cv, 0.0, 0.0);
      C0_ = range(c0, n_c);
    }
    // z - sum of the stage values of element e >= 0 (one operand of "or").
    for (int n = 1; n < N_FE_; ++n) {
      for (int k = 0; k < n_c; ++k) {
        auto sum_vars = [&](int e, bool of_lambda) {
          return of_lambda ? lambda_terms(e, k) : c_terms(e, k);
        };
        // pi = sigma^B or sigma^F:  pi >= sigma^B, pi >= sigma^F, pi <= sigma^B + sigma^F (10)
        for (int which = 0; which < 2; ++which) {
          const bool of_lambda = which == 1;
          const int pi = nlp.add_variables(1, 0.0, kInf, 0.0);
          (of_lambda ? pi_l_ : pi_c_)[n][k] = pi;
          std::vector<int> vb{pi}, vf{pi}, vbf{pi};
          std::vector<double> ab{1.0}, af{1.0}, abf{1.0};
          for (int var : sum_vars(n - 1, of_lambda))
            vb.push_back(var), vbf.push_back(var), ab.push_back(-1.0), abf.push_back(-1.0);
          for (int var : sum_vars(n, of_lambda))
            vf.push_back(var), vbf.push_back(var), af.push_back(-1.0), abf.push_back(-1.0);
          if (const int extra = backward_extra(n, k, of_lambda); extra >= 0) {
            vb.push_back(extra);
            ab.push_back(-1.0);
            vbf.push_back(extra);
            abf.push_back(-1.0);
          }
          row(vb, ab, 0.0, kInf);
          row(vf, af, 0.0, kInf);
          row(vbf, abf, -kInf, 0.0);
        }
        // nu_k = pi_c and pi_lambda: nu <= pi_c, nu <= pi_lambda, nu >= pi_c + pi_lambda - max,
        // max = max(pi_c, pi_lambda) = min z s.t. z >= pi_c, z >= pi_lambda by its KKT
        // conditions: max - pi_c = s1 >= 0, max - pi_lambda = s2 >= 0, mu1 + mu2 = 1,
        // 0 <= s1 perp mu1 >= 0, 0 <= s2 perp mu2 >= 0.
        const int pc = pi_c_[n][k], pl = pi_l_[n][k];
        const int mx = max_[n][k] = nlp.add_variables(1, 0.0, kInf, 0.0);
        const int nk = nu_k_[n][k] = nlp.add_variables(1, 0.0, kInf, 0.0);
        const int s1 = s1_[n][k] = nlp.add_variables(1, 0.0, kInf, 0.0);
        const int s2 = s2_[n][k] = nlp.add_variables(1, 0.0, kInf, 0.0);
        const int m1 = mu1_[n][k] = nlp.add_variables(1, 0.0, 1.0, 0.5);
        const int m2 = mu2_[n][k] = nlp.add_variables(1, 0.0, 1.0, 0.5);
        row({nk, pc}, {1.0, -1.0}, -kInf, 0.0);
        row({nk, pl}, {1.0, -1.0}, -kInf, 0.0);
        row({nk, pc, pl, mx}, {1.0, -1.0, -1.0, 1.0}, 0.0, kInf);
        row({mx, pc, s1}, {1.0, -1.0, -1.0}, 0.0, 0.0);
        row({mx, pl, s2}, {1.0, -1.0, -1.0}, 0.0, 0.0);
        row({m1, m2}, {1.0, 1.0}, 1.0, 1.0);
        lp_pairs.push_back({s1, m1});
        lp_pairs.push_back({s2, m2});
      }
      // nu_n = nu_1 or ... or nu_{n_c}: positive exactly when some constraint switches at n.
      if (n_c == 1) {
        nu_[n] = nu_k_[n][0];
      } else {
        nu_[n] = nlp.add_variables(1, 0.0, kInf, 0.0);
        std::vector<int> all{nu_[n]};
        std::vector<double> a{1.0};
        for (int k = 0; k < n_c; ++k) {
          row({nu_[n], nu_k_[n][k]}, {1.0, -1.0}, 0.0, kInf);
          all.push_back(nu_k_[n][k]);
          a.push_back(-1.0);
        }
        row(all, a, -kInf, 0.0);
      }
      // -nu_n M <= h_{n-1} - h_n <= nu_n M
      row({h(n - 1), h(n), nu_[n]}, {1.0, -1.0, -pds_.M}, -kInf, 0.0);
      row({h(n - 1), h(n), nu_[n]}, {1.0, -1.0, pds_.M}, 0.0, kInf);
    }
  }
  // ---- complementarity: (6b), or (8a)-(8c) for FESD ----
  groups_.clear();
  residual_pairs_.clear();
  std::map<int, CompGroup> by_c;  // pairs sharing their C variable
  auto add = [&](int c_var, int l_var) {
    const CompPair pair{c_var, l_var};
    residual_pairs_.push_back(pair);
    if (!fesd || opt_.cross_comp == CrossComp::Sparse)
      groups_.push_back({{pair}});
    else
      by_c[c_var].pairs.push_back(pair);
  };
  std::vector<CompGroup> two_sided;
  for (int n = 0; n < N_FE_; ++n)
    for (int k = 0; k < n_c; ++k)
      for (int i = 0; i < n_s_; ++i) {
        if (!fesd) {
          add(C(n, i, k), lambda(n, i, k));  // (6b)
          continue;
        }
        if (i == 0 && free_first_) {
          // Lobatto IIIC: stage 1 is no trajectory point (c_1 = 0, X_{n,1} != x_n), so
          // c(X_{n,1}) has no sign condition: its pairs (8a), (8c) are relaxed on both sides
          // (c(X_{n,1}) = 0 where a lambda of the element or lambda_{n-1,n_s} is positive, free in
          // a free element). lambda_{n,1} keeps its sign and its pairs with the other stages and
          // with the start point x_n ((8b); for n = 0 c(s0), also without sign).
          CompGroup own{{}, /*two_sided=*/true};
          for (int j = 0; j < n_s_; ++j) own.pairs.push_back({C(n, 0, k), lambda(n, j, k)});
          if (n >= 1) {
            own.pairs.push_back({C(n, 0, k), lambda(n - 1, n_s_ - 1, k)});  // (8c)
            add(C(n - 1, n_s_ - 1, k), lambda(n, 0, k));                    // (8b)
          }
          if (n == 0)
            for (int j = 0; j < n_s_; ++j) own.pairs.push_back({C0_[k], lambda(0, j, k)});
          for (const CompPair& pair : own.pairs) {
            residual_pairs_.push_back(pair);
            if (opt_.cross_comp == CrossComp::Sparse) two_sided.push_back({{pair}, true});
          }
          if (opt_.cross_comp != CrossComp::Sparse) two_sided.push_back(std::move(own));
          continue;
        }
        for (int j = 0; j < n_s_; ++j) add(C(n, i, k), lambda(n, j, k));  // (8a)
        if (n >= 1) {
          add(C(n - 1, n_s_ - 1, k), lambda(n, i, k));  // (8b)
          add(C(n, i, k), lambda(n - 1, n_s_ - 1, k));  // (8c)
        }
      }
  for (auto& [var, g] : by_c) groups_.push_back(std::move(g));
  for (CompGroup& g : two_sided) groups_.push_back(std::move(g));
  for (const CompPair& pair : lp_pairs) {
    residual_pairs_.push_back(pair);
    groups_.push_back({{pair}});
  }
}

void PdsInterval::set_guess(std::vector<double>& w, const Eigen::VectorXd& x0,
                            const std::vector<Eigen::VectorXd>& X_guess,
                            const std::vector<Eigen::VectorXd>& lambda_guess,
                            const Eigen::VectorXd& q, const Eigen::VectorXd& p) const {
  const int n_x = model_.n_x(), n_c = model_.n_c();
  const double h0 = in_.T / N_FE_;
  (void)x0;
  Eigen::VectorXd f(n_x), g(n_x), c(n_c);
  for (int n = 0; n < N_FE_; ++n) {
    w[h(n)] = h0;
    for (int i = 0; i < n_s_; ++i) {
      const Eigen::VectorXd& Xg = X_guess[idx(n, i)];
      const Eigen::VectorXd& lg = lambda_guess[idx(n, i)];
      model_.functions().f(Xg.data(), q.data(), p.data(), f.data());
      model_.functions().grad_c_lambda(Xg.data(), p.data(), lg.data(), g.data());
      model_.functions().c(Xg.data(), p.data(), c.data());
      for (int j = 0; j < n_x; ++j) {
        w[X(n, i, j)] = Xg[j];
        w[V(n, i, j)] = f[j] + g[j];
      }
      for (int k = 0; k < n_c; ++k) {
        w[lambda(n, i, k)] = std::max(lg[k], 0.0);
        w[C(n, i, k)] = i == 0 && free_first_ ? c[k] : std::max(c[k], 0.0);
      }
    }
  }
  if (nu_.empty() || !opt_.use_fesd) return;
  if (!C0_.empty()) {
    Eigen::VectorXd xs(n_x);
    for (int j = 0; j < n_x; ++j) xs[j] = w[x(0, j)];
    model_.functions().c(xs.data(), p.data(), c.data());
    for (int k = 0; k < n_c; ++k) w[C0_[k]] = c[k];
  }
  for (int n = 1; n < N_FE_; ++n) {
    double nu_max = 0;
    for (int k = 0; k < n_c; ++k) {
      double cb = 0, cf = 0, lb = 0, lf = 0;
      for (int v : c_terms(n - 1, k)) cb += w[v];
      for (int v : c_terms(n, k)) cf += w[v];
      for (int v : lambda_terms(n - 1, k)) lb += w[v];
      for (int v : lambda_terms(n, k)) lf += w[v];
      if (const int e = backward_extra(n, k, false); e >= 0) cb += w[e];
      if (const int e = backward_extra(n, k, true); e >= 0) lb += w[e];
      const double pc = std::max(cb, cf), pl = std::max(lb, lf), mx = std::max(pc, pl);
      w[pi_c_[n][k]] = pc;
      w[pi_l_[n][k]] = pl;
      w[max_[n][k]] = mx;
      w[nu_k_[n][k]] = std::min(pc, pl);
      w[s1_[n][k]] = mx - pc;
      w[s2_[n][k]] = mx - pl;
      w[mu1_[n][k]] = pc >= pl ? 1.0 : 0.0;
      w[mu2_[n][k]] = pc >= pl ? 0.0 : 1.0;
      nu_max = std::max(nu_max, std::min(pc, pl));
    }
    w[nu_[n]] = nu_max;
  }
}

std::vector<int> PdsInterval::c_terms(int e, int k) const {
  std::vector<int> v;
  if (free_first_) v.push_back(e == 0 ? C0_[k] : C(e - 1, n_s_ - 1, k));
  for (int i = free_first_ ? 1 : 0; i < n_s_; ++i) v.push_back(C(e, i, k));
  return v;
}

std::vector<int> PdsInterval::lambda_terms(int e, int k) const {
  std::vector<int> v;
  for (int i = 0; i < n_s_; ++i) v.push_back(lambda(e, i, k));
  return v;
}

int PdsInterval::backward_extra(int n, int k, bool of_lambda) const {
  if (n_s_ != 1 || n < 1) return -1;
  if (n >= 2) return of_lambda ? lambda(n - 2, 0, k) : C(n - 2, 0, k);
  return of_lambda || C0_.empty() ? -1 : C0_[k];
}

std::vector<int> PdsInterval::active_set(const double* w, int n) const {
  std::vector<int> active;
  for (int k = 0; k < model_.n_c(); ++k) {
    double l = 0, c = 0;
    for (int v : lambda_terms(n, k)) l += w[v];
    if (free_first_) {
      for (int v : c_terms(n, k)) c += w[v];
    } else {
      for (int i = 0; i < n_s_; ++i) c += w[C(n, i, k)];
    }
    if (n_s_ == 1 && opt_.use_fesd) {
      if (one_stage_active(w, n, k)) active.push_back(k);
    } else if (l > c) {
      active.push_back(k);
    }
  }
  return active;
}

bool PdsInterval::one_stage_active(const double* w, int n, int k) const {
  // The last element of a contact (its end the leaving point) and the last one before a contact
  // (its end the contact point) have lambda = c = 0 at their only stage ((8b), (8c)): such a tie
  // continues the element before (in contact, resp. not), so that the switch is at its end.
  // A tie: both factors below kTie of the larger neighbouring value of the same factor (in the
  // relaxed solution they are O(complementarity_tol / the other factor), not exactly 0).
  constexpr double kTie = 1e-3;
  bool active = false;
  for (int e = 0; e <= n; ++e) {
    const double l = w[lambda(e, 0, k)], c = w[C(e, 0, k)];
    double l_near = 0, c_near = 0;
    for (int d : {e - 1, e + 1})
      if (d >= 0 && d < N_FE_) {
        l_near = std::max(l_near, w[lambda(d, 0, k)]);
        c_near = std::max(c_near, w[C(d, 0, k)]);
      }
    const bool tie = e > 0 && l <= kTie * l_near && c <= kTie * c_near;
    if (!tie) active = l > c;
  }
  return active;
}

std::vector<nlp::Bound> PdsInterval::active_set_bounds(const double* w) const {
  std::vector<std::vector<int>> active(N_FE_);
  for (int n = 0; n < N_FE_; ++n) active[n] = active_set(w, n);
  auto has = [](const std::vector<int>& a, int k) {
    return std::find(a.begin(), a.end(), k) != a.end();
  };
  std::vector<nlp::Bound> bounds;
  for (int n = 0; n < N_FE_; ++n)
    for (int k = 0; k < model_.n_c(); ++k) {
      const bool on = has(active[n], k);
      for (int i = 0; i < n_s_; ++i)
        bounds.push_back({on ? C(n, i, k) : lambda(n, i, k), 0.0, 0.0});
      if (n + 1 < N_FE_ && on != has(active[n + 1], k))
        bounds.push_back({on ? lambda(n, n_s_ - 1, k) : C(n, n_s_ - 1, k), 0.0, 0.0});
    }
  return bounds;
}

}  // namespace fesd::discretization
