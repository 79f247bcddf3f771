#include "mpcc/relaxation.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "fesd/error.hpp"
#include "nlp/block.hpp"
#include "nlp/sum_block.hpp"

namespace fesd::mpcc {
namespace {

/// Smoothed Fischer-Burmeister function of one complementarity pair (a, B):
/// phi = a + B - sqrt(a^2 + B^2 + 2 sigma), with a = w[0] the factor all products of the group
/// share, B the sum of the other factors w[1..m], sigma = w[m + 1] (a variable fixed by its
/// bounds). phi is symmetric in (a, B), so "common theta" and "common lambda" groups are the same.
struct FischerBurmeister {
  int m = 0;  // number of summed factors
  int num_inputs() const { return m + 2; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    using std::sqrt;
    T B(0.0);
    for (int i = 1; i <= m; ++i) B = B + w[i];
    const T& a = w[0];
    const T& sigma = w[m + 1];
    c[0] = a + B - sqrt(a * a + B * B + 2.0 * sigma);
  }
};

/// The objective term s (one input).
struct Identity {
  int num_inputs() const { return 1; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    c[0] = w[0];
  }
};

/// A group's products over local indices into its distinct variables (in order of appearance).
struct LocalGroup {
  std::vector<int> vars;
  nlp::ProductSum sum;  // hand-written derivatives: no input limit (nlp/sum_block.hpp)
};

LocalGroup localize(const CompGroup& g) {
  LocalGroup lg;
  auto local = [&](int global) {
    auto it = std::find(lg.vars.begin(), lg.vars.end(), global);
    if (it != lg.vars.end()) return static_cast<int>(it - lg.vars.begin());
    lg.vars.push_back(global);
    return static_cast<int>(lg.vars.size()) - 1;
  };
  for (const CompPair& p : g.pairs) {
    const int a = local(p.a);
    const int b = local(p.b);
    lg.sum.pairs.emplace_back(a, b);
  }
  lg.sum.k = static_cast<int>(lg.vars.size());
  return lg;
}

/// The row lb <= sum of products <= ub of a group.
int add_product_row(nlp::BlockNlp& nlp, const CompGroup& g, double lb, double ub) {
  LocalGroup lg = localize(g);
  return nlp.add_constraint(nlp::make_block(std::move(lg.sum)), std::move(lg.vars), lb, ub);
}

/// The Fischer-Burmeister row phi(a, B) = 0 of a group whose products share one factor.
int add_fischer_burmeister_row(nlp::BlockNlp& nlp, const CompGroup& g, int sigma_var) {
  const auto shares = [&](auto factor) {
    return std::all_of(g.pairs.begin(), g.pairs.end(),
                       [&](const CompPair& p) { return factor(p) == factor(g.pairs.front()); });
  };
  const bool common_a = shares([](const CompPair& p) { return p.a; });
  const bool common_b = shares([](const CompPair& p) { return p.b; });
  if (!common_a && !common_b)
    throw InvalidOption(fmt::format(
        "homotopy.mpcc_mode = fischer_burmeister: a complementarity constraint sums {} products "
        "without a common factor, which one smoothed C-function cannot express; it needs "
        "cross_comp_mode sparse or stage_sum (element and neighbor sum the products of different "
        "theta and lambda)",
        g.pairs.size()));
  std::vector<int> vars{common_a ? g.pairs.front().a : g.pairs.front().b};
  for (const CompPair& p : g.pairs) vars.push_back(common_a ? p.b : p.a);
  FischerBurmeister f;
  f.m = static_cast<int>(g.pairs.size());
  vars.push_back(sigma_var);
  return nlp.add_constraint(nlp::make_block(f), std::move(vars), 0.0, 0.0);
}

}  // namespace

std::vector<int> add_scholtes_rows(nlp::BlockNlp& nlp, const std::vector<CompGroup>& groups) {
  std::vector<int> rows;
  rows.reserve(groups.size());
  // Initial bounds for sigma = 1; set_sigma sets the homotopy's value.
  for (const CompGroup& g : groups)
    rows.push_back(add_product_row(nlp, g, g.two_sided ? -1.0 : -nlp::kInf, 1.0));
  return rows;
}

void set_sigma(nlp::BlockNlp& nlp, const std::vector<int>& rows, double sigma) {
  for (int r : rows) {
    nlp.g_ub[r] = sigma;
    if (nlp.g_lb[r] > -nlp::kInf) nlp.g_lb[r] = -sigma;  // two-sided group
  }
}

Relaxation::Relaxation(nlp::BlockNlp& nlp, const std::vector<CompGroup>& groups, MpccMode mode,
                       double s_max, double s_0, bool scaling_direct)
    : mode_(mode), group_rows_(groups.size(), -1) {
  if (mode == MpccMode::ScholtesIneq) {
    // Exactly the rows of add_scholtes_rows (results stay bit-identical to it), empty groups
    // included: their row 0 <= sigma is harmless.
    group_rows_ = add_scholtes_rows(nlp, groups);
    for (std::size_t k = 0; k < groups.size(); ++k)
      (groups[k].two_sided ? two_sided_rows_ : upper_rows_).push_back(group_rows_[k]);
    return;
  }
  // The extra variables exist whatever the groups are, so that two relaxations of the same
  // variables with different groups (the integrator's stage_sum NLP and its sparse fallback)
  // keep one layout.
  if (mode == MpccMode::FischerBurmeister)  // sigma enters the rows as a variable fixed by bounds
    sigma_var_ = nlp.add_variables(1, 1.0, 1.0, 1.0);  // IPOPT removes it (make_parameter)
  const bool elastic = is_elastic(mode);
  if (elastic) elastic_var_ = nlp.add_variables(1, 0.0, s_max, s_0);

  for (std::size_t k = 0; k < groups.size(); ++k) {
    const CompGroup& g = groups[k];
    if (g.pairs.empty()) continue;            // identically zero: = sigma would be infeasible
    if (mode == MpccMode::ElasticTwoSided) {  // G - s <= 0 and G + s >= 0, every group
      for (const bool upper : {true, false}) {
        LocalGroup lg = localize(g);
        lg.vars.push_back(elastic_var_);
        (upper ? lg.sum.minus_last : lg.sum.plus_last) = true;
        const int row = nlp.add_constraint(nlp::make_block(std::move(lg.sum)), std::move(lg.vars),
                                           upper ? -nlp::kInf : 0.0, upper ? 0.0 : nlp::kInf);
        if (upper) group_rows_[k] = row;
      }
      continue;
    }
    if (g.two_sided) {  // free-sign product: Scholtes in every mode (header)
      group_rows_[k] = add_product_row(nlp, g, -1.0, 1.0);
      two_sided_rows_.push_back(group_rows_[k]);
      continue;
    }
    switch (mode) {
      case MpccMode::ScholtesEq:
        group_rows_[k] = add_product_row(nlp, g, 1.0, 1.0);
        equal_rows_.push_back(group_rows_[k]);
        break;
      case MpccMode::FischerBurmeister:
        group_rows_[k] = add_fischer_burmeister_row(nlp, g, sigma_var_);
        break;
      case MpccMode::L1Penalty: {
        // One objective term per group.
        LocalGroup lg = localize(g);
        objectives_.push_back(
            nlp.add_objective(nlp::make_block(std::move(lg.sum)), std::move(lg.vars), 1.0));
        break;
      }
      case MpccMode::ElasticIneq: {
        LocalGroup lg = localize(g);
        lg.vars.push_back(elastic_var_);
        lg.sum.minus_last = true;  // sum of products - s <= 0
        group_rows_[k] = nlp.add_constraint(nlp::make_block(std::move(lg.sum)), std::move(lg.vars),
                                            -nlp::kInf, 0.0);
        break;
      }
      case MpccMode::ScholtesIneq:
      case MpccMode::ElasticTwoSided:
        break;  // handled above
    }
  }
  const int n_cost = nlp.num_objectives() - static_cast<int>(objectives_.size());
  if (elastic)
    objectives_.push_back(nlp.add_objective(nlp::make_block(Identity{}), {elastic_var_}, 1.0));
  inverse_ = !scaling_direct && !objectives_.empty();
  if (inverse_)
    for (int o = 0; o < n_cost; ++o) cost_terms_.emplace_back(o, nlp.objective_weight(o));
}

void Relaxation::set_sigma(nlp::BlockNlp& nlp, double sigma) const {
  for (int r : upper_rows_) nlp.g_ub[r] = sigma;
  for (int r : two_sided_rows_) {
    nlp.g_lb[r] = -sigma;
    nlp.g_ub[r] = sigma;
  }
  for (int r : equal_rows_) nlp.g_lb[r] = nlp.g_ub[r] = sigma;
  for (int o : objectives_) nlp.set_objective_weight(o, inverse_ ? 1.0 : 1.0 / sigma);
  for (const auto& [o, w] : cost_terms_) nlp.set_objective_weight(o, sigma * w);
  if (sigma_var_ >= 0) nlp.x_lb[sigma_var_] = nlp.x_ub[sigma_var_] = nlp.x_init[sigma_var_] = sigma;
}

}  // namespace fesd::mpcc
