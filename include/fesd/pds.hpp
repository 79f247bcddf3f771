// include/fesd/pds.hpp: projected dynamical systems (PDS), papers/fesd-pds.txt (docs/pds.md).
//
//   x' = P_{T_C(x)}(f(x, u, p)),   C = { x : c(x) >= 0 },  c: R^n_x -> R^n_c,
//
// written as the dynamic complementarity system (3) of the paper:
//
//   x' = f(x, u, p) + grad c(x) lambda,   0 <= c(x)  perp  lambda >= 0.
//
// User functions are templates on the scalar type (see ad.hpp), as for a Pss. A C++ model is a
// struct with
//
//   template <class T> void c(const T* x, const T* p, T* c_out) const;            // n_c values
//   template <class T> void f(const T* x, const T* u, const T* p, T* f_out) const; // n_x values
//
// grad c(x) lambda is computed from c by forward-mode AD (one pass of c per state component), so
// c must be a template that works with any of fesd's scalar types (arithmetic and the math
// functions of ad.hpp). Example 1 of the paper (the unit circle flow kept above x2 = -1):
//
//   struct Example1 {
//     template <class T> void c(const T* x, const T*, T* c) const { c[0] = x[1] + 1.0; }
//     template <class T> void f(const T* x, const T*, const T*, T* f) const {
//       f[0] = x[1];
//       f[1] = -x[0];
//     }
//   };
//   fesd::Pds model = fesd::make_pds(Example1{}, fesd::PdsDims{.n_x = 2, .n_c = 1});
//   fesd::IntegratorResult r = fesd::integrate(model, x0, T, 1, options);
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "fesd/ad.hpp"
#include "fesd/integrator.hpp"
#include "fesd/options.hpp"

namespace fesd {

/// Sizes of a PDS.
struct PdsDims {
  int n_x = 0;
  int n_u = 0;
  int n_p = 0;
  /// Number of constraint functions c (C = { x : c(x) >= 0 }), >= 1.
  int n_c = 0;
};

/// Type-erased user functions of a PDS, one virtual per scalar type (implemented by make_pds).
/// grad_c_lambda(x, p, lambda) = grad c(x) lambda = sum_k lambda_k grad c_k(x) (n_x values).
class PdsFunctions {
 public:
  virtual ~PdsFunctions() = default;
#define FESD_DECLARE_PDS_FUNCTIONS(T)                                     \
  virtual void c(const T* x, const T* p, T* c_out) const = 0;             \
  virtual void f(const T* x, const T* u, const T* p, T* f_out) const = 0; \
  virtual void grad_c_lambda(const T* x, const T* p, const T* lambda, T* out) const = 0;
  FESD_FOR_EACH_SCALAR(FESD_DECLARE_PDS_FUNCTIONS)
#undef FESD_DECLARE_PDS_FUNCTIONS
};

/// A projected dynamical system in the DCS form (3). Cheap to copy (shares its functions).
class Pds {
 public:
  Pds() = default;
  /// Validates the sizes; throws fesd::InvalidModel naming the problem.
  Pds(PdsDims dims, std::shared_ptr<const PdsFunctions> functions);

  const PdsDims& dims() const { return dims_; }
  int n_x() const { return dims_.n_x; }
  int n_u() const { return dims_.n_u; }
  int n_p() const { return dims_.n_p; }
  int n_c() const { return dims_.n_c; }
  const PdsFunctions& functions() const { return *functions_; }

  /// Optional names (for messages and results); defaults x1.., u1.., p1...
  std::vector<std::string> state_names, control_names, parameter_names;
  /// Parameter values used when the caller passes none.
  Eigen::VectorXd p_default;
  /// An initial state with min_k c_k(x0) < -x0_tol is rejected (outside C).
  double x0_tol = 1e-9;

