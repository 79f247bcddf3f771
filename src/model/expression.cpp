// src/model/expression.cpp: parser, constant folder and evaluator of math expressions.
//
// A recursive-descent parser compiles the text to three-address code: every instruction computes
// one operation of the expression tree from its operands (an input, an earlier result or a
// constant) into a scratch slot. Each result is constructed in place in its slot, and the last
// one directly in evaluate()'s return value, so no value is ever copied (a Jet copy is a memmove
// of its gradient). Slots are reused as soon as their value has been consumed; a slot is never
// the destination of an instruction that reads it. Constant subexpressions are folded while
// parsing, through the same double operations the program would run.
#include "model/expression.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <new>
#include <numbers>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>

#include <fesd/ad.hpp>
#include <fesd/error.hpp>

namespace fesd::expr {
namespace {

// ---- program ------------------------------------------------------------------------------------
// An operand reference r >= 0 is slot r, r < 0 is input ~r. "a", "b" are the instruction's
// operands, "k" its constant.
enum class Op : std::uint8_t {
  kConst,  // k
  kCopy,   // a
  kAdd,    // a + b
  kSub,
  kMul,
  kDiv,
  kPow,   // pow(a, b)
  kAddC,  // a + k
  kSubC,  // a - k
  kCSub,  // k - a
  kMulC,  // a * k
  kDivC,  // a / k
  kCDiv,  // k / a
  kPowC,  // pow(a, k)
  kCPow,  // pow(k, a)
  kIPow,  // a^b by multiplications (b integer, 2 <= |b| <= kMaxIntegerExponent)
  kNeg,
  kSin,
  kCos,
  kTan,
  kExp,
  kLog,
  kSqrt,
  kTanh,
  kAbs,
  kSinh,
  kCosh,
  kAtan,
};

/// Whether b is an operand reference (rather than unused or an exponent).
constexpr bool reads_b(Op op) {
  return op >= Op::kAdd && op <= Op::kPow;
}

struct Instr {
  Op op;
  int dst = 0;  // slot of the result
  int a = 0;
  int b = 0;
  double k = 0.0;
};

constexpr int kMaxIntegerExponent = 64;
constexpr int kMaxNesting = 256;

struct Function {
  std::string_view name;
  int arity;
  Op op;
};
constexpr Function kFunctions[] = {
    {"sin", 1, Op::kSin},   {"cos", 1, Op::kCos},   {"tan", 1, Op::kTan},   {"exp", 1, Op::kExp},
    {"log", 1, Op::kLog},   {"sqrt", 1, Op::kSqrt}, {"tanh", 1, Op::kTanh}, {"abs", 1, Op::kAbs},
    {"sinh", 1, Op::kSinh}, {"cosh", 1, Op::kCosh}, {"atan", 1, Op::kAtan}, {"pow", 2, Op::kPow},
};

/// Nonsmooth functions people write for a switch (lower case): not in the language, because a
/// switch must be a region boundary that FESD can locate (call() explains the region form).
constexpr std::string_view kNonsmoothFunctions[] = {"sign", "sgn",   "signum",    "min",    "max",
                                                    "fmin", "fmax",  "heaviside", "step",   "floor",
                                                    "ceil", "round", "if_else",   "ifelse", "relu"};

bool is_nonsmooth_function(std::string_view name) {
  std::string lower(name);
  for (char& ch : lower)
    if (ch >= 'A' && ch <= 'Z') ch = static_cast<char>(ch - 'A' + 'a');
  return std::find(std::begin(kNonsmoothFunctions), std::end(kNonsmoothFunctions), lower) !=
         std::end(kNonsmoothFunctions);
}

const Function* find_function(std::string_view name) {
  for (const Function& f : kFunctions)
    if (f.name == name) return &f;
  return nullptr;
}

// ---- scalar helpers (every scalar type) ---------------------------------------------------------
/// x^m, m >= 1, by square-and-multiply.
template <class T>
T positive_power(const T& x, int m) {
  if (m <= 1) return x;  // m >= 1 is the caller's promise; never recurse below 1
  if (m == 2) return x * x;
  if (m == 3) return x * x * x;
  const T h = positive_power(x, m / 2);
  return m % 2 != 0 ? h * h * x : h * h;
}
/// x^n for an integer n: x^0 = 1 for every x (as std::pow, also 0^0), x^-n = 1 / x^n.
template <class T>
T integer_power(const T& x, int n) {
  if (n == 0) return T(1.0);
  return n > 0 ? positive_power(x, n) : 1.0 / positive_power(x, -n);
}

/// Whether a value carries no derivative information (a constant for this scalar type).
template <int N>
bool is_passive(const ad::Jet<N>& a) {
  return std::all_of(a.g, a.g + a.n, [](double g) { return g == 0.0; });
}
template <class U>
bool is_passive(const ad::Dual<U>& a) {
  return is_passive(a.v) && is_passive(a.d) && ad::value_of(a.d) == 0.0;
}
inline bool is_passive(const ad::Pattern& a) {
  return a.is_constant();
}

/// pow(a, b) with b computed at run time. A passive b goes through pow(a, double), which is
/// defined for a < 0; ad::pow(Dual, Dual) always takes exp(b log a).
template <class T>
T general_power(const T& a, const T& b) {
  using std::pow;
  if constexpr (std::is_same_v<T, double>) {
    return pow(a, b);
  } else {
    if (is_passive(b)) return pow(a, ad::value_of(b));
    return pow(a, b);
  }
}

bool is_small_integer(double e) {
  return std::trunc(e) == e && std::abs(e) <= kMaxIntegerExponent;
}

/// What the program computes for constant operands; constant folding goes through here.
double fold_unary(Op op, double a) {
  switch (op) {
    case Op::kNeg:
      return -a;
    case Op::kSin:
      return std::sin(a);
    case Op::kCos:
      return std::cos(a);
    case Op::kTan:
      return std::tan(a);
    case Op::kExp:
      return std::exp(a);
    case Op::kLog:
      return std::log(a);
    case Op::kSqrt:
      return std::sqrt(a);
    case Op::kTanh:
      return std::tanh(a);
    case Op::kAbs:
      return std::abs(a);
    case Op::kSinh:
      return std::sinh(a);
    case Op::kCosh:
      return std::cosh(a);
    case Op::kAtan:
      return std::atan(a);
    default:
      return a;
  }
}
double fold_binary(Op op, double a, double b) {
  switch (op) {
    case Op::kAdd:
      return a + b;
    case Op::kSub:
      return a - b;
    case Op::kMul:
      return a * b;
    case Op::kDiv:
      return a / b;
    default:
      return is_small_integer(b) ? integer_power(a, static_cast<int>(b)) : std::pow(a, b);
  }
}

/// The value of one instruction, returned as a prvalue (constructed where the caller wants it).
template <class T>
T apply(const Instr& in, const T* s, const T* x) {
  using std::abs;
  using std::atan;
  using std::cos;
  using std::cosh;
  using std::exp;
  using std::log;
  using std::pow;
  using std::sin;
  using std::sinh;
  using std::sqrt;
  using std::tan;
  using std::tanh;
  if (in.op == Op::kConst) return T(in.k);
  const T& a = in.a >= 0 ? s[in.a] : x[~in.a];
  const auto b = [&]() -> const T& { return in.b >= 0 ? s[in.b] : x[~in.b]; };
  switch (in.op) {
    case Op::kConst:
      break;
    case Op::kCopy:
      return a;
    case Op::kAdd:
      return a + b();
    case Op::kSub:
      return a - b();
    case Op::kMul:
      return a * b();
    case Op::kDiv:
      return a / b();
    case Op::kPow:
      return general_power(a, b());
    case Op::kAddC:
      return a + in.k;
    case Op::kSubC:
      return a - in.k;
    case Op::kCSub:
      return in.k - a;
    case Op::kMulC:
      return a * in.k;
    case Op::kDivC:
      return a / in.k;
    case Op::kCDiv:
      return in.k / a;
    case Op::kPowC:
      return pow(a, in.k);
    case Op::kCPow:
      return pow(in.k, a);
    case Op::kIPow:
      return integer_power(a, in.b);
    case Op::kNeg:
      return -a;
    case Op::kSin:
      return sin(a);
    case Op::kCos:
      return cos(a);
    case Op::kTan:
      return tan(a);
    case Op::kExp:
      return exp(a);
    case Op::kLog:
      return log(a);
    case Op::kSqrt:
      return sqrt(a);
    case Op::kTanh:
      return tanh(a);
    case Op::kAbs:
      return abs(a);
    case Op::kSinh:
      return sinh(a);
    case Op::kCosh:
      return cosh(a);
    case Op::kAtan:
      return atan(a);
  }
  return T(0.0);  // not reached
}

/// Runs `code` (not empty) on inputs x with scratch slots s.
template <class T>
T run(const std::vector<Instr>& code, const T* x, T* s) {
  const Instr* in = code.data();
  const Instr* const last = in + code.size() - 1;
  for (; in != last; ++in) {
    if constexpr (std::is_trivially_destructible_v<T>)
      ::new (static_cast<void*>(s + in->dst)) T(apply(*in, s, x));
    else
      s[in->dst] = apply(*in, s, x);
  }
  return apply(*last, s, x);
}

// ---- text helpers -------------------------------------------------------------------------------
bool is_digit(char c) {
  return c >= '0' && c <= '9';
}
bool is_ident_start(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
bool is_ident_char(char c) {
  return is_ident_start(c) || is_digit(c);
}
bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}
bool is_continuation(char c) {
  return (static_cast<unsigned char>(c) & 0xC0U) == 0x80U;
}

/// Optimal string alignment distance (insertions, deletions, substitutions, transpositions).
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

/// The closest candidate within edit distance 2 (and less than the longer name's length, so "y"
/// does not suggest "x"); the first one on ties; empty if none.
std::string_view closest(std::string_view name, const std::vector<std::string_view>& candidates) {
  std::string_view best;
  std::size_t best_distance = 3;
  for (std::string_view c : candidates) {
    // The distance is at least the difference of the lengths: skip (a long name is cheap).
    if (std::max(name.size(), c.size()) - std::min(name.size(), c.size()) >= best_distance)
      continue;
    const std::size_t dist = edit_distance(name, c);
    if (dist < best_distance && dist < std::max(name.size(), c.size())) {
      best = c;
      best_distance = dist;
    }
  }
  return best;
}

/// Longest part of an expression (in characters) quoted in a message; longer ones end in "...".
constexpr std::size_t kShownChars = 60;

/// `s` as a message quotes it: on one line (control characters as spaces), at most kShownChars
/// UTF-8 characters, then "..." if there is more (a 2 MB expression must not make a 2 MB message).
std::string shown(std::string_view s) {
  std::string out;
  std::size_t chars = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!is_continuation(s[i]) && chars++ == kShownChars) return out + "...";
    out += static_cast<unsigned char>(s[i]) < 0x20 ? ' ' : s[i];
  }
  return out;
}

