// src/discretization/pds_interval.hpp: the equations of one interval [0, T] of a projected
// dynamical system (include/fesd/pds.hpp) with N_FE finite elements and an n_s-stage RK method
// with c_{n_s} = 1 (Radau IIA, Lobatto IIIC), papers/fesd-pds.txt
// Sect. III, written into a BlockNlp (docs/pds.md):
//
//   per element n and stage i (lifted stage derivatives V and constraint values C):
//     V_{n,i} = f(X_{n,i}, q, p) + grad c(X_{n,i}) lambda_{n,i}               (6a)
//     X_{n,i} = x_n + h_n sum_j a_{i,j} V_{n,j}                              (6a)
//     C_{n,i} = c(X_{n,i}),  C >= 0,  lambda >= 0                            (6b)
//     x_{n+1} = X_{n,n_s}                                                    (c_{n_s} = 1)
//   standard RK (6): h_n = T / N_FE fixed, complementarity C_{n,i} lambda_{n,i} (6b).
//   FESD: h_n free in [(1 - gamma_h) h0, (1 + gamma_h) h0], sum h_n = T, the cross
//   complementarity (8a) C_{n,i} lambda_{n,j}, (8b) C_{n-1,n_s} lambda_{n,j}, (8c) C_{n,i}
//   lambda_{n-1,n_s}, and the step equilibration of Sect. III-C: the sums (10), per constraint k
//   pi_c = sigma_c^B or sigma_c^F, pi_lambda = sigma_lambda^B or sigma_lambda^F,
//   nu_k = pi_c and pi_lambda (the Boolean operators, max by the KKT conditions of its LP), nu_n =
//   nu_1 or ... or nu_{n_c}, and -nu_n M <= h_{n-1} - h_n <= nu_n M.
//
// Lobatto IIIC with FESD: stage 1 (c_1 = 0 but X_{n,1} != x_n) is no trajectory point: C_{n,1}
// has no sign condition, its products with the lambdas of the element and lambda_{n-1,n_s} are
// relaxed on both sides, it is in no sum (10) (c at the start point x_n replaces it there).
//
// Unlike Stewart's lambda, the PDS lambda jumps at contact (Prop. 2): there is no lambda at the
// element start and no continuity condition (27). The complementarity pairs are returned, not
// imposed: the MPCC layer relaxes them (as for FesdInterval).
#pragma once
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "discretization/fesd_interval.hpp"
#include "fesd/options.hpp"
#include "fesd/pds.hpp"
#include "fesd/tableau.hpp"
#include "nlp/block_nlp.hpp"

namespace fesd::discretization {

/// IPOPT's push of a warm start away from the bounds (warm_start_bound_push,
/// warm_start_slack_bound_push, warm_start_mult_bound_push) for the NLPs of PDS intervals. IPOPT's
/// default 1e-3 moves every variable that sits at a bound by up to 1e-3 when an NLP of the
/// homotopy is warm-started: the multipliers, constraint values and step-equilibration variables
/// that the previous NLP had driven to O(sigma), among them nu_n, whose bound M nu_n on
/// |h_{n-1} - h_n| then jumps from O(M sigma) to 1e-3 M = 1e3 (M = 1e6) >> h0: the element lengths
/// are released and drift (docs/pds.md, "Warm starts").
inline constexpr double kPdsWarmStartPush = 1e-9;
/// `o` with the three warm-start pushes set to kPdsWarmStartPush unless [ipopt] sets them.
NlpOptions pds_nlp_options(const NlpOptions& o);

/// Where the interval's inputs live in the NLP (variables, possibly fixed by their bounds).
struct PdsIntervalInputs {
  std::vector<int> s0;  ///< n_x: state at the interval start
  std::vector<int> q;   ///< n_u: control of the interval
  std::vector<int> p;   ///< n_p: parameters
  double T = 0;         ///< interval length
};

class PdsInterval {
 public:
  /// Throws fesd::InvalidOption for a scheme without c_{n_s} = 1 and stiff accuracy (only Radau
  /// IIA and Lobatto IIIC), FESD with N_FE < 2, or M <= 0.
  PdsInterval(const Pds& model, const Tableau& tableau, const DiscretizationOptions& options,
              const PdsOptions& pds_options);

  /// The scheme and option checks of the constructor, one message each (empty: fine).
  static std::vector<std::string> errors(const Tableau& tableau, const DiscretizationOptions& o,
                                         const PdsOptions& pds_options);

  /// Adds variables and constraint blocks to `nlp`.
  void build(nlp::BlockNlp& nlp, const PdsIntervalInputs& in);

  /// Sets the guess of every variable of the interval from stage states and multipliers (one per
  /// element and stage, index n * n_s + i); V, C and the step-equilibration variables follow.
  void set_guess(std::vector<double>& w, const Eigen::VectorXd& x0,
                 const std::vector<Eigen::VectorXd>& X_guess,
                 const std::vector<Eigen::VectorXd>& lambda_guess, const Eigen::VectorXd& q,
                 const Eigen::VectorXd& p) const;