 private:
  PdsDims dims_;
  std::shared_ptr<const PdsFunctions> functions_;
};

namespace detail {
template <class Model>
class PdsFunctionsFor final : public PdsFunctions {
 public:
  PdsFunctionsFor(Model m, PdsDims dims) : m_(std::move(m)), dims_(dims) {}
#define FESD_IMPLEMENT_PDS_FUNCTIONS(T)                                                \
  void c(const T* x, const T* p, T* c_out) const override {                            \
    m_.c(x, p, c_out);                                                                 \
  }                                                                                    \
  void f(const T* x, const T* u, const T* p, T* f_out) const override {                \
    m_.f(x, u, p, f_out);                                                              \
  }                                                                                    \
  void grad_c_lambda(const T* x, const T* p, const T* lambda, T* out) const override { \
    grad_c_lambda_impl<T>(x, p, lambda, out);                                          \
  }
  FESD_FOR_EACH_SCALAR(FESD_IMPLEMENT_PDS_FUNCTIONS)
#undef FESD_IMPLEMENT_PDS_FUNCTIONS
 private:
  /// One forward pass of c over Dual<T> per state component i: out_i = sum_k lambda_k dc_k/dx_i
  /// (p carries a zero direction).
  template <class T>
  void grad_c_lambda_impl(const T* x, const T* p, const T* lambda, T* out) const {
    using D = ad::Dual<T>;
    std::vector<D> xd(static_cast<std::size_t>(dims_.n_x)), cd(static_cast<std::size_t>(dims_.n_c));
    std::vector<D> pd(static_cast<std::size_t>(dims_.n_p));
    for (int i = 0; i < dims_.n_x; ++i) xd[i] = D(x[i], T(0.0));
    for (int j = 0; j < dims_.n_p; ++j) pd[j] = D(p[j], T(0.0));
    for (int i = 0; i < dims_.n_x; ++i) {
      xd[i].d = T(1.0);
      m_.c(xd.data(), pd.data(), cd.data());
      xd[i].d = T(0.0);
      T s(0.0);
      for (int k = 0; k < dims_.n_c; ++k) s = s + lambda[k] * cd[k].d;
      out[i] = s;
    }
  }
  Model m_;
  PdsDims dims_;
};
}  // namespace detail

/// Wraps a C++ model (see the top of this file) into a Pds.
template <class Model>
Pds make_pds(Model model, PdsDims dims) {
  auto fn = std::make_shared<detail::PdsFunctionsFor<Model>>(std::move(model), dims);
  return Pds(dims, std::move(fn));
}

/// Options of the PDS discretization that the Stewart DCS has not.
struct PdsOptions {
  /// M > 0 of the step equilibration -nu_n M <= h_{n-1} - h_n <= nu_n M (Sect. III-C; the paper
  /// asks M >> 1 and gives no value). nu_n = min(pi_c, pi_lambda) of the sums (10) is small at a
  /// leaving point close to an element end: c grows quadratically after leaving, so sigma_c^F of
  /// a short element is O(h^2) (Example 1, N_sim = 100 steps of 2 elements: nu = 4e-6 where h
  /// had to change by 0.04, M = 1e3 failed). Where nothing switches, nu_n = 0 exactly after the
  /// fixed-active-set re-solve, whatever M; during the homotopy the h_penalty term keeps h from
  /// drifting. Default 1e6 (docs/pds.md).
  double M = 1e6;
  /// FESD: add rho_h / N_FE sum_n ((h_n - h0) / h0)^2 to the objective (h0 = T / N_FE). The
  /// paper's integrator NLP has no objective; without one, the relaxed NLPs of the homotopy
  /// (where nu_n > 0 at every boundary) leave h free and IPOPT drifts to solutions with collapsed
  /// elements. The term only chooses among the relaxed solutions: where the step equilibration
  /// and cross complementarity determine h (sigma -> 0), it does not move the solution.
  bool h_penalty = true;
};

/// Simulates the PDS from x0 over [0, T_sim] with N_sim steps of N_FE finite elements each: the
/// standard RK discretization (6) (use_fesd = false) or FESD with cross complementarity (8) and
/// the step equilibration of Sect. III-C (docs/pds.md). Schemes with c_{n_s} = 1 only: Radau IIA
/// (FESD with every n_s; n_s = 1 with extended backward sums) and Lobatto IIIC (n_s >= 2; with
/// FESD its first stage, no trajectory point, has c without sign condition, docs/pds.md). Every
/// step is solved by the MPCC homotopy (step_solver is not used: the active-set path is specific to
/// Stewart's DCS). Result: lambda holds the PDS multipliers (n_c per stage), theta and mu stay
/// empty, active_set lists the active constraints of each element (sum over its stages of lambda_k
/// > sum of c_k), switches are contact and leaving events. Bad input (sizes, NaN, x0 outside C,
/// options, schemes) throws fesd::Error.
IntegratorResult integrate(const Pds& model, const Eigen::VectorXd& x0, double T_sim, int N_sim,
                           const IntegratorOptions& options = {}, const Eigen::VectorXd& u = {},
                           const Eigen::VectorXd& p = {}, const PdsOptions& pds = {});

/// simulate() (integrator.hpp) of a PDS: the step count chosen by AccuracyOptions (tol_sim, or
/// N_sim with two companion runs) and the error estimate of the result from step doubling at the
/// scheme's order, exactly as for piecewise smooth models (docs/problem-files.md, "Accuracy";
/// docs/pds.md, "Accuracy"). Bad input throws fesd::Error as integrate() does.
IntegratorResult simulate(const Pds& model, const Eigen::VectorXd& x0, double T_sim,
                          const AccuracyOptions& accuracy, const IntegratorOptions& options = {},
                          const Eigen::VectorXd& u = {}, const Eigen::VectorXd& p = {},
                          const PdsOptions& pds = {});

}  // namespace fesd