std::string describe(double v) {
  if (std::isnan(v)) return "nan";
  return v > 0 ? "inf" : "-inf";
}

// ---- parser -------------------------------------------------------------------------------------
struct Token {
  enum Kind { kNumber, kIdent, kPunct, kEnd } kind;
  std::size_t begin, end;  // byte offsets in the text
  double value = 0.0;
};

struct Operand {
  enum Kind { kConst, kInput, kSlot } kind;
  double value = 0.0;      // kConst
  int index = 0;           // kInput: the input; kSlot: the slot
  std::size_t start;       // first instruction of the operand's code
  std::size_t begin, end;  // source span
};

struct Compiled {
  std::vector<Instr> code;
  std::vector<int> deps;
  std::size_t slots = 0;
};

class Parser {
 public:
  Parser(std::string_view text, const std::vector<std::string>& symbols, std::string_view where)
      : text_(text), symbols_(symbols), where_(where) {}

  Compiled run() {
    lex();
    if (tokens_.front().kind == Token::kEnd) syntax("empty expression");
    Operand result = expression();
    if (!at(Token::kEnd)) {
      if (at(')')) syntax("unmatched ')' at column " + column(tok().begin));
      syntax(unexpected());
    }
    return finish(result);
  }

 private:
  std::string_view text_;
  const std::vector<std::string>& symbols_;
  std::string_view where_;
  std::vector<Token> tokens_;
  std::size_t pos_ = 0;
  std::vector<Instr> code_;
  std::vector<bool> busy_;  // slots holding a value not yet consumed
  std::size_t slots_ = 0;
  int nesting_ = 0;

