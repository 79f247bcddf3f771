// include/fesd/ad.hpp: the scalar types fesd evaluates user functions with.
//
// Every function a user gives fesd (vector fields f_i, switching functions c, indicator functions
// g, costs, constraints) is a template on its scalar type T. fesd instantiates it with
//   double            values,
//   ad::Jet<N>        value + gradient (forward mode, first derivatives, N = capacity),
//   ad::Hyper<N>      a Jet with one more forward direction (one Hessian column per pass),
//   ad::Pattern       value + structural dependence (which inputs, which Hessian pairs),
// so exact first and second derivatives and their sparsity come from one source (docs/derivatives.md).
// Users never name these types. In a model, write math calls unqualified after
// `using std::sin;` (or call fesd::math::sin): argument-dependent lookup finds the overloads here.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <utility>
#include <vector>

namespace fesd::ad {

// ---- first order: Jet ------------------------------------------------------------------------
/// Value and gradient w.r.t. at most N inputs. Only the first `n` gradient entries are meaningful;
/// the rest are zero by definition (constants have n = 0, so they cost nothing).
template <int N>
struct Jet {
  double v = 0.0;
  int n = 0;
  double g[N];

  Jet() = default;
  Jet(double value) : v(value), n(0) {}  // NOLINT: implicit on purpose, constants mix freely
  Jet(const Jet& o) : v(o.v), n(o.n) { std::copy_n(o.g, o.n, g); }
  Jet& operator=(const Jet& o) {
    v = o.v;
    n = o.n;
    std::copy_n(o.g, o.n, g);
    return *this;
  }
  /// Input number i of n: gradient e_i.
  static Jet variable(double value, int i, int n_dirs) {
    Jet r(value);
    r.n = n_dirs;
    std::fill_n(r.g, n_dirs, 0.0);
    r.g[i] = 1.0;
    return r;
  }
  double d(int i) const { return i < n ? g[i] : 0.0; }
};

/// r = value + ca * grad(a) + cb * grad(b), with missing gradient entries taken as zero.
/// Tells the optimizer that 0 <= n <= N (gradient lengths always are).
template <int N>
inline void assume_length(int n) {
#if defined(__GNUC__)
  if (n < 0 || n > N) __builtin_unreachable();
#else
  (void)n;
#endif
}

template <int N>
inline Jet<N> lincomb(double value, double ca, const Jet<N>& a, double cb, const Jet<N>& b) {
  assume_length<N>(a.n);
  assume_length<N>(b.n);
  Jet<N> r(value);
  const int lo = std::min(a.n, b.n);
  r.n = std::max(a.n, b.n);
  for (int i = 0; i < lo; ++i) r.g[i] = ca * a.g[i] + cb * b.g[i];
  for (int i = lo; i < a.n; ++i) r.g[i] = ca * a.g[i];
  for (int i = lo; i < b.n; ++i) r.g[i] = cb * b.g[i];
  return r;
}
/// r = value + ca * grad(a).
template <int N>
inline Jet<N> scaled(double value, double ca, const Jet<N>& a) {
  assume_length<N>(a.n);
  Jet<N> r(value);
  r.n = a.n;
  for (int i = 0; i < a.n; ++i) r.g[i] = ca * a.g[i];
  return r;
}

template <int N>
inline Jet<N> operator+(const Jet<N>& a, const Jet<N>& b) {
  return lincomb(a.v + b.v, 1.0, a, 1.0, b);
}
template <int N>
inline Jet<N> operator-(const Jet<N>& a, const Jet<N>& b) {
  return lincomb(a.v - b.v, 1.0, a, -1.0, b);
}
template <int N>
inline Jet<N> operator*(const Jet<N>& a, const Jet<N>& b) {
  return lincomb(a.v * b.v, b.v, a, a.v, b);
}
template <int N>
inline Jet<N> operator/(const Jet<N>& a, const Jet<N>& b) {
  const double q = a.v / b.v;
  return lincomb(q, 1.0 / b.v, a, -q / b.v, b);
}
template <int N>
inline Jet<N> operator-(const Jet<N>& a) {
  return scaled(-a.v, -1.0, a);
}
template <int N>
inline Jet<N> operator+(const Jet<N>& a) {
  return a;
}
template <int N>
inline Jet<N> operator+(const Jet<N>& a, double b) {
  Jet<N> r(a);
  r.v += b;
  return r;
}
template <int N>
inline Jet<N> operator+(double a, const Jet<N>& b) {
  return b + a;
}
template <int N>
inline Jet<N> operator-(const Jet<N>& a, double b) {
  return a + (-b);
}
template <int N>
inline Jet<N> operator-(double a, const Jet<N>& b) {
  return scaled(a - b.v, -1.0, b);
}
template <int N>
inline Jet<N> operator*(const Jet<N>& a, double b) {
  return scaled(a.v * b, b, a);
}
template <int N>
inline Jet<N> operator*(double a, const Jet<N>& b) {
  return scaled(a * b.v, a, b);
}
template <int N>
inline Jet<N> operator/(const Jet<N>& a, double b) {
  return scaled(a.v / b, 1.0 / b, a);
}
template <int N>
inline Jet<N> operator/(double a, const Jet<N>& b) {
  const double q = a / b.v;
  return scaled(q, -q / b.v, b);
}
template <int N>
inline Jet<N>& operator+=(Jet<N>& a, const Jet<N>& b) {
  return a = a + b;
}
template <int N>
inline Jet<N>& operator-=(Jet<N>& a, const Jet<N>& b) {
  return a = a - b;
}
template <int N>
inline Jet<N>& operator*=(Jet<N>& a, const Jet<N>& b) {
  return a = a * b;
}
template <int N>
inline Jet<N>& operator/=(Jet<N>& a, const Jet<N>& b) {
  return a = a / b;
}

// Elementary functions: f(a) = f(v) + f'(v) grad(a).
template <int N>
inline Jet<N> sin(const Jet<N>& a) {
  return scaled(std::sin(a.v), std::cos(a.v), a);
}
template <int N>
inline Jet<N> cos(const Jet<N>& a) {
  return scaled(std::cos(a.v), -std::sin(a.v), a);
}
template <int N>
inline Jet<N> tan(const Jet<N>& a) {
  const double t = std::tan(a.v);
  return scaled(t, 1.0 + t * t, a);
}
template <int N>
inline Jet<N> exp(const Jet<N>& a) {
  const double e = std::exp(a.v);
  return scaled(e, e, a);
}
template <int N>
inline Jet<N> log(const Jet<N>& a) {
  return scaled(std::log(a.v), 1.0 / a.v, a);
}
template <int N>
inline Jet<N> sqrt(const Jet<N>& a) {
  const double s = std::sqrt(a.v);
  return scaled(s, 0.5 / s, a);
}
template <int N>
inline Jet<N> tanh(const Jet<N>& a) {
  const double t = std::tanh(a.v);
  return scaled(t, 1.0 - t * t, a);
}
template <int N>
inline Jet<N> sinh(const Jet<N>& a) {
  return scaled(std::sinh(a.v), std::cosh(a.v), a);
}
template <int N>
inline Jet<N> cosh(const Jet<N>& a) {
  return scaled(std::cosh(a.v), std::sinh(a.v), a);
}
template <int N>
inline Jet<N> atan(const Jet<N>& a) {
  return scaled(std::atan(a.v), 1.0 / (1.0 + a.v * a.v), a);
}
/// |a|; the derivative at 0 is taken as 0.
template <int N>
inline Jet<N> abs(const Jet<N>& a) {
  return scaled(std::abs(a.v), a.v > 0 ? 1.0 : (a.v < 0 ? -1.0 : 0.0), a);
}
template <int N>
inline Jet<N> pow(const Jet<N>& a, double p) {
  if (p == 0.0) return Jet<N>(1.0);
  return scaled(std::pow(a.v, p), p * std::pow(a.v, p - 1.0), a);
}
/// a^b with the value of std::pow (so 0^0 = 1 and (-2)^3 = -8 as for double, where
/// exp(b log a) would give NaN) and d(a^b) = b a^(b - 1) da + a^b log(a) db.
template <int N>
inline Jet<N> pow(const Jet<N>& a, const Jet<N>& b) {
  if (b.n == 0) return pow(a, b.v);
  const double r = std::pow(a.v, b.v);
  const double ca = b.v * std::pow(a.v, b.v - 1.0), cb = r * std::log(a.v);
  if (std::isfinite(ca) && std::isfinite(cb)) return lincomb(r, ca, a, cb, b);
  // log(a) of a <= 0 (or 0^(b - 1)) is not finite: an input that only a (or only b) depends on
  // still gets its derivative ((-2)^y at y = 3: d/dx = 12), not 0 * inf = NaN.
  assume_length<N>(a.n);
  assume_length<N>(b.n);
  Jet<N> out(r);
  out.n = std::max(a.n, b.n);
  for (int i = 0; i < out.n; ++i) {
    const double da = a.d(i), db = b.d(i);
    out.g[i] = (da != 0.0 ? ca * da : 0.0) + (db != 0.0 ? cb * db : 0.0);
  }
  return out;
}
template <int N>
inline Jet<N> pow(double a, const Jet<N>& b) {
  const double r = std::pow(a, b.v);
  return scaled(r, r * std::log(a), b);
}

// ---- second order: Dual over a Jet -----------------------------------------------------------
/// x + d * eps with eps^2 = 0, over any scalar T. Dual<Jet<N>> seeded with the gradient directions
/// in the Jet and one direction e_j in d gives grad and the Hessian column j in one pass.
template <class T>
struct Dual {
  T v{};
  T d{};
  Dual() = default;
  Dual(double value) : v(value), d(0.0) {}  // NOLINT: implicit on purpose
  Dual(const T& value, const T& dir) : v(value), d(dir) {}
};
template <int N>
using Hyper = Dual<Jet<N>>;

template <class T>
inline Dual<T> operator+(const Dual<T>& a, const Dual<T>& b) {
  return {a.v + b.v, a.d + b.d};
}
template <class T>
inline Dual<T> operator-(const Dual<T>& a, const Dual<T>& b) {
  return {a.v - b.v, a.d - b.d};
}
template <class T>
inline Dual<T> operator*(const Dual<T>& a, const Dual<T>& b) {
  return {a.v * b.v, a.v * b.d + a.d * b.v};
}
template <class T>
inline Dual<T> operator/(const Dual<T>& a, const Dual<T>& b) {
  const T q = a.v / b.v;
  return {q, (a.d - q * b.d) / b.v};
}
template <class T>
inline Dual<T> operator-(const Dual<T>& a) {
  return {-a.v, -a.d};
}
template <class T>
inline Dual<T> operator+(const Dual<T>& a) {
  return a;
}
template <class T>
inline Dual<T> operator+(const Dual<T>& a, double b) {
  return {a.v + b, a.d};
}
template <class T>
inline Dual<T> operator+(double a, const Dual<T>& b) {
  return {a + b.v, b.d};
}
template <class T>
inline Dual<T> operator-(const Dual<T>& a, double b) {
  return {a.v - b, a.d};
}
template <class T>
inline Dual<T> operator-(double a, const Dual<T>& b) {
  return {a - b.v, -b.d};
}
template <class T>
inline Dual<T> operator*(const Dual<T>& a, double b) {
  return {a.v * b, a.d * b};
}
template <class T>
inline Dual<T> operator*(double a, const Dual<T>& b) {
  return {a * b.v, a * b.d};
}
template <class T>
inline Dual<T> operator/(const Dual<T>& a, double b) {
  return {a.v / b, a.d / b};
}
template <class T>
inline Dual<T> operator/(double a, const Dual<T>& b) {
  const T q = a / b.v;
  return {q, -q * b.d / b.v};
}
template <class T>
inline Dual<T>& operator+=(Dual<T>& a, const Dual<T>& b) {
  return a = a + b;
}
template <class T>
inline Dual<T>& operator-=(Dual<T>& a, const Dual<T>& b) {
  return a = a - b;
}
template <class T>
inline Dual<T>& operator*=(Dual<T>& a, const Dual<T>& b) {
  return a = a * b;
}
template <class T>
inline Dual<T>& operator/=(Dual<T>& a, const Dual<T>& b) {
  return a = a / b;
}

template <class T>
inline Dual<T> sin(const Dual<T>& a) {
  return {sin(a.v), cos(a.v) * a.d};
}
template <class T>
inline Dual<T> cos(const Dual<T>& a) {
  return {cos(a.v), -(sin(a.v) * a.d)};
}
template <class T>
inline Dual<T> tan(const Dual<T>& a) {
  const T t = tan(a.v);
  return {t, (1.0 + t * t) * a.d};
}
template <class T>
inline Dual<T> exp(const Dual<T>& a) {
  const T e = exp(a.v);
  return {e, e * a.d};
}
template <class T>
inline Dual<T> log(const Dual<T>& a) {
  return {log(a.v), a.d / a.v};
}
template <class T>
inline Dual<T> sqrt(const Dual<T>& a) {
  const T s = sqrt(a.v);
  return {s, a.d / (2.0 * s)};
}
template <class T>
inline Dual<T> tanh(const Dual<T>& a) {
  const T t = tanh(a.v);
  return {t, (1.0 - t * t) * a.d};
}
template <class T>
inline Dual<T> sinh(const Dual<T>& a) {
  return {sinh(a.v), cosh(a.v) * a.d};
}
template <class T>
inline Dual<T> cosh(const Dual<T>& a) {
  return {cosh(a.v), sinh(a.v) * a.d};
}
template <class T>
inline Dual<T> atan(const Dual<T>& a) {
  return {atan(a.v), a.d / (1.0 + a.v * a.v)};
}
template <class T>
inline Dual<T> abs(const Dual<T>& a);
template <class T>
inline Dual<T> pow(const Dual<T>& a, double p) {
  if (p == 0.0) return Dual<T>(1.0);
  return {pow(a.v, p), (p * pow(a.v, p - 1.0)) * a.d};
}
template <class T>
inline Dual<T> pow(const Dual<T>& a, const Dual<T>& b);  // defined below, after value_of
template <class T>
inline Dual<T> pow(double a, const Dual<T>& b) {
  return exp(b * std::log(a));
}

// ---- structure: Pattern ----------------------------------------------------------------------
/// A value plus the inputs it depends on and the pairs (i >= j) of its nonzero Hessian entries.
/// Evaluating a function once with Pattern inputs gives the structural Jacobian and Hessian.
struct Pattern {
  double v = 0.0;
  std::vector<int> dep;                    // sorted, unique
  std::vector<std::pair<int, int>> hess;  // sorted, unique, first >= second

