// src/io/problem_file.cpp: problem files (TOML) -> SimulationProblem. The format is documented in
// docs/problem-files.md; every check here has a line there.
//
// Reading order: syntax (toml++), unknown keys per table, then [model] (names, expressions, sign
// matrices, vector fields, x0), [simulation], [discretization], [homotopy], [ipopt], and finally
// the option ranges of validate() (options.hpp). The first mistake found is thrown as
// "<file>:<line>: <key path>: <what is wrong> (<expected>, got <got>)".
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "fesd/error.hpp"
#include "fesd/problem_file.hpp"
#include "model/expression.hpp"
#include "model/expression_model.hpp"

namespace fesd {
namespace {

// ---- key tables ------------------------------------------------------------------------------

constexpr std::array<std::string_view, 7> kTopKeys{
    "name", "description", "model", "simulation", "discretization", "homotopy", "ipopt"};
constexpr std::array<std::string_view, 9> kModelKeys{"x", "u", "p",  "c",        "S",
                                                     "F", "g", "x0", "subsystem"};
constexpr std::array<std::string_view, 4> kSubsystemKeys{"c", "S", "g", "F"};
constexpr std::array<std::string_view, 4> kSimulationKeys{"T_sim", "N_sim", "u", "t0"};

// Names the expression language reserves (src/model/expression.hpp).
constexpr std::array<std::string_view, 13> kReservedNames{
    "sin", "cos", "tan", "exp", "log", "sqrt", "tanh", "abs", "sinh", "cosh", "atan", "pow", "pi"};

// ---- scalar options: one table for files and overrides ----------------------------------------

enum class Kind { Int, Double, Bool, Scheme, CrossCompMode, StepEqMode, StageSignMode, Mpcc };

/// A value read from a file or a command line, already converted to the option's kind.
struct OptionValue {
  int i = 0;
  double d = 0;
  bool b = false;
  RkScheme scheme = RkScheme::RadauIIA;
  CrossComp cross = CrossComp::StageSum;
  StepEq step = StepEq::HeuristicMean;
  StageLambdaSign stage_sign = StageLambdaSign::Auto;
  MpccMode mpcc = MpccMode::ScholtesIneq;
};

struct OptionSpec {
  std::string_view table;
  std::string_view key;
  Kind kind;
  void (*set)(SimulationProblem&, const OptionValue&);
};

using Sp = SimulationProblem;
using Ov = OptionValue;

// Every scalar option: table, file key, kind, and where it goes.
constexpr std::array<OptionSpec, 21> kOptions{{
    {"simulation", "T_sim", Kind::Double, [](Sp& q, const Ov& v) { q.T_sim = v.d; }},
    {"simulation", "N_sim", Kind::Int, [](Sp& q, const Ov& v) { q.N_sim = v.i; }},
    {"discretization", "rk_scheme", Kind::Scheme,
     [](Sp& q, const Ov& v) { q.options.discretization.rk_scheme = v.scheme; }},
    {"discretization", "n_s", Kind::Int,
     [](Sp& q, const Ov& v) { q.options.discretization.n_s = v.i; }},
    {"discretization", "N_finite_elements", Kind::Int,
     [](Sp& q, const Ov& v) { q.options.discretization.N_FE = v.i; }},
    {"discretization", "use_fesd", Kind::Bool,
     [](Sp& q, const Ov& v) { q.options.discretization.use_fesd = v.b; }},
    {"discretization", "cross_comp_mode", Kind::CrossCompMode,
     [](Sp& q, const Ov& v) { q.options.discretization.cross_comp = v.cross; }},
    {"discretization", "step_equilibration", Kind::StepEqMode,
     [](Sp& q, const Ov& v) { q.options.discretization.step_eq = v.step; }},
    {"discretization", "stage_lambda_sign", Kind::StageSignMode,
     [](Sp& q, const Ov& v) { q.options.discretization.stage_lambda_sign = v.stage_sign; }},
    {"discretization", "gamma_h", Kind::Double,
     [](Sp& q, const Ov& v) { q.options.discretization.gamma_h = v.d; }},
    {"discretization", "rho_h", Kind::Double,
     [](Sp& q, const Ov& v) { q.options.discretization.rho_h = v.d; }},
    {"homotopy", "mpcc_mode", Kind::Mpcc,
     [](Sp& q, const Ov& v) { q.options.homotopy.mpcc_mode = v.mpcc; }},
    {"homotopy", "sigma_0", Kind::Double,
     [](Sp& q, const Ov& v) { q.options.homotopy.sigma_0 = v.d; }},
    {"homotopy", "homotopy_update_slope", Kind::Double,
     [](Sp& q, const Ov& v) { q.options.homotopy.homotopy_update_slope = v.d; }},
    {"homotopy", "sigma_N", Kind::Double,
     [](Sp& q, const Ov& v) { q.options.homotopy.sigma_N = v.d; }},
    {"homotopy", "complementarity_tol", Kind::Double,
     [](Sp& q, const Ov& v) { q.options.homotopy.complementarity_tol = v.d; }},
    {"homotopy", "N_homotopy", Kind::Int,
     [](Sp& q, const Ov& v) { q.options.homotopy.max_homotopy_steps = v.i; }},
    {"ipopt", "tol", Kind::Double, [](Sp& q, const Ov& v) { q.options.nlp.tol = v.d; }},
    {"ipopt", "acceptable_tol", Kind::Double,
     [](Sp& q, const Ov& v) { q.options.nlp.acceptable_tol = v.d; }},
    {"ipopt", "max_iter", Kind::Int, [](Sp& q, const Ov& v) { q.options.nlp.max_iter = v.i; }},
    {"ipopt", "print_level", Kind::Int,
     [](Sp& q, const Ov& v) { q.options.nlp.print_level = v.i; }},
}};

std::vector<std::string_view> keys_of_table(std::string_view table) {
  std::vector<std::string_view> keys;
  if (table == "simulation") keys.assign(kSimulationKeys.begin(), kSimulationKeys.end());
  for (const OptionSpec& o : kOptions)
    if (o.table == table && std::find(keys.begin(), keys.end(), o.key) == keys.end())
      keys.push_back(o.key);
  return keys;
}

template <class E, std::size_t K>
std::string name_list(const std::array<E, K>& values) {
  std::string s;
  for (E v : values) s += (s.empty() ? "" : ", ") + std::string(to_string(v));
  return s;
}
constexpr std::array<RkScheme, 5> kSchemes{RkScheme::RadauIIA, RkScheme::GaussLegendre,
                                           RkScheme::LobattoIIIA, RkScheme::LobattoIIIC,
                                           RkScheme::ExplicitRK};
constexpr std::array<CrossComp, 4> kCrossComps{CrossComp::Sparse, CrossComp::StageSum,
                                               CrossComp::Element, CrossComp::Neighbor};
constexpr std::array<StepEq, 5> kStepEqs{StepEq::None, StepEq::Eta, StepEq::EtaTanh,
                                         StepEq::HeuristicMean, StepEq::L2Relaxed};
constexpr std::array<StageLambdaSign, 3> kStageSigns{
    StageLambdaSign::All, StageLambdaSign::Boundary, StageLambdaSign::Auto};
constexpr std::array<MpccMode, 5> kMpccModes{MpccMode::ScholtesIneq, MpccMode::ScholtesEq,
                                             MpccMode::FischerBurmeister, MpccMode::L1Penalty,
                                             MpccMode::ElasticIneq};

/// Parses an enum option name; on failure returns "unknown name (expected one of ...)".
std::optional<std::string> parse_enum(Kind kind, std::string_view name, OptionValue& v) {
  std::string valid;
  switch (kind) {
    case Kind::Scheme:
      if (parse(name, v.scheme)) return std::nullopt;
      valid = name_list(kSchemes);
      break;
    case Kind::CrossCompMode:
      if (parse(name, v.cross)) return std::nullopt;
      valid = name_list(kCrossComps);
      break;
    case Kind::StepEqMode:
      if (parse(name, v.step)) return std::nullopt;
      valid = name_list(kStepEqs);
      break;
    case Kind::StageSignMode:
      if (parse(name, v.stage_sign)) return std::nullopt;
      valid = name_list(kStageSigns);
      break;
    case Kind::Mpcc:
      if (parse(name, v.mpcc)) return std::nullopt;
      valid = name_list(kMpccModes);
      break;
    default:
      break;
  }
  return fmt::format("unknown name (expected one of {}; got \"{}\")", valid, name);
}

// ---- nearest keys ------------------------------------------------------------------------------

std::string lower(std::string_view s) {
  std::string r(s);
  for (char& ch : r)
    if (ch >= 'A' && ch <= 'Z') ch = static_cast<char>(ch - 'A' + 'a');
  return r;
}

/// Optimal-string-alignment distance (insertions, deletions, substitutions, transpositions).
int edit_distance(std::string_view a, std::string_view b) {
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::vector<int>> d(n + 1, std::vector<int>(m + 1, 0));
  for (std::size_t i = 0; i <= n; ++i) d[i][0] = static_cast<int>(i);
  for (std::size_t j = 0; j <= m; ++j) d[0][j] = static_cast<int>(j);
  for (std::size_t i = 1; i <= n; ++i)
    for (std::size_t j = 1; j <= m; ++j) {
      const int cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[n][m];
}

/// "(did you mean 'n_s'?)" with the nearest valid keys, or "(valid keys: ...)" if none is near.
std::string key_hint(std::string_view key, std::span<const std::string_view> valid) {
  // nosnoc's names (MATLAB and Python) and the paper's symbols that differ from the file keys.
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 11> kAliases{{
      {"n_fe", "N_finite_elements"},
      {"max_homotopy_steps", "N_homotopy"},
      {"max_iter_homotopy", "N_homotopy"},
      {"comp_tol", "complementarity_tol"},
      {"terminal_time", "T_sim"},
      {"irk_scheme", "rk_scheme"},
      {"cross_comp", "cross_comp_mode"},
      {"g_ind", "g"},
      {"g_indicator", "g"},
      {"g_stewart", "g"},
      {"p_global", "p"},
  }};
  const std::string k = lower(key);
  std::vector<std::pair<int, std::string_view>> near;
  for (std::string_view v : valid) {
    const std::string lv = lower(v);
    int d = edit_distance(k, lv);
    for (const auto& [alias, target] : kAliases)
      if (alias == k && target == v) d = 0;
    if (k.size() >= 3 && lv.size() >= 3 &&
        (lv.find(k) != std::string::npos || k.find(lv) != std::string::npos))
      d = std::min(d, 1);
    const int threshold = std::max<int>(1, std::min<int>(3, static_cast<int>(k.size()) / 3 + 1));
    if (d <= threshold) near.emplace_back(d, v);
  }
  // Only the nearest ones; among equally near keys, those of similar length first.
  if (!near.empty()) {
    const int best = std::min_element(near.begin(), near.end())->first;
    std::erase_if(near, [&](const auto& e) { return e.first > best; });
  }
  const auto length_gap = [&](std::string_view v) {
    return std::abs(static_cast<int>(v.size()) - static_cast<int>(k.size()));
  };
  std::stable_sort(near.begin(), near.end(), [&](const auto& a, const auto& b) {
    return length_gap(a.second) < length_gap(b.second);
  });
  std::string list;
  if (near.empty()) {
    for (std::string_view v : valid) list += (list.empty() ? "" : ", ") + std::string(v);
    return fmt::format("(valid keys: {})", list);
  }
  const std::size_t n = std::min<std::size_t>(near.size(), 3);
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) list += i + 1 == n ? " or " : ", ";
    list += fmt::format("'{}'", near[i].second);
  }
  return fmt::format("(did you mean {}?)", list);
}

// ---- small helpers ----------------------------------------------------------------------------

std::string join(std::string_view path, std::string_view key) {
  return path.empty() ? std::string(key) : fmt::format("{}.{}", path, key);
}
std::string index(std::string_view path, std::size_t i) {
  return fmt::format("{}[{}]", path, i);
}

std::string describe(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: {
      std::string s = n.as_string()->get();
      if (s.size() > 40) s = s.substr(0, 37) + "...";
      return fmt::format("string \"{}\"", s);
    }
    case toml::node_type::integer:
      return fmt::format("integer {}", n.as_integer()->get());
    case toml::node_type::floating_point:
      return fmt::format("float {}", n.as_floating_point()->get());
    case toml::node_type::boolean:
      return fmt::format("boolean {}", n.as_boolean()->get());
    case toml::node_type::array:
      return fmt::format("an array of {}", n.as_array()->size());
    case toml::node_type::table:
      return "a table";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    default:
      return "nothing";
  }
}