  // -- errors --
  [[noreturn]] void fail(const std::string& message) const {
    if (where_.empty()) throw ExpressionError(message);
    throw ExpressionError(std::string(where_) + ": " + message);
  }
  [[noreturn]] void syntax(const std::string& what) const {
    fail("cannot parse " + quoted() + ": " + what);
  }
  /// The text in quotes, on one line, shortened (shown()).
  std::string quoted() const {
    std::string q = "'";  // (not "'" + std::string&&: GCC 12 -Wrestrict false positive)
    q += shown(text_);
    q += '\'';
    return q;
  }
  std::string span(std::size_t begin, std::size_t end) const {
    return std::string(text_.substr(begin, end - begin));
  }
  /// A part of the text as a message shows it (shown()).
  std::string shown_span(std::size_t begin, std::size_t end) const {
    return shown(text_.substr(begin, end - begin));
  }
  /// 1-based column of a byte offset, counting UTF-8 characters.
  std::string column(std::size_t offset) const {
    std::size_t col = 1;
    for (std::size_t i = 0; i < offset && i < text_.size(); ++i)
      if (!is_continuation(text_[i])) ++col;
    return std::to_string(col);
  }
  std::string unexpected() const {
    const Token& t = tok();
    return "unexpected '" + shown_span(t.begin, t.end) + "' at column " + column(t.begin);
  }
  [[noreturn]] void expected_operand() const {
    const Token& t = tok();
    std::string what = "expected a number, symbol, function or '(' at column " + column(t.begin);
    if (t.kind == Token::kEnd) {
      what += " (end of input)";
    } else if (at('*') && pos_ > 0 && tokens_[pos_ - 1].kind == Token::kPunct &&
               text_[tokens_[pos_ - 1].begin] == '*' && tokens_[pos_ - 1].end == t.begin) {
      what += " (write powers as x^2)";
    }
    syntax(what);
  }
  void check_folded(double v, std::size_t begin, std::size_t end) const {
    if (!std::isfinite(v))
      fail("constant subexpression '" + shown_span(begin, end) + "' evaluates to " + describe(v) +
           " in " + quoted());
  }

