// src/io/problem_file_reader.hpp: what simulation files (problem_file.cpp) and optimal control
// files (ocp_problem_file.cpp) share: the typed TOML reader with "file:line: what" messages, the
// [model] table, the option tables read by the option registry (src/core/option_registry.hpp),
// key hints, and the parsing of command-line override values. Internal to src/io; the format is
// documented in docs/problem-files.md.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
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

#include "core/option_registry.hpp"
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
/// "(did you mean 'n_s'?)" with the nearest valid keys (by spelling, or by meaning: nosnoc's names
/// and synonyms such as T for T_sim), or "(<all>: ...)" listing them if none is near.
std::string key_hint(std::string_view key, std::span<const std::string_view> valid,
                     std::string_view all = "valid keys");

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

/// The top-level keys every problem file has: `source` (the file), `name` (default: the file's
/// stem) and `description`.
template <class Problem>  // SimulationProblem or OcpProblem
void read_name(const Reader& r, const toml::table& root, std::string_view source_name,
               Problem& problem) {
  problem.source = std::string(source_name);
  problem.name = std::filesystem::path(std::string(source_name)).stem().string();
  if (const toml::node* n = root.get("name")) {
    problem.name = r.string(*n, "name");
    if (problem.name.empty()) r.fail(n->source(), "name", "empty (expected a non-empty name)");
  }
  if (const toml::node* n = root.get("description"))
    problem.description = r.string(*n, "description");
}

// ---- [model] ----------------------------------------------------------------------------------

/// Names and their symbol layout: [x..., ("t"), u..., p...].
struct Symbols {
  std::vector<std::string> x, u, p, z;  // z: algebraic variables, after p
  std::vector<std::string> all;
  int time_index = -1;  // index of the time slot "t", -1 if a state is named t
  /// The equations g_z read a control: then z depends on u, and what gets no u (c, g, the Mayer
  /// term, terminal constraints) must not read z.
  std::string z_control;  // the first control g_z reads ("": none)
  int first_u() const { return static_cast<int>(x.size()) + (time_index >= 0 ? 1 : 0); }
  int first_z() const { return first_u() + static_cast<int>(u.size() + p.size()); }
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
  /// Algebraic equations g_z (one per name in sym.z) and Newton's start z0 (default zeros).
  std::vector<expr::Expression> g_z;
  Eigen::VectorXd z0;
  /// Whether some c, g, F or g_z expression reads the time `t` (then a clock state is needed).
  bool uses_time() const;
};

/// Reads the names and expressions of [model] (every check but x0's).
ModelSpec read_model_spec(const Reader& r, const toml::table& root);

/// The Pss of a ModelSpec, with x0 and the parameter values.
struct BuiltModel {
  Pss model;
  /// The algebraic equations (null without z): the [ocp] expressions read z too.
  std::shared_ptr<const AlgebraicEquations> algebraic;
  Eigen::VectorXd x0;  ///< [model] x0, with t0 appended if there is a clock
  Eigen::VectorXd p;
};

/// Reads [model] x0 and builds the Pss. With `has_clock`, a clock state t with t' = 1 and initial
/// value t0 is appended (docs/problem-files.md, "The time t and the clock state").
BuiltModel build_model(const Reader& r, ModelSpec spec, bool has_clock, double t0);

/// Fails with "<what> cannot depend on controls" if `e` reads a control.
void check_no_controls(const Reader& r, const expr::Expression& e, const toml::node& n,
                       std::string_view path, const Symbols& sym, std::string_view what);

// ---- options: the keys of the option registry (src/core/option_registry.hpp) -------------------

/// The value of `o` in a file, converted to the registry's number (Bool 0/1, Enum the index);
/// throws ProblemFileError (type, NaN) or InvalidOption (unknown enum name).
double read_option(const Reader& r, const registry::Option& o, const toml::node& n);

/// Fails on a key of `t` that problems of `kind` do not have in `table` ([ipopt] takes any key).
void check_table_keys(const Reader& r, const toml::table& t, registry::Table table,
                      registry::Use kind);
/// Fails with "missing key 'T' (expected the length of the horizon, a number > 0)" if the table's
/// required key is absent.
void check_required_key(const Reader& r, const toml::table& t, registry::Table table);
/// "missing table [ocp] (expected at least T, the length of the horizon)".
[[noreturn]] void fail_missing_table(const Reader& r, registry::Table table);

