// src/model/expression_model.hpp: a PSS whose switching functions c, indicator functions g and
// region vector fields f_i are parsed math expressions (problem files, docs/problem-files.md).
//
// Every expression reads one input vector, the symbols in this order:
//
//   [ x_0 .. x_{n_x_slots-1},  u_0 .. u_{n_u-1},  p_0 .. p_{n_p-1},  z_0 .. z_{n_z-1},
//     alpha_0 .. alpha_{n_alpha-1} ]
//
// alpha (only for a model given by f_alpha, the Heaviside step form's general inclusion) holds
// the step form's alpha in f_alpha and the region's 0/1 vertex in f(region); zeros elsewhere.
//
// z are the user's algebraic variables (model/algebraic.hpp): their slots are filled with the
// solution of g_z = 0 at (x, u, p) before each evaluation. c and g get no u: if they read z, the
// reader makes sure that g_z reads no control.
//
// n_x_slots is n_x or n_x + 1: the problem-file reader always offers the time `t` as the symbol
// after the states; if no expression reads it, the model has no clock state and that slot holds 0.
// If one does, a clock state t' = 1 is part of x and the slot is the clock (n_x_slots = n_x).
//
// The regions of all subsystems are numbered in order (subsystem 0's regions first), as for every
// fesd::Pss: c (resp. g) of all c-form (g-form) subsystems are concatenated, eq. (13) and (21).
#pragma once
#include <memory>
#include <vector>

#include "fesd/model.hpp"
#include "model/algebraic.hpp"
#include "model/expression.hpp"

namespace fesd {

/// The expressions of one subsystem k of (20)-(21): either c^k (c-form, the sign matrix lives in
/// fesd::Subsystem) or g^k (g-form), and one vector field f_i^k per region, n_x expressions each.
struct ExpressionSubsystem {
  std::vector<expr::Expression> c;               ///< switching functions c^k(x, p), may be empty
  std::vector<expr::Expression> g;               ///< indicator functions g^k(x, p), may be empty
  std::vector<std::vector<expr::Expression>> F;  ///< F[i][j] = component j of f_i^k(x, u, p)
  /// Or (one c-form subsystem only, F empty): the general inclusion f_alpha(x, alpha, u, p), n_x
  /// expressions reading alpha in the layout's alpha slots; F[i] is then f_alpha at the 0/1 vertex
  /// of region i (alpha_j = 1 where S_ij = +1, else 0).
  std::vector<expr::Expression> f_alpha;
};

/// Sizes of the symbol vector the expressions were parsed with.
struct ExpressionLayout {
  int n_x = 0;        ///< states of the Pss (the clock included, if any)
  int n_x_slots = 0;  ///< state slots in the symbol vector: n_x or n_x + 1 (unused time slot)
  int n_u = 0;
  int n_p = 0;
  /// The algebraic variables z and their equations g_z (null: none).
  std::shared_ptr<const AlgebraicEquations> algebraic{};
  int n_z() const { return algebraic ? algebraic->n_z() : 0; }
  /// alpha slots after z: n_c if the model is given by f_alpha, else 0.
  int n_alpha = 0;
  int n_symbols() const { return n_x_slots + n_u + n_p + n_z() + n_alpha; }
};

/// fesd::PssFunctions evaluating parsed expressions, for every scalar type. c and g must not read
/// controls (PssFunctions::c and ::g get no u); the constructor checks this and all sizes and
/// throws fesd::InvalidModel.
class ExpressionModel final : public PssFunctions {
 public:
  ExpressionModel(ExpressionLayout layout, std::vector<ExpressionSubsystem> subsystems);

  const ExpressionLayout& layout() const { return layout_; }
  int n_regions() const { return static_cast<int>(fields_.size()); }
  /// The parsed expressions, in Pss order (text() is the source): c and g of all subsystems
  /// concatenated, one vector field per region. For descriptions of the model (`fesd check`).
  const std::vector<expr::Expression>& c_expressions() const { return c_; }
  const std::vector<expr::Expression>& g_expressions() const { return g_; }
  const std::vector<std::vector<expr::Expression>>& fields() const { return fields_; }

#define FESD_DECLARE_EXPRESSION_FUNCTIONS(T)                                       \
  void c(const T* x, const T* p, T* c_out) const override;                         \
  void g(const T* x, const T* p, T* g_out) const override;                         \
  void f(int region, const T* x, const T* u, const T* p, T* f_out) const override; \
  void f_alpha(const T* x, const T* alpha, const T* u, const T* p, T* f_out) const override;
  FESD_FOR_EACH_SCALAR(FESD_DECLARE_EXPRESSION_FUNCTIONS)
#undef FESD_DECLARE_EXPRESSION_FUNCTIONS
  int n_z() const override {
    return layout_.n_z();
  }
  void algebraic(const double* x, const double* u, const double* p, double* z) const override;
  bool has_f_alpha() const override {
    return !f_alpha_.empty();
  }
  /// With f_alpha: the regions' 0/1 alpha vertices from the sign matrix (rows: regions); their
  /// fields are f_alpha there (make_expression_pss calls this).
  void set_vertices(const Eigen::MatrixXd& S);
  /// f_alpha (empty if the model has region fields).
  const std::vector<expr::Expression>& f_alpha_expressions() const {
    return f_alpha_;
  }

 private:
  template <class T>
  void eval_list(const std::vector<expr::Expression>& list, const T* x, const T* u, const T* p,
                 T* out, const T* alpha = nullptr, const double* vertex = nullptr) const;

  ExpressionLayout layout_;
  std::vector<expr::Expression> c_;                    // all c-form subsystems' c, concatenated
  std::vector<expr::Expression> g_;                    // all g-form subsystems' g, concatenated
  std::vector<std::vector<expr::Expression>> fields_;  // one per region over all subsystems
  std::vector<expr::Expression> f_alpha_;              // the general inclusion, or empty
  std::vector<std::vector<double>> vertices_;          // with f_alpha: region r's 0/1 alpha
};

/// Convenience: the Pss of an ExpressionModel (dims.n_x, n_u, n_p must match the layout). With
/// f_alpha (one c-form subsystem), the region fields are filled in from f_alpha and S.
Pss make_expression_pss(PssDims dims, ExpressionLayout layout,
                        std::vector<ExpressionSubsystem> subsystems);

}  // namespace fesd