  // -- lexer --
  void lex() {
    std::size_t p = 0;
    const std::size_t n = text_.size();
    while (p < n) {
      const char c = text_[p];
      if (is_space(c)) {
        ++p;
      } else if (is_digit(c) || (c == '.' && p + 1 < n && is_digit(text_[p + 1]))) {
        p = lex_number(p);
      } else if (is_ident_start(c)) {
        const std::size_t b = p;
        while (p < n && is_ident_char(text_[p])) ++p;
        tokens_.push_back({Token::kIdent, b, p});
      } else if (std::string_view("+-*/^(),").find(c) != std::string_view::npos) {
        tokens_.push_back({Token::kPunct, p, p + 1});
        ++p;
      } else {
        std::size_t e = p + 1;
        while (e < n && is_continuation(text_[e])) ++e;
        syntax("unexpected character '" + shown_span(p, e) + "' at column " + column(p));
      }
    }
    tokens_.push_back({Token::kEnd, n, n});
  }

  std::size_t lex_number(std::size_t p) {
    const std::size_t b = p;
    const std::size_t n = text_.size();
    while (p < n && is_digit(text_[p])) ++p;
    if (p < n && text_[p] == '.') ++p;
    while (p < n && is_digit(text_[p])) ++p;
    if (p < n && (text_[p] == 'e' || text_[p] == 'E')) {
      std::size_t q = p + 1;
      if (q < n && (text_[q] == '+' || text_[q] == '-')) ++q;
      if (q >= n || !is_digit(text_[q]))
        syntax("malformed number '" + shown_span(b, q) + "' at column " + column(b) +
               ": the exponent has no digits");
      p = q;
      while (p < n && is_digit(text_[p])) ++p;
    }
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(text_.data() + b, text_.data() + p, v);
    if (ec == std::errc::result_out_of_range) {
      if (overflows(b, p))
        fail("number '" + shown_span(b, p) + "' is too large (not a finite double) in " + quoted());
      v = 0.0;  // underflow
    } else if (ec != std::errc() || ptr != text_.data() + p) {
      syntax("malformed number '" + shown_span(b, p) + "' at column " + column(b));
    }
    tokens_.push_back({Token::kNumber, b, p, v});
    return p;
  }

