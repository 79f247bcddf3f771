// src/io/problem_file_reader.hpp: what simulation files (problem_file.cpp) and optimal control
// files (ocp_problem_file.cpp) share: the typed TOML reader with "file:line: what" messages, the
// [model] table, the option table of [discretization], [homotopy] and [ipopt], key hints, and the
// parsing of command-line override values. Internal to src/io; the format is documented in
// docs/problem-files.md.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>
#include <Eigen/Dense>

#include "fesd/error.hpp"
#include "fesd/model.hpp"
#include "fesd/options.hpp"
#include "model/expression.hpp"
#include "model/expression_model.hpp"

namespace fesd::io_detail {

// ---- small helpers ----------------------------------------------------------------------------

std::string join(std::string_view path, std::string_view key);
std::string index(std::string_view path, std::size_t i);
/// "string \"abc\"", "integer 3", "an array of 2", ... for "got ..." in messages.
std::string describe(const toml::node& n);
std::string format_number(double v);
/// "1 number", "2 numbers".
std::string count(std::size_t n, std::string_view noun);
bool is_identifier(std::string_view s);
/// Entries of a table in the order they were written (toml++ keeps tables sorted by key).
std::vector<std::pair<const toml::key*, const toml::node*>> in_file_order(const toml::table& t);
/// "(did you mean 'n_s'?)" with the nearest valid keys, or "(valid keys: ...)" if none is near.
std::string key_hint(std::string_view key, std::span<const std::string_view> valid);

/// The file's text; throws ProblemFileError "<path>: cannot read problem file (...)".
std::string read_problem_text(const std::string& path);
/// TOML syntax; throws ProblemFileError "<file>:<line>:<column>: TOML syntax error: ...".
toml::table parse_toml(std::string_view text, std::string_view source_name);

// ---- the reader -------------------------------------------------------------------------------

/// One parse of one file: the file name for messages and typed accessors that throw
/// "<file>:<line>: <path>: <what>".
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  std::string at(const toml::source_region& s) const {
    return s.begin.line > 0 ? fmt::format("{}:{}", file_, s.begin.line) : file_;
  }
  [[noreturn]] void fail(const toml::source_region& s, std::string_view path,
                         std::string_view what) const {
    if (path.empty()) throw ProblemFileError(fmt::format("{}: {}", at(s), what));
    throw ProblemFileError(fmt::format("{}: {}: {}", at(s), path, what));
  }
  [[noreturn]] void wrong_type(const toml::node& n, std::string_view path,
                               std::string_view expected) const {
    fail(n.source(), path, fmt::format("wrong type (expected {}, got {})", expected, describe(n)));
  }

  void check_keys(const toml::table& t, std::span<const std::string_view> valid,
                  std::string_view path) const {
    for (auto&& [k, v] : t) {
      if (std::find(valid.begin(), valid.end(), k.str()) != valid.end()) continue;
      const std::string where = path.empty() ? "at the top level" : fmt::format("in [{}]", path);
      fail(k.source(), "",
           fmt::format("unknown key '{}' {} {}", expr::shorten(k.str()), where,
                       key_hint(k.str(), valid)));
    }
  }