  // ---- layout (valid after build); n: element, i: stage 0..n_s-1, j: state, k: constraint ----
  int N_FE() const { return N_FE_; }
  int n_s() const { return n_s_; }
  int x(int n, int j) const { return n == 0 ? in_.s0[j] : X(n - 1, n_s_ - 1, j); }  ///< n = 0..N_FE
  int h(int n) const { return h_[n]; }
  int X(int n, int i, int j) const { return X_[idx(n, i)] + j; }
  int V(int n, int i, int j) const { return V_[idx(n, i)] + j; }
  int lambda(int n, int i, int k) const { return lambda_[idx(n, i)] + k; }
  int C(int n, int i, int k) const { return C_[idx(n, i)] + k; }
  /// nu_n of boundary n = 1..N_FE-1 (FESD), else -1.
  int nu(int n) const { return nu_.empty() || n < 1 ? -1 : nu_[n]; }

  /// The complementarity constraints (groups sharing their C variable, or single pairs with
  /// cross_comp_mode sparse) and every product, whose max is the complementarity residual.
  const std::vector<CompGroup>& groups() const { return groups_; }
  const std::vector<CompPair>& residual_pairs() const { return residual_pairs_; }

  /// Active constraints of element n at w: k with sum_i lambda_{n,i,k} > sum_i C_{n,i,k} (the
  /// factor that vanishes is the smaller one).
  std::vector<int> active_set(const double* w, int n) const;
  /// The bounds of the re-solve with the active set of every element fixed (FESD,
  /// HomotopyOptions::fix_active_set): constraint k active in element n: C_{n,i,k} = 0 at every
  /// stage; inactive: lambda_{n,i,k} = 0 at every stage; and at a boundary where k switches
  /// (Prop. 3: k in W_{n-1,n_s}) both factors of the last stage before it are 0: C_{n-1,n_s,k}
  /// where k becomes active (contact), lambda_{n-1,n_s,k} where it becomes inactive (leaving).
  /// Complementarity then holds exactly, and the contact and leaving points are the equations
  /// c(x_n) = 0 and lambda_{n-1,n_s} = 0 instead of products <= sigma (whose tolerance lets a
  /// leaving point drift by up to complementarity_tol / c(x_{n,1}), growing as h shrinks).
  std::vector<nlp::Bound> active_set_bounds(const double* w) const;

 private:
  int idx(int n, int i) const { return n * n_s_ + i; }
  /// n_s = 1: one more term of the backward sums (10) of boundary n, else -1. With one stage the
  /// paper's sigma^B of element n-1 is only its end point, where (8b)/(8c) make c = 0 at a
  /// contact and lambda = 0 at a leaving point, so nu_n would be 0 exactly where the boundary must
  /// move (Table I's + entries fail). The backward sums then also take the point before: c at the
  /// element's start (C of element n-2's stage, or c(s0) for n = 1) and lambda of element n-2's
  /// stage (none for n = 1). Table I holds again: at a contact c > 0 there (free flight before),
  /// at a leaving point lambda > 0 there (contact before); where nothing switches the added term
  /// is 0 exactly when the paper's is (docs/pds.md, "n_s = 1").
  int backward_extra(int n, int k, bool of_lambda) const;
  /// The terms of the sums (10) over element e (also the rule of active_set): C and lambda of its
  /// stages; with free_first_ (Lobatto IIIC) c at the element's start point (C of the last stage
  /// before, C0_ for e = 0) instead of c(X_{e,1}), which is no trajectory point.
  std::vector<int> c_terms(int e, int k) const;
  std::vector<int> lambda_terms(int e, int k) const;
  /// n_s = 1 with FESD: whether constraint k is active in element n (the rule of active_set, with
  /// ties continuing the element before).
  bool one_stage_active(const double* w, int n, int k) const;

  const Pds& model_;
  Tableau tab_;
  DiscretizationOptions opt_;
  PdsOptions pds_;
  PdsIntervalInputs in_;
  int N_FE_ = 0, n_s_ = 0;
  /// FESD with Lobatto IIIC: stage 1 (c_1 = 0, X_{n,1} != x_n) is no trajectory point, so
  /// C_{n,1} = c(X_{n,1}) has no sign condition and only two-sided products (docs/pds.md,
  /// "Lobatto IIIC").
  bool free_first_ = false;
  std::vector<int> h_, X_, V_, lambda_, C_;
  std::vector<int> C0_;  ///< FESD with n_s = 1 or Lobatto IIIC: c(s0) (n_c variables), else empty
  // step equilibration, per boundary n (index n, 0 unused) and constraint k
  std::vector<int> nu_;
  std::vector<std::vector<int>> pi_c_, pi_l_, max_, nu_k_, s1_, s2_, mu1_, mu2_;
  std::vector<CompGroup> groups_;
  std::vector<CompPair> residual_pairs_;
};

}  // namespace fesd::discretization