  /// For a number out of range: whether it is too large (rather than too small).
  bool overflows(std::size_t b, std::size_t e) const {
    long long exponent = 0;  // decimal exponent of the first nonzero digit
    long long digits_before_point = 0;
    long long first_nonzero = -1;  // its index among the mantissa digits
    long long index = 0;
    std::size_t p = b;
    bool seen_point = false;
    for (; p < e && text_[p] != 'e' && text_[p] != 'E'; ++p) {
      if (text_[p] == '.') {
        seen_point = true;
        continue;
      }
      if (!seen_point) ++digits_before_point;
      if (text_[p] != '0' && first_nonzero < 0) first_nonzero = index;
      ++index;
    }
    if (p < e) {
      ++p;
      const bool negative = text_[p] == '-';
      if (text_[p] == '+' || text_[p] == '-') ++p;
      for (; p < e; ++p) exponent = std::min(exponent * 10 + (text_[p] - '0'), 1000000LL);
      if (negative) exponent = -exponent;
    }
    return first_nonzero >= 0 && digits_before_point - 1 - first_nonzero + exponent > 0;
  }

  // -- token access --
  const Token& tok() const { return tokens_[pos_]; }
  bool at(Token::Kind kind) const { return tok().kind == kind; }
  bool at(char c) const { return tok().kind == Token::kPunct && text_[tok().begin] == c; }
  void advance() {
    if (tok().kind != Token::kEnd) ++pos_;
  }

  // -- grammar --
  // expression := term (('+' | '-') term)*
  // term       := unary (('*' | '/') unary)*
  // unary      := ('-' | '+') unary | power
  // power      := primary ('^' unary)?
  // primary    := number | symbol | name '(' arguments ')' | '(' expression ')'
  Operand expression() {
    Operand l = term();
    while (at('+') || at('-')) {
      const Op op = at('+') ? Op::kAdd : Op::kSub;
      advance();
      l = combine(op, l, term());
    }
    return l;
  }

  Operand term() {
    Operand l = unary();
    while (at('*') || at('/')) {
      const Op op = at('*') ? Op::kMul : Op::kDiv;
      advance();
      l = combine(op, l, unary());
    }
    return l;
  }

  Operand unary() {
    if (++nesting_ > kMaxNesting)
      syntax("expression nested too deeply (more than " + std::to_string(kMaxNesting) +
             " levels) at column " + column(tok().begin));
    if (!at('-') && !at('+')) {
      Operand a = power();
      --nesting_;
      return a;
    }
    const bool minus = at('-');
    const std::size_t begin = tok().begin;
    advance();
    Operand a = unary();
    a.begin = begin;
    --nesting_;
    return minus ? apply_unary(Op::kNeg, a) : a;
  }

  Operand power() {
    Operand base = primary();
    if (!at('^')) return base;
    advance();
    return make_power(base, unary());
  }

  Operand primary() {
    const Token t = tok();
    switch (t.kind) {
      case Token::kNumber:
        advance();
        return {Operand::kConst, t.value, 0, code_.size(), t.begin, t.end};
      case Token::kIdent:
        advance();
        if (at('(')) return call(t);
        return symbol(t);
      case Token::kPunct:
        if (at('(')) {
          advance();
          Operand a = expression();
          close(t.begin, "'('");
          a.begin = t.begin;
          a.end = tokens_[pos_ - 1].end;
          return a;
        }
        break;
      case Token::kEnd:
        break;
    }
    expected_operand();
  }

