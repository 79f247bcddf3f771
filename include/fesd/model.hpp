// include/fesd/model.hpp: piecewise smooth systems (PSS) in Stewart's form, Sect. 2 of
// papers/fesd-filippov.txt.
//
//   x' = f_i(x, u, p)  if x in R_i,   R_i = { x : g_i(x) < min_{j != i} g_j(x) }        (1), (4)
//
// The regions of a subsystem are given either by switching functions c(x) in R^{n_c} and a sign
// matrix S (rows = regions, entries +-1, R_i = { diag(S_i) c(x) > 0 }, g(x) = -S c(x), eq. 12-13),
// or directly by indicator functions g(x). Several independent subsystems form a Cartesian product
// (eq. 20-21): x' = sum_k F^k(x, u, p) theta^k, one convex combination theta^k per subsystem.
//
// User functions are templates on the scalar type (see ad.hpp) so that fesd can differentiate
// them exactly. A C++ model is a struct with these members (only those its subsystems need):
//
//   template <class T> void c(const T* x, const T* p, T* c) const;   // all c-form subsystems' c,
//   concatenated template <class T> void g(const T* x, const T* p, T* g) const;   // all g-form
//   subsystems' g, concatenated template <class T> void f(int region, const T* x, const T* u, const
//   T* p, T* f_out) const;
//
// `region` counts regions over all subsystems in order (subsystem 0's regions first). Example
// (x' in 2 - sign(x), Example 3(a)):
//
//   struct TwoSided {
//     template <class T> void c(const T* x, const T*, T* c) const { c[0] = x[0]; }
//     template <class T> void f(int r, const T*, const T*, const T*, T* f) const { f[0] = T(r == 0
//     ? 1.0 : 3.0); }
//   };
//   fesd::Pss model = fesd::make_pss(TwoSided{}, fesd::PssDims{.n_x = 1, .subsystems =
//   {fesd::Subsystem::from_c(1)}});
//
// With the default sign matrix for n_c = 1, S = [[1], [-1]]: region 0 is c > 0, region 1 is c < 0.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "fesd/ad.hpp"

namespace fesd {

/// One independent subsystem k of (20)-(21).
struct Subsystem {
  /// Number of switching functions c^k (c-form), 0 for a g-form subsystem.
  int n_c = 0;
  /// Sign matrix S^k (n_f^k x n_c^k, entries +-1, no repeated rows). Empty: all 2^{n_c} rows in the
  /// paper's order, first row all +1, last row all -1 (Sect. 2.2.1).
  Eigen::MatrixXd S;
  /// Number of indicator functions g^k given directly (g-form), 0 for a c-form subsystem.
  int n_g = 0;

  static Subsystem from_c(int n_c, Eigen::MatrixXd S = {}) { return {n_c, std::move(S), 0}; }
  static Subsystem from_g(int n_g) { return {0, {}, n_g}; }
  /// n_f^k: number of regions.
  int n_f() const;
};

/// Sizes and structure of a PSS.
struct PssDims {
  int n_x = 0;
  int n_u = 0;
  int n_p = 0;
  std::vector<Subsystem> subsystems;
};

/// Type-erased user functions, one virtual per scalar type (implemented by make_pss and by
/// problem files). Library users never derive from it directly.
class PssFunctions {
 public:
  virtual ~PssFunctions() = default;
#define FESD_DECLARE_PSS_FUNCTIONS(T)                         \
  virtual void c(const T* x, const T* p, T* c_out) const = 0; \
  virtual void g(const T* x, const T* p, T* g_out) const = 0; \
  virtual void f(int region, const T* x, const T* u, const T* p, T* f_out) const = 0;
  FESD_FOR_EACH_SCALAR(FESD_DECLARE_PSS_FUNCTIONS)
#undef FESD_DECLARE_PSS_FUNCTIONS
  /// Algebraic variables z (problem files' z, g_z; 0 for C++ models, which compute what they need
  /// inside c, g and f): the number of them and their values z(x, u, p) (u may be null: zeros).
  virtual int n_z() const {
    return 0;
  }
  virtual void algebraic(const double* /*x*/, const double* /*u*/, const double* /*p*/,
                         double* /*z*/) const {}
  /// A general inclusion in the Heaviside step form (problem files' f_alpha): x' = f_alpha(x,
  /// alpha, u, p), one alpha per switching function (all subsystems' c, concatenated). Only in
  /// discretization.dcs_mode = step; f(r, ...) is then f_alpha at region r's 0/1 alpha vertex.
  virtual bool has_f_alpha() const {
    return false;
  }
#define FESD_DECLARE_F_ALPHA(T)                                                            \
  virtual void f_alpha(const T* /*x*/, const T* /*alpha*/, const T* /*u*/, const T* /*p*/, \
                       T* /*f_out*/) const {}
  FESD_FOR_EACH_SCALAR(FESD_DECLARE_F_ALPHA)
#undef FESD_DECLARE_F_ALPHA
};

/// A piecewise smooth system in Stewart form. Cheap to copy (shares its functions).
class Pss {
 public:
  Pss() = default;
  /// Validates the structure; throws fesd::InvalidModel naming the problem.
  Pss(PssDims dims, std::shared_ptr<const PssFunctions> functions);

