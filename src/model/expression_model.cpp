// src/model/expression_model.cpp: evaluation of parsed c, g and f_i, one symbol vector per call.
#include "model/expression_model.hpp"

#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "fesd/error.hpp"

namespace fesd {
namespace {

// The symbol vector (x, u, p) of one call. Up to kStackBytes it lives on the stack (the common
// case: a few states of a small scalar type); larger vectors of large AD types go to the heap.
// Elements are copy-constructed in place, never default-constructed first: a default-constructed
// Dual<Jet<128>> would zero two kilobytes per element.
template <class T>
class SymbolBuffer {
 public:
  explicit SymbolBuffer(int n) : capacity_(n) {
    if (n > kStackCapacity) heap_ = std::allocator<T>().allocate(static_cast<std::size_t>(n));
  }
  ~SymbolBuffer() {
    T* d = data();
    std::destroy_n(d, size_);
    if (heap_ != nullptr)
      std::allocator<T>().deallocate(heap_, static_cast<std::size_t>(capacity_));
  }
  SymbolBuffer(const SymbolBuffer&) = delete;
  SymbolBuffer& operator=(const SymbolBuffer&) = delete;

  void push(const T& value) {
    std::construct_at(data() + size_, value);
    ++size_;
  }
  void push_range(const T* values, int n) {
    for (int i = 0; i < n; ++i) push(values[i]);
  }
  void push_zeros(int n) {
    for (int i = 0; i < n; ++i) push(T(0.0));
  }
  T* data() { return heap_ != nullptr ? heap_ : std::launder(reinterpret_cast<T*>(stack_)); }

 private:
  static constexpr std::size_t kStackBytes = 16384;
  static constexpr int kStackCapacity =
      static_cast<int>(std::clamp<std::size_t>(kStackBytes / sizeof(T), 1, 64));