  /// Consumes the ')' closing `what`, which starts at byte `open`.
  void close(std::size_t open, const std::string& what) {
    if (at(')')) {
      advance();
      return;
    }
    if (at(Token::kEnd)) syntax("missing ')' for " + what + " at column " + column(open));
    syntax(unexpected());
  }

  int find_symbol(std::string_view name) const {
    for (std::size_t i = 0; i < symbols_.size(); ++i)
      if (symbols_[i] == name) return static_cast<int>(i);
    return -1;
  }

  Operand symbol(const Token& t) {
    const std::string name = span(t.begin, t.end);
    const int index = find_symbol(name);
    if (index >= 0) return {Operand::kInput, 0.0, index, code_.size(), t.begin, t.end};
    if (name == "pi") return {Operand::kConst, std::numbers::pi, 0, code_.size(), t.begin, t.end};
    if (find_function(name))
      fail("'" + name + "' is a function, not a symbol, in " + quoted() + " (write '" + name +
           "(...)')");
    const std::string name_shown = shown(name);
    std::vector<std::string_view> candidates(symbols_.begin(), symbols_.end());
    candidates.push_back("pi");
    std::string message = "unknown symbol '" + name_shown + "' in " + quoted() + " (";
    if (const std::string_view s = closest(name, candidates); !s.empty())
      message += "did you mean '" + shown(s) + "'?; ";
    message += "known symbols: ";
    if (symbols_.empty()) message += "none";
    constexpr std::size_t kListed = 20;  // the message stays one readable line
    for (std::size_t i = 0; i < symbols_.size() && i < kListed; ++i)
      message += (i > 0 ? ", " : "") + shown(symbols_[i]);
    if (symbols_.size() > kListed)
      message += ", ... (" + std::to_string(symbols_.size() - kListed) + " more)";
    fail(message + ")");
  }

  Operand call(const Token& name_token) {
    const std::string name = span(name_token.begin, name_token.end);
    const Function* f = find_function(name);
    const std::string name_shown = shown(name);
    if (!f) {
      if (find_symbol(name) >= 0)
        fail("'" + name + "' is a symbol, not a function, in " + quoted() + " (write '" + name +
             "*(...)' to multiply)");
      if (name == "pi") fail("'pi' is a constant, not a function, in " + quoted());
      if (is_nonsmooth_function(name))
        fail("'" + name_shown + "' in " + quoted() +
             ": nonsmooth functions (sign, min, max, heaviside, step, ...) are not part of the "
             "expression language; write the switch as regions, with switching functions c, a "
             "sign matrix S and one vector field per region in F (one state: x' = -sign(x) is "
             "c = [\"x\"], F = [[\"-1\"], [\"1\"]]; docs/problem-files.md, \"Nonsmooth "
             "functions: regions\"). nosnoc's Heaviside step reformulation is a discretization "
             "option of nosnoc, not a function in expressions");
      std::vector<std::string_view> names;
      std::string list;
      for (const Function& g : kFunctions) {
        names.push_back(g.name);
        list += (list.empty() ? "" : ", ") + std::string(g.name);
      }
      std::string message = "unknown function '" + name_shown + "'";
      if (const std::string_view s = closest(name, names); !s.empty())
        message += " (did you mean '" + std::string(s) + "'?)";
      fail(message + " in " + quoted() + "; functions are " + list);
    }
    advance();  // '('
    std::vector<Operand> args;
    if (!at(')')) {
      args.push_back(expression());
      while (at(',')) {
        advance();
        args.push_back(expression());
      }
    }
    close(name_token.begin, "'" + name + "('");
    const std::size_t begin = name_token.begin;
    const std::size_t end = tokens_[pos_ - 1].end;
    if (static_cast<int>(args.size()) != f->arity)
      fail("'" + name + "' takes " + std::to_string(f->arity) +
           (f->arity == 1 ? " argument" : " arguments") + ", got " + std::to_string(args.size()) +
           ", in " + quoted());
    Operand r =
        f->arity == 1 ? apply_unary(f->op, args[0], begin, end) : make_power(args[0], args[1]);
    r.begin = begin;
    r.end = end;
    return r;
  }