  const toml::table& table(const toml::node& n, std::string_view path) const {
    if (const toml::table* t = n.as_table()) return *t;
    wrong_type(n, path, "a table");
  }
  const toml::array& array(const toml::node& n, std::string_view path,
                           std::string_view expected) const {
    if (const toml::array* a = n.as_array()) return *a;
    wrong_type(n, path, expected);
  }
  std::string string(const toml::node& n, std::string_view path) const {
    if (const auto* s = n.as_string()) return s->get();
    wrong_type(n, path, "a string");
  }
  bool boolean(const toml::node& n, std::string_view path) const {
    if (const auto* b = n.as_boolean()) return b->get();
    wrong_type(n, path, "a boolean (true or false)");
  }
  /// An integer or a float; must be finite, or (allow_inf) +-inf but never NaN.
  double number(const toml::node& n, std::string_view path, bool allow_inf = false) const {
    double v = 0;
    if (const auto* i = n.as_integer())
      v = static_cast<double>(i->get());
    else if (const auto* f = n.as_floating_point())
      v = f->get();
    else
      wrong_type(n, path, "a number");
    if (std::isnan(v) || (!allow_inf && !std::isfinite(v)))
      throw ProblemFileError(
          fmt::format("{}: {} = {}: must be {}", at(n.source()), path, format_number(v),
                      allow_inf ? "a number (inf and -inf are allowed, nan is not)" : "finite"));
    return v;
  }
  int integer(const toml::node& n, std::string_view path) const {
    const auto* i = n.as_integer();
    if (i == nullptr) wrong_type(n, path, "an integer");
    const std::int64_t v = i->get();
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
      fail(n.source(), path,
           fmt::format("out of range (expected an integer in {}..{}, got {})",
                       std::numeric_limits<int>::min(), std::numeric_limits<int>::max(), v));
    return static_cast<int>(v);
  }
  /// An array of numbers of the given length (-1: any length); allow_inf as for number().
  Eigen::VectorXd vector(const toml::node& n, std::string_view path, int expected_length,
                         std::string_view what, bool allow_inf = false) const {
    const toml::array& a = array(n, path, "an array of numbers");
    if (expected_length >= 0 && static_cast<int>(a.size()) != expected_length)
      fail(n.source(), path,
           fmt::format("wrong length (expected {}, {}, got {})",
                       count(static_cast<std::size_t>(expected_length), "number"), what, a.size()));
    Eigen::VectorXd v(static_cast<Eigen::Index>(a.size()));
    for (std::size_t i = 0; i < a.size(); ++i)
      v[static_cast<Eigen::Index>(i)] = number(a[i], index(path, i), allow_inf);
    return v;
  }
  std::vector<std::pair<std::string, const toml::node*>> names(const toml::node& n,
                                                               std::string_view path) const {
    const toml::array& a = array(n, path, "an array of names");
    std::vector<std::pair<std::string, const toml::node*>> out;
    for (std::size_t i = 0; i < a.size(); ++i)
      out.emplace_back(string(a[i], index(path, i)), &a[i]);
    return out;
  }
  /// A string expression (or a plain number) parsed with `symbols`.
  expr::Expression expression(const toml::node& n, std::string_view path,
                              const std::vector<std::string>& symbols) const {
    std::string text;
    if (const auto* s = n.as_string())
      text = s->get();
    else if (const auto* i = n.as_integer())
      text = fmt::format("{}", i->get());
    else if (n.is_floating_point())
      text = format_number(number(n, path));
    else
      wrong_type(n, path, "an expression (a string such as \"-x1 + 2*u1\", or a number)");
    return expr::Expression::parse(text, symbols, fmt::format("{}: {}", at(n.source()), path));
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

// ---- [model] ----------------------------------------------------------------------------------

/// Names and their symbol layout: [x..., ("t"), u..., p...].
struct Symbols {
  std::vector<std::string> x, u, p;
  std::vector<std::string> all;
  int time_index = -1;  // index of the time slot "t", -1 if a state is named t
  int first_u() const { return static_cast<int>(x.size()) + (time_index >= 0 ? 1 : 0); }
};

/// One subsystem as read: its expressions, sign matrix (empty: all 2^n_c rows) and regions.
struct RawSubsystem {
  ExpressionSubsystem expressions;
  Eigen::MatrixXd S;  // empty: all 2^n_c rows
  int n_f = 0;
};

/// [model] as read, before the clock is decided: names, parameter values and expressions.
struct ModelSpec {
  const toml::table* table = nullptr;
  Symbols sym;
  std::vector<double> p_values;
  std::vector<RawSubsystem> subsystems;
  /// Whether some c, g or F expression reads the time `t` (then a clock state is needed).
  bool uses_time() const;
};

/// Reads the names and expressions of [model] (every check but x0's).
ModelSpec read_model_spec(const Reader& r, const toml::table& root);

/// The Pss of a ModelSpec, with x0 and the parameter values.
struct BuiltModel {
  Pss model;
  Eigen::VectorXd x0;  ///< [model] x0, with t0 appended if there is a clock
  Eigen::VectorXd p;
};

/// Reads [model] x0 and builds the Pss. With `has_clock`, a clock state t with t' = 1 and initial
/// value t0 is appended (docs/problem-files.md, "The time t and the clock state").
BuiltModel build_model(const Reader& r, ModelSpec spec, bool has_clock, double t0);

/// Fails with "<what> cannot depend on controls" if `e` reads a control.
void check_no_controls(const Reader& r, const expr::Expression& e, const toml::node& n,
                       std::string_view path, const Symbols& sym, std::string_view what);

// ---- scalar options: one table for files and overrides ----------------------------------------

enum class Kind {
  Int,
  Double,
  Bool,
  Scheme,
  CrossCompMode,
  StepEqMode,
  StageSignMode,
  Mpcc,
  TerminalMode,  // [ocp] relax_terminal_constraint
  InitMode,      // [ocp] initialization
};

/// A value read from a file or a command line, already converted to the option's kind. Enum
/// names of kinds without a C++ enum here (TerminalMode, InitMode) are kept in `name`.
struct OptionValue {
  int i = 0;
  double d = 0;
  bool b = false;
  RkScheme scheme = RkScheme::RadauIIA;
  CrossComp cross = CrossComp::StageSum;
  StepEq step = StepEq::HeuristicMean;
  StageLambdaSign stage_sign = StageLambdaSign::Auto;
  MpccMode mpcc = MpccMode::ScholtesIneq;
  std::string name;
};

/// One scalar option of a problem type (SimulationProblem or OcpProblem).
template <class Problem>
struct OptionSpec {
  std::string_view table;
  std::string_view key;
  Kind kind;
  void (*set)(Problem&, const OptionValue&);
};

/// The options of [discretization], [homotopy] and [ipopt], for every problem type whose
/// `options` has members discretization, homotopy and nlp.
template <class Problem>
constexpr std::array<OptionSpec<Problem>, 21> solver_option_specs() {
  using P = Problem;
  using V = OptionValue;
  return {{
      {"discretization", "rk_scheme", Kind::Scheme,
       [](P& q, const V& v) { q.options.discretization.rk_scheme = v.scheme; }},
      {"discretization", "n_s", Kind::Int,
       [](P& q, const V& v) { q.options.discretization.n_s = v.i; }},
      {"discretization", "N_finite_elements", Kind::Int,
       [](P& q, const V& v) { q.options.discretization.N_FE = v.i; }},
      {"discretization", "use_fesd", Kind::Bool,
       [](P& q, const V& v) { q.options.discretization.use_fesd = v.b; }},
      {"discretization", "cross_comp_mode", Kind::CrossCompMode,
       [](P& q, const V& v) { q.options.discretization.cross_comp = v.cross; }},
      {"discretization", "step_equilibration", Kind::StepEqMode,
       [](P& q, const V& v) { q.options.discretization.step_eq = v.step; }},
      {"discretization", "stage_lambda_sign", Kind::StageSignMode,
       [](P& q, const V& v) { q.options.discretization.stage_lambda_sign = v.stage_sign; }},
      {"discretization", "gamma_h", Kind::Double,
       [](P& q, const V& v) { q.options.discretization.gamma_h = v.d; }},
      {"discretization", "rho_h", Kind::Double,
       [](P& q, const V& v) { q.options.discretization.rho_h = v.d; }},
      {"discretization", "pin_sliding_exits", Kind::Bool,
       [](P& q, const V& v) { q.options.discretization.pin_sliding_exits = v.b; }},
      {"homotopy", "mpcc_mode", Kind::Mpcc,
       [](P& q, const V& v) { q.options.homotopy.mpcc_mode = v.mpcc; }},
      {"homotopy", "sigma_0", Kind::Double,
       [](P& q, const V& v) { q.options.homotopy.sigma_0 = v.d; }},
      {"homotopy", "homotopy_update_slope", Kind::Double,
       [](P& q, const V& v) { q.options.homotopy.homotopy_update_slope = v.d; }},
      {"homotopy", "sigma_N", Kind::Double,
       [](P& q, const V& v) { q.options.homotopy.sigma_N = v.d; }},
      {"homotopy", "complementarity_tol", Kind::Double,
       [](P& q, const V& v) { q.options.homotopy.complementarity_tol = v.d; }},
      {"homotopy", "N_homotopy", Kind::Int,
       [](P& q, const V& v) { q.options.homotopy.max_homotopy_steps = v.i; }},
      {"homotopy", "intermediate_tol", Kind::Double,
       [](P& q, const V& v) { q.options.homotopy.intermediate_tol = v.d; }},
      {"ipopt", "tol", Kind::Double, [](P& q, const V& v) { q.options.nlp.tol = v.d; }},
      {"ipopt", "acceptable_tol", Kind::Double,
       [](P& q, const V& v) { q.options.nlp.acceptable_tol = v.d; }},
      {"ipopt", "max_iter", Kind::Int, [](P& q, const V& v) { q.options.nlp.max_iter = v.i; }},
      {"ipopt", "print_level", Kind::Int,
       [](P& q, const V& v) { q.options.nlp.print_level = v.i; }},
  }};
}

/// `first` followed by `second`.
template <class T, std::size_t A, std::size_t B>
constexpr std::array<T, A + B> concat(const std::array<T, A>& first,
                                      const std::array<T, B>& second) {
  std::array<T, A + B> out{};
  for (std::size_t i = 0; i < A; ++i) out[i] = first[i];
  for (std::size_t i = 0; i < B; ++i) out[A + i] = second[i];
  return out;
}

/// The keys of `table` among `specs`, in table order, after `extra` (keys handled outside the
/// table, like [simulation] u).
template <class Problem, std::size_t K>
std::vector<std::string_view> keys_of_table(const std::array<OptionSpec<Problem>, K>& specs,
                                            std::string_view table,
                                            std::span<const std::string_view> extra = {}) {
  std::vector<std::string_view> keys(extra.begin(), extra.end());
  for (const OptionSpec<Problem>& o : specs)
    if (o.table == table && std::find(keys.begin(), keys.end(), o.key) == keys.end())
      keys.push_back(o.key);
  return keys;
}

/// The option `key` of `table` (of any table if `table` is empty; the last match), or nullptr:
/// the lookup of a command-line override.
template <class Problem, std::size_t K>
const OptionSpec<Problem>* find_option(const std::array<OptionSpec<Problem>, K>& specs,
                                       std::string_view table, std::string_view key) {
  const OptionSpec<Problem>* spec = nullptr;
  for (const OptionSpec<Problem>& o : specs)
    if (o.key == key && (table.empty() || o.table == table)) spec = &o;
  return spec;
}

/// Parses an enum option name; on failure returns "unknown name (expected one of ...)".
std::optional<std::string> parse_enum(Kind kind, std::string_view name, OptionValue& v);

/// Converts a TOML value to the option's kind; throws ProblemFileError / InvalidOption.
OptionValue read_option(const Reader& r, std::string_view table, std::string_view key, Kind kind,
                        const toml::node& n);

/// An [ipopt] value as IPOPT's option string (numbers shortest exact, booleans yes/no).
std::string ipopt_value(const Reader& r, const toml::node& n, std::string_view path);
/// Appends every key of the [ipopt] table `t` that is not one of fesd's own `keys` to `extra`, in
/// file order, as (name, IPOPT value string).
void read_ipopt_extra(const Reader& r, const toml::table& t,
                      const std::vector<std::string_view>& keys,
                      std::vector<std::pair<std::string, std::string>>& extra);

/// The "table.key" a validate() message starts with ("discretization.n_s = 0: ...").
std::string_view message_key(std::string_view message);

/// Joins validation messages into one InvalidOption, each prefixed with the file and the line of
/// the key it names (or just the file).
[[noreturn]] void throw_validation_errors(const Reader& r, const toml::table& root,
                                          const std::vector<std::string>& errors);

// ---- overrides --------------------------------------------------------------------------------

std::optional<int> parse_int(std::string_view s);
std::optional<double> parse_double(std::string_view s);
std::string trim(std::string_view s);
[[noreturn]] void override_error(const std::string& head, std::string_view what);
/// Parses an override value of `kind` ("3", "1e-9", "true", "gauss_legendre"); throws
/// InvalidOption "<head>: <what>". Numbers must be finite.
OptionValue override_value(Kind kind, const std::string& value, const std::string& head);
/// An override as given: leading dashes dropped, an optional "table." prefix split off and
/// checked against `tables`, "N_FE" read as "N_finite_elements", the value trimmed. `head` is
/// "--<key as given> = <value>", the start of every message about it.
struct OverrideArg {
  std::string_view table, key;
  std::string value, head;
};
OverrideArg parse_override_arg(std::string_view key, std::string_view value,
                               std::span<const std::string_view> tables);
/// Sets the IPOPT option `key` to `value` in `extra`, replacing an earlier value.
void set_ipopt_option(std::vector<std::pair<std::string, std::string>>& extra, std::string_view key,
                      const std::string& value);
/// Joins the validation messages of an override; the key's own "table.key = v: " prefix is
/// dropped (the head already names it).
[[noreturn]] void throw_override_errors(const std::string& head, std::string_view canonical_key,
                                        const std::vector<std::string>& errors);

}  // namespace fesd::io_detail