  const PssDims& dims() const { return dims_; }
  int n_x() const { return dims_.n_x; }
  int n_u() const { return dims_.n_u; }
  int n_p() const { return dims_.n_p; }
  int n_sys() const { return static_cast<int>(dims_.subsystems.size()); }
  /// Total number of regions over all subsystems (length of theta and lambda).
  int n_theta() const { return n_theta_; }
  int n_c() const { return n_c_; }  // switching functions over all subsystems
  int n_g() const { return n_g_; }  // direct indicator functions over all subsystems
  /// Algebraic variables z (PssFunctions::n_z; results report z at the stage points).
  int n_z() const { return functions_ ? functions_->n_z() : 0; }
  /// Whether the dynamics are a general inclusion f_alpha(x, alpha, u, p) (PssFunctions).
  bool has_f_alpha() const { return functions_ && functions_->has_f_alpha(); }
  /// First region index of subsystem k; regions of k are [region_offset(k), region_offset(k+1)).
  int region_offset(int k) const { return region_offset_[k]; }
  /// The sign matrix of subsystem k (filled in if it was given empty). Empty for g-form.
  const Eigen::MatrixXd& S(int k) const { return S_[k]; }
  const PssFunctions& functions() const { return *functions_; }

  /// Optional names (for messages, results and plots); defaults x1.., u1.., p1...
  std::vector<std::string> state_names, control_names, parameter_names, algebraic_names;
  /// Parameter values used when the caller passes none.
  Eigen::VectorXd p_default;

 private:
  PssDims dims_;
  std::shared_ptr<const PssFunctions> functions_;
  std::vector<Eigen::MatrixXd> S_;
  std::vector<int> region_offset_;
  int n_theta_ = 0, n_c_ = 0, n_g_ = 0;
};

/// The default sign matrix of Sect. 2.2.1: all 2^n_c sign patterns, first row +1 ... +1, last
/// row -1 ... -1, last column alternating fastest.
Eigen::MatrixXd all_sign_rows(int n_c);

namespace detail {
template <class Model>
class PssFunctionsFor final : public PssFunctions {
 public:
  explicit PssFunctionsFor(Model m) : m_(std::move(m)) {}
#define FESD_IMPLEMENT_PSS_FUNCTIONS(T)                                                       \
  void c(const T* x, const T* p, T* c_out) const override {                                   \
    if constexpr (requires { m_.c(x, p, c_out); }) m_.c(x, p, c_out);                         \
  }                                                                                           \
  void g(const T* x, const T* p, T* g_out) const override {                                   \
    if constexpr (requires { m_.g(x, p, g_out); }) m_.g(x, p, g_out);                         \
  }                                                                                           \
  void f(int region, const T* x, const T* u, const T* p, T* f_out) const override {           \
    m_.f(region, x, u, p, f_out);                                                             \
  }                                                                                           \
  void f_alpha(const T* x, const T* alpha, const T* u, const T* p, T* f_out) const override { \
    if constexpr (requires { m_.f_alpha(x, alpha, u, p, f_out); })                            \
      m_.f_alpha(x, alpha, u, p, f_out);                                                      \
  }
  FESD_FOR_EACH_SCALAR(FESD_IMPLEMENT_PSS_FUNCTIONS)
#undef FESD_IMPLEMENT_PSS_FUNCTIONS
  bool has_f_alpha() const override {
    return requires(const Model& m, const double* v, double* o) {
      m.f_alpha(v, v, v, v, o);
    };
  }

 private:
  Model m_;
};
}  // namespace detail

/// Wraps a C++ model (see the top of this file) into a Pss.
template <class Model>
Pss make_pss(Model model, PssDims dims) {
  return Pss(std::move(dims), std::make_shared<detail::PssFunctionsFor<Model>>(std::move(model)));
}

}  // namespace fesd