bool is_identifier(std::string_view s) {
  if (s.empty()) return false;
  const auto alpha = [](char ch) {
    return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || ch == '_';
  };
  if (!alpha(s[0])) return false;
  return std::all_of(s.begin() + 1, s.end(),
                     [&](char ch) { return alpha(ch) || (ch >= '0' && ch <= '9'); });
}

bool before(const toml::source_region& a, const toml::source_region& b) {
  return a.begin.line != b.begin.line ? a.begin.line < b.begin.line
                                      : a.begin.column < b.begin.column;
}

/// Entries of a table in the order they were written (toml++ keeps tables sorted by key).
std::vector<std::pair<const toml::key*, const toml::node*>> in_file_order(const toml::table& t) {
  std::vector<std::pair<const toml::key*, const toml::node*>> entries;
  for (auto&& [k, v] : t) entries.emplace_back(&k, &v);
  std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    return before(a.first->source(), b.first->source());
  });
  return entries;
}

std::string format_number(double v) {
  return fmt::format("{}", v);
}

/// "1 number", "2 numbers".
std::string count(std::size_t n, std::string_view noun) {
  return fmt::format("{} {}{}", n, noun, n == 1 ? "" : "s");
}

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
           fmt::format("unknown key '{}' {} {}", k.str(), where, key_hint(k.str(), valid)));
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
  /// An integer or a float; must be finite.
  double number(const toml::node& n, std::string_view path) const {
    double v = 0;
    if (const auto* i = n.as_integer())
      v = static_cast<double>(i->get());
    else if (const auto* f = n.as_floating_point())
      v = f->get();
    else
      wrong_type(n, path, "a number");
    if (!std::isfinite(v))
      throw ProblemFileError(
          fmt::format("{}: {} = {}: must be finite", at(n.source()), path, format_number(v)));
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
  /// An array of numbers of the given length (-1: any length).
  Eigen::VectorXd vector(const toml::node& n, std::string_view path, int expected_length,
                         std::string_view what) const {
    const toml::array& a = array(n, path, "an array of numbers");
    if (expected_length >= 0 && static_cast<int>(a.size()) != expected_length)
      fail(n.source(), path,
           fmt::format("wrong length (expected {}, {}, got {})",
                       count(static_cast<std::size_t>(expected_length), "number"), what, a.size()));
    Eigen::VectorXd v(static_cast<Eigen::Index>(a.size()));
    for (std::size_t i = 0; i < a.size(); ++i)
      v[static_cast<Eigen::Index>(i)] = number(a[i], index(path, i));
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

void check_names(const Reader& r,
                 const std::vector<std::pair<std::string, const toml::node*>>& names,
                 std::string_view path, std::string_view kind, std::set<std::string>& seen,
                 bool t_allowed) {
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto& [name, node] = names[i];
    const std::string p = index(path, i);
    if (!is_identifier(name))
      r.fail(node->source(), p,
             fmt::format("invalid {} name (expected an identifier [A-Za-z_][A-Za-z0-9_]*, got "
                         "\"{}\")",
                         kind, name));
    if (std::find(kReservedNames.begin(), kReservedNames.end(), name) != kReservedNames.end())
      r.fail(node->source(), p,
             fmt::format("'{}' is reserved by the expression language (functions sin cos tan exp "
                         "log sqrt tanh abs sinh cosh atan pow and the constant pi); choose "
                         "another {} name",
                         name, kind));
    if (name == "t" && !t_allowed)
      r.fail(node->source(), p,
             fmt::format("'t' is the time; only a state may be named t (got a {} named t)", kind));
    if (!seen.insert(name).second)
      r.fail(node->source(), p,
             fmt::format("duplicate name '{}' (names must be unique across x, u and p)", name));
  }
}

void check_no_controls(const Reader& r, const expr::Expression& e, const toml::node& n,
                       std::string_view path, const Symbols& sym, std::string_view what) {
  for (std::size_t j = 0; j < sym.u.size(); ++j)
    if (e.depends_on(sym.first_u() + static_cast<int>(j)))
      r.fail(n.source(), path,
             fmt::format("{} cannot depend on controls (expected a function of x and p, got "
                         "control '{}' in \"{}\")",
                         what, sym.u[j], e.text()));
}

Eigen::MatrixXd read_sign_matrix(const Reader& r, const toml::node& n, std::string_view path,
                                 int n_c) {
  const toml::array& rows = r.array(n, path, "an array of rows of +1/-1");
  if (rows.empty()) r.fail(n.source(), path, "no rows (expected one row of +1/-1 per region)");
  Eigen::MatrixXd S(static_cast<Eigen::Index>(rows.size()), n_c);
  std::set<std::vector<int>> seen;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string rp = index(path, i);
    const toml::array& row = r.array(rows[i], rp, "a row of +1/-1");
    if (static_cast<int>(row.size()) != n_c)
      r.fail(rows[i].source(), rp,
             fmt::format("wrong length (expected {} entries, one per switching function in c, "
                         "got {})",
                         n_c, row.size()));
    std::vector<int> signs;
    for (std::size_t j = 0; j < row.size(); ++j) {
      const std::string ep = index(rp, j);
      const double v = r.number(row[j], ep);
      if (v != 1.0 && v != -1.0)
        r.fail(row[j].source(), ep, fmt::format("bad sign (expected 1 or -1, got {})", v));
      S(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = v;
      signs.push_back(v > 0 ? 1 : -1);
    }
    if (!seen.insert(signs).second)
      r.fail(rows[i].source(), rp, "repeats an earlier row (each region needs its own sign row)");
  }
  return S;
}

RawSubsystem read_subsystem(const Reader& r, const toml::table& t, std::string_view path,
                            const Symbols& sym) {
  RawSubsystem out;
  const toml::node* c = t.get("c");
  const toml::node* S = t.get("S");
  const toml::node* g = t.get("g");
  const toml::node* F = t.get("F");
  if (c != nullptr && g != nullptr)
    r.fail(g->source(), path,
           "both c and g given (expected either switching functions c, with an optional sign "
           "matrix S, or indicator functions g)");
  if (c == nullptr && g == nullptr)
    r.fail(t.source(), path,
           "missing regions (expected switching functions c = [...], with an optional sign matrix "
           "S, or indicator functions g = [...])");
  if (S != nullptr && c == nullptr)
    r.fail(S->source(), join(path, "S"),
           "a sign matrix needs switching functions c (with indicator functions g, give no S)");
  if (F == nullptr)
    r.fail(t.source(), path,
           "missing key 'F' (expected one vector field per region, each an array of n_x "
           "expressions)");

  if (c != nullptr) {
    const std::string cp = join(path, "c");
    const toml::array& a = r.array(*c, cp, "an array of expressions");
    if (a.empty()) r.fail(c->source(), cp, "empty (expected at least one switching function)");
    for (std::size_t i = 0; i < a.size(); ++i) {
      out.expressions.c.push_back(r.expression(a[i], index(cp, i), sym.all));
      check_no_controls(r, out.expressions.c.back(), a[i], index(cp, i), sym,
                        "a switching function");
    }
    const int n_c = static_cast<int>(a.size());
    if (S != nullptr) {
      out.S = read_sign_matrix(r, *S, join(path, "S"), n_c);
      out.n_f = static_cast<int>(out.S.rows());
    } else {
      if (n_c > 10)
        r.fail(c->source(), cp,
               fmt::format("{} switching functions give 2^{} regions (expected at most 10 without "
                           "a sign matrix; give S with the regions you need)",
                           n_c, n_c));
      out.n_f = 1 << n_c;
    }
  } else {
    const std::string gp = join(path, "g");
    const toml::array& a = r.array(*g, gp, "an array of expressions");
    if (a.empty()) r.fail(g->source(), gp, "empty (expected one indicator function per region)");
    for (std::size_t i = 0; i < a.size(); ++i) {
      out.expressions.g.push_back(r.expression(a[i], index(gp, i), sym.all));
      check_no_controls(r, out.expressions.g.back(), a[i], index(gp, i), sym,
                        "an indicator function");
    }
    out.n_f = static_cast<int>(a.size());
  }

  const std::string fp = join(path, "F");
  const toml::array& fields = r.array(*F, fp, "an array of vector fields, one per region");
  const std::string region_source =
      c != nullptr ? (S != nullptr ? "one per row of S" : "one per row of the default S, 2^n_c")
                   : "one per indicator function in g";
  if (static_cast<int>(fields.size()) != out.n_f)
    r.fail(F->source(), fp,
           fmt::format("wrong number of vector fields (expected {}, {}, got {})", out.n_f,
                       region_source, fields.size()));
  const std::size_t n_x = sym.x.size();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const std::string rp = index(fp, i);
    const toml::array& field = r.array(fields[i], rp, "an array of n_x expressions");
    if (field.size() != n_x)
      r.fail(fields[i].source(), rp,
             fmt::format("wrong length (expected {} expressions, one per state, got {})", n_x,
                         field.size()));
    std::vector<expr::Expression> f;
    for (std::size_t j = 0; j < field.size(); ++j)
      f.push_back(r.expression(field[j], index(rp, j), sym.all));
    out.expressions.F.push_back(std::move(f));
  }
  return out;
}