/// Reads every scalar option of `table` that `kind` has into `target`, except the keys in
/// `read_elsewhere`; in [ipopt], every other key goes to `extra` (IPOPT's own options).
void read_option_table(const Reader& r, const toml::table& t, registry::Table table,
                       registry::Use kind, const registry::OptionTarget& target,
                       std::vector<std::pair<std::string, std::string>>& extra,
                       std::span<const std::string_view> read_elsewhere = {});

/// An [ipopt] value as IPOPT's option string (numbers shortest exact, booleans yes/no).
std::string ipopt_value(const Reader& r, const toml::node& n, std::string_view path);

/// The key path a validation message starts with: "discretization.n_s" of
/// "discretization.n_s = 0: ...", "model.x0[1]" of "model.x0[1]: 2 is outside ...".
std::string_view message_key(std::string_view message);

/// The messages joined by "; ", each prefixed with the file and the line of the key it names (or
/// just the file).
std::string located(const Reader& r, const toml::table& root,
                    const std::vector<std::string>& messages);
/// throw InvalidOption(located(...)).
[[noreturn]] void throw_validation_errors(const Reader& r, const toml::table& root,
                                          const std::vector<std::string>& errors);

// ---- overrides --------------------------------------------------------------------------------

std::optional<int> parse_int(std::string_view s);
std::optional<double> parse_double(std::string_view s);
std::string trim(std::string_view s);
[[noreturn]] void override_error(const std::string& head, std::string_view what);
/// Parses an override value of `o` ("3", "1e-9", "true", "gauss_legendre") into the registry's
/// number; throws InvalidOption "<head>: <what>". Numbers must be finite.
double override_value(const registry::Option& o, const std::string& value, const std::string& head);
/// An override as given: leading dashes dropped, an optional "table." prefix split off and
/// checked against the tables of `kind`, the value trimmed, and the registry option it names (by
/// key or alias, within the table if one is given; nullptr if none). `head` is
/// "--<key as given> = <value>", the start of every message about it.
struct OverrideArg {
  std::string_view table, key;
  std::string value, head;
  const registry::Option* option = nullptr;
};
OverrideArg parse_override_arg(std::string_view key, std::string_view value, registry::Use kind);
/// Sets a scalar option, or returns false for a key that is not one (Input keys, IPOPT's own).
bool set_scalar_override(const OverrideArg& a, const registry::OptionTarget& target);
/// Sets the IPOPT option `key` to `value` in `extra`, replacing an earlier value.
void set_ipopt_option(std::vector<std::pair<std::string, std::string>>& extra, std::string_view key,
                      const std::string& value);
/// Comma-separated numbers ("0.5, -2", "" for none) as an override value of `path` ("model.x0"):
/// exactly n of them (`what`: "one per state"), all finite; throws InvalidOption "<head>: ...".
Eigen::VectorXd override_vector(const std::string& head, std::string_view value, int n,
                                std::string_view path, std::string_view what);
/// "p" ("NAME=VALUE", one parameter of `names`, stored in p and p_default), with or without the
/// "model." prefix; false for any other key. Shared by piecewise smooth and projected models.
bool set_parameter_override(const OverrideArg& a, const std::vector<std::string>& names,
                            Eigen::VectorXd& p, Eigen::VectorXd& p_default);
/// The [model] overrides both kinds of problem have: "x0" (n_x numbers, the states of model.x;
/// a clock keeps its start value) and "p" ("NAME=VALUE", one parameter of model.p, also stored
/// as model.p_default), with or without the "model." prefix. False for any other key.
bool set_model_override(const OverrideArg& a, Pss& model, bool has_clock, Eigen::VectorXd& x0,
                        Eigen::VectorXd& p);
/// "unknown option 'n_S' (did you mean 'n_s'?)"; for a key that only a file can set, says so; for
/// a parameter name of `model`, shows the --p form.
[[noreturn]] void unknown_override(const OverrideArg& a, registry::Use kind, const Pss& model);
/// Joins the validation messages of an override; the overridden key's own "table.key = v: "
/// prefix is dropped (the head already names it).
[[noreturn]] void throw_override_errors(const OverrideArg& a,
                                        const std::vector<std::string>& errors);

}  // namespace fesd::io_detail