  Pattern() = default;
  Pattern(double value) : v(value) {}  // NOLINT: implicit on purpose
  static Pattern variable(double value, int i) {
    Pattern p(value);
    p.dep.push_back(i);
    return p;
  }
  bool is_constant() const { return dep.empty(); }
};

namespace pattern_detail {
inline std::vector<int> merge(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<int> r;
  r.reserve(a.size() + b.size());
  std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(r));
  return r;
}
inline std::vector<std::pair<int, int>> merge(const std::vector<std::pair<int, int>>& a,
                                              const std::vector<std::pair<int, int>>& b) {
  std::vector<std::pair<int, int>> r;
  r.reserve(a.size() + b.size());
  std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(r));
  return r;
}
/// Hessian pairs of a product of functions depending on a and b: all (i, j) in a x b.
inline std::vector<std::pair<int, int>> outer(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<std::pair<int, int>> r;
  for (int i : a)
    for (int j : b) r.emplace_back(std::max(i, j), std::min(i, j));
  std::sort(r.begin(), r.end());
  r.erase(std::unique(r.begin(), r.end()), r.end());
  return r;
}
inline Pattern linear(double value, const Pattern& a, const Pattern& b) {
  Pattern r(value);
  r.dep = merge(a.dep, b.dep);
  r.hess = merge(a.hess, b.hess);
  return r;
}
/// A nonlinear function of a alone: Hessian gains dep(a) x dep(a).
inline Pattern nonlinear(double value, const Pattern& a) {
  Pattern r(value);
  r.dep = a.dep;
  r.hess = merge(a.hess, outer(a.dep, a.dep));
  return r;
}
}  // namespace pattern_detail