bool uses_symbol(const RawSubsystem& s, int index) {
  const auto any = [&](const std::vector<expr::Expression>& list) {
    return std::any_of(list.begin(), list.end(),
                       [&](const expr::Expression& e) { return e.depends_on(index); });
  };
  if (any(s.expressions.c) || any(s.expressions.g)) return true;
  return std::any_of(s.expressions.F.begin(), s.expressions.F.end(), any);
}

void read_model(const Reader& r, const toml::table& root, SimulationProblem& problem, double t0) {
  const toml::node* model_node = root.get("model");
  if (model_node == nullptr)
    r.fail(toml::source_region{}, "model",
           "missing table [model] (expected x, x0, F and either c or g)");
  const toml::table& model = r.table(*model_node, "model");
  r.check_keys(model, kModelKeys, "model");

  // Names.
  Symbols sym;
  std::set<std::string> seen;
  const toml::node* x_node = model.get("x");
  if (x_node == nullptr)
    r.fail(model.source(), "model",
           "missing key 'x' (expected the state names, e.g. x = [\"x1\"])");
  const auto x_names = r.names(*x_node, "model.x");
  if (x_names.empty())
    r.fail(x_node->source(), "model.x", "no states (expected at least one state name)");
  check_names(r, x_names, "model.x", "state", seen, true);
  std::vector<std::pair<std::string, const toml::node*>> u_names;
  if (const toml::node* n = model.get("u")) u_names = r.names(*n, "model.u");
  check_names(r, u_names, "model.u", "control", seen, false);
  std::vector<std::pair<std::string, const toml::node*>> p_names;
  std::vector<double> p_values;
  if (const toml::node* n = model.get("p")) {
    const toml::table* pt = n->as_table();
    if (pt == nullptr)
      r.wrong_type(*n, "model.p", "a table of name = value, e.g. { omega = 6.28 }");
    for (const auto& [k, v] : in_file_order(*pt)) {
      p_names.emplace_back(k->str(), v);
      p_values.push_back(r.number(*v, join("model.p", k->str())));
    }
  }
  check_names(r, p_names, "model.p", "parameter", seen, false);

  for (const auto& n : x_names) sym.x.push_back(n.first);
  for (const auto& n : u_names) sym.u.push_back(n.first);
  for (const auto& n : p_names) sym.p.push_back(n.first);
  sym.all = sym.x;
  if (std::find(sym.x.begin(), sym.x.end(), "t") == sym.x.end()) {
    sym.time_index = static_cast<int>(sym.all.size());
    sym.all.push_back("t");
  }
  sym.all.insert(sym.all.end(), sym.u.begin(), sym.u.end());
  sym.all.insert(sym.all.end(), sym.p.begin(), sym.p.end());

  // Regions and vector fields: directly in [model] or in [[model.subsystem]].
  std::vector<RawSubsystem> subsystems;
  if (const toml::node* sub = model.get("subsystem")) {
    for (std::string_view k : kSubsystemKeys)
      if (const toml::node* direct = model.get(k))
        r.fail(direct->source(), join("model", k),
               "given both in [model] and as [[model.subsystem]] (expected c/S/g/F either "
               "directly in [model] or in every [[model.subsystem]], not both)");
    const toml::array* list = sub->as_array();
    if (list != nullptr && list->empty())
      r.fail(sub->source(), "model.subsystem", "empty (expected at least one subsystem)");
    if (list == nullptr || !list->is_array_of_tables())
      r.wrong_type(*sub, "model.subsystem", "an array of tables ([[model.subsystem]])");
    for (std::size_t k = 0; k < list->size(); ++k) {
      const std::string path = index("model.subsystem", k);
      const toml::table& t = *(*list)[k].as_table();
      r.check_keys(t, kSubsystemKeys, path);
      subsystems.push_back(read_subsystem(r, t, path, sym));
    }
  } else {
    subsystems.push_back(read_subsystem(r, model, "model", sym));
  }

  // The clock: appended if some expression reads t.
  bool has_clock = false;
  if (sym.time_index >= 0)
    for (const RawSubsystem& s : subsystems)
      has_clock = has_clock || uses_symbol(s, sym.time_index);
  const int n_x_user = static_cast<int>(sym.x.size());
  const int n_x = n_x_user + (has_clock ? 1 : 0);
  if (has_clock) {
    const expr::Expression one = expr::Expression::parse("1", sym.all, "clock t' = 1");
    const expr::Expression zero = expr::Expression::parse("0", sym.all, "clock t' = 0");
    for (std::size_t k = 0; k < subsystems.size(); ++k)
      for (auto& field : subsystems[k].expressions.F) field.push_back(k == 0 ? one : zero);
  }

  // x0.
  const toml::node* x0_node = model.get("x0");
  if (x0_node == nullptr)
    r.fail(model.source(), "model",
           fmt::format("missing key 'x0' (expected the initial state, {})",
                       count(static_cast<std::size_t>(n_x_user), "number")));
  Eigen::VectorXd x0 = r.vector(*x0_node, "model.x0", n_x_user, "one per state in x");
  if (has_clock) {
    x0.conservativeResize(n_x);
    x0[n_x_user] = t0;
  }  // without a clock, t0 has no effect

  // The Pss.
  PssDims dims;
  dims.n_x = n_x;
  dims.n_u = static_cast<int>(sym.u.size());
  dims.n_p = static_cast<int>(sym.p.size());
  std::vector<ExpressionSubsystem> expressions;
  for (RawSubsystem& s : subsystems) {
    if (!s.expressions.c.empty())
      dims.subsystems.push_back(Subsystem::from_c(static_cast<int>(s.expressions.c.size()), s.S));
    else
      dims.subsystems.push_back(Subsystem::from_g(static_cast<int>(s.expressions.g.size())));
    expressions.push_back(std::move(s.expressions));
  }
  ExpressionLayout layout;
  layout.n_x = n_x;
  layout.n_x_slots = n_x_user + (sym.time_index >= 0 ? 1 : 0);
  layout.n_u = dims.n_u;
  layout.n_p = dims.n_p;
  try {
    problem.model = make_expression_pss(std::move(dims), layout, std::move(expressions));
  } catch (const InvalidModel& e) {
    throw InvalidModel(fmt::format("{}: {}", r.at(model.source()), e.what()));
  }
  problem.model.state_names = sym.x;
  if (has_clock) problem.model.state_names.push_back("t");
  problem.model.control_names = sym.u;
  problem.model.parameter_names = sym.p;
  problem.p = Eigen::Map<const Eigen::VectorXd>(p_values.data(),
                                                static_cast<Eigen::Index>(p_values.size()));
  problem.model.p_default = problem.p;
  problem.x0 = x0;
  problem.has_clock = has_clock;
}

