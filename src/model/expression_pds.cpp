// ExpressionPds: f and c of a projected dynamical system from parsed expressions. grad c(x) lambda
// is one directional derivative of every c_k per state component: over Jet<8> (one direction) for
// double, over Dual<T> (Hyper<N> for Jet<N>) for the derivative types.
#include "model/expression_pds.hpp"

#include <fmt/format.h>

#include "fesd/error.hpp"

namespace fesd {
namespace {

template <class T>
struct DirectionType {
  using type = ad::Dual<T>;
};

template <>
struct DirectionType<double> {
  using type = ad::Jet<8>;
};

template <class D, class T>
D seeded(const T& v, bool on) {
  if constexpr (std::is_same_v<D, ad::Jet<8>>)
    return on ? ad::Jet<8>::variable(v, 0, 1) : ad::Jet<8>(v);
  else
    return D(v, T(on ? 1.0 : 0.0));
}
template <class D>
auto direction_of(const D& d) {
  if constexpr (std::is_same_v<D, ad::Jet<8>>)
    return d.d(0);
  else
    return d.d;
}

class ExpressionPds final : public PdsFunctions {
 public:
  ExpressionPds(ExpressionLayout layout, std::vector<expr::Expression> f,
                std::vector<expr::Expression> c)
      : layout_(layout), f_(std::move(f)), c_(std::move(c)) {}

#define FESD_IMPLEMENT_EXPRESSION_PDS(T)                                               \
  void c(const T* x, const T* p, T* c_out) const override {                            \
    std::vector<T> in = inputs<T>(x, nullptr, p);                                      \
    for (std::size_t k = 0; k < c_.size(); ++k) c_out[k] = c_[k].evaluate(in.data());  \
  }                                                                                    \
  void f(const T* x, const T* u, const T* p, T* f_out) const override {                \
    std::vector<T> in = inputs<T>(x, u, p);                                            \
    for (std::size_t j = 0; j < f_.size(); ++j) f_out[j] = f_[j].evaluate(in.data());  \
  }                                                                                    \
  void grad_c_lambda(const T* x, const T* p, const T* lambda, T* out) const override { \
    grad_impl<T>(x, p, lambda, out);                                                   \
  }
  FESD_FOR_EACH_SCALAR(FESD_IMPLEMENT_EXPRESSION_PDS)
#undef FESD_IMPLEMENT_EXPRESSION_PDS

  const std::vector<expr::Expression>& f_expressions() const {
    return f_;
  }
  const std::vector<expr::Expression>& c_expressions() const {
    return c_;
  }

 private:
  /// The symbol vector [x (n_x_slots), u, p]; an unused time slot holds 0, controls 0 if u is
  /// null (c reads none).
  template <class T>
  std::vector<T> inputs(const T* x, const T* u, const T* p) const {
    std::vector<T> in(static_cast<std::size_t>(layout_.n_symbols()), T(0.0));
    for (int i = 0; i < layout_.n_x; ++i) in[i] = x[i];
    for (int i = 0; i < layout_.n_u && u != nullptr; ++i) in[layout_.n_x_slots + i] = u[i];
    for (int i = 0; i < layout_.n_p; ++i) in[layout_.n_x_slots + layout_.n_u + i] = p[i];
    return in;
  }
  template <class T>
  void grad_impl(const T* x, const T* p, const T* lambda, T* out) const {
    if constexpr (std::is_same_v<T, ad::Pattern>) {
      // Structure only: d c_k / d x_i depends on at most what c_k depends on, so
      // sum_k lambda_k c_k(x) is a superset of the pattern of every component.
      std::vector<T> in = inputs<T>(x, nullptr, p);
      T s(0.0);
      for (std::size_t k = 0; k < c_.size(); ++k) s = s + lambda[k] * c_[k].evaluate(in.data());
      for (int i = 0; i < layout_.n_x; ++i) out[i] = s;
    } else {
      using D = typename DirectionType<T>::type;
      std::vector<D> in(static_cast<std::size_t>(layout_.n_symbols()), D(0.0));
      for (int i = 0; i < layout_.n_x; ++i) in[i] = seeded<D>(x[i], false);
      for (int i = 0; i < layout_.n_p; ++i)
        in[layout_.n_x_slots + layout_.n_u + i] = seeded<D>(p[i], false);
      for (int i = 0; i < layout_.n_x; ++i) {
        in[i] = seeded<D>(x[i], true);
        T s(0.0);
        for (std::size_t k = 0; k < c_.size(); ++k)
          s = s + lambda[k] * direction_of(c_[k].evaluate(in.data()));
        in[i] = seeded<D>(x[i], false);
        out[i] = s;
      }
    }
  }

  ExpressionLayout layout_;
  std::vector<expr::Expression> f_, c_;
};

}  // namespace

Pds make_expression_pds(PdsDims dims, ExpressionLayout layout, std::vector<expr::Expression> f,
                        std::vector<expr::Expression> c) {
  if (static_cast<int>(f.size()) != dims.n_x)
    throw InvalidModel(
        fmt::format("f has {} expressions, expected one per state ({})", f.size(), dims.n_x));
  if (static_cast<int>(c.size()) != dims.n_c)
    throw InvalidModel(
        fmt::format("constraints: {} expressions, expected n_c = {}", c.size(), dims.n_c));
  if (layout.n_x != dims.n_x || layout.n_u != dims.n_u || layout.n_p != dims.n_p)
    throw InvalidModel("expression layout does not match the model's sizes");
  for (std::size_t k = 0; k < c.size(); ++k)
    for (int i = 0; i < layout.n_u; ++i)
      if (c[k].depends_on(layout.n_x_slots + i))
        throw InvalidModel(
            fmt::format("constraints[{}] = \"{}\": a constraint cannot depend on "
                        "controls",
                        k, expr::shorten(c[k].text())));
  return Pds(dims, std::make_shared<ExpressionPds>(layout, std::move(f), std::move(c)));
}

PdsExpressionView expressions_of(const Pds& model) {
  const auto* e = dynamic_cast<const ExpressionPds*>(&model.functions());
  if (e == nullptr) return {};
  return {&e->f_expressions(), &e->c_expressions()};
}

}  // namespace fesd
