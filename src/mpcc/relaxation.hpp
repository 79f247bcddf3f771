// src/mpcc/relaxation.hpp: how the complementarity constraints (60c) of the MPCC (60) (Sect. 5.2)
// enter the relaxed NLPs of the homotopy. sigma > 0 is the homotopy parameter of every method; each
// NLP of the sequence is a smooth NLP, and sigma -> 0 recovers the MPCC.
//
// A complementarity constraint is a CompGroup: G(w) = sum_p a_p b_p with a_p, b_p >= 0 by their
// variable bounds, so G >= 0 and the MPCC asks G = 0. Per MpccMode:
//
//   scholtes_ineq       G <= sigma                                  (one row per group)
//   scholtes_eq         G  = sigma                                  (one row per group)
//   fischer_burmeister  phi(a, B) = a + B - sqrt(a^2 + B^2 + 2 sigma) = 0 with B = sum_p b_p when
//                       every pair shares its a (or the roles swapped when every pair shares b).
//                       phi = 0 <=> a, B > 0 and a B = sigma, i.e. the smoothed Fischer-Burmeister
//                       C-function of Sect. 1 imposes G = sigma by a function that is smooth
//                       everywhere for sigma > 0, a = B = 0 included. Groups without a common
//                       factor (cross_comp_mode element, neighbor) are rejected: they are not one
//                       complementarity pair.
//   ell_1_penalty       objective += (1 / sigma) * sum of all G      (no rows)
//   elastic_ineq        G <= s for every group with one variable s in [0, s_max],
//                       objective += s / sigma
//   elastic_two_sided   -s <= G <= s for every group (two-sided ones included: the one mode in
//                       which a free-sign product is penalized rather than Scholtes-bounded, by
//                       the bound s on |G|), one s in [0, s_max], objective += s / sigma (nosnoc:
//                       ELASTIC_TWO_SIDED). For groups with G >= 0 the lower row is inactive and
//                       the mode equals elastic_ineq.
//
// The penalty modes (ell_1_penalty, elastic_ineq, elastic_two_sided) weigh their term 1 / sigma
// against the cost J (every objective term added before the relaxation, OCP cost and step
// equilibration alike): J + (1/sigma) P. With objective_scaling_direct = false (nosnoc's inverse
// scaling) the NLP's objective is sigma J + P instead: the same minimizers, an objective that
// stays O(1) as sigma -> 0 rather than growing as 1/sigma, so that IPOPT's scaled tolerances see
// another problem. The other modes have no penalty term and ignore the setting.
//
// The elastic variable s is nosnoc's s_elastic, in [s_elastic_min, s_elastic_max] with the guess
// s_elastic_0. fesd's defaults (HomotopyOptions::s_elastic_max = 1e20, i.e. unbounded, and
// s_elastic_0 = 0) are not nosnoc's (10 and 1, in MATLAB nosnoc and nosnoc_py alike): the
// problem files that reproduce nosnoc's examples set them.
//
// ell_1_penalty and elastic_ineq are exact penalties: once 1 / sigma exceeds the multipliers of
// the complementarity constraints, their NLP solution is complementary (up to IPOPT's tolerance),
// often from the first sigma on. scholtes_eq and fischer_burmeister are equations: with
// cross_comp_mode sparse every theta_{n,m,i} of FESD gets one equation per lambda point of its
// element, more equations than unknowns (Example 3(a), Radau IIA, n_s = 1 or 2, N_FE = 2: IPOPT
// stops with Not_Enough_Degrees_Of_Freedom), so they need stage_sum; and they ask a * B = sigma > 0
// also of pairs that vanish together at the solution (both theta and lambda -> 0, e.g. where a
// sliding mode ends), where the relaxed NLPs are degenerate.
//
// Two-sided groups (CompGroup::two_sided: b is a lambda without sign condition, so a_p b_p has no
// sign) stay Scholtes rows -sigma <= G <= sigma in every mode but elastic_two_sided: a product of
// free sign can neither be penalized (it would be driven to -inf), nor smoothed by a C-function
// (which needs b >= 0), nor be set = sigma (its sign is not known in advance).
#pragma once
#include <utility>
#include <vector>

#include "discretization/fesd_interval.hpp"
#include "fesd/options.hpp"
#include "nlp/block_nlp.hpp"

namespace fesd::mpcc {

using discretization::CompGroup;
using discretization::CompPair;

/// The relaxation of the complementarity groups of one NLP in one MpccMode.
class Relaxation {
 public:
  /// Adds rows / variables / objective terms for `groups` to `nlp` (before nlp.finalize()).
  /// Throws fesd::InvalidOption naming the problem when the mode cannot express a group
  /// (fischer_burmeister on a group without a common factor).
  /// `s_max`, `s_0`: bounds [0, s_max] and guess of the elastic variable (elastic modes only).
  /// `scaling_direct`: the penalty modes' objective J + (1/sigma) P (true) or sigma J + P.
  Relaxation(nlp::BlockNlp& nlp, const std::vector<CompGroup>& groups, MpccMode mode,
             double s_max = nlp::kInf, double s_0 = 0.0, bool scaling_direct = true);

  /// Sets sigma: row bounds, the fixed sigma variable (fischer_burmeister), objective weights
  /// (penalty modes: 1 / sigma on the penalty, or sigma on the cost terms).
  void set_sigma(nlp::BlockNlp& nlp, double sigma) const;

  MpccMode mode() const { return mode_; }
  /// Per group: its constraint row, or -1 (ell_1_penalty groups, which are objective terms, and
  /// empty groups outside scholtes_ineq, which are identically zero).
  const std::vector<int>& group_rows() const { return group_rows_; }
  /// The NLP variable fixed to sigma by its bounds (fischer_burmeister), else -1.
  int sigma_variable() const { return sigma_var_; }
  /// The elastic variable s (elastic_ineq, elastic_two_sided), else -1.
  int elastic_variable() const { return elastic_var_; }

 private:
  MpccMode mode_;
  std::vector<int> group_rows_;
  std::vector<int> upper_rows_;      // -inf <= G <= sigma
  std::vector<int> two_sided_rows_;  // -sigma <= G <= sigma
  std::vector<int> equal_rows_;      // G = sigma
  std::vector<int> objectives_;      // penalty terms: weight 1 / sigma (or 1, inverse scaling)
  // Inverse scaling: the cost terms (objectives before the relaxation's) and their own weights,
  // which set_sigma multiplies by sigma.
  std::vector<std::pair<int, double>> cost_terms_;
  bool inverse_ = false;  // a penalty mode with objective_scaling_direct = false
  int sigma_var_ = -1, elastic_var_ = -1;
};

/// Adds one row per group (Scholtes: -inf <= sum of products <= sigma; -sigma <= sum <= sigma for
/// two-sided groups); returns the rows. The scholtes_ineq mode of Relaxation.
std::vector<int> add_scholtes_rows(nlp::BlockNlp& nlp, const std::vector<CompGroup>& groups);
/// Sets sigma in rows made by add_scholtes_rows.
void set_sigma(nlp::BlockNlp& nlp, const std::vector<int>& rows, double sigma);

}  // namespace fesd::mpcc