// ---- options ----------------------------------------------------------------------------------

/// Converts a TOML value to the option's kind; throws ProblemFileError / InvalidOption.
OptionValue read_option(const Reader& r, const OptionSpec& o, const toml::node& n) {
  const std::string path = join(o.table, o.key);
  OptionValue v;
  switch (o.kind) {
    case Kind::Int:
      v.i = r.integer(n, path);
      break;
    case Kind::Double:
      v.d = r.number(n, path);
      break;
    case Kind::Bool:
      v.b = r.boolean(n, path);
      break;
    default: {
      const std::string name = r.string(n, path);
      if (auto error = parse_enum(o.kind, name, v))
        throw InvalidOption(fmt::format("{}: {}: {}", r.at(n.source()), path, *error));
    }
  }
  return v;
}

/// Rules for [simulation] that validate() (options.hpp) does not cover.
std::vector<std::string> validate_simulation(const SimulationProblem& q) {
  std::vector<std::string> e;
  if (!(std::isfinite(q.T_sim) && q.T_sim > 0))
    e.push_back(fmt::format("simulation.T_sim = {}: must be > 0", q.T_sim));
  if (q.N_sim < 1) e.push_back(fmt::format("simulation.N_sim = {}: must be >= 1", q.N_sim));
  return e;
}