  alignas(T) unsigned char stack_[static_cast<std::size_t>(kStackCapacity) * sizeof(T)];
  T* heap_ = nullptr;
  int capacity_ = 0;
  int size_ = 0;
};

int max_dependency(const expr::Expression& e) {
  const std::vector<int>& deps = e.dependencies();
  return deps.empty() ? -1 : deps.back();
}

/// The symbols every expression reads before the step form's alpha: x (and the unused time slot),
/// u (zeros where the caller has none: c, g), p, and z = z(x, u, p) solved from g_z = 0.
template <class T>
void push_x_u_p_z(SymbolBuffer<T>& in, const ExpressionLayout& layout, const T* x, const T* u,
                  const T* p) {
  in.push_range(x, layout.n_x);
  in.push_zeros(layout.n_x_slots - layout.n_x);
  if (u != nullptr)
    in.push_range(u, layout.n_u);
  else
    in.push_zeros(layout.n_u);
  in.push_range(p, layout.n_p);
  if (layout.algebraic) {
    in.push_zeros(layout.n_z());
    layout.algebraic->solve<T>(in.data());
  }
}

}  // namespace

ExpressionModel::ExpressionModel(ExpressionLayout layout,
                                 std::vector<ExpressionSubsystem> subsystems)
    : layout_(layout) {
  const ExpressionLayout& L = layout_;
  if (L.n_x < 1)
    throw InternalError(fmt::format("internal: expression model: n_x = {}: must be >= 1", L.n_x));
  if (L.n_x_slots != L.n_x && L.n_x_slots != L.n_x + 1)
    throw InternalError(
        fmt::format("internal: expression model: n_x_slots = {}: must be n_x = {} or n_x + 1",
                    L.n_x_slots, L.n_x));
  if (L.n_u < 0 || L.n_p < 0)
    throw InternalError(
        fmt::format("internal: expression model: n_u = {}, n_p = {}: must be >= 0", L.n_u, L.n_p));
  if (subsystems.empty()) throw InternalError("internal: expression model: no subsystem given");

  const int first_u = L.n_x_slots;
  const auto reads_control = [&](const expr::Expression& e) {
    for (int i = first_u; i < first_u + L.n_u; ++i)
      if (e.depends_on(i)) return true;
    return false;
  };
  const auto check_symbols = [&](const expr::Expression& e, const std::string& what) {
    if (max_dependency(e) >= L.n_symbols())
      throw InternalError(
          fmt::format("internal: expression model: {} = '{}' reads input {}, but there are "
                      "only {} symbols",
                      what, expr::shorten(e.text()), max_dependency(e), L.n_symbols()));
  };

  for (std::size_t k = 0; k < subsystems.size(); ++k) {
    ExpressionSubsystem& s = subsystems[k];
    const std::string where = fmt::format("internal: expression model: subsystem {}", k);
    if (s.c.empty() == s.g.empty())
      throw InternalError(where + ": give either switching functions c or indicator functions g");
    if (!s.f_alpha.empty()) {
      if (subsystems.size() != 1 || s.c.empty() || !s.F.empty())
        throw InternalError(where + ": f_alpha needs one c-form subsystem and no F");
      if (static_cast<int>(s.f_alpha.size()) != L.n_x || L.n_alpha != static_cast<int>(s.c.size()))
        throw InternalError(fmt::format("{}: f_alpha has {} components (n_x = {}), n_alpha = {}",
                                        where, s.f_alpha.size(), L.n_x, L.n_alpha));
      for (const expr::Expression& e : s.f_alpha) check_symbols(e, where + " f_alpha");
    } else if (s.F.empty()) {
      throw InternalError(where + ": no vector fields F");
    }
    for (const auto& list : {std::cref(s.c), std::cref(s.g)}) {
      for (const expr::Expression& e : list.get()) {
        check_symbols(e, where + " c/g");
        if (reads_control(e))
          throw InternalError(
              fmt::format("{}: '{}' reads a control; switching and indicator "
                          "functions depend on x and p only",
                          where, expr::shorten(e.text())));
      }
    }
    for (std::size_t i = 0; i < s.F.size(); ++i) {
      if (static_cast<int>(s.F[i].size()) != L.n_x)
        throw InternalError(fmt::format("{}: F[{}] has {} components, expected n_x = {}", where, i,
                                        s.F[i].size(), L.n_x));
      for (const expr::Expression& e : s.F[i]) check_symbols(e, fmt::format("{} F[{}]", where, i));
    }
    for (expr::Expression& e : s.c) c_.push_back(std::move(e));
    for (expr::Expression& e : s.g) g_.push_back(std::move(e));
    for (auto& field : s.F) fields_.push_back(std::move(field));
    if (!s.f_alpha.empty()) f_alpha_ = std::move(s.f_alpha);
  }
}

void ExpressionModel::set_vertices(const Eigen::MatrixXd& S) {
  vertices_.clear();
  fields_.clear();
  for (Eigen::Index i = 0; i < S.rows(); ++i) {
    std::vector<double> v;
    for (Eigen::Index j = 0; j < S.cols(); ++j) v.push_back(S(i, j) > 0 ? 1.0 : 0.0);
    vertices_.push_back(std::move(v));
    fields_.push_back(f_alpha_);
  }
}

template <class T>
void ExpressionModel::eval_list(const std::vector<expr::Expression>& list, const T* x, const T* u,
                                const T* p, T* out, const T* alpha, const double* vertex) const {
  SymbolBuffer<T> in(layout_.n_symbols());
  push_x_u_p_z(in, layout_, x, u, p);
  if (alpha != nullptr)
    in.push_range(alpha, layout_.n_alpha);
  else if (vertex != nullptr)
    for (int j = 0; j < layout_.n_alpha; ++j) in.push(T(vertex[j]));
  else
    in.push_zeros(layout_.n_alpha);
  const T* symbols = in.data();
  for (std::size_t i = 0; i < list.size(); ++i) out[i] = list[i].template evaluate<T>(symbols);
}

#define FESD_DEFINE_EXPRESSION_FUNCTIONS(T)                                                   \
  void ExpressionModel::c(const T* x, const T* p, T* c_out) const {                           \
    eval_list<T>(c_, x, nullptr, p, c_out);                                                   \
  }                                                                                           \
  void ExpressionModel::g(const T* x, const T* p, T* g_out) const {                           \
    eval_list<T>(g_, x, nullptr, p, g_out);                                                   \
  }                                                                                           \
  void ExpressionModel::f(int region, const T* x, const T* u, const T* p, T* f_out) const {   \
    const auto r = static_cast<std::size_t>(region);                                          \
    eval_list<T>(fields_.at(r), x, u, p, f_out, nullptr,                                      \
                 vertices_.empty() ? nullptr : vertices_.at(r).data());                       \
  }                                                                                           \
  void ExpressionModel::f_alpha(const T* x, const T* alpha, const T* u, const T* p, T* f_out) \
      const {                                                                                 \
    eval_list<T>(f_alpha_, x, u, p, f_out, alpha);                                            \
  }
FESD_FOR_EACH_SCALAR(FESD_DEFINE_EXPRESSION_FUNCTIONS)
#undef FESD_DEFINE_EXPRESSION_FUNCTIONS

void ExpressionModel::algebraic(const double* x, const double* u, const double* p,
                                double* z) const {
  if (!layout_.algebraic) return;
  SymbolBuffer<double> in(layout_.n_symbols());
  push_x_u_p_z(in, layout_, x, u, p);
  std::copy_n(in.data() + layout_.n_symbols() - layout_.n_alpha - layout_.n_z(), layout_.n_z(), z);
}

Pss make_expression_pss(PssDims dims, ExpressionLayout layout,
                        std::vector<ExpressionSubsystem> subsystems) {
  if (dims.n_x != layout.n_x || dims.n_u != layout.n_u || dims.n_p != layout.n_p)
    throw InternalError(
        fmt::format("internal: expression model: dims (n_x {}, n_u {}, n_p {}) differ from "
                    "the expression layout (n_x {}, n_u {}, n_p {})",
                    dims.n_x, dims.n_u, dims.n_p, layout.n_x, layout.n_u, layout.n_p));
  if (dims.subsystems.size() != subsystems.size())
    throw InternalError(
        fmt::format("internal: expression model: {} subsystems in dims, {} with expressions",
                    dims.subsystems.size(), subsystems.size()));
  for (std::size_t k = 0; k < subsystems.size(); ++k) {
    const Subsystem& d = dims.subsystems[k];
    const ExpressionSubsystem& s = subsystems[k];
    if (d.n_c != static_cast<int>(s.c.size()) || d.n_g != static_cast<int>(s.g.size()))
      throw InternalError(
          fmt::format("internal: expression model: subsystem {}: n_c = {}, n_g = {} but {} c "
                      "and {} g expressions",
                      k, d.n_c, d.n_g, s.c.size(), s.g.size()));
    if (s.f_alpha.empty() && d.n_f() != static_cast<int>(s.F.size()))
      throw InternalError(
          fmt::format("internal: expression model: subsystem {}: {} regions but {} vector "
                      "fields F",
                      k, d.n_f(), s.F.size()));
  }
  const bool by_alpha = !subsystems.front().f_alpha.empty();
  auto functions = std::make_shared<ExpressionModel>(layout, std::move(subsystems));
  if (by_alpha) {
    const Subsystem& d = dims.subsystems.front();
    functions->set_vertices(d.S.size() > 0 ? d.S : all_sign_rows(d.n_c));
  }
  return Pss(std::move(dims), std::shared_ptr<const ExpressionModel>(std::move(functions)));
}

}  // namespace fesd
