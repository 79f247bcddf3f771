#include "mpcc/homotopy.hpp"

#include <algorithm>
#include <cmath>

namespace fesd::mpcc {
namespace {

/// sum_p w[a_p] * w[b_p] over local indices.
struct ProductSum {
  std::vector<std::pair<int, int>> pairs;
  int k = 0;
  int num_inputs() const { return k; }
  int num_outputs() const { return 1; }
  template <class T>
  void operator()(const T* w, T* c) const {
    T s(0.0);
    for (const auto& [a, b] : pairs) s = s + w[a] * w[b];
    c[0] = s;
  }
};

}  // namespace

double comp_residual(const double* x, const std::vector<CompPair>& pairs) {
  double r = 0.0;
  for (const CompPair& p : pairs) r = std::max(r, std::abs(x[p.a] * x[p.b]));
  return r;
}

std::vector<int> add_scholtes_rows(nlp::BlockNlp& nlp, const std::vector<CompGroup>& groups) {
  std::vector<int> rows;
  rows.reserve(groups.size());
  for (const CompGroup& g : groups) {
    std::vector<int> vars;
    ProductSum f;
    auto local = [&](int global) {
      auto it = std::find(vars.begin(), vars.end(), global);
      if (it != vars.end()) return static_cast<int>(it - vars.begin());
      vars.push_back(global);
      return static_cast<int>(vars.size()) - 1;
    };
    for (const CompPair& p : g.pairs) {
      const int a = local(p.a);
      const int b = local(p.b);
      f.pairs.emplace_back(a, b);
    }
    f.k = static_cast<int>(vars.size());
    rows.push_back(
        nlp.add_constraint(nlp::make_block(f), vars, g.two_sided ? -1.0 : -nlp::kInf, 1.0));
  }
  return rows;
}

void set_sigma(nlp::BlockNlp& nlp, const std::vector<int>& rows, double sigma) {
  for (int r : rows) {
    nlp.g_ub[r] = sigma;
    if (nlp.g_lb[r] > -nlp::kInf) nlp.g_lb[r] = -sigma;  // two-sided group
  }
}

HomotopyResult solve_homotopy(nlp::BlockNlp& nlp, const std::vector<int>& comp_rows,
                              const std::vector<CompPair>& residual_pairs, nlp::NlpSolver& solver,
                              nlp::Iterate& it, const HomotopyOptions& o) {
  HomotopyResult res;
  double sigma = o.sigma_0;
  bool last_ok = false, eval_failed = false;
  int max_steps = o.max_homotopy_steps;
  if (max_steps == 0)  // automatic: until sigma reaches sigma_N
    max_steps =
        1 + static_cast<int>(std::ceil(
                std::log(o.sigma_N / o.sigma_0) / std::log(o.homotopy_update_slope) - 1e-9));
  for (int k = 0; k < max_steps; ++k) {
    set_sigma(nlp, comp_rows, sigma);
    const nlp::NlpResult r = solver.solve(nlp, it, /*warm_start=*/k > 0);
    res.comp_residual = comp_residual(it.x.data(), residual_pairs);
    res.rows.push_back({k, sigma, res.comp_residual, r.objective, r.inf_pr, r.iterations, r.status,
                        r.total_s, r.linear_solver});
    res.eval_s += r.eval_s;
    res.solver_s += r.total_s - r.eval_s;
    res.nlp_iterations += r.iterations;
    res.last_nlp_status = r.status;
    last_ok = r.success;
    eval_failed = r.eval_error;
    if (last_ok && res.comp_residual <= o.complementarity_tol) break;
    if (sigma <= o.sigma_N) break;  // sigma cannot get smaller: another NLP would repeat this one
    sigma = std::max(o.homotopy_update_slope * sigma, o.sigma_N);
  }
  if (last_ok && res.comp_residual <= o.complementarity_tol)
    res.status = Status::Success;
  else if (!last_ok)
    res.status = eval_failed ? Status::EvaluationFailed : Status::NlpFailed;
  else
    res.status = Status::ComplementarityNotMet;
  return res;
}

}  // namespace fesd::mpcc
