// fuzz/oracles.hpp: what the fuzz targets (fuzz/*.cpp) and their regression test
// (tests/bad_input/fuzz_regression_test.cpp) demand of any input text. Each returns "" when the
// input is handled cleanly, else a description of the finding. Crashes, sanitizer reports and
// timeouts are findings too (libFuzzer sees them itself). docs/fuzzing.md.
//
// Problem files: loading either succeeds or throws a fesd::Error (bad input, exit code 2); a
// simulation file that loads also builds: the NLP of one step is assembled and evaluated once as
// integrate() does, without IPOPT ("check says valid, simulate fails" is a finding).
// Expressions: parsing succeeds or throws fesd::ExpressionError with a short message; a parsed
// expression evaluates with every scalar type, the Jet value equals the double value, the
// second-order value agrees within rounding and the pattern reads only declared dependencies.
#pragma once
#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <string_view>
#include <vector>

#include "discretization/fesd_interval.hpp"
#include "fesd/ad.hpp"
#include "fesd/error.hpp"
#include "fesd/problem_file.hpp"
#include "model/expression.hpp"
#include "mpcc/relaxation.hpp"
#include "nlp/block_nlp.hpp"

namespace fesd::fuzz {

/// Longest error message accepted (messages quote at most 60 characters of an expression).
inline constexpr std::size_t kMaxMessage = 4000;
/// Larger step NLPs are valid input but too slow to build for every fuzz input.
inline constexpr double kMaxBuildSize = 2e5;

namespace detail {

inline std::vector<int> fixed_vars(nlp::BlockNlp& nlp, const Eigen::VectorXd& v) {
  std::vector<int> out;
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(nlp.add_variables(1, v[i], v[i], v[i]));
  return out;
}

inline std::vector<int> free_vars(nlp::BlockNlp& nlp, int n, double lb) {
  std::vector<int> out;
  const int first = nlp.add_variables(n, lb, nlp::kInf, 0.0);
  for (int i = 0; i < n; ++i) out.push_back(first + i);
  return out;
}

/// Builds and evaluates the NLP of one integration step of `q` (as integrate() does).
inline void build_step(const SimulationProblem& q) {
  const DiscretizationOptions& o = q.options.discretization;
  const Pss& m = q.model;
  const double size = static_cast<double>(o.N_FE) * o.n_s * (3.0 * m.n_x() + 3.0 * m.n_theta());
  if (size > kMaxBuildSize) return;
  nlp::BlockNlp nlp;
  discretization::IntervalInputs in;
  in.s0 = fixed_vars(nlp, q.x0);
  in.q = fixed_vars(nlp, q.u);
  in.p = fixed_vars(nlp, q.p);
  in.lambda_start = free_vars(nlp, m.n_theta(), 0.0);
  in.mu_start = free_vars(nlp, m.n_sys(), -nlp::kInf);
  in.lp_at_start = o.use_fesd;
  in.T = q.T_sim / std::max(q.N_sim, 1);  // N_sim = 0: chosen by simulate(), at least one step
  in.boundary_at_end = true;
  discretization::FesdInterval iv(m, make_tableau(o.rk_scheme, o.n_s), o);
  iv.build(nlp, in);
  const mpcc::Relaxation relaxation(nlp, iv.groups(), q.options.homotopy.mpcc_mode);
  nlp.finalize();
  std::vector<double> g(static_cast<std::size_t>(nlp.num_constraints()));
  std::vector<double> jac(static_cast<std::size_t>(nlp.jac_nnz()));
  std::vector<double> hess(static_cast<std::size_t>(nlp.hess_nnz()));
  std::vector<double> grad(nlp.x_init.size());
  const std::vector<double> y(g.size(), 1.0);
  double f = 0;
  (void)nlp.eval_f(nlp.x_init.data(), f);
  (void)nlp.eval_grad_f(nlp.x_init.data(), grad.data());
  (void)nlp.eval_g(nlp.x_init.data(), g.data());
  (void)nlp.eval_jac_g(nlp.x_init.data(), jac.data());
  (void)nlp.eval_h(nlp.x_init.data(), 1.0, y.data(), hess.data());
}

inline std::string too_long(const std::exception& e) {
  const std::string_view m = e.what();
  return m.size() > kMaxMessage ? "message of " + std::to_string(m.size()) +
                                      " characters: " + std::string(m.substr(0, 200)) + "..."
                                : std::string{};
}

}  // namespace detail

inline std::string problem_file_finding(std::string_view text) {
  std::string finding;
  try {
    const SimulationProblem q = parse_simulation_problem(text, "fuzz.toml");
    try {
      detail::build_step(q);
    } catch (const InvalidOption& e) {
      return std::string("loads, but the step NLP does not build: ") + e.what();
    }
  } catch (const Error& e) {
    finding = detail::too_long(e);
  } catch (const std::exception& e) {
    return std::string("simulation file: not a fesd::Error: ") + e.what();
  }
  if (!finding.empty()) return finding;
  try {
    (void)parse_ocp_problem(text, "fuzz.toml");
  } catch (const Error& e) {
    finding = detail::too_long(e);
  } catch (const std::exception& e) {
    return std::string("ocp file: not a fesd::Error: ") + e.what();
  }
  return finding;
}

inline std::string expression_finding(std::string_view text) {
  static const std::vector<std::string> names{"x", "y", "z", "t", "p"};
  constexpr int n = 5;
  expr::Expression e;
  try {
    e = expr::Expression::parse(text, names, "fuzz");
  } catch (const ExpressionError& err) {
    return detail::too_long(err);
  } catch (const std::exception& err) {
    return std::string("not an ExpressionError: ") + err.what();
  }
  using Jet = ad::Jet<8>;
  using Hyper = ad::Hyper<8>;
  const double points[2][n] = {{0.5, -1.25, 2.0, 0.0, 3.0}, {0.0, -0.0, 1.0, -1.0, 1e-300}};
  for (const auto& point : points) {
    const double v = e.evaluate(point);
    Jet jet_in[n];
    Hyper hyper_in[n];
    ad::Pattern pattern_in[n];
    for (int i = 0; i < n; ++i) {
      jet_in[i] = Jet::variable(point[i], i, n);
      hyper_in[i] = Hyper(Jet::variable(point[i], i, n), Jet(i == 0 ? 1.0 : 0.0));
      pattern_in[i] = ad::Pattern::variable(point[i], i);
    }
    const double jv = e.evaluate(jet_in).v;
    if (!(jv == v || (std::isnan(jv) && std::isnan(v))))
      return "Jet value " + std::to_string(jv) + " differs from the double value " +
             std::to_string(v);
    const double hv = e.evaluate(hyper_in).v.v;
    if (std::isfinite(hv) && std::isfinite(v) &&
        std::abs(hv - v) > 1e-9 * std::max(1.0, std::abs(v)))
      return "second-order value " + std::to_string(hv) + " differs from the double value " +
             std::to_string(v);
    for (int i : e.evaluate(pattern_in).dep)
      if (!e.depends_on(i)) return "the pattern reads input " + std::to_string(i) + ", undeclared";
  }
  return {};
}

}  // namespace fesd::fuzz