std::vector<std::string> validate_all(const SimulationProblem& q) {
  std::vector<std::string> e = validate_simulation(q);
  for (std::string& s : validate(q.options)) e.push_back(std::move(s));
  return e;
}

/// The "table.key" a validate() message starts with ("discretization.n_s = 0: ...").
std::string_view message_key(std::string_view message) {
  const std::size_t eq = message.find(" = ");
  return eq == std::string_view::npos ? std::string_view{} : message.substr(0, eq);
}

std::string ipopt_value(const Reader& r, const toml::node& n, std::string_view path) {
  if (const auto* s = n.as_string()) return s->get();
  if (const auto* i = n.as_integer()) return fmt::format("{}", i->get());
  if (n.is_floating_point()) return format_number(r.number(n, path));
  if (const auto* b = n.as_boolean()) return b->get() ? "yes" : "no";
  r.wrong_type(n, path, "a string, number or boolean (an IPOPT option value)");
}

void read_options(const Reader& r, const toml::table& root, SimulationProblem& problem) {
  for (std::string_view table_name : {"simulation", "discretization", "homotopy", "ipopt"}) {
    const toml::node* tn = root.get(table_name);
    const bool required = table_name == "simulation";
    if (tn == nullptr) {
      if (required)
        r.fail(toml::source_region{}, table_name,
               "missing table [simulation] (expected at least T_sim, the length of the time "
               "interval)");
      continue;
    }
    const toml::table& t = r.table(*tn, table_name);
    const std::vector<std::string_view> keys = keys_of_table(table_name);
    if (table_name != "ipopt") r.check_keys(t, keys, table_name);
    for (const OptionSpec& o : kOptions) {
      if (o.table != table_name) continue;
      if (const toml::node* n = t.get(o.key)) o.set(problem, read_option(r, o, *n));
    }
    if (required && t.get("T_sim") == nullptr)
      r.fail(t.source(), "simulation",
             "missing key 'T_sim' (expected the length of the time interval, a number > 0)");
    if (table_name == "ipopt") {
      for (const auto& [k, v] : in_file_order(t)) {
        if (std::find(keys.begin(), keys.end(), k->str()) != keys.end()) continue;
        problem.options.nlp.extra.emplace_back(k->str(),
                                               ipopt_value(r, *v, join("ipopt", k->str())));
      }
    }
  }
  const std::vector<std::string> errors = validate_all(problem);
  if (errors.empty()) return;
  std::string msg;
  for (const std::string& e : errors) {
    std::string where = r.file();
    const std::string_view key = message_key(e);
    if (!key.empty()) {
      const auto node = root.at_path(key);
      if (node) where = r.at(node.node()->source());
    }
    msg += (msg.empty() ? "" : "; ") + fmt::format("{}: {}", where, e);
  }
  throw InvalidOption(msg);
}

