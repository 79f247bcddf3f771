// src/core/option_registry.hpp: the option registry. Every key of the problem-file tables
// [simulation], [ocp], [discretization], [homotopy] and [ipopt] is declared once, in
// option_registry.cpp: table, key (nosnoc's name where nosnoc has one), kind, where the value lives
// in the C++ structs, range, a one-line doc, nosnoc's name and the problem kinds that have it.
// validate() and its messages, the problem-file reader (keys, hints, values), the command-line
// overrides and their --help, and the check of docs/problem-files.md's tables all read it.
// Internal: the public API stays the plain option structs of include/fesd/options.hpp and ocp.hpp.
#pragma once
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fesd/options.hpp"

namespace fesd {
struct OcpData;
struct OcpOptions;
enum class TerminalConstraint;
enum class OcpInitialization;
enum class KktSolver;
}  // namespace fesd

namespace fesd::registry {

/// The problem-file tables with options, in the order of docs/problem-files.md.
enum class Table { Simulation, Ocp, Discretization, Homotopy, Ipopt };
/// "simulation", "ocp", "discretization", "homotopy", "ipopt".
std::string_view to_string(Table t);

/// How a value is read and checked. Input: a key the loader reads itself (arrays, expressions, the
/// clock's t0); listed for key checks, hints, --help and the docs, without a scalar value here.
enum class Kind { Int, Double, Bool, Enum, Input };

/// Which problem kinds have an option; Both also means "any kind" where a kind is asked for.
enum class Use { Simulation, Ocp, Both };

/// Where the options of one problem live. Null where the problem has no such part (a simulation
/// has no Ocp). T_sim and N_sim are integrate()'s arguments, so they are pointed at one by one.
struct OptionTarget {
  DiscretizationOptions* discretization = nullptr;
  HomotopyOptions* homotopy = nullptr;
  NlpOptions* nlp = nullptr;
  double* T_sim = nullptr;
  int* N_sim = nullptr;
  double* tol_sim = nullptr;  ///< simulate()'s accuracy target (AccuracyOptions)
  int* N_sim_max = nullptr;
  bool* error_estimate = nullptr;     ///< simulate()'s companion runs (AccuracyOptions)
  StepSolver* step_solver = nullptr;  ///< IntegratorOptions::step_solver
  bool* sensitivities = nullptr;      ///< IntegratorOptions::sensitivities
  OcpData* ocp = nullptr;             ///< [ocp] keys stored in the problem
  OcpOptions* ocp_options = nullptr;  ///< [ocp] keys stored in the solver options
};

/// Read-only targets for validate(): the registry's getters never write through them.
OptionTarget target_of(const DiscretizationOptions& o);
OptionTarget target_of(const HomotopyOptions& o);
OptionTarget target_of(const NlpOptions& o);
OptionTarget target_of(const IntegratorOptions& o);
OptionTarget target_of(const OcpOptions& o);

/// lo <= v <= hi, either end open or absent (infinite). An Int range is written "1..9".
struct Range {
  static constexpr double kNone = std::numeric_limits<double>::infinity();
  double min = -kNone, max = kNone;
  bool min_open = false, max_open = false;
  /// Appended to a broken range's message: "(0: automatic)".
  std::string_view note = {};
};

/// One key of one table.
struct Option {
  Table table;
  std::string_view key;  ///< the file key: nosnoc's name where nosnoc has one
  Kind kind;
  Use use;
  std::string_view doc;         ///< one line, for --help and messages ("the length of the horizon")
  std::string_view nosnoc;      ///< nosnoc's name ("" if fesd only)
  Range range = {};             ///< Int/Double: the documented range (finite is always required)
  std::string_view alias = {};  ///< a second override name (the paper's symbol)
  bool required = false;        ///< the file must give it (the length of the time interval)
  bool overridable = true;      ///< settable by apply_override / the command line
  /// Enum: value names from the enum's one table (enum_names), index = enum value.
  std::span<const std::string_view> names = {};
  /// Enum: the index of a name, -1 if unknown (accepts what the enum's parse() accepts).
  int (*parse_name)(std::string_view) = nullptr;
  bool (*present)(const OptionTarget&) = nullptr;  ///< the target has the part that holds it
  double (*get)(const OptionTarget&) = nullptr;    ///< Int/Bool/Enum as numbers (enum: index)
  void (*set)(const OptionTarget&, double) = nullptr;
  /// Where the range depends on another option (stages on the scheme): that range and the words
  /// naming it ("radau_iia").
  std::pair<Range, std::string_view> (*range_for)(const OptionTarget&) = nullptr;
  /// A named rule between options, checked once the range holds ("must be <= ...");
  /// returns "" when it holds.
  std::string (*rule)(const OptionTarget&, double value) = nullptr;
};

/// The value names of an enum, indexed by its values: the one table behind its to_string() and
/// parse() (src/core/options.cpp).
template <class E>
std::span<const std::string_view> enum_names();
template <>
std::span<const std::string_view> enum_names<RkScheme>();
template <>
std::span<const std::string_view> enum_names<CrossComp>();
template <>
std::span<const std::string_view> enum_names<StepEq>();
template <>
std::span<const std::string_view> enum_names<StageLambdaSign>();
template <>
std::span<const std::string_view> enum_names<DcsMode>();
template <>
std::span<const std::string_view> enum_names<MpccMode>();
template <>
std::span<const std::string_view> enum_names<TerminalConstraint>();
template <>
std::span<const std::string_view> enum_names<OcpInitialization>();
template <>
std::span<const std::string_view> enum_names<KktSolver>();
template <>
std::span<const std::string_view> enum_names<KktScaling>();
template <>
std::span<const std::string_view> enum_names<StepSolver>();
template <>
std::span<const std::string_view> enum_names<HomotopyUpdateRule>();

/// Whether the caller passes IPOPT option `name` itself ([ipopt] / NlpOptions::extra).
bool user_sets(const NlpOptions& o, std::string_view name);

/// Every option, table by table.
std::span<const Option> all();
/// The tables of a problem kind, in reading order: [simulation] or [ocp], then [discretization],
/// [homotopy], [ipopt].
std::span<const Table> tables(Use kind);
/// Whether `o` belongs to problems of `kind` (Both: any kind).
bool has(const Option& o, Use kind);
/// The option `key` of `table`, or nullptr.
const Option* find(Table table, std::string_view key);
/// Every key of `table` that `kind` has, Input keys included, in registry order.
std::vector<std::string_view> keys(Table table, Use kind);
/// The first required option of `table`, or nullptr.
const Option* required_option(Table table);

/// "table.key".
std::string path_of(const Option& o);
/// A value as written in a file: 3, 1e-09, true, radau_iia.
std::string format_value(const Option& o, double v);
/// "1..9", "> 0", "(0, 1]", "radau_iia, gauss_legendre, ...", "" (Bool, Input, no bounds).
std::string range_text(const Option& o);
/// "a number > 0", "an integer in 1..9", "a boolean", "one of none, ell_1".
std::string expected_text(const Option& o);
/// `doc` and what values are accepted, for --help.
std::string help_text(const Option& o);
/// "unknown name (expected one of radau_iia, ...; got \"radau\")".
std::string unknown_name(const Option& o, std::string_view got);

/// The broken range or rule of `o` for `value` ("" if none), as "<path> = <value>: must be ...";
/// path empty: path_of(o). The target supplies the other options of range_for and rule.
std::string check(const Option& o, const OptionTarget& t, double value, std::string_view path = {});
/// Every broken range and rule of the options of `table` that the target has, in registry order.
std::vector<std::string> check(Table table, const OptionTarget& t);

/// The rules of integrate()'s time interval and number of steps, written once (the [simulation]
/// ranges and the smallest step T_sim / N_sim, core::step_length_error, relative to the start
/// time t0); used by integrate(), which needs N_sim >= 1.
std::vector<std::string> validate_simulation(double T_sim, int N_sim, double t0 = 0.0);
/// The same for simulate() and simulation problem files, with its accuracy keys: N_sim = 0
/// (chosen by tol_sim) allowed, tol_sim, N_sim_max.
std::vector<std::string> validate_simulation(double T_sim, int N_sim, double tol_sim, int N_sim_max,
                                             double t0, bool error_estimate = true);

/// Messages joined by "; ".
std::string join(const std::vector<std::string>& messages);

}  // namespace fesd::registry
