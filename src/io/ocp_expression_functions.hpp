// src/io/ocp_expression_functions.hpp: fesd::OcpFunctions whose costs and constraints are parsed
// math expressions ([ocp] f_q, f_q_T, g_path, g_terminal, g_path_comp of a problem file).
//
// The expressions read the same symbol vector as the model's (model/expression_model.hpp):
//
//   [ x_0 .. x_{n_x_slots-1},  u_0 .. u_{n_u-1},  p_0 .. p_{n_p-1} ]
//
// f_q_T and g_terminal get no controls (OcpFunctions passes none): their u slots hold 0, and the
// reader rejects expressions that read them.
#pragma once
#include <optional>
#include <vector>

#include "fesd/ocp.hpp"
#include "model/expression.hpp"
#include "model/expression_model.hpp"

namespace fesd {

/// The parsed expressions of [ocp]; absent costs are zero.
struct OcpExpressions {
  std::optional<expr::Expression> f_q;       ///< Lagrange term f_q(x, u, p)
  std::optional<expr::Expression> f_q_T;     ///< Mayer term f_q_T(x, p)
  std::vector<expr::Expression> g_path;      ///< path constraints g_path(x, u, p)
  std::vector<expr::Expression> g_terminal;  ///< terminal constraints g_terminal(x, p)
  /// Path complementarity pairs (a_i, b_i): a_1 .. a_n, then b_1 .. b_n.
  std::vector<expr::Expression> g_path_comp;
};

/// OcpFunctions evaluating parsed expressions for every scalar type. The constructor checks that
/// every expression reads only symbols of `layout` and that f_q_T and g_terminal read no control;
/// it throws fesd::InvalidModel.
class ExpressionOcpFunctions final : public OcpFunctions {
 public:
  ExpressionOcpFunctions(ExpressionLayout layout, OcpExpressions expressions);

  bool has_f_q() const override { return e_.f_q.has_value(); }
  bool has_f_q_T() const override { return e_.f_q_T.has_value(); }
  int n_g_path() const { return static_cast<int>(e_.g_path.size()); }
  int n_g_terminal() const { return static_cast<int>(e_.g_terminal.size()); }
  int n_g_path_comp() const { return static_cast<int>(e_.g_path_comp.size()) / 2; }
  /// The parsed expressions (text() is the source), for descriptions of the problem.
  const OcpExpressions& expressions() const { return e_; }

#define FESD_DECLARE_EXPRESSION_OCP_FUNCTIONS(T)                          \
  T f_q(const T* x, const T* u, const T* p) const override;               \
  T f_q_T(const T* x, const T* p) const override;                         \
  void g_path(const T* x, const T* u, const T* p, T* out) const override; \
  void g_terminal(const T* x, const T* p, T* out) const override;         \
  void g_path_comp(const T* x, const T* u, const T* p, T* out) const override;
  FESD_FOR_EACH_SCALAR(FESD_DECLARE_EXPRESSION_OCP_FUNCTIONS)
#undef FESD_DECLARE_EXPRESSION_OCP_FUNCTIONS

 private:
  template <class T>
  void eval(const expr::Expression* list, int n, const T* x, const T* u, const T* p, T* out) const;

  ExpressionLayout layout_;
  OcpExpressions e_;
};

}  // namespace fesd
