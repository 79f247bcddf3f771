// src/nlp/block_nlp.hpp: an NLP assembled from blocks,
//
//   min  sum_o weight_o * f_o(x[vars_o])    s.t.  g_lb <= c_b(x[vars_b]) <= g_ub,  x_lb <= x <=
//   x_ub,
//
// with the sparsity of the constraint Jacobian and of the Hessian of the Lagrangian taken from the
// block structure (each block's own pattern mapped through its variable indices, duplicates
// merged). Knows nothing of models or FESD: variables are numbers, blocks are functions.
#pragma once
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "nlp/block.hpp"

namespace fesd::nlp {

inline constexpr double kInf = 1e20;  // IPOPT treats |bound| >= 1e19 as infinite

/// New bounds lb <= x[var] <= ub of one variable (e.g. a sliding exit pinned).
struct Bound {
  int var = -1;
  double lb = 0, ub = 0;
};

class BlockNlp {
 public:
  /// Adds n variables; returns the index of the first.
  int add_variables(int n, double lb, double ub, double init);
  /// Adds the constraint rows lb <= block(x[vars]) <= ub; returns the first row index.
  int add_constraint(std::shared_ptr<const Block> block, std::vector<int> vars,
                     std::vector<double> lb, std::vector<double> ub);
  /// Same with scalar bounds for every row.
  int add_constraint(std::shared_ptr<const Block> block, std::vector<int> vars, double lb,
                     double ub);
  /// Adds weight * block(x[vars]) (block with one output) to the objective; returns its index.
  int add_objective(std::shared_ptr<const Block> block, std::vector<int> vars, double weight = 1.0);

  /// Builds the sparsity structures. Call once after all blocks are added and the initial
  /// point is set (the patterns are probed there).
  void finalize();
  bool finalized() const { return finalized_; }

  int num_variables() const { return static_cast<int>(x_lb.size()); }
  int num_constraints() const { return static_cast<int>(g_lb.size()); }
  int jac_nnz() const { return static_cast<int>(jac_row_.size()); }
  int hess_nnz() const { return static_cast<int>(hess_row_.size()); }
  const std::vector<int>& jac_rows() const { return jac_row_; }
  const std::vector<int>& jac_cols() const { return jac_col_; }
  const std::vector<int>& hess_rows() const { return hess_row_; }
  const std::vector<int>& hess_cols() const { return hess_col_; }
  /// Tests: every block's Hessian passes replaced by the reference plan (plan_column_passes), the
  /// Hessian as computed before the planned passes. Call after finalize().
  void use_column_hessian_passes();
  void set_objective_weight(int objective, double w) { objectives_[objective].weight = w; }
  double objective_weight(int objective) const { return objectives_[objective].weight; }
  int num_objectives() const { return static_cast<int>(objectives_.size()); }

  // Evaluations; each returns false if a block produced a non-finite value.
  bool eval_f(const double* x, double& f) const;
  bool eval_grad_f(const double* x, double* grad) const;
  bool eval_g(const double* x, double* g) const;
  bool eval_jac_g(const double* x, double* values) const;
  bool eval_h(const double* x, double obj_factor, const double* lambda, double* values) const;

  // Bounds and initial point (public data: the owner edits them between solves).
  std::vector<double> x_lb, x_ub, x_init;
  std::vector<double> g_lb, g_ub;

 private:
  struct Instance {
    std::shared_ptr<const Block> block;
    std::vector<int> vars;
    int row0 = -1;        // first constraint row, -1 for an objective term
    double weight = 1.0;  // objective terms only
    const BlockPattern* pattern = nullptr;
    std::vector<int> jac_index;   // per (r, i) pattern entry: position in the Jacobian values
    std::vector<int> hess_index;  // per pattern pair: position in the Hessian values
  };
  void gather(const Instance& in, const double* x, double* w) const;
  bool add_hessian(const Instance& in, const double* x, double factor, const double* y,
                   double* values) const;

  std::vector<Instance> constraints_, objectives_;
  std::vector<std::unique_ptr<BlockPattern>> patterns_;
  std::vector<int> jac_row_, jac_col_, hess_row_, hess_col_;
  bool finalized_ = false;
  int max_k_ = 0, max_m_ = 0;
  std::size_t max_hess_ = 0;  // the most Hessian pattern entries of one block
};

}  // namespace fesd::nlp
