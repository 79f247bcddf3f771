// src/model/expression.hpp: math expressions from problem files ("x1 + omega*x2",
// "sin(q1)*exp(-t)").
//
// Language:
//   numbers      2  2.5  .5  2.  1e-3  6.02E23   (must be finite doubles)
//   symbols      [A-Za-z_][A-Za-z0-9_]*, looked up in the list given to parse(); the constant `pi`
//                is used only when no symbol is named "pi" (a symbol shadows it)
//   operators    + - * / (left-associative), ^ (right-associative, binds tighter than unary minus:
//                -x^2 = -(x^2), 2^3^2 = 512, x^-1 = 1/x), unary - and +, parentheses
//   functions    sin cos tan exp log sqrt tanh abs sinh cosh atan (one argument), pow(a, b) = a^b.
//                A name followed by '(' is a function call, otherwise a symbol, so a symbol may
//                share a function's name.
//
// parse() compiles the text to a small bytecode program. Constant subexpressions are folded (a
// folded value that is not finite, like 1/0 or log(0), is an error). A constant integer exponent
// |n| <= 64 (x^2, x^3, x^-1, pow(x, 2)) is evaluated by repeated multiplication, exact for every
// scalar type (d(x^2)/dx at x = 0 is 0); x^0 is the constant 1 and x^1 is x. Other exponents use
// pow() of the scalar type. No other algebra is done: 0*x still depends on x.
//
// evaluate<T>() runs the program on a scratch array of values (on the stack for double, Jet<8>
// and Hyper<8>, else one array per thread and type) and allocates nothing in steady state. It is
// instantiated for every type of FESD_FOR_EACH_SCALAR (include/fesd/ad.hpp), and for ad::Dual of
// Hyper<N> (one directional derivative more: model/expression_pds.cpp), and for no other.
#pragma once
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace fesd::expr {

/// A parsed expression: an immutable shared program, cheap to copy, safe to evaluate concurrently.
class Expression {
 public:
  /// The constant 0 (text "0").
  Expression();
  /// Copies share the program. No move operations: a moved-from Expression keeps its value.
  Expression(const Expression&) = default;
  Expression& operator=(const Expression&) = default;

  /// Parses `text`. `symbols` are the input names in evaluation order (states, controls,
  /// parameters, "t", ...); if a name repeats, the first one counts. `where` prefixes every error
  /// message ("oscillator.toml: model.F[1][0]"). Throws fesd::ExpressionError on any problem.
  static Expression parse(std::string_view text, const std::vector<std::string>& symbols,
                          std::string_view where);

  /// Value with inputs[i] = value of symbols[i] (the array must hold all symbols given to parse();
  /// it may be null when is_constant()).
  template <class T>
  T evaluate(const T* inputs) const;

  /// Whether the compiled program reads input `symbol_index` (structurally, after folding).
  bool depends_on(int symbol_index) const;
  /// The indices of the inputs read, sorted.
  const std::vector<int>& dependencies() const;
  /// No input is read: the value is evaluate<double>(nullptr).
  bool is_constant() const { return dependencies().empty(); }
  /// The source text as given to parse().
  const std::string& text() const;

 private:
  struct Program;
  explicit Expression(std::shared_ptr<const Program> program);
  std::shared_ptr<const Program> program_;
};

/// `text` as error messages quote an expression: on one line, at most 60 characters, then "...".
std::string shorten(std::string_view text);

}  // namespace fesd::expr
