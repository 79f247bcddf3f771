#include "nlp/block_nlp.hpp"

#include <algorithm>
#include <cstdint>
#include <unordered_map>

namespace fesd::nlp {

int BlockNlp::add_variables(int n, double lb, double ub, double init) {
  const int first = num_variables();
  x_lb.insert(x_lb.end(), n, lb);
  x_ub.insert(x_ub.end(), n, ub);
  x_init.insert(x_init.end(), n, init);
  finalized_ = false;
  return first;
}

int BlockNlp::add_constraint(std::shared_ptr<const Block> block, std::vector<int> vars,
                             std::vector<double> lb, std::vector<double> ub) {
  const int first = num_constraints();
  const int m = block->num_outputs();
  if (static_cast<int>(vars.size()) != block->num_inputs() || static_cast<int>(lb.size()) != m ||
      static_cast<int>(ub.size()) != m)
    throw InternalError("internal: constraint block sizes do not match its variables or bounds");
  g_lb.insert(g_lb.end(), lb.begin(), lb.end());
  g_ub.insert(g_ub.end(), ub.begin(), ub.end());
  constraints_.push_back({std::move(block), std::move(vars), first, 1.0, nullptr, {}, {}});
  finalized_ = false;
  return first;
}

int BlockNlp::add_constraint(std::shared_ptr<const Block> block, std::vector<int> vars, double lb,
                             double ub) {
  const int m = block->num_outputs();
  return add_constraint(std::move(block), std::move(vars), std::vector<double>(m, lb),
                        std::vector<double>(m, ub));
}

int BlockNlp::add_objective(std::shared_ptr<const Block> block, std::vector<int> vars,
                            double weight) {
  if (block->num_outputs() != 1 || static_cast<int>(vars.size()) != block->num_inputs())
    throw InternalError("internal: objective block must have one output and match its variables");
  objectives_.push_back({std::move(block), std::move(vars), -1, weight, nullptr, {}, {}});
  finalized_ = false;
  return static_cast<int>(objectives_.size()) - 1;
}

void BlockNlp::gather(const Instance& in, const double* x, double* w) const {
  for (std::size_t i = 0; i < in.vars.size(); ++i) w[i] = x[in.vars[i]];
}

void BlockNlp::finalize() {
  patterns_.clear();
  jac_row_.clear();
  jac_col_.clear();
  hess_row_.clear();
  hess_col_.clear();
  max_k_ = max_m_ = 0;
  max_hess_ = 0;
  // One pattern per distinct block object: instances sharing a block share its structure.
  std::unordered_map<const Block*, const BlockPattern*> cache;
  std::vector<double> w;
  auto pattern_of = [&](Instance& in) {
    auto it = cache.find(in.block.get());
    if (it != cache.end()) return it->second;
    w.resize(in.vars.size());
    gather(in, x_init.data(), w.data());
    patterns_.push_back(std::make_unique<BlockPattern>(in.block->pattern(w.data())));
    cache.emplace(in.block.get(), patterns_.back().get());
    return static_cast<const BlockPattern*>(patterns_.back().get());
  };
  std::unordered_map<std::int64_t, int> hess_pos;
  auto add_hess = [&](Instance& in) {
    in.hess_index.clear();
    for (const auto& [i, j] : in.pattern->hess) {
      const int a = std::max(in.vars[i], in.vars[j]), b = std::min(in.vars[i], in.vars[j]);
      const std::int64_t key = static_cast<std::int64_t>(a) * (num_variables() + 1) + b;
      auto [it, fresh] = hess_pos.emplace(key, static_cast<int>(hess_row_.size()));
      if (fresh) {
        hess_row_.push_back(a);
        hess_col_.push_back(b);
      }
      in.hess_index.push_back(it->second);
    }
    max_hess_ = std::max(max_hess_, in.pattern->hess.size());
  };
  for (Instance& in : constraints_) {
    in.pattern = pattern_of(in);
    in.jac_index.clear();
    for (std::size_t r = 0; r < in.pattern->jac_rows.size(); ++r)
      for (int i : in.pattern->jac_rows[r]) {
        in.jac_index.push_back(static_cast<int>(jac_row_.size()));
        jac_row_.push_back(in.row0 + static_cast<int>(r));
        jac_col_.push_back(in.vars[i]);
      }
    add_hess(in);
    max_k_ = std::max(max_k_, in.block->num_inputs());
    max_m_ = std::max(max_m_, in.block->num_outputs());
  }
  for (Instance& in : objectives_) {
    in.pattern = pattern_of(in);
    add_hess(in);
    max_k_ = std::max(max_k_, in.block->num_inputs());
  }
  finalized_ = true;
}

void BlockNlp::use_column_hessian_passes() {
  std::unordered_map<const BlockPattern*, int> inputs;
  for (const auto* list : {&constraints_, &objectives_})
    for (const Instance& in : *list) inputs[in.pattern] = in.block->num_inputs();
  for (auto& p : patterns_)  // hand-written blocks (no passes) compute their Hessian directly
    if (!p->passes.empty()) plan_column_passes(*p, inputs.at(p.get()));
}

bool BlockNlp::eval_f(const double* x, double& f) const {
  f = 0.0;
  std::vector<double>& w = scratch<double>(max_k_, 0);
  double c = 0.0;
  for (const Instance& in : objectives_) {
    gather(in, x, w.data());
    if (!in.block->eval(w.data(), &c)) return false;
    f += in.weight * c;
  }
  return true;
}

bool BlockNlp::eval_grad_f(const double* x, double* grad) const {
  std::fill_n(grad, num_variables(), 0.0);
  std::vector<double>& w = scratch<double>(max_k_, 0);
  std::vector<double>& J = scratch<double>(max_k_, 1);
  double c = 0.0;
  for (const Instance& in : objectives_) {
    gather(in, x, w.data());
    if (!in.block->jacobian(w.data(), &c, J.data())) return false;
    for (int i : in.pattern->jac_rows[0]) grad[in.vars[i]] += in.weight * J[i];
  }
  return true;
}

bool BlockNlp::eval_g(const double* x, double* g) const {
  std::vector<double>& w = scratch<double>(max_k_, 0);
  for (const Instance& in : constraints_) {
    gather(in, x, w.data());
    if (!in.block->eval(w.data(), g + in.row0)) return false;
  }
  return true;
}

bool BlockNlp::eval_jac_g(const double* x, double* values) const {
  std::vector<double>& w = scratch<double>(max_k_, 0);
  std::vector<double>& J = scratch<double>(static_cast<std::size_t>(max_k_) * max_m_, 1);
  std::vector<double>& c = scratch<double>(max_m_, 2);
  for (const Instance& in : constraints_) {
    const int k = in.block->num_inputs();
    gather(in, x, w.data());
    if (!in.block->jacobian(w.data(), c.data(), J.data())) return false;
    std::size_t e = 0;
    for (std::size_t r = 0; r < in.pattern->jac_rows.size(); ++r)
      for (int i : in.pattern->jac_rows[r]) values[in.jac_index[e++]] = J[r * k + i];
  }
  return true;
}

bool BlockNlp::add_hessian(const Instance& in, const double* x, double factor, const double* y,
                           double* values) const {
  if (in.pattern->hess.empty()) return true;
  const int m = in.block->num_outputs();
  std::vector<double>& w = scratch<double>(max_k_, 0);
  std::vector<double>& h = scratch<double>(max_hess_, 1);
  std::vector<double>& ys = scratch<double>(std::max(max_m_, 1), 2);
  bool any = false;
  for (int r = 0; r < m; ++r) {
    ys[r] = factor * y[r];
    any = any || ys[r] != 0.0;
  }
  if (!any) return true;
  gather(in, x, w.data());
  if (!in.block->hessian(w.data(), ys.data(), *in.pattern, h.data())) return false;
  for (std::size_t e = 0; e < in.pattern->hess.size(); ++e) values[in.hess_index[e]] += h[e];
  return true;
}

bool BlockNlp::eval_h(const double* x, double obj_factor, const double* lambda,
                      double* values) const {
  std::fill_n(values, hess_nnz(), 0.0);
  for (const Instance& in : objectives_) {
    const double y = in.weight;
    if (!add_hessian(in, x, obj_factor, &y, values)) return false;
  }
  for (const Instance& in : constraints_)
    if (!add_hessian(in, x, 1.0, lambda + in.row0, values)) return false;
  return true;
}

}  // namespace fesd::nlp