// ---- overrides --------------------------------------------------------------------------------

std::optional<int> parse_int(std::string_view s) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  long long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    return std::nullopt;
  return static_cast<int>(v);
}

std::optional<double> parse_double(std::string_view s) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

[[noreturn]] void override_error(const std::string& head, std::string_view what) {
  throw InvalidOption(fmt::format("{}: {}", head, what));
}

std::string trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return std::string(s);
}

}  // namespace

SimulationProblem parse_simulation_problem(std::string_view toml_text,
                                           std::string_view source_name) {
  const Reader r{std::string(source_name)};
  toml::table root;
  try {
    root = toml::parse(toml_text, std::string(source_name));
  } catch (const toml::parse_error& e) {
    throw ProblemFileError(fmt::format("{}:{}:{}: TOML syntax error: {}", source_name,
                                       e.source().begin.line, e.source().begin.column,
                                       e.description()));
  }
  r.check_keys(root, kTopKeys, "");

  SimulationProblem problem;
  problem.source = std::string(source_name);
  problem.name = std::filesystem::path(std::string(source_name)).stem().string();
  if (const toml::node* n = root.get("name")) {
    problem.name = r.string(*n, "name");
    if (problem.name.empty()) r.fail(n->source(), "name", "empty (expected a non-empty name)");
  }
  if (const toml::node* n = root.get("description"))
    problem.description = r.string(*n, "description");

  // t0 is needed by the model (clock initial value); read it first.
  double t0 = 0.0;
  if (const toml::node* sim = root.get("simulation"))
    if (const toml::table* st = sim->as_table())
      if (const toml::node* n = st->get("t0")) t0 = r.number(*n, "simulation.t0");

  read_model(r, root, problem, t0);

  problem.u = Eigen::VectorXd::Zero(problem.model.n_u());
  if (const toml::node* sim = root.get("simulation"))
    if (const toml::table* st = sim->as_table())
      if (const toml::node* un = st->get("u"))
        problem.u =
            r.vector(*un, "simulation.u", problem.model.n_u(), "one per control in model.u");

  read_options(r, root, problem);
  return problem;
}