inline Pattern operator+(const Pattern& a, const Pattern& b) {
  return pattern_detail::linear(a.v + b.v, a, b);
}
inline Pattern operator-(const Pattern& a, const Pattern& b) {
  return pattern_detail::linear(a.v - b.v, a, b);
}
inline Pattern operator*(const Pattern& a, const Pattern& b) {
  Pattern r = pattern_detail::linear(a.v * b.v, a, b);
  if (!a.is_constant() && !b.is_constant())
    r.hess = pattern_detail::merge(r.hess, pattern_detail::outer(a.dep, b.dep));
  return r;
}
inline Pattern operator/(const Pattern& a, const Pattern& b) {
  Pattern r = pattern_detail::linear(a.v / b.v, a, b);
  if (!b.is_constant()) {
    const std::vector<int> all = pattern_detail::merge(a.dep, b.dep);
    r.hess = pattern_detail::merge(r.hess, pattern_detail::outer(all, b.dep));
  }
  return r;
}
inline Pattern operator-(const Pattern& a) {
  Pattern r(a);
  r.v = -a.v;
  return r;
}
inline Pattern operator+(const Pattern& a) { return a; }
inline Pattern& operator+=(Pattern& a, const Pattern& b) { return a = a + b; }
inline Pattern& operator-=(Pattern& a, const Pattern& b) { return a = a - b; }
inline Pattern& operator*=(Pattern& a, const Pattern& b) { return a = a * b; }
inline Pattern& operator/=(Pattern& a, const Pattern& b) { return a = a / b; }
inline Pattern sin(const Pattern& a) { return pattern_detail::nonlinear(std::sin(a.v), a); }
inline Pattern cos(const Pattern& a) { return pattern_detail::nonlinear(std::cos(a.v), a); }
inline Pattern tan(const Pattern& a) { return pattern_detail::nonlinear(std::tan(a.v), a); }
inline Pattern exp(const Pattern& a) { return pattern_detail::nonlinear(std::exp(a.v), a); }
inline Pattern log(const Pattern& a) { return pattern_detail::nonlinear(std::log(a.v), a); }
inline Pattern sqrt(const Pattern& a) { return pattern_detail::nonlinear(std::sqrt(a.v), a); }
inline Pattern tanh(const Pattern& a) { return pattern_detail::nonlinear(std::tanh(a.v), a); }
inline Pattern sinh(const Pattern& a) { return pattern_detail::nonlinear(std::sinh(a.v), a); }
inline Pattern cosh(const Pattern& a) { return pattern_detail::nonlinear(std::cosh(a.v), a); }
inline Pattern atan(const Pattern& a) { return pattern_detail::nonlinear(std::atan(a.v), a); }
/// |a| is piecewise linear: its Hessian is zero wherever it exists.
inline Pattern abs(const Pattern& a) {
  Pattern r(a);
  r.v = std::abs(a.v);
  return r;
}
inline Pattern pow(const Pattern& a, double p) {
  if (p == 0.0) return Pattern(1.0);
  if (p == 1.0) return a;
  return pattern_detail::nonlinear(std::pow(a.v, p), a);
}
inline Pattern pow(const Pattern& a, const Pattern& b) {
  if (b.is_constant()) return pow(a, b.v);
  return exp(b * log(a));
}
inline Pattern pow(double a, const Pattern& b) {
  return pattern_detail::nonlinear(std::pow(a, b.v), b);
}

