// src/io/ocp_expression_functions.cpp: evaluation of the parsed [ocp] expressions.
#include "io/ocp_expression_functions.hpp"

#include <algorithm>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "fesd/error.hpp"

namespace fesd {
namespace {

/// The symbol vector of one call, one buffer per thread and scalar type: after the first call it
/// allocates nothing (the cost and constraint blocks are evaluated once per element and stage,
/// for every derivative type).
template <class T>
std::vector<T>& symbol_buffer() {
  thread_local std::vector<T> buffer;
  return buffer;
}

}  // namespace

ExpressionOcpFunctions::ExpressionOcpFunctions(ExpressionLayout layout, OcpExpressions expressions)
    : layout_(layout), e_(std::move(expressions)) {
  const int n_symbols = layout_.n_symbols() + e_.n_rk;
  const int first_u = layout_.n_x_slots;
  const auto check = [&](const expr::Expression& e, const char* what, bool controls_allowed) {
    const std::vector<int>& deps = e.dependencies();
    if (!deps.empty() && deps.back() >= n_symbols)
      throw InternalError(
          fmt::format("internal: ocp expressions: {} = '{}' reads input {}, but there are "
                      "only {} symbols",
                      what, expr::shorten(e.text()), deps.back(), n_symbols));
    if (!controls_allowed)
      for (int i = first_u; i < first_u + layout_.n_u; ++i)
        if (e.depends_on(i))
          throw InternalError(fmt::format(
              "internal: ocp expressions: {} = '{}' reads a control; it depends on x and p only",
              what, expr::shorten(e.text())));
  };
  if (e_.f_q) check(*e_.f_q, "f_q", true);
  if (e_.f_q_T) check(*e_.f_q_T, "f_q_T", false);
  for (const expr::Expression& e : e_.g_path) check(e, "g_path", true);
  for (const expr::Expression& e : e_.g_terminal) check(e, "g_terminal", false);
  for (const expr::Expression& e : e_.g_path_comp) check(e, "g_path_comp", true);
  for (const expr::Expression& e : e_.g_rk_comp) check(e, "g_path_comp", true);
  // Only the stage pairs may read y.
  const auto reads_y = [&](const expr::Expression& e) {
    const std::vector<int>& deps = e.dependencies();
    return !deps.empty() && deps.back() >= layout_.n_symbols();
  };
  const auto no_y = [&](const expr::Expression& e, const char* what) {
    if (reads_y(e))
      throw InternalError(fmt::format("internal: ocp expressions: {} = '{}' reads a stage variable",
                                      what, expr::shorten(e.text())));
  };
  if (e_.f_q) no_y(*e_.f_q, "f_q");
  if (e_.f_q_T) no_y(*e_.f_q_T, "f_q_T");
  for (const expr::Expression& e : e_.g_path) no_y(e, "g_path");
  for (const expr::Expression& e : e_.g_terminal) no_y(e, "g_terminal");
  for (const expr::Expression& e : e_.g_path_comp) no_y(e, "g_path_comp");
  for (int i = 0; i < e_.n_rk; ++i)
    if (std::any_of(e_.g_rk_comp.begin(), e_.g_rk_comp.end(), [&](const expr::Expression& e) {
          return e.depends_on(layout_.n_symbols() + i);
        }))
      rk_inputs_.push_back(i);
}

template <class T>
void ExpressionOcpFunctions::eval(const expr::Expression* list, int n, const T* x, const T* u,
                                  const T* p, T* out, const T* y) const {
  std::vector<T>& in = symbol_buffer<T>();
  in.clear();
  for (int i = 0; i < layout_.n_x; ++i) in.push_back(x[i]);
  // The time slot of a model without a clock state: no expression reads it.
  for (int i = layout_.n_x; i < layout_.n_x_slots; ++i) in.push_back(T(0.0));
  for (int i = 0; i < layout_.n_u; ++i) in.push_back(u != nullptr ? u[i] : T(0.0));
  for (int i = 0; i < layout_.n_p; ++i) in.push_back(p[i]);
  if (layout_.algebraic) {  // z(x, u, p) from g_z = 0 (model/algebraic.hpp)
    for (int i = 0; i < layout_.n_z(); ++i) in.push_back(T(0.0));
    layout_.algebraic->solve<T>(in.data());
  }
  if (y != nullptr)  // the stage variables (g_rk_comp)
    for (int i = 0; i < e_.n_rk; ++i) in.push_back(y[i]);
  const T* symbols = in.data();
  for (int i = 0; i < n; ++i) out[i] = list[i].template evaluate<T>(symbols);
}

#define FESD_DEFINE_EXPRESSION_OCP_FUNCTIONS(T)                                                  \
  T ExpressionOcpFunctions::f_q(const T* x, const T* u, const T* p) const {                      \
    if (!e_.f_q) return T(0.0);                                                                  \
    T out(0.0);                                                                                  \
    eval<T>(&*e_.f_q, 1, x, u, p, &out);                                                         \
    return out;                                                                                  \
  }                                                                                              \
  T ExpressionOcpFunctions::f_q_T(const T* x, const T* p) const {                                \
    if (!e_.f_q_T) return T(0.0);                                                                \
    T out(0.0);                                                                                  \
    eval<T>(&*e_.f_q_T, 1, x, nullptr, p, &out);                                                 \
    return out;                                                                                  \
  }                                                                                              \
  void ExpressionOcpFunctions::g_path(const T* x, const T* u, const T* p, T* out) const {        \
    eval<T>(e_.g_path.data(), n_g_path(), x, u, p, out);                                         \
  }                                                                                              \
  void ExpressionOcpFunctions::g_terminal(const T* x, const T* p, T* out) const {                \
    eval<T>(e_.g_terminal.data(), n_g_terminal(), x, nullptr, p, out);                           \
  }                                                                                              \
  void ExpressionOcpFunctions::g_path_comp(const T* x, const T* u, const T* p, T* out) const {   \
    eval<T>(e_.g_path_comp.data(), 2 * n_g_path_comp(), x, u, p, out);                           \
  }                                                                                              \
  void ExpressionOcpFunctions::g_rk_comp(const T* x, const T* u, const T* p, const T* y, T* out) \
      const {                                                                                    \
    eval<T>(e_.g_rk_comp.data(), 2 * n_g_rk_comp(), x, u, p, out, y);                            \
  }
FESD_FOR_EACH_SCALAR(FESD_DEFINE_EXPRESSION_OCP_FUNCTIONS)
#undef FESD_DEFINE_EXPRESSION_OCP_FUNCTIONS

}  // namespace fesd