  // -- code generation --
  static int ref(const Operand& o) { return o.kind == Operand::kSlot ? o.index : ~o.index; }
  void release(const Operand& o) {
    if (o.kind == Operand::kSlot) busy_[o.index] = false;
  }
  /// Emits op(a[, b]) into a free slot, then frees the operands' slots.
  Operand produce(Op op, const Operand& a, const Operand* b, double k, int n, std::size_t start,
                  std::size_t begin, std::size_t end) {
    const auto free = std::find(busy_.begin(), busy_.end(), false);
    const int dst = static_cast<int>(free - busy_.begin());
    if (free == busy_.end())
      busy_.push_back(true);
    else
      *free = true;
    slots_ = std::max(slots_, busy_.size());
    release(a);
    if (b) release(*b);
    code_.push_back({op, dst, ref(a), b ? ref(*b) : n, k});
    return {Operand::kSlot, 0.0, dst, start, begin, end};
  }

  Operand apply_unary(Op op, const Operand& a) { return apply_unary(op, a, a.begin, a.end); }
  Operand apply_unary(Op op, Operand a, std::size_t begin, std::size_t end) {
    if (a.kind == Operand::kConst) {
      a.value = fold_unary(op, a.value);
      check_folded(a.value, begin, end);
      return a;
    }
    return produce(op, a, nullptr, 0.0, 0, a.start, begin, end);
  }

  Operand combine(Op op, const Operand& l, const Operand& r) {
    auto pick = [op](Op add, Op sub, Op mul, Op div) {
      return op == Op::kAdd ? add : op == Op::kSub ? sub : op == Op::kMul ? mul : div;
    };
    if (l.kind == Operand::kConst && r.kind == Operand::kConst) {
      const double v = fold_binary(op, l.value, r.value);
      check_folded(v, l.begin, r.end);
      return {Operand::kConst, v, 0, l.start, l.begin, r.end};
    }
    if (r.kind == Operand::kConst)
      return produce(pick(Op::kAddC, Op::kSubC, Op::kMulC, Op::kDivC), l, nullptr, r.value, 0,
                     l.start, l.begin, r.end);
    if (l.kind == Operand::kConst)
      return produce(pick(Op::kAddC, Op::kCSub, Op::kMulC, Op::kCDiv), r, nullptr, l.value, 0,
                     l.start, l.begin, r.end);
    return produce(op, l, &r, 0.0, 0, l.start, l.begin, r.end);
  }

  Operand make_power(Operand base, const Operand& e) {
    const std::size_t begin = base.begin;
    const std::size_t end = e.end;
    if (base.kind == Operand::kConst && e.kind == Operand::kConst) {
      const double v = fold_binary(Op::kPow, base.value, e.value);
      check_folded(v, begin, end);
      return {Operand::kConst, v, 0, base.start, begin, end};
    }
    if (e.kind == Operand::kConst) {
      if (e.value == 0.0) {  // x^0 = 1 for every x, as std::pow: drop the code of x
        code_.erase(code_.begin() + static_cast<std::ptrdiff_t>(base.start), code_.end());
        release(base);
        return {Operand::kConst, 1.0, 0, base.start, begin, end};
      }
      if (e.value == 1.0) {
        base.begin = begin;
        base.end = end;
        return base;
      }
      if (is_small_integer(e.value))
        return produce(Op::kIPow, base, nullptr, 0.0, static_cast<int>(e.value), base.start, begin,
                       end);
      return produce(Op::kPowC, base, nullptr, e.value, 0, base.start, begin, end);
    }
    if (base.kind == Operand::kConst)
      return produce(Op::kCPow, e, nullptr, base.value, 0, base.start, begin, end);
    return produce(Op::kPow, base, &e, 0.0, 0, base.start, begin, end);
  }