// ---- values and comparisons for every scalar type --------------------------------------------
inline double value_of(double x) { return x; }
template <int N>
inline double value_of(const Jet<N>& x) {
  return x.v;
}
template <class T>
inline double value_of(const Dual<T>& x) {
  return value_of(x.v);
}
inline double value_of(const Pattern& x) { return x.v; }

template <class T>
inline Dual<T> abs(const Dual<T>& a) {
  const double s = value_of(a.v) > 0 ? 1.0 : (value_of(a.v) < 0 ? -1.0 : 0.0);
  return {abs(a.v), s * a.d};
}

inline bool has_derivative(double) { return false; }
template <int N>
inline bool has_derivative(const Jet<N>& x) {
  for (int i = 0; i < x.n; ++i)
    if (x.g[i] != 0.0) return true;
  return false;
}
template <class T>
inline bool has_derivative(const Dual<T>& x) {
  return has_derivative(x.v) || has_derivative(x.d) || value_of(x.d) != 0.0;
}
/// a^b; a constant exponent goes through pow(a, double), so negative bases work.
template <class T>
inline Dual<T> pow(const Dual<T>& a, const Dual<T>& b) {
  if (!has_derivative(b)) return pow(a, value_of(b));
  using std::log;
  using std::pow;
  const T r = pow(a.v, b.v);  // as pow(Jet, Jet): the value of std::pow
  return {r, (b.v * pow(a.v, b.v - 1.0)) * a.d + (r * log(a.v)) * b.d};
}

