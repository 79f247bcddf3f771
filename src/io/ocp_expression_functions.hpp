// src/io/ocp_expression_functions.hpp: fesd::OcpFunctions whose costs and constraints are parsed
// math expressions ([ocp] f_q, f_q_T, g_path, g_terminal, g_path_comp of a problem file).
//
// The expressions read the same symbol vector as the model's (model/expression_model.hpp):
//
//   [ x_0 .. x_{n_x_slots-1},  u_0 .. u_{n_u-1},  p_0 .. p_{n_p-1} ]
//
// The pairs of g_path_comp that read the DCS algebraic variables of an RK stage (theta_i, ...)
// are g_rk_comp: their expressions read the symbols above followed by the stage vector y of
// fesd::RkAlgebraic (n_rk entries).
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
  /// The pairs that read the stage variables y (symbols after the layout's, RkAlgebraic): a_1 ..
  /// a_n, then b_1 .. b_n.
  std::vector<expr::Expression> g_rk_comp;
  int n_rk = 0;  ///< the size of y (RkAlgebraic::size()), 0 without g_rk_comp
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
  int n_g_rk_comp() const { return static_cast<int>(e_.g_rk_comp.size()) / 2; }
  /// The entries of y that g_rk_comp reads.
  std::vector<int> g_rk_comp_inputs() const override { return rk_inputs_; }
  /// The parsed expressions (text() is the source), for descriptions of the problem.
  const OcpExpressions& expressions() const { return e_; }

#define FESD_DECLARE_EXPRESSION_OCP_FUNCTIONS(T)                               \
  T f_q(const T* x, const T* u, const T* p) const override;                    \
  T f_q_T(const T* x, const T* p) const override;                              \
  void g_path(const T* x, const T* u, const T* p, T* out) const override;      \
  void g_terminal(const T* x, const T* p, T* out) const override;              \
  void g_path_comp(const T* x, const T* u, const T* p, T* out) const override; \
  void g_rk_comp(const T* x, const T* u, const T* p, const T* y, T* out) const override;
  FESD_FOR_EACH_SCALAR(FESD_DECLARE_EXPRESSION_OCP_FUNCTIONS)
#undef FESD_DECLARE_EXPRESSION_OCP_FUNCTIONS

 private:
  template <class T>
  void eval(const expr::Expression* list, int n, const T* x, const T* u, const T* p, T* out,
            const T* y = nullptr) const;

  ExpressionLayout layout_;
  OcpExpressions e_;
  std::vector<int> rk_inputs_;
};

}  // namespace fesd