  /// The program whose last instruction computes `result`.
  Compiled finish(const Operand& result) {
    if (result.kind == Operand::kConst) code_ = {{Op::kConst, 0, 0, 0, result.value}};
    if (result.kind == Operand::kInput) code_ = {{Op::kCopy, 0, ref(result), 0, 0.0}};
    Compiled c;
    for (const Instr& in : code_) {
      if (in.op != Op::kConst && in.a < 0) c.deps.push_back(~in.a);
      if (reads_b(in.op) && in.b < 0) c.deps.push_back(~in.b);
    }
    std::sort(c.deps.begin(), c.deps.end());
    c.deps.erase(std::unique(c.deps.begin(), c.deps.end()), c.deps.end());
    c.code = std::move(code_);
    c.slots = slots_;
    return c;
  }
};

}  // namespace

std::string shorten(std::string_view text) {
  return shown(text);
}

// ---- Expression ---------------------------------------------------------------------------------
struct Expression::Program {
  std::string text;
  std::vector<Instr> code;  // never empty; the last instruction gives the value
  std::vector<int> deps;
  std::size_t slots = 0;  // scratch slots the code uses
};

Expression::Expression() {
  static const std::shared_ptr<const Program> zero =
      std::make_shared<const Program>(Program{"0", {{Op::kConst, 0, 0, 0, 0.0}}, {}, 0});
  program_ = zero;
}

Expression::Expression(std::shared_ptr<const Program> program) : program_(std::move(program)) {}

Expression Expression::parse(std::string_view text, const std::vector<std::string>& symbols,
                             std::string_view where) {
  Compiled c = Parser(text, symbols, where).run();
  return Expression(std::make_shared<const Program>(
      Program{std::string(text), std::move(c.code), std::move(c.deps), c.slots}));
}

template <class T>
T Expression::evaluate(const T* inputs) const {
  const Program& p = *program_;
  // Small values of trivially destructible types: scratch slots on the stack, raw storage (the
  // slots are constructed by run()). Otherwise one scratch vector per thread and type.
  constexpr std::size_t kLocalBytes = 2048;
  if constexpr (std::is_trivially_destructible_v<T> && sizeof(T) <= kLocalBytes / 8) {
    constexpr std::size_t kLocalSlots = kLocalBytes / sizeof(T);
    if (p.slots <= kLocalSlots) {
      alignas(T) unsigned char local[kLocalSlots * sizeof(T)];
      return run(p.code, inputs, reinterpret_cast<T*>(local));
    }
  }
  thread_local std::vector<T> scratch;
  if (scratch.size() < p.slots) scratch.resize(p.slots);
  return run(p.code, inputs, scratch.data());
}

bool Expression::depends_on(int symbol_index) const {
  return std::binary_search(program_->deps.begin(), program_->deps.end(), symbol_index);
}
const std::vector<int>& Expression::dependencies() const {
  return program_->deps;
}
const std::string& Expression::text() const {
  return program_->text;
}

#define FESD_EXPRESSION_INSTANTIATE(T) template T Expression::evaluate<T>(const T*) const;
FESD_FOR_EACH_SCALAR(FESD_EXPRESSION_INSTANTIATE)
#undef FESD_EXPRESSION_INSTANTIATE
// One directional derivative on top of the Hessian types (grad c(x) lambda of a
// projected dynamical system's constraints, model/expression_pds.cpp; Dual<Jet<N>> = Hyper<N> is
// above, and double takes Jet<8>).
#define FESD_EXPRESSION_INSTANTIATE_DUAL(T) \
  template ad::Dual<T> Expression::evaluate<ad::Dual<T>>(const ad::Dual<T>*) const;
FESD_EXPRESSION_INSTANTIATE_DUAL(::fesd::ad::Hyper<8>)
FESD_EXPRESSION_INSTANTIATE_DUAL(::fesd::ad::Hyper<32>)
FESD_EXPRESSION_INSTANTIATE_DUAL(::fesd::ad::Hyper<128>)
#undef FESD_EXPRESSION_INSTANTIATE_DUAL

}  // namespace fesd::expr