#define FESD_AD_COMPARISONS(TYPE, TEMPLATE_HEAD)                                         \
  TEMPLATE_HEAD inline bool operator<(const TYPE& a, const TYPE& b) {                    \
    return value_of(a) < value_of(b);                                                    \
  }                                                                                      \
  TEMPLATE_HEAD inline bool operator>(const TYPE& a, const TYPE& b) {                    \
    return value_of(a) > value_of(b);                                                    \
  }                                                                                      \
  TEMPLATE_HEAD inline bool operator<=(const TYPE& a, const TYPE& b) {                   \
    return value_of(a) <= value_of(b);                                                   \
  }                                                                                      \
  TEMPLATE_HEAD inline bool operator>=(const TYPE& a, const TYPE& b) {                   \
    return value_of(a) >= value_of(b);                                                   \
  }                                                                                      \
  TEMPLATE_HEAD inline bool operator==(const TYPE& a, const TYPE& b) {                   \
    return value_of(a) == value_of(b);                                                   \
  }                                                                                      \
  TEMPLATE_HEAD inline bool operator!=(const TYPE& a, const TYPE& b) {                   \
    return value_of(a) != value_of(b);                                                   \
  }                                                                                      \
  TEMPLATE_HEAD inline bool operator==(const TYPE& a, double b) { return value_of(a) == b; } \
  TEMPLATE_HEAD inline bool operator!=(const TYPE& a, double b) { return value_of(a) != b; } \
  TEMPLATE_HEAD inline bool operator<(const TYPE& a, double b) { return value_of(a) < b; }  \
  TEMPLATE_HEAD inline bool operator>(const TYPE& a, double b) { return value_of(a) > b; }  \
  TEMPLATE_HEAD inline bool operator<=(const TYPE& a, double b) { return value_of(a) <= b; } \
  TEMPLATE_HEAD inline bool operator>=(const TYPE& a, double b) { return value_of(a) >= b; } \
  TEMPLATE_HEAD inline bool operator<(double a, const TYPE& b) { return a < value_of(b); }  \
  TEMPLATE_HEAD inline bool operator>(double a, const TYPE& b) { return a > value_of(b); }  \
  TEMPLATE_HEAD inline bool operator<=(double a, const TYPE& b) { return a <= value_of(b); } \
  TEMPLATE_HEAD inline bool operator>=(double a, const TYPE& b) { return a >= value_of(b); }