SimulationProblem load_simulation_problem(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw ProblemFileError(
        fmt::format("{}: cannot read problem file ({})", path,
                    std::filesystem::exists(path, ec) ? "not a regular file" : "no such file"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ProblemFileError(fmt::format("{}: cannot open problem file", path));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw ProblemFileError(fmt::format("{}: error while reading problem file", path));
  return parse_simulation_problem(text.str(), path);
}

void apply_override(SimulationProblem& problem, std::string_view key_in,
                    std::string_view value_in) {
  std::string_view key = key_in;
  while (!key.empty() && key.front() == '-') key.remove_prefix(1);
  const std::string value = trim(value_in);
  const std::string head = fmt::format("--{} = {}", key, value);

  // Optional "table." prefix.
  std::string_view table;
  if (const std::size_t dot = key.find('.'); dot != std::string_view::npos) {
    table = key.substr(0, dot);
    key = key.substr(dot + 1);
    constexpr std::array<std::string_view, 4> kTables{"simulation", "discretization", "homotopy",
                                                      "ipopt"};
    if (std::find(kTables.begin(), kTables.end(), table) == kTables.end())
      override_error(head, fmt::format("unknown table '{}' {}", table, key_hint(table, kTables)));
  }
  if (key == "N_FE") key = "N_finite_elements";

  SimulationProblem updated = problem;
  const OptionSpec* spec = nullptr;
  for (const OptionSpec& o : kOptions)
    if (o.key == key && (table.empty() || o.table == table)) spec = &o;

  if (spec != nullptr) {
    OptionValue v;
    switch (spec->kind) {
      case Kind::Int: {
        const auto i = parse_int(value);
        if (!i) override_error(head, "expected an integer");
        v.i = *i;
        break;
      }
      case Kind::Double: {
        const auto d = parse_double(value);
        if (!d) override_error(head, "expected a number");
        if (!std::isfinite(*d)) override_error(head, "must be finite");
        v.d = *d;
        break;
      }
      case Kind::Bool:
        if (value == "1" || value == "true")
          v.b = true;
        else if (value == "0" || value == "false")
          v.b = false;
        else
          override_error(
              head, fmt::format("expected a boolean (1, 0, true or false, got \"{}\")", value));
        break;
      default:
        if (auto error = parse_enum(spec->kind, value, v)) override_error(head, *error);
    }
    spec->set(updated, v);
  } else if ((table.empty() || table == "simulation") && key == "t0") {
    const auto d = parse_double(value);
    if (!d) override_error(head, "expected a number");
    if (!std::isfinite(*d)) override_error(head, "must be finite");
    if (updated.has_clock) updated.x0[updated.x0.size() - 1] = *d;
  } else if ((table.empty() || table == "simulation") && key == "u") {
    std::vector<double> u;
    std::string_view rest = value;
    while (!rest.empty()) {
      const std::size_t comma = rest.find(',');
      const auto d = parse_double(trim(rest.substr(0, comma)));
      if (!d) override_error(head, "expected comma-separated numbers, one per control");
      if (!std::isfinite(*d)) override_error(head, "must be finite");
      u.push_back(*d);
      rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    }
    if (static_cast<int>(u.size()) != updated.model.n_u())
      override_error(
          head,
          fmt::format("wrong length (expected {}, one per control, got {})",
                      count(static_cast<std::size_t>(updated.model.n_u()), "number"), u.size()));
    updated.u = Eigen::Map<const Eigen::VectorXd>(u.data(), static_cast<Eigen::Index>(u.size()));
  } else if (table == "ipopt" && !key.empty()) {
    auto& extra = updated.options.nlp.extra;
    const auto it =
        std::find_if(extra.begin(), extra.end(), [&](const auto& kv) { return kv.first == key; });
    if (it != extra.end())
      it->second = value;
    else
      extra.emplace_back(std::string(key), value);
  } else {
    std::vector<std::string_view> valid;
    for (std::string_view t : {"simulation", "discretization", "homotopy", "ipopt"})
      if (table.empty() || t == table)
        for (std::string_view k : keys_of_table(t)) valid.push_back(k);
    if (table.empty() || table == "discretization") valid.push_back("N_FE");
    override_error(head, fmt::format("unknown option '{}' {}", key, key_hint(key, valid)));
  }

  const std::vector<std::string> errors = validate_all(updated);
  if (!errors.empty()) {
    const std::string canonical =
        spec != nullptr ? fmt::format("{}.{}", spec->table, spec->key) : std::string{};
    std::string msg;
    for (const std::string& e : errors) {
      std::string_view text = e;
      if (!canonical.empty() && message_key(text) == canonical) {
        const std::size_t colon = text.find(": ");
        if (colon != std::string_view::npos) text.remove_prefix(colon + 2);
      }
      msg += (msg.empty() ? "" : "; ") + std::string(text);
    }
    override_error(head, msg);
  }
  problem = std::move(updated);
}

}  // namespace fesd
