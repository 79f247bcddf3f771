// tests/model/expression_test.cpp: the math-expression parser and evaluator of problem files.
//
// Values are checked against the C++ standard library, first derivatives (ad::Jet) against central
// differences of the double evaluation, second derivatives (ad::Hyper) against central
// differences of the Jet gradient, and structure (ad::Pattern) against hand-derived sparsity.
#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <fesd/ad.hpp>
#include <fesd/error.hpp>
#include "model/expression.hpp"

namespace fesd::expr {
namespace {

using ad::Hyper;
using ad::Jet;
using ad::Pattern;

const std::vector<std::string> kXyz = {"x", "y", "z"};

Expression parse(const std::string& text, const std::vector<std::string>& symbols = {}) {
  return Expression::parse(text, symbols, "test.toml: model.F[0]");
}

double eval(const std::string& text, const std::vector<std::string>& symbols = {},
            const std::vector<double>& values = {}) {
  return parse(text, symbols).evaluate(values.data());
}

/// The message of the ExpressionError parse() throws, or "<no error>".
std::string error_of(const std::string& text,
                     const std::vector<std::string>& symbols = {"x1", "x2", "omega"}) {
  try {
    parse(text, symbols);
  } catch (const ExpressionError& e) {
    return e.what();
  }
  return "<no error>";
}

#define EXPECT_ERROR(text, substring)                                        \
  do {                                                                       \
    const std::string message_ = error_of(text);                             \
    EXPECT_NE(message_.find(substring), std::string::npos) << message_;      \
    EXPECT_EQ(message_.rfind("test.toml: model.F[0]: ", 0), 0u) << message_; \
    EXPECT_EQ(message_.find('\n'), std::string::npos) << message_;           \
  } while (false)

// ---- values -------------------------------------------------------------------------------------
TEST(Expression, PrecedenceAndAssociativity) {
  const std::pair<const char*, double> cases[] = {
      {"1+2*3", 7.0},      {"(1+2)*3", 9.0},   {"-2^2", -4.0},       {"2^3^2", 512.0},
      {"(2^3)^2", 64.0},   {"8/4/2", 1.0},     {"10-4-3", 3.0},      {"6/2*3", 9.0},
      {"2*3^2", 18.0},     {"2^-1", 0.5},      {"2^-2^2", 0.0625},   {"-2^-2", -0.25},
      {"2*-3", -6.0},      {"1 - -1", 2.0},    {"- -2", 2.0},        {"+3", 3.0},
      {"-(1+2)*4", -12.0}, {"1-2+3", 2.0},     {"2^2*3", 12.0},      {"-2*-2^2", 8.0},
      {"  7 ", 7.0},       {"((((5))))", 5.0}, {"2.5", 2.5},         {".5", 0.5},
      {"2.", 2.0},         {"1e-3", 1e-3},     {"6.02E23", 6.02e23}, {"1E+2", 100.0},
      {"2.5e1", 25.0},     {"1e-999", 0.0},    {"pow(2, 3)", 8.0},   {"pow(2, 3)^2", 64.0},
  };
  for (const auto& [text, expected] : cases) EXPECT_EQ(eval(text), expected) << text;
}

TEST(Expression, FunctionsMatchStd) {
  const std::pair<const char*, std::function<double(double)>> functions[] = {
      {"sin(x)", [](double x) { return std::sin(x); }},
      {"cos(x)", [](double x) { return std::cos(x); }},
      {"tan(x)", [](double x) { return std::tan(x); }},
      {"exp(x)", [](double x) { return std::exp(x); }},
      {"log(abs(x))", [](double x) { return std::log(std::abs(x)); }},
      {"sqrt(abs(x))", [](double x) { return std::sqrt(std::abs(x)); }},
      {"tanh(x)", [](double x) { return std::tanh(x); }},
      {"abs(x)", [](double x) { return std::abs(x); }},
      {"sinh(x)", [](double x) { return std::sinh(x); }},
      {"cosh(x)", [](double x) { return std::cosh(x); }},
      {"atan(x)", [](double x) { return std::atan(x); }},
      {"pow(abs(x), 2.5)", [](double x) { return std::pow(std::abs(x), 2.5); }},
      {"abs(x)^x", [](double x) { return std::pow(std::abs(x), x); }},
      {"3^x", [](double x) { return std::pow(3.0, x); }},
      {"x^2", [](double x) { return x * x; }},
      {"x^3", [](double x) { return x * x * x; }},
      {"x^-1", [](double x) { return 1.0 / x; }},
      {"x^-3", [](double x) { return 1.0 / (x * x * x); }},
      {"x^0", [](double) { return 1.0; }},
      {"x^1", [](double x) { return x; }},
      {"x^70", [](double x) { return std::pow(x, 70.0); }},
  };
  for (const auto& [text, f] : functions) {
    const Expression e = parse(text, {"x"});
    for (double x : {-1.7, -0.3, 0.4, 2.9}) {
      const double got = e.evaluate(&x);
      EXPECT_NEAR(got, f(x), 1e-14 * std::max(1.0, std::abs(f(x)))) << text << " at " << x;
    }
  }
  // Exact where the standard functions are used directly.
  const double x = 0.8;
  EXPECT_EQ(parse("sin(x)", {"x"}).evaluate(&x), std::sin(x));
  EXPECT_EQ(parse("exp(x)", {"x"}).evaluate(&x), std::exp(x));
  EXPECT_EQ(parse("x^0.5", {"x"}).evaluate(&x), std::pow(x, 0.5));
  EXPECT_EQ(parse("x^2", {"x"}).evaluate(&x), x * x);
}

TEST(Expression, Pi) {
  EXPECT_EQ(eval("pi"), std::numbers::pi);
  EXPECT_EQ(eval("2*pi"), 2.0 * std::numbers::pi);
  EXPECT_NEAR(eval("sin(pi/6)"), 0.5, 1e-15);
  EXPECT_NEAR(eval("cos(pi)"), -1.0, 1e-15);
  // A symbol named pi shadows the constant.
  EXPECT_EQ(eval("pi", {"x", "pi"}, {1.0, 3.0}), 3.0);
}

TEST(Expression, Symbols) {
  const std::vector<std::string> symbols = {"x1", "x2", "omega", "t"};
  const std::vector<double> v = {0.5, -2.0, 3.0, 0.25};
  EXPECT_EQ(eval("x1 + omega*x2", symbols, v), 0.5 + 3.0 * -2.0);
  EXPECT_EQ(eval("-0.05*x1^3 + x2", symbols, v), -0.05 * (0.5 * 0.5 * 0.5) + -2.0);
  EXPECT_EQ(eval("sin(x1)*exp(-t)", symbols, v), std::sin(0.5) * std::exp(-0.25));
  EXPECT_EQ(eval("x2 - x1", symbols, v), -2.5);
  EXPECT_EQ(eval("x2 / x1", symbols, v), -4.0);
  EXPECT_EQ(eval("x1 - x2*omega", symbols, v), 6.5);
  EXPECT_EQ(eval("x1 / (x2*omega)", symbols, v), 0.5 / -6.0);
  EXPECT_EQ(eval("(x2*omega) / x1", symbols, v), -12.0);
  EXPECT_EQ(eval("(x2*omega) - x1", symbols, v), -6.5);
  EXPECT_EQ(eval("2 - x2*omega", symbols, v), 8.0);
  EXPECT_EQ(eval("3 / (x2*omega)", symbols, v), -0.5);
  EXPECT_EQ(eval("x1*x1 + t", symbols, v), 0.5);
  EXPECT_EQ(eval("_a1 + B_", {"_a1", "B_"}, {1.0, 2.0}), 3.0);
  // A bare symbol.
  for (const char* text : {"x2", "(x2)", "+x2", "x2^1", "pow(x2, 1)"})
    EXPECT_EQ(eval(text, symbols, v), -2.0) << text;
  // A symbol may share a function's name: only a name followed by '(' is a call.
  EXPECT_EQ(eval("exp(exp)", {"exp"}, {0.0}), 1.0);
  // The first of repeated names counts.
  EXPECT_EQ(eval("a", {"a", "a"}, {1.0, 2.0}), 1.0);
}

TEST(Expression, ConstantFoldingKeepsValues) {
  // The same expression with constants written out and with the constants as inputs.
  const std::vector<std::string> symbols = {"a", "b", "c", "d"};
  const std::vector<double> v = {0.3, 1.7, 2.0, 5.0};
  const std::pair<const char*, const char*> cases[] = {
      {"sin(0.3)*1.7^3 + exp(2)/pi", "sin(a)*b^3 + exp(c)/pi"},
      {"-(1.7 - 5)/0.3^0.5", "-(b - d)/a^0.5"},
      {"pow(1.7, 2) * atan(5) - tanh(0.3) + sqrt(2)*log(5)",
       "pow(b, 2) * atan(d) - tanh(a) + sqrt(c)*log(d)"},
      {"2^0.3 + cosh(1.7)*sinh(0.3) + abs(-5) + tan(0.3)",
       "c^a + cosh(b)*sinh(a) + abs(-d) + tan(a)"},
      {"1.7^-2 + 1.7^5", "b^-2 + b^5"},
  };
  for (const auto& [folded, symbolic] : cases) {
    const Expression f = parse(folded, symbols);
    EXPECT_TRUE(f.is_constant()) << folded;
    EXPECT_TRUE(f.dependencies().empty()) << folded;
    EXPECT_DOUBLE_EQ(f.evaluate<double>(nullptr), eval(symbolic, symbols, v)) << folded;
    const Jet<8> j = f.evaluate<Jet<8>>(nullptr);
    EXPECT_DOUBLE_EQ(j.v, f.evaluate<double>(nullptr));
    EXPECT_EQ(j.n, 0);
  }
  // Folding inside a larger expression: x*(2*3) and x*6 agree, x + 1 + 2 keeps its order.
  const double x = 0.1;
  EXPECT_EQ(eval("x*(2*3)", {"x"}, {x}), x * 6.0);
  EXPECT_EQ(eval("x + 1 + 2", {"x"}, {x}), (x + 1.0) + 2.0);
  EXPECT_EQ(eval("2*3*x", {"x"}, {x}), 6.0 * x);
}

TEST(Expression, EveryScalarTypeGivesTheSameValue) {
  const Expression e = parse("x*y/(1 + z^2) - sqrt(x)*log(y) + tanh(x*z) + 2^z - x^y", kXyz);
  const std::vector<double> x = {0.7, 1.3, -0.4};
  const double expected = e.evaluate(x.data());
  auto check = [&](auto tag) {
    using T = decltype(tag);
    std::vector<T> in(x.begin(), x.end());
    EXPECT_DOUBLE_EQ(ad::value_of(e.evaluate(in.data())), expected);
  };
  check(Jet<8>{});
  check(Jet<32>{});
  check(Jet<128>{});
  check(Hyper<8>{});
  check(Hyper<32>{});
  check(Hyper<128>{});
  check(Pattern{});
}

// ---- derivatives --------------------------------------------------------------------------------
const char* const kSmoothCases[] = {
    "-0.05*x^3 + y",
    "sin(x)*exp(-z)",
    "x*y/(1 + z^2) - sqrt(x)*log(y) + tanh(x*z)",
    "pow(x, y) + atan(x/y) + x^0.5 + cosh(y)*sinh(z) + tan(z)/3",
    "abs(x - y)*2^z - 1/x^2 + (x + y)^-1 + x^y^0.5",
    "2 - x - (y - z)/x - 3/y + x/(y*z) - (y*z)/x + pow(x + y, z*y) - x^70/10",
};
const std::vector<double> kPoint = {0.7, 1.3, -0.4};

std::vector<double> jet_gradient(const Expression& e, std::vector<double> x) {
  const int n = static_cast<int>(x.size());
  std::vector<Jet<8>> in;
  for (int i = 0; i < n; ++i) in.push_back(Jet<8>::variable(x[i], i, n));
  const Jet<8> out = e.evaluate(in.data());
  EXPECT_DOUBLE_EQ(out.v, e.evaluate(x.data()));
  std::vector<double> g;
  for (int i = 0; i < n; ++i) g.push_back(out.d(i));
  return g;
}

double step(double x) {
  return 1e-6 * std::max(1.0, std::abs(x));
}

TEST(Expression, JetGradientMatchesCentralDifferences) {
  for (const char* text : kSmoothCases) {
    const Expression e = parse(text, kXyz);
    const std::vector<double> g = jet_gradient(e, kPoint);
    for (std::size_t i = 0; i < kPoint.size(); ++i) {
      std::vector<double> xp = kPoint, xm = kPoint;
      const double h = step(kPoint[i]);
      xp[i] += h;
      xm[i] -= h;
      const double fd = (e.evaluate(xp.data()) - e.evaluate(xm.data())) / (2.0 * h);
      EXPECT_NEAR(g[i], fd, 1e-7 * std::max(1.0, std::abs(fd))) << text << ", d/d" << kXyz[i];
    }
  }
}

TEST(Expression, HyperHessianMatchesDifferencesOfTheGradient) {
  const int n = 3;
  for (const char* text : kSmoothCases) {
    const Expression e = parse(text, kXyz);
    const std::vector<double> g = jet_gradient(e, kPoint);
    for (int j = 0; j < n; ++j) {
      std::vector<Hyper<8>> in;
      for (int i = 0; i < n; ++i)
        in.emplace_back(Jet<8>::variable(kPoint[i], i, n), Jet<8>(i == j ? 1.0 : 0.0));
      const Hyper<8> out = e.evaluate(in.data());
      EXPECT_DOUBLE_EQ(out.v.v, e.evaluate(kPoint.data())) << text;
      EXPECT_NEAR(out.d.v, g[j], 1e-12 * std::max(1.0, std::abs(g[j]))) << text;
      std::vector<double> xp = kPoint, xm = kPoint;
      const double h = step(kPoint[j]);
      xp[j] += h;
      xm[j] -= h;
      const std::vector<double> gp = jet_gradient(e, xp), gm = jet_gradient(e, xm);
      for (int i = 0; i < n; ++i) {
        EXPECT_NEAR(out.v.d(i), g[i], 1e-12 * std::max(1.0, std::abs(g[i]))) << text;
        const double fd = (gp[i] - gm[i]) / (2.0 * h);
        EXPECT_NEAR(out.d.d(i), fd, 1e-6 * std::max(1.0, std::abs(fd)))
            << text << ", d2/d" << kXyz[j] << "d" << kXyz[i];
      }
    }
  }
}

TEST(Expression, IntegerPowersAreExactAtZero) {
  const Expression square = parse("x^2", {"x"});
  const Jet<8> x0 = Jet<8>::variable(0.0, 0, 1);
  const Jet<8> d = square.evaluate(&x0);
  EXPECT_EQ(d.v, 0.0);
  EXPECT_EQ(d.g[0], 0.0);  // not NaN, as exp(2 log x) would give
  const Jet<8> p = parse("pow(x, 2)", {"x"}).evaluate(&x0);
  EXPECT_EQ(p.g[0], 0.0);
  const Jet<8> cube = parse("x^3 + x^(1+1)", {"x"}).evaluate(&x0);
  EXPECT_EQ(cube.g[0], 0.0);
  const Hyper<8> h0(Jet<8>::variable(0.0, 0, 1), Jet<8>(1.0));
  const Hyper<8> s = square.evaluate(&h0);
  EXPECT_EQ(s.v.g[0], 0.0);
  EXPECT_EQ(s.d.v, 0.0);
  EXPECT_EQ(s.d.g[0], 2.0);
  // Negative bases are fine for integer exponents.
  const Jet<8> xm = Jet<8>::variable(-2.0, 0, 1);
  const Jet<8> inv = parse("x^-1", {"x"}).evaluate(&xm);
  EXPECT_EQ(inv.v, -0.5);
  EXPECT_EQ(inv.g[0], -0.25);
  const Jet<8> c = parse("x^3", {"x"}).evaluate(&xm);
  EXPECT_EQ(c.v, -8.0);
  EXPECT_EQ(c.g[0], 12.0);
}

TEST(Expression, RuntimeConstantExponentWithNegativeBase) {
  // x^p with p an input that carries no derivative (a parameter): defined for x < 0.
  const Expression e = parse("x^p", {"x", "p"});
  const std::vector<Jet<8>> jet_in = {Jet<8>::variable(-1.5, 0, 1), Jet<8>(2.0)};
  const Jet<8> j = e.evaluate(jet_in.data());
  EXPECT_DOUBLE_EQ(j.v, 2.25);
  EXPECT_DOUBLE_EQ(j.g[0], -3.0);
  const std::vector<Hyper<8>> hyper_in = {Hyper<8>(Jet<8>::variable(-1.5, 0, 1), Jet<8>(1.0)),
                                          Hyper<8>(2.0)};
  const Hyper<8> h = e.evaluate(hyper_in.data());
  EXPECT_DOUBLE_EQ(h.v.v, 2.25);
  EXPECT_DOUBLE_EQ(h.v.g[0], -3.0);
  EXPECT_DOUBLE_EQ(h.d.v, -3.0);
  EXPECT_DOUBLE_EQ(h.d.g[0], 2.0);
}

// ---- structure ----------------------------------------------------------------------------------
Pattern pattern_of(const std::string& text) {
  const std::vector<Pattern> in = {Pattern::variable(0.7, 0), Pattern::variable(1.3, 1),
                                   Pattern::variable(-0.4, 2)};
  return parse(text, kXyz).evaluate(in.data());
}
using Pairs = std::vector<std::pair<int, int>>;

TEST(Expression, PatternStructure) {
  const Pattern a = pattern_of("x*y + sin(z)");
  EXPECT_EQ(a.dep, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(a.hess, (Pairs{{1, 0}, {2, 2}}));
  EXPECT_DOUBLE_EQ(a.v, 0.7 * 1.3 + std::sin(-0.4));

  const Pattern b = pattern_of("x^2");
  EXPECT_EQ(b.dep, (std::vector<int>{0}));
  EXPECT_EQ(b.hess, (Pairs{{0, 0}}));

  const Pattern c = pattern_of("3*x + y");
  EXPECT_EQ(c.dep, (std::vector<int>{0, 1}));
  EXPECT_TRUE(c.hess.empty());

  const Pattern d = pattern_of("x/y - 2*abs(z) + x^0");
  EXPECT_EQ(d.dep, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(d.hess, (Pairs{{1, 0}, {1, 1}}));

  const Pattern e = pattern_of("y^-1 + exp(x*z) + 2^y");
  EXPECT_EQ(e.dep, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(e.hess, (Pairs{{0, 0}, {1, 1}, {2, 0}, {2, 2}}));

  const Pattern f = pattern_of("(x - y)/4 - (z + 1)");
  EXPECT_EQ(f.dep, (std::vector<int>{0, 1, 2}));
  EXPECT_TRUE(f.hess.empty());
}

TEST(Expression, DependsOn) {
  const std::vector<std::string> symbols = {"x1", "x2", "omega", "t"};
  const Expression e = parse("x1 + omega*x2", symbols);
  EXPECT_TRUE(e.depends_on(0));
  EXPECT_TRUE(e.depends_on(1));
  EXPECT_TRUE(e.depends_on(2));
  EXPECT_FALSE(e.depends_on(3));
  EXPECT_FALSE(e.depends_on(-1));
  EXPECT_FALSE(e.depends_on(99));
  EXPECT_EQ(e.dependencies(), (std::vector<int>{0, 1, 2}));
  EXPECT_FALSE(e.is_constant());
  // No algebra beyond folding constants: 0*x2 still reads x2. x^0 is the constant 1.
  const Expression z = parse("x1 + 0*x2 + t^0", symbols);
  EXPECT_EQ(z.dependencies(), (std::vector<int>{0, 1}));
  EXPECT_FALSE(z.depends_on(3));
  const Expression c = parse("2*pi + sin(1)", symbols);
  EXPECT_TRUE(c.is_constant());
  EXPECT_FALSE(c.depends_on(0));
  EXPECT_EQ(parse("t^1", symbols).dependencies(), (std::vector<int>{3}));
}

TEST(Expression, ValueSemantics) {
  const Expression def;
  EXPECT_EQ(def.text(), "0");
  EXPECT_EQ(def.evaluate<double>(nullptr), 0.0);
  EXPECT_TRUE(def.is_constant());
  Expression a = parse(" x * 2 ", {"x"});
  const Expression b = a;
  a = parse("x + 1", {"x"});
  const double x = 3.0;
  EXPECT_EQ(b.evaluate(&x), 6.0);
  EXPECT_EQ(a.evaluate(&x), 4.0);
  EXPECT_EQ(b.text(), " x * 2 ");
  EXPECT_EQ(a.text(), "x + 1");
  std::vector<Expression> list;
  list.push_back(std::move(a));
  list.resize(3);
  EXPECT_EQ(list[0].evaluate(&x), 4.0);
  EXPECT_EQ(list[2].evaluate(&x), 0.0);
  EXPECT_EQ(a.evaluate(&x), 4.0);  // NOLINT(bugprone-use-after-move): documented to keep its value
}

TEST(Expression, LargeExpressions) {
  // Deep right nesting needs a long value stack.
  std::string nested = "x*y";
  for (int i = 1; i < 150; ++i) nested = "x*y + (" + nested + ")";
  const std::vector<double> v = {2.0, 3.0};
  EXPECT_DOUBLE_EQ(eval(nested, {"x", "y"}, v), 150 * 6.0);
  const std::vector<Jet<8>> jv = {Jet<8>::variable(2.0, 0, 2), Jet<8>::variable(3.0, 1, 2)};
  const Jet<8> j = parse(nested, {"x", "y"}).evaluate(jv.data());
  EXPECT_DOUBLE_EQ(j.g[0], 150 * 3.0);
  EXPECT_DOUBLE_EQ(j.g[1], 150 * 2.0);
  const std::vector<Jet<128>> j128 = {Jet<128>::variable(2.0, 0, 2), Jet<128>::variable(3.0, 1, 2)};
  EXPECT_DOUBLE_EQ(parse(nested, {"x", "y"}).evaluate(j128.data()).g[1], 150 * 2.0);
  const std::vector<Pattern> pv = {Pattern::variable(2.0, 0), Pattern::variable(3.0, 1)};
  const Pattern pn = parse(nested, {"x", "y"}).evaluate(pv.data());
  EXPECT_DOUBLE_EQ(pn.v, 150 * 6.0);
  EXPECT_EQ(pn.hess, (Pairs{{1, 0}}));
  // A long flat sum.
  std::string sum = "x";
  for (int i = 1; i < 5000; ++i) sum += " + x*y";
  EXPECT_DOUBLE_EQ(eval(sum, {"x", "y"}, v), 2.0 + 4999 * 6.0);
}

// ---- errors -------------------------------------------------------------------------------------
TEST(Expression, SyntaxErrors) {
  EXPECT_EQ(error_of("x1 +* 2"),
            "test.toml: model.F[0]: cannot parse 'x1 +* 2': expected a number, symbol, function "
            "or '(' at column 5");
  EXPECT_EQ(error_of("x1 x2"),
            "test.toml: model.F[0]: cannot parse 'x1 x2': unexpected 'x2' at column 4");
  EXPECT_ERROR("", "cannot parse '': empty expression");
  EXPECT_ERROR("   ", "empty expression");
  EXPECT_ERROR("x1 +", "expected a number, symbol, function or '(' at column 5 (end of input)");
  EXPECT_ERROR("(x1 + 2", "cannot parse '(x1 + 2': missing ')' for '(' at column 1");
  EXPECT_ERROR("sin(x1 + (2)", "missing ')' for 'sin(' at column 1");
  EXPECT_ERROR("x1 + 2)", "unmatched ')' at column 7");
  EXPECT_ERROR("()", "expected a number, symbol, function or '(' at column 2");
  EXPECT_ERROR("(x1 x2)", "unexpected 'x2' at column 5");
  EXPECT_ERROR("pow(x1 x2)", "unexpected 'x2' at column 8");
  EXPECT_ERROR("2x1", "unexpected 'x1' at column 2");
  EXPECT_ERROR("x1 $ 2", "unexpected character '$' at column 4");
  EXPECT_ERROR("x1 · 2", "unexpected character '·' at column 4");
  EXPECT_ERROR("x1**2", "at column 4 (write powers as x^2)");
  EXPECT_ERROR("1e+ x1", "malformed number '1e+' at column 1");
  EXPECT_ERROR("x1 +\n* 2", "cannot parse 'x1 + * 2'");  // on one line
  EXPECT_ERROR(std::string(300, '(') + "x1" + std::string(300, ')'), "nested too deeply");
  EXPECT_ERROR(std::string(300, '-') + "x1", "nested too deeply");
}

TEST(Expression, UnknownSymbols) {
  EXPECT_EQ(error_of("omga*x1"),
            "test.toml: model.F[0]: unknown symbol 'omga' in 'omga*x1' (did you mean 'omega'?; "
            "known symbols: x1, x2, omega)");
  EXPECT_EQ(error_of("zeta*x1"),
            "test.toml: model.F[0]: unknown symbol 'zeta' in 'zeta*x1' (known symbols: x1, x2, "
            "omega)");
  EXPECT_ERROR("X1 + 1", "(did you mean 'x1'?;");
  EXPECT_ERROR("x3", "unknown symbol 'x3' in 'x3' (did you mean 'x1'?;");
  EXPECT_ERROR("pie", "(did you mean 'pi'?;");
  EXPECT_NE(error_of("y").find("unknown symbol 'y' in 'y' (known symbols: x1, x2, omega)"),
            std::string::npos);
  EXPECT_NE(error_of("y", {}).find("(known symbols: none)"), std::string::npos);
}

TEST(Expression, FunctionErrors) {
  EXPECT_ERROR("sine(x1)", "unknown function 'sine' (did you mean 'sin'?) in 'sine(x1)'");
  EXPECT_ERROR("Exp(x1)", "unknown function 'Exp' (did you mean 'exp'?)");
  EXPECT_ERROR("frob(x1)", "unknown function 'frob' in 'frob(x1)'; functions are sin, cos,");
  EXPECT_ERROR("pow(x1)", "'pow' takes 2 arguments, got 1, in 'pow(x1)'");
  EXPECT_ERROR("sin(x1, x2)", "'sin' takes 1 argument, got 2");
  EXPECT_ERROR("sin()", "'sin' takes 1 argument, got 0");
  EXPECT_ERROR("omega(x1 + x2)", "'omega' is a symbol, not a function, in 'omega(x1 + x2)'");
  EXPECT_ERROR("sin*x1", "'sin' is a function, not a symbol, in 'sin*x1'");
  EXPECT_ERROR("2*pi(x1)", "'pi' is a constant, not a function");
}

// Issue 13, 4: a nonsmooth function points to the region form (not "did you mean 'sin'?").
TEST(Expression, NonsmoothFunctionsPointToRegions) {
  EXPECT_EQ(
      error_of("x2 - sign(x1)"),
      "test.toml: model.F[0]: 'sign' in 'x2 - sign(x1)': nonsmooth functions (sign, min, max, "
      "heaviside, step, ...) are not part of the expression language; write the switch as "
      "regions, with switching functions c, a sign matrix S and one vector field per region "
      "in F (one state: x' = -sign(x) is c = [\"x\"], F = [[\"-1\"], [\"1\"]]; "
      "docs/problem-files.md, \"Nonsmooth functions: regions\"). nosnoc's Heaviside step "
      "reformulation is a discretization option of nosnoc, not a function in expressions");
  for (const char* e : {"min(x1, x2)", "max(x1, 0)", "heaviside(x1)", "step(x1)", "Sign(x1)",
                        "sgn(x1)", "fmax(x1, 1)", "if_else(x1, 1, 2)", "floor(x1)"})
    EXPECT_ERROR(e, "nonsmooth functions (sign, min, max, heaviside, step, ...)");
  // abs stays a function (docs/problem-files.md, "Nonsmooth functions: regions"); a symbol named
  // max is called as a symbol is.
  EXPECT_EQ(error_of("abs(x1)"), "<no error>");
  EXPECT_EQ(error_of("2*max", {"max"}), "<no error>");
}

TEST(Expression, NonFiniteConstants) {
  EXPECT_ERROR("1e999*x1", "number '1e999' is too large (not a finite double) in '1e999*x1'");
  EXPECT_ERROR("x1 + 999999999e300", "number '999999999e300' is too large");
  EXPECT_ERROR("x1 + 1/0", "constant subexpression '1/0' evaluates to inf in 'x1 + 1/0'");
  EXPECT_ERROR("x1*log(0)", "constant subexpression 'log(0)' evaluates to -inf");
  EXPECT_ERROR("sqrt(-1) + x1", "constant subexpression 'sqrt(-1)' evaluates to nan");
  EXPECT_ERROR("x1 + (10^400)", "constant subexpression '10^400' evaluates to inf");
  // Only constants are checked: x1/0 is inf at run time.
  EXPECT_EQ(error_of("x1/0"), "<no error>");
}

TEST(Expression, ConstantToThePowerZeroIsOne) {
  // Issue 12, 6(a): folding c^0 recursed without end (SIGSEGV) for every constant c.
  const char* cases[] = {"2^0",   "pow(1, 0)", "2^(1-1)", "0^0",       "(-3)^0",
                         "pi^-0", "2^0 + 1",   "x^(2-2)", "pow(x, 0)", "1e300^0"};
  for (const char* text : cases) {
    const Expression e = parse(text, {"x"});
    const double x = 0.25;
    EXPECT_EQ(e.evaluate(&x), std::string(text) == "2^0 + 1" ? 2.0 : 1.0) << text;
    EXPECT_TRUE(e.is_constant()) << text;
    const Jet<8> j = e.evaluate<Jet<8>>(nullptr);
    EXPECT_EQ(j.n, 0) << text;
  }
  EXPECT_EQ(eval("x^0 * y^(3-3)", {"x", "y"}, {0.0, -2.0}), 1.0);
}

TEST(Expression, VariablePowerHasTheDoubleValueForEveryScalarType) {
  // Found by fuzz/fuzz_expression.cpp: x^y with both variable took exp(y log x) in AD, NaN at
  // x = 0, y = 0 (std::pow gives 1) and for x < 0 with integer y.
  const Expression e = parse("x^y", {"x", "y"});
  for (const auto& [x, y] : {std::pair{0.0, 0.0}, {0.0, -0.0}, {-2.0, 3.0}, {0.5, 1.5}}) {
    const double v = std::pow(x, y);
    const double xy[] = {x, y};
    EXPECT_EQ(e.evaluate(xy), v);
    const Jet<8> jin[] = {Jet<8>::variable(x, 0, 2), Jet<8>::variable(y, 1, 2)};
    const Jet<8> j = e.evaluate(jin);
    EXPECT_EQ(j.v, v) << x << "^" << y;
    const Hyper<8> hin[] = {Hyper<8>(Jet<8>::variable(x, 0, 2), Jet<8>(1.0)),
                            Hyper<8>(Jet<8>::variable(y, 1, 2), Jet<8>(0.0))};
    EXPECT_EQ(e.evaluate(hin).v.v, v) << x << "^" << y;
    if (x > 0) {  // d/dx = y x^(y-1), d/dy = x^y log x
      EXPECT_DOUBLE_EQ(j.g[0], y * std::pow(x, y - 1));
      EXPECT_DOUBLE_EQ(j.g[1], v * std::log(x));
    }
  }
  const double at[] = {-2.0, 3.0};
  const Jet<8> jin[] = {Jet<8>::variable(at[0], 0, 2), Jet<8>::variable(at[1], 1, 2)};
  EXPECT_EQ(e.evaluate(jin).g[0], 12.0);  // d/dx (-2)^3 = 3 * 4
}

TEST(Expression, LongTextIsShortenedInMessages) {
  // Issue 12, 6(d): a 2 MB expression nested too deeply was repeated whole in the message.
  const std::string deep = std::string(1000000, '(') + "x1" + std::string(1000000, ')');
  const std::string message = error_of(deep);
  EXPECT_NE(message.find("nested too deeply"), std::string::npos) << message.substr(0, 200);
  EXPECT_LT(message.size(), 200U) << message.substr(0, 400);
  EXPECT_NE(message.find(std::string("'") + std::string(60, '(') + "...'"), std::string::npos)
      << message;
  // Every part of the text a message quotes is shortened: symbols, functions, numbers.
  const std::string long_name(100000, 'q');
  for (const std::string& text :
       {long_name + " + x1", long_name + "(x1)",
        std::string("x1 + 1") + std::string(100000, '0') + "e999",
        std::string("x1 + ") + std::string(5000, '1') + "/0", "x1 " + long_name}) {
    const std::string m = error_of(text);
    EXPECT_LT(m.size(), 400U) << m.substr(0, 400);
    EXPECT_EQ(m.find('\n'), std::string::npos);
  }
  // Up to 60 characters are quoted whole, UTF-8 characters are not cut.
  EXPECT_ERROR("x1 +* 2", "cannot parse 'x1 +* 2'");
  const std::string sixty = std::string(58, 'x') + " $";
  EXPECT_NE(error_of(sixty).find(std::string("'") + sixty + "'"), std::string::npos)
      << error_of(sixty);
  const std::string utf8 = std::string(59, 'x') + "\u00b7\u00b7 $";
  EXPECT_NE(error_of(utf8).find(std::string("'") + std::string(59, 'x') + "\u00b7...'"),
            std::string::npos)
      << error_of(utf8);
  // Long symbol names and long symbol lists too.
  std::vector<std::string> many;
  for (int i = 0; i < 1000; ++i) many.push_back(std::string(500, 'a') + std::to_string(i));
  const std::string listed = error_of("b", many);
  EXPECT_LT(listed.size(), 2000U) << listed.substr(0, 300);
  EXPECT_NE(listed.find("... (980 more))"), std::string::npos)
      << listed.substr(listed.size() - 100);
  EXPECT_EQ(shorten(std::string(61, 'a')), std::string(60, 'a') + "...");
  EXPECT_EQ(shorten("a\nb"), "a b");
}

TEST(Expression, ErrorWithoutWhere) {
  try {
    Expression::parse("q", {}, "");
    FAIL() << "no error";
  } catch (const ExpressionError& e) {
    EXPECT_EQ(std::string(e.what()), "unknown symbol 'q' in 'q' (known symbols: none)");
  }
}

}  // namespace
}  // namespace fesd::expr