#define FESD_AD_TEMPLATE_INT template <int N>
#define FESD_AD_TEMPLATE_CLASS template <class T>
#define FESD_AD_NO_TEMPLATE
FESD_AD_COMPARISONS(Jet<N>, FESD_AD_TEMPLATE_INT)
FESD_AD_COMPARISONS(Dual<T>, FESD_AD_TEMPLATE_CLASS)
FESD_AD_COMPARISONS(Pattern, FESD_AD_NO_TEMPLATE)
#undef FESD_AD_COMPARISONS
#undef FESD_AD_TEMPLATE_INT
#undef FESD_AD_TEMPLATE_CLASS
#undef FESD_AD_NO_TEMPLATE

// Pattern arithmetic with plain doubles goes through the implicit constructor; Dual and Jet have
// explicit overloads above. Dual<T> op Jet etc. never occur: one block uses one scalar type.
inline Pattern operator+(const Pattern& a, double b) { return a + Pattern(b); }
inline Pattern operator+(double a, const Pattern& b) { return Pattern(a) + b; }
inline Pattern operator-(const Pattern& a, double b) { return a - Pattern(b); }
inline Pattern operator-(double a, const Pattern& b) { return Pattern(a) - b; }
inline Pattern operator*(const Pattern& a, double b) { return a * Pattern(b); }
inline Pattern operator*(double a, const Pattern& b) { return Pattern(a) * b; }
inline Pattern operator/(const Pattern& a, double b) { return a / Pattern(b); }
inline Pattern operator/(double a, const Pattern& b) { return Pattern(a) / b; }

/// Gradient capacities fesd instantiates; a block with k inputs uses the smallest N >= k.
inline constexpr int kCapacities[] = {8, 32, 128};
inline constexpr int kMaxInputs = 128;

}  // namespace fesd::ad

namespace fesd::math {
// Unqualified math for user models: fesd::math::sin(x) works for double and every fesd scalar.
#define FESD_MATH_FORWARD(name)      \
  template <class T>                 \
  inline T name(const T& x) {        \
    using std::name;                 \
    return name(x);                  \
  }
FESD_MATH_FORWARD(sin)
FESD_MATH_FORWARD(cos)
FESD_MATH_FORWARD(tan)
FESD_MATH_FORWARD(exp)
FESD_MATH_FORWARD(log)
FESD_MATH_FORWARD(sqrt)
FESD_MATH_FORWARD(tanh)
FESD_MATH_FORWARD(sinh)
FESD_MATH_FORWARD(cosh)
FESD_MATH_FORWARD(atan)
FESD_MATH_FORWARD(abs)
#undef FESD_MATH_FORWARD
template <class T>
inline T pow(const T& x, double p) {
  using std::pow;
  return pow(x, p);
}
}  // namespace fesd::math

/// Calls X(type) for every scalar type user functions are instantiated with.
#define FESD_FOR_EACH_SCALAR(X)                                                              \
  X(double)                                                                                  \
  X(::fesd::ad::Jet<8>)                                                                      \
  X(::fesd::ad::Jet<32>) X(::fesd::ad::Jet<128>) X(::fesd::ad::Hyper<8>) X(::fesd::ad::Hyper<32>) \
      X(::fesd::ad::Hyper<128>) X(::fesd::ad::Pattern)
