// src/cli/main.cpp: the `fesd` program.
//
//   fesd simulate FILE [--json OUT] [--csv OUT] [--plot OUT.png|OUT.svg] [--quiet] [overrides]
//   fesd solve FILE [--json OUT] [--csv OUT] [--plot OUT.png|OUT.svg] [--quiet] [overrides]
//   fesd check FILE [overrides]
//
// `simulate` reads a simulation file ([simulation] table), `solve` an optimal control problem file
// ([ocp] table), `check` either kind.
//
// Exit codes (kExitHelp below; README.md and docs/problem-files.md list the same):
//   0  solved (simulate, solve) or valid (check)
//   1  not converged: the numerical method failed (the outputs are still written)
//   2  bad input: command line, problem file, option values (fesd::Error)
//   3  I/O failure: an output file, gnuplot, or standard output (a full disk, a closed pipe)
//   4  internal error: a bug in fesd (fesd::InternalError) or out of memory (std::bad_alloc)
// Every error is one line on stderr: "fesd: error: <message>". A closed stdout never kills the
// program (SIGPIPE is ignored): the --json/--csv/--plot outputs are written, then exit 3.
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "core/accuracy_options.hpp"
#include "core/option_registry.hpp"
#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/io.hpp"
#include "fesd/ocp.hpp"
#include "fesd/options.hpp"
#include "fesd/pds_problem_file.hpp"
#include "fesd/problem_file.hpp"
#include "fesd/status.hpp"
#include "fesd/tableau.hpp"
#include "io/describe.hpp"
#include "nlp/nlp_solver.hpp"

#ifndef FESD_VERSION
#define FESD_VERSION "0.1.0"
#endif

namespace {

/// Bad command-line input found by the program itself (exit code 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

constexpr int kExitSolved = 0;
constexpr int kExitBadInput = 2;
constexpr int kExitIo = 3;
constexpr int kExitInternal = 4;
constexpr const char* kExitHelp =
    "Exit codes: 0 solved (check: valid), 1 not converged (outputs still written), 2 bad input,\n"
    "3 I/O failure (output files, standard output), 4 internal error (a bug, or out of memory).";

/// Error messages are printed as one line: line breaks become "; ".
std::string one_line(std::string_view text) {
  std::string out;
  bool pending_break = false;
  for (char ch : text) {
    if (ch == '\n' || ch == '\r') {
      pending_break = !out.empty();
      continue;
    }
    if (pending_break) out += "; ";
    pending_break = false;
    out += ch;
  }
  return out;
}

// ---- standard output ----------------------------------------------------------------------------
// Writing to stdout never throws and never kills the program: SIGPIPE is ignored (main), a failed
// write is remembered, and main() reports it at the end as an I/O error (exit 3), after the
// outputs asked for with --json/--csv/--plot have been written.

int stdout_errno = 0;  ///< errno of the first failed write to stdout, 0 if none

namespace out {
/// fmt::print to stdout without exceptions (fmt::print throws when a write fails).
template <class... Args>
void print(fmt::format_string<Args...> format, Args&&... args) {
  const std::string text = fmt::format(format, std::forward<Args>(args)...);
  errno = 0;
  if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() && stdout_errno == 0)
    stdout_errno = errno != 0 ? errno : EIO;
}
}  // namespace out

/// fflush(stdout), remembering why it failed.
void flush_stdout() {
  errno = 0;
  if (std::fflush(stdout) != 0 && stdout_errno == 0) stdout_errno = errno != 0 ? errno : EIO;
}

/// Flushes stdout; false (and stdout_errno set) if anything written to it was lost.
bool stdout_ok() {
  std::cout.flush();
  flush_stdout();
  if ((std::ferror(stdout) != 0 || std::cout.fail()) && stdout_errno == 0) stdout_errno = EIO;
  return stdout_errno == 0;
}

void print_error(std::string_view message) {
  flush_stdout();
  std::cerr << "fesd: error: " << one_line(message) << std::endl;
}

// ---- overrides -------------------------------------------------------------------------------

/// Which subcommands offer an override: simulation files, OCP files, or both (`check`).
using Scope = fesd::registry::Use;

constexpr const char* kOverridesFooter =
    "Overrides act as if written in the problem file. A key may be qualified by its table "
    "(--discretization.n_s 3, --model.x0 1,0); --ipopt.NAME VALUE or --ipopt NAME=VALUE sets any "
    "IPOPT option. Lists are comma-separated numbers (--x0 0.5,-1; --x0=-1,2 when the first is "
    "negative).";

/// "Overrides [discretization]": one --help group per problem-file table.
std::string override_group(fesd::registry::Table table) {
  return fmt::format("Overrides [{}]", fesd::registry::to_string(table));
}

/// The override options of one subcommand, made from the option registry, and their values after
/// parsing.
struct Overrides {
  std::vector<const fesd::registry::Option*> keys;
  std::vector<std::string> values;
  std::vector<CLI::Option*> options;
  std::vector<std::string> ipopt;
  std::string x0;  ///< --x0 V1,V2,... ([model] x0)
  CLI::Option* x0_option = nullptr;
  std::vector<std::string> parameters;  ///< --p NAME=VALUE, repeatable ([model] p)
  /// Arguments CLI11 did not recognize (the command allows extras): an unknown --KEY VALUE goes
  /// to fesd::apply_override, whose message names the nearest option ("unknown option 'n_S'
  /// (did you mean 'n_s'?)").
  std::vector<std::string> extras;

  /// Adds the options of `scope` (Both: every option, for `check`, which reads either kind).
  void add_to(CLI::App& app, Scope scope) {
    app.allow_extras();
    x0_option = app.add_option("--x0", x0,
                               "initial state x(0) (of an OCP: its guess if free), one number per "
                               "state of model.x, comma-separated")
                    ->type_name("V1,V2,...")
                    ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast)
                    ->group("Overrides [model]");
    app.add_option("--p", parameters, "the value of a parameter of model.p (repeatable)")
        ->type_name("NAME=VALUE")
        ->allow_extra_args(false)
        ->group("Overrides [model]");
    for (const fesd::registry::Option& o : fesd::registry::all())
      if (o.overridable && fesd::registry::has(o, scope)) keys.push_back(&o);
    values.resize(keys.size());
    options.resize(keys.size(), nullptr);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const fesd::registry::Option& o = *keys[i];
      std::string names = fmt::format("--{}", o.key);
      if (!o.alias.empty()) names += fmt::format(",--{}", o.alias);
      const bool list = o.key == "u" || o.key == "u_guess";  // comma-separated numbers
      options[i] = app.add_option(names, values[i], fesd::registry::help_text(o))
                       ->type_name(list ? "V1,V2,..." : type_name(o.kind))
                       ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast)
                       ->group(override_group(o.table));
    }
    app.add_option("--ipopt", ipopt, "any IPOPT option, NAME=VALUE (repeatable)")
        ->type_name("NAME=VALUE")
        ->allow_extra_args(false)
        ->group(override_group(fesd::registry::Table::Ipopt));
    app.footer(kOverridesFooter);
  }

  static const char* type_name(fesd::registry::Kind kind) {
    switch (kind) {
      case fesd::registry::Kind::Int:
        return "INT";
      case fesd::registry::Kind::Double:
        return "NUMBER";
      case fesd::registry::Kind::Bool:
        return "BOOL";
      case fesd::registry::Kind::Enum:
        return "NAME";
      default:
        return "VALUE";
    }
  }

  /// (key, value) pairs in a fixed order, the --ipopt ones last (as keys "ipopt.NAME", so that
  /// any IPOPT option name is accepted).
  std::vector<std::pair<std::string, std::string>> pairs() const {
    std::vector<std::pair<std::string, std::string>> out;
    if (x0_option != nullptr && x0_option->count() > 0) out.emplace_back("x0", x0);
    for (const std::string& item : parameters) out.emplace_back("p", item);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      if (options[i] != nullptr && options[i]->count() > 0) {
        out.emplace_back(keys[i]->key, values[i]);
      }
    }
    for (std::size_t i = 0; i < extras.size(); ++i) {
      const std::string& item = extras[i];
      if (item.size() < 3 || item.compare(0, 2, "--") != 0)
        throw UsageError(fmt::format("unexpected argument '{}'", item));
      const std::size_t eq = item.find('=');
      if (eq != std::string::npos) {
        out.emplace_back(item.substr(2, eq - 2), item.substr(eq + 1));
      } else if (i + 1 < extras.size() && extras[i + 1].compare(0, 2, "--") != 0) {
        out.emplace_back(item.substr(2), extras[i + 1]);
        ++i;
      } else {
        throw UsageError(fmt::format("option '{}' needs a value ({} VALUE)", item, item));
      }
    }
    for (const std::string& item : ipopt) {
      const std::size_t eq = item.find('=');
      if (eq == std::string::npos || eq == 0) {
        throw UsageError("--ipopt '" + item + "': expected NAME=VALUE, e.g. mu_strategy=monotone");
      }
      out.emplace_back("ipopt." + item.substr(0, eq), item.substr(eq + 1));
    }
    return out;
  }
};

/// The command line for CLI11 (reversed, without the program name), with the qualified override
/// forms of docs/problem-files.md rewritten: "--TABLE.KEY" -> "--KEY" for a registry key of
/// TABLE, and "--ipopt.NAME VALUE" / "--ipopt.NAME=VALUE" -> "--ipopt NAME=VALUE" for any other
/// IPOPT option. Nothing after "--" is rewritten.
std::vector<std::string> cli11_args(int argc, char** argv) {
  std::vector<std::string> args;
  bool options_end = false;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    const std::size_t dot = arg.find('.');
    const std::size_t eq = arg.find('=');
    if (arg == "--") options_end = true;
    if (options_end || arg.rfind("--", 0) != 0 || dot == std::string::npos || eq < dot) {
      args.push_back(std::move(arg));
      continue;
    }
    const std::string table = arg.substr(2, dot - 2);
    const std::string key = arg.substr(dot + 1, eq == std::string::npos ? eq : eq - dot - 1);
    const std::string rest = eq == std::string::npos ? "" : arg.substr(eq);  // "=VALUE" or ""
    const fesd::registry::Option* o = nullptr;
    for (const fesd::registry::Option& x : fesd::registry::all())
      if (fesd::registry::to_string(x.table) == table && (x.key == key || x.alias == key)) o = &x;
    if ((o != nullptr && o->overridable) || (table == "model" && (key == "x0" || key == "p"))) {
      args.push_back("--" + key + rest);
    } else if (table == "ipopt" && !key.empty() && (!rest.empty() || i + 1 < argc)) {
      args.push_back("--ipopt");
      args.push_back(key + (rest.empty() ? "=" + std::string(argv[++i]) : rest));
    } else {
      args.push_back(std::move(arg));
    }
  }
  return {args.rbegin(), args.rend()};
}

// ---- checks before solving ---------------------------------------------------------------------

void check_input_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) throw UsageError("cannot read '" + path + "': no such file");
  if (fs::is_directory(st)) throw UsageError("cannot read '" + path + "': it is a directory");
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext;
}

/// Fails before a possibly long solve if an output file cannot be created (nothing is written).
void check_output_path(const std::string& option, const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) throw UsageError(option + ": the path is empty");
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (fs::is_directory(st)) throw fesd::IoError("cannot write '" + path + "': it is a directory");
  if (fs::exists(st)) {
    if (::access(path.c_str(), W_OK) != 0) {
      throw fesd::IoError("cannot write '" + path + "': " + std::strerror(errno));
    }
    return;
  }
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  const fs::file_status dir_st = fs::status(dir, ec);
  if (!fs::exists(dir_st)) {
    throw fesd::IoError("cannot write '" + path + "': directory '" + dir.string() +
                        "' does not exist");
  }
  if (!fs::is_directory(dir_st)) {
    throw fesd::IoError("cannot write '" + path + "': '" + dir.string() + "' is not a directory");
  }
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    throw fesd::IoError("cannot write '" + path + "': " + std::strerror(errno));
  }
}

// ---- the summary printed before solving --------------------------------------------------------

std::string join_vector(const Eigen::VectorXd& v, const std::vector<std::string>& names = {}) {
  std::string out;
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    const std::size_t k = static_cast<std::size_t>(i);
    if (i > 0) out += ", ";
    if (k < names.size() && !names[k].empty()) out += names[k] + " = ";
    out += fmt::format("{:.6g}", v[i]);
  }
  return names.empty() ? "[" + out + "]" : out;
}

std::string yes_no(bool b) {
  return b ? "1" : "0";
}

/// The first lines of simulation and OCP headers: name, model, x0, p. `x0_note` follows x0.
void print_model_header(const std::string& name, const std::string& source,
                        const std::string& description, const fesd::Pss& m, bool has_clock,
                        const Eigen::VectorXd& x0, const std::string& x0_note,
                        const Eigen::VectorXd& p) {
  std::string names;
  for (int i = 0; i < m.n_x(); ++i) {
    const std::string state = static_cast<std::size_t>(i) < m.state_names.size()
                                  ? m.state_names[static_cast<std::size_t>(i)]
                                  : fmt::format("x{}", i + 1);
    names += (i ? ", " : "") + state;
  }
  std::string regions;
  for (int k = 0; k < m.n_sys(); ++k) {
    const fesd::Subsystem& sub = m.dims().subsystems[static_cast<std::size_t>(k)];
    const int n_f = m.region_offset(k + 1) - m.region_offset(k);
    regions += fmt::format(
        "{}{} ({})", k ? ", " : "", n_f,
        sub.n_c > 0 ? fmt::format("n_c = {}", sub.n_c) : fmt::format("n_g = {}", sub.n_g));
  }

  out::print("fesd {}: {} ({})\n", FESD_VERSION, name, source);
  if (!description.empty()) out::print("  {}\n", one_line(description));
  out::print("  model       n_x = {} ({}), n_u = {}, n_p = {}{}\n", m.n_x(), names, m.n_u(),
             m.n_p(), has_clock ? ", with clock state t" : "");
  out::print("  regions     {} subsystem{}, regions per subsystem: {} (n_theta = {})\n", m.n_sys(),
             m.n_sys() == 1 ? "" : "s", regions, m.n_theta());
  out::print("  x0          {}{}\n", join_vector(x0), x0_note);
  if (p.size() > 0) out::print("  p           {}\n", join_vector(p, m.parameter_names));
}

/// The solver lines of the headers: discretization (N_FE as text: a number or a list), homotopy,
/// IPOPT.
void print_solver_header(const std::string& n_fe, const fesd::DiscretizationOptions& d,
                         const fesd::HomotopyOptions& h, const fesd::NlpOptions& nlp) {
  out::print("  scheme      {}, n_s = {}, N_FE = {}, use_fesd = {}", fesd::to_string(d.rk_scheme),
             d.n_s, n_fe, yes_no(d.use_fesd));
  if (d.use_fesd) {
    out::print(" (cross_comp_mode = {}, step_equilibration = {})", fesd::to_string(d.cross_comp),
               fesd::to_string(d.step_eq));
  }
  out::print("\n");
  out::print("  homotopy    mpcc_mode = {}, sigma_0 = {:g}, slope = {:g}, ",
             fesd::to_string(h.mpcc_mode), h.sigma_0, h.homotopy_update_slope);
  if (h.homotopy_update_rule != fesd::HomotopyUpdateRule::Linear)
    out::print("{} (exponent {:g}), ", fesd::to_string(h.homotopy_update_rule),
               h.homotopy_update_exponent);
  out::print("sigma_N = {:g}, complementarity_tol = {:g}, N_homotopy = {}", h.sigma_N,
             h.complementarity_tol, h.max_homotopy_steps);
  if (fesd::is_elastic(h.mpcc_mode))
    out::print(", s_elastic_max = {:g}, s_elastic_0 = {:g}", h.s_elastic_max, h.s_elastic_0);
  if (!h.objective_scaling_direct && fesd::penalizes(h.mpcc_mode))
    out::print(", objective_scaling_direct = false (sigma J + P)");
  out::print("\n");
  out::print("  ipopt       tol = {:g}, acceptable_tol = {:g}, max_iter = {}, print_level = {}",
             nlp.tol, nlp.acceptable_tol, nlp.max_iter, nlp.print_level);
  for (const auto& [key, value] : nlp.extra) out::print(", {} = {}", key, value);
  out::print("\n");
  for (const std::string& w : fesd::warnings(h)) out::print("  warning     {}\n", w);
  for (const std::string& w : fesd::nlp::warnings(nlp)) out::print("  warning     {}\n", w);
}

void print_header(const fesd::SimulationProblem& problem) {
  const fesd::IntegratorOptions& o = problem.options;
  print_model_header(problem.name, problem.source, problem.description, problem.model,
                     problem.has_clock, problem.x0, "", problem.p);
  if (problem.u.size() > 0)
    out::print("  u           {}\n", join_vector(problem.u, problem.model.control_names));
  print_solver_header(std::to_string(o.discretization.N_FE), o.discretization, o.homotopy, o.nlp);
  const fesd::AccuracyOptions accuracy = fesd::accuracy_options(problem);
  out::print("  simulation  T_sim = {:g}, {}; fix_active_set = {}\n", problem.T_sim,
             fesd::format_accuracy_rule(accuracy, problem.T_sim),
             yes_no(o.homotopy.fix_active_set));
  if (!o.discretization.use_fesd)
    out::print(
        "  step solver homotopy (the standard method has no free lengths: every step by IPOPT)\n");
  else if (o.step_solver == fesd::StepSolver::ActiveSet)
    out::print(
        "  step solver active_set (Newton on the square system of Thm 15; the homotopy only "
        "where no consistent active set is found)\n");
  else
    out::print("  step solver homotopy (every step an MPCC homotopy of IPOPT solves)\n");
  flush_stdout();
}

/// "[-inf, 2]" per entry, or "none".
std::string bounds_text(const Eigen::VectorXd& lb, const Eigen::VectorXd& ub) {
  if (lb.size() == 0 && ub.size() == 0) return "none";
  std::string out;
  const Eigen::Index n = std::max(lb.size(), ub.size());
  for (Eigen::Index i = 0; i < n; ++i) {
    const double l = i < lb.size() ? lb[i] : -INFINITY, u = i < ub.size() ? ub[i] : INFINITY;
    out += fmt::format("{}[{:g}, {:g}]", i ? ", " : "", l, u);
  }
  return out;
}

void print_header(const fesd::OcpProblem& problem) {
  const fesd::Ocp& ocp = problem.ocp;
  const fesd::OcpOptions& o = problem.options;
  std::string n_fe = std::to_string(o.discretization.N_FE);
  if (!ocp.N_FE.empty()) {
    n_fe.clear();
    for (int n : ocp.N_FE) n_fe += fmt::format("{}{}", n_fe.empty() ? "" : ", ", n);
    n_fe = "[" + n_fe + "]";
  }
  const bool free_x0 = ocp.lbx0.size() > 0;
  print_model_header(problem.name, problem.source, problem.description, ocp.model,
                     problem.has_clock, ocp.x0, free_x0 ? " (free: the guess)" : "", ocp.p);
  print_solver_header(n_fe, o.discretization, o.homotopy, o.nlp);
  const fesd::OcpFunctions* f = ocp.functions.get();
  out::print("  ocp         T = {:g}, N_stages = {} (control interval {:g}), initialization = {}",
             ocp.T, ocp.N_stages, ocp.N_stages > 0 ? ocp.T / ocp.N_stages : 0.0,
             fesd::to_string(o.initialization));
  if (o.initial_theta >= 0) out::print(", initial_theta = {:g}", o.initial_theta);
  out::print("\n");
  out::print("  cost        Lagrange term f_q: {}, Mayer term f_q_T: {}\n",
             f != nullptr && f->has_f_q() ? "yes" : "no",
             f != nullptr && f->has_f_q_T() ? "yes" : "no");
  out::print("  constraints {} path{}, {} terminal{}", ocp.n_g_path,
             o.constraints_at_stages ? " (also at stage points)" : "", ocp.n_g_terminal,
             ocp.terminal_constraint == fesd::TerminalConstraint::L1
                 ? fmt::format(" (relaxed: ell_1, rho_terminal = {:g})", ocp.rho_terminal)
                 : "");
  out::print("\n");
  if (free_x0) out::print("  bounds x0   {}\n", bounds_text(ocp.lbx0, ocp.ubx0));
  out::print("  bounds x    {}\n", bounds_text(ocp.lbx, ocp.ubx));
  if (ocp.model.n_u() > 0) {
    out::print("  bounds u    {}\n", bounds_text(ocp.lbu, ocp.ubu));
    if (ocp.u_guess.size() > 0)
      out::print("  u guess     {}\n", join_vector(ocp.u_guess, ocp.model.control_names));
  }
  for (const std::string& w : fesd::warnings(ocp)) out::print("  warning     {}\n", w);
  flush_stdout();
}

/// Loads a problem file of either kind, applies the overrides and re-checks the options.
template <class Problem>
Problem load(const std::string& file, const Overrides& overrides) {
  check_input_file(file);
  Problem problem;
  if constexpr (std::is_same_v<Problem, fesd::OcpProblem>) {
    problem = fesd::load_ocp_problem(file);
  } else {
    problem = fesd::load_simulation_problem(file);
  }
  fesd::apply_overrides(problem, overrides.pairs());
  if (const std::vector<std::string> errors = fesd::validate(problem.options); !errors.empty()) {
    std::string all;
    for (const std::string& e : errors) all += (all.empty() ? "" : "; ") + e;
    throw fesd::InvalidOption(all);
  }
  return problem;
}

// ---- subcommands -------------------------------------------------------------------------------

struct SolveArgs {
  std::string file, json, csv, plot;
  bool quiet = false;
  Overrides overrides;
};

int run_check_pds(const std::string& file, const Overrides& overrides);

int run_check(const std::string& file, const Overrides& overrides) {
  check_input_file(file);
  if (fesd::is_projected_problem_file(file)) return run_check_pds(file, overrides);
  // The header, then the model as read: every region's sign pattern and vector field.
  if (fesd::problem_file_kind(file) == fesd::ProblemKind::Ocp) {
    const auto problem = load<fesd::OcpProblem>(file, overrides);
    print_header(problem);
    out::print("{}", fesd::io_detail::describe(problem));
  } else {
    const auto problem = load<fesd::SimulationProblem>(file, overrides);
    print_header(problem);
    out::print("{}", fesd::io_detail::describe(problem));
  }
  out::print("check: '{}' is valid (nothing was solved)\n", file);
  return kExitSolved;
}

/// Everything about the outputs that can be checked before solving (nothing is written).
void check_outputs(const SolveArgs& args, const CLI::App& cmd) {
  if (cmd.count("--plot") > 0) {
    const std::string ext = lower_extension(args.plot);
    if (ext != ".png" && ext != ".svg") {
      throw UsageError(
          "--plot '" + args.plot + "': unsupported " +
          (ext.empty() ? std::string("missing extension") : "extension '" + ext + "'") +
          " (supported: .png, .svg)");
    }
    check_output_path("--plot", args.plot);
    fesd::require_gnuplot();
  }
  if (cmd.count("--json") > 0) check_output_path("--json", args.json);
  if (cmd.count("--csv") > 0) check_output_path("--csv", args.csv);
}

/// Prints the report, writes the outputs that were asked for (also after a numerical failure,
/// then saying so) and returns the exit code. `what` names the run in the failure message.
template <class Result, class Model>
int finish(const Result& result, const std::string& report, const Model& model,
           const std::string& title, const SolveArgs& args, const CLI::App& cmd, const char* what) {
  std::fflush(stderr);
  out::print("{}", report);
  if (!report.empty() && report.back() != '\n') out::print("\n");

  const bool solved = result.status == fesd::Status::Success;
  const std::string note =
      solved ? "" : fmt::format(" (from an unsolved result: {})", fesd::to_string(result.status));
  std::vector<std::string> io_errors;
  auto write = [&](const char* option, const std::string& path, const char* kind, auto&& writer) {
    if (cmd.count(option) == 0) return;
    try {
      writer();
      out::print("wrote {} {}{}\n", kind, path, note);
    } catch (const fesd::IoError& e) {
      io_errors.emplace_back(e.what());
    }
  };
  write("--json", args.json, "JSON", [&] { fesd::write_json(result, model, args.json); });
  write("--csv", args.csv, "CSV ", [&] { fesd::write_csv(result, model, args.csv); });
  write("--plot", args.plot, "plot", [&] { fesd::write_plot(result, model, args.plot, title); });
  flush_stdout();

  if (!io_errors.empty()) {
    std::string message = io_errors.front();
    if (io_errors.size() > 1) {
      message += fmt::format(" (and {} more output{} failed)", io_errors.size() - 1,
                             io_errors.size() > 2 ? "s" : "");
    }
    print_error(message);
    return kExitIo;
  }
  if (!solved) {
    print_error(fmt::format("the {} failed ({}): {}", what, fesd::to_string(result.status),
                            result.message));
  }
  return fesd::exit_code(result.status);
}

/// Progress lines on stderr: one per integration step, or the homotopy table of an OCP.
void show_progress(fesd::IntegratorOptions& o) {
  o.on_step = [](const fesd::StepProgress& p) {
    std::cerr << fesd::format_step_progress(p) << std::flush;
  };
}
void show_progress(fesd::OcpOptions& o) {
  std::cerr << fesd::homotopy_table_header() << std::flush;
  o.on_homotopy_row = [](const fesd::HomotopyRow& r) {
    std::cerr << fesd::format_homotopy_row(r) << std::flush;
  };
  // A line every 30 s while an NLP runs (the hopper's and the gearboxes' take minutes).
  o.on_nlp_progress = [](const fesd::NlpProgress& p) {
    std::cerr << fesd::format_nlp_progress(p) << std::flush;
  };
}

/// Loads the problem file with the overrides, checks the output paths (before a possibly long
/// solve), prints the header unless --quiet, and turns progress lines on unless --quiet.
template <class Problem>
Problem prepare(const SolveArgs& args, const CLI::App& cmd) {
  Problem problem = load<Problem>(args.file, args.overrides);
  check_outputs(args, cmd);
  if (!args.quiet) {
    print_header(problem);
    out::print("\n");
    flush_stdout();
  }
  if (!args.quiet) show_progress(problem.options);
  return problem;
}

/// The first lines of the header of a projected file: name, source, what it is, sizes,
/// description, x0 and the scheme.
template <class Problem>
void print_pds_header(const Problem& problem, std::string_view what, const std::string& sizes,
                      const fesd::Pds& model, const Eigen::VectorXd& x0,
                      const fesd::DiscretizationOptions& d) {
  out::print("{} ({}): {}, n_x = {}, {}\n", problem.name, problem.source, what, model.n_x(), sizes);
  if (!problem.description.empty()) out::print("  {}\n", problem.description);
  out::print("  x0          {}\n", join_vector(x0, model.state_names));
  out::print("  scheme      {}, n_s = {}, N_FE = {}, use_fesd = {}\n", fesd::to_string(d.rk_scheme),
             d.n_s, d.N_FE, yes_no(d.use_fesd));
}

void print_header(const fesd::PdsSimulationProblem& problem) {
  print_pds_header(problem, "projected dynamical system",
                   fmt::format("n_c = {}", problem.model.n_c()), problem.model, problem.x0,
                   problem.options.discretization);
  out::print("  simulation  T_sim = {:g}{}, {}\n", problem.T_sim,
             problem.t0 != 0 ? fmt::format(" from t0 = {:g}", problem.t0) : "",
             fesd::format_accuracy_rule(fesd::accuracy_options(problem), problem.T_sim));
}

void print_header(const fesd::PdsOcpProblem& problem) {
  const fesd::PdsOcp& ocp = problem.ocp;
  print_pds_header(problem, "optimal control of a projected dynamical system",
                   fmt::format("n_u = {}, n_c = {}", ocp.model.n_u(), ocp.model.n_c()), ocp.model,
                   ocp.x0, problem.options.discretization);
  out::print("  ocp         T = {:g}, N_stages = {}\n", ocp.T, ocp.N_stages);
}

/// `fesd check` of a projected file: the header and the model as read (docs/pds.md).
int run_check_pds(const std::string& file, const Overrides& overrides) {
  auto run = [&](auto problem) {
    fesd::apply_overrides(problem, overrides.pairs());
    print_header(problem);
    out::print("{}", fesd::io_detail::describe(problem));
  };
  if (fesd::problem_file_kind(file) == fesd::ProblemKind::Ocp)
    run(fesd::load_pds_ocp_problem(file));
  else
    run(fesd::load_pds_simulation_problem(file));
  out::print("check: '{}' is valid (nothing was solved)\n", file);
  return kExitSolved;
}

/// `fesd simulate` of a projected dynamical system ([model] kind = "projected", docs/pds.md): the
/// header, integrate() and the report; --json and --csv as for piecewise smooth models.
/// One progress line per simulation run on stderr (N_sim chosen by tol_sim, or the companions of
/// the error estimate); none with --quiet.
std::function<void(const fesd::AccuracyRun&)> progress_lines(const SolveArgs& args, double tol_sim,
                                                             int N_sim) {
  if (args.quiet) return {};
  const double tol = tol_sim > 0 ? tol_sim : N_sim == 0 ? fesd::kDefaultTolSim : 0.0;
  return [tol](const fesd::AccuracyRun& r) {
    std::cerr << fesd::format_accuracy_run(r, tol) << std::flush;
  };
}

int run_simulate_pds(const SolveArgs& args, const CLI::App& cmd) {
  check_outputs(args, cmd);
  fesd::PdsSimulationProblem problem = fesd::load_pds_simulation_problem(args.file);
  fesd::apply_overrides(problem, args.overrides.pairs());
  if (!args.quiet) {
    print_header(problem);
    out::print("\n");
    flush_stdout();
  }
  const auto on_run = progress_lines(args, problem.tol_sim, problem.N_sim);
  const fesd::IntegratorResult result = fesd::simulate(problem, on_run);
  return finish(result, result.full_report(), problem.model, problem.name, args, cmd, "simulation");
}

int run_simulate(const SolveArgs& args, const CLI::App& cmd) {
  check_input_file(args.file);
  if (fesd::is_projected_problem_file(args.file)) return run_simulate_pds(args, cmd);
  const auto problem = prepare<fesd::SimulationProblem>(args, cmd);
  const auto on_run = progress_lines(args, problem.tol_sim, problem.N_sim);
  const fesd::IntegratorResult result = fesd::simulate(problem, on_run);
  return finish(result, result.full_report(), problem.model, problem.name, args, cmd, "simulation");
}

/// `fesd solve` of a projected dynamical system (docs/pds.md, "Optimal control"): the header, the
/// homotopy table as progress, solve() and the report; --json and --csv as for piecewise smooth
/// OCPs.
int run_solve_pds(const SolveArgs& args, const CLI::App& cmd) {
  check_outputs(args, cmd);
  fesd::PdsOcpProblem problem = fesd::load_pds_ocp_problem(args.file);
  fesd::apply_overrides(problem, args.overrides.pairs());
  const fesd::PdsOcp& ocp = problem.ocp;
  if (!args.quiet) {
    print_header(problem);
    out::print("\n");
    flush_stdout();
    show_progress(problem.options);
  }
  const fesd::OcpResult result = fesd::solve(ocp, problem.options);
  // The homotopy table is the progress output (none with --quiet): not repeated in the report.
  return finish(result, result.full_report(/*with_homotopy_table=*/false), ocp.model, problem.name,
                args, cmd, "optimal control problem");
}

int run_solve(const SolveArgs& args, const CLI::App& cmd) {
  check_input_file(args.file);
  if (fesd::is_projected_problem_file(args.file)) return run_solve_pds(args, cmd);
  const auto problem = prepare<fesd::OcpProblem>(args, cmd);
  const fesd::OcpResult result = fesd::solve(problem.ocp, problem.options);
  // The homotopy table is the progress output (none with --quiet): not repeated in the report.
  return finish(result, result.full_report(/*with_homotopy_table=*/false), problem.ocp.model,
                problem.name, args, cmd, "optimal control problem");
}

/// Adds FILE, the output options and --quiet to `simulate` or `solve`.
void add_solve_options(CLI::App& cmd, SolveArgs& args, const char* csv_help,
                       const char* plot_help) {
  cmd.add_option("FILE", args.file, "problem file (TOML)")->required();
  cmd.add_option("--json", args.json, "write the full result as JSON")->type_name("OUT");
  cmd.add_option("--csv", args.csv, csv_help)->type_name("OUT");
  cmd.add_option("--plot", args.plot, plot_help)->type_name("OUT.png|OUT.svg");
  cmd.add_flag("-q,--quiet", args.quiet, "no header, no progress lines");
}

int run(int argc, char** argv) {
  CLI::App app{
      "fesd: simulate and optimally control piecewise smooth (Filippov) systems with Finite "
      "Elements with Switch Detection",
      "fesd"};
  app.set_version_flag("--version", std::string("fesd ") + FESD_VERSION);
  app.footer(kExitHelp);
  app.require_subcommand(0, 1);

  SolveArgs sim;
  CLI::App* simulate = app.add_subcommand(
      "simulate", "simulate a problem file with a [simulation] table and report the result");
  add_solve_options(*simulate, sim, "write t and x at the element boundaries as CSV",
                    "plot states and step sizes with gnuplot");
  sim.overrides.add_to(*simulate, Scope::Simulation);

  SolveArgs ocp;
  CLI::App* solve = app.add_subcommand(
      "solve", "solve an optimal control problem file (an [ocp] table) and report the result");
  add_solve_options(*solve, ocp,
                    "write t, x at the element boundaries and the control of each row's interval "
                    "as CSV",
                    "plot states, controls, step sizes and the switch indicator with gnuplot");
  ocp.overrides.add_to(*solve, Scope::Ocp);

  std::string check_file;
  Overrides check_overrides;
  CLI::App* check_cmd = app.add_subcommand(
      "check", "load and validate a problem file (simulation or optimal control), do not solve");
  check_cmd->add_option("FILE", check_file, "problem file (TOML)")->required();
  check_overrides.add_to(*check_cmd, Scope::Both);

  // The first word that is not an option must be a command (the main program has only flags).
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg.empty() || arg.front() == '-') continue;
    if (arg != "simulate" && arg != "solve" && arg != "check") {
      print_error(fmt::format(
          "unknown command '{}' (commands: simulate, solve, check; see fesd --help)", arg));
      return kExitBadInput;
    }
    break;
  }

  try {
    std::vector<std::string> args = cli11_args(argc, argv);
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    print_error(std::string(e.what()) + " (see fesd --help)");
    return kExitBadInput;
  }

  sim.overrides.extras = simulate->remaining();
  ocp.overrides.extras = solve->remaining();
  check_overrides.extras = check_cmd->remaining();
  if (simulate->parsed()) return run_simulate(sim, *simulate);
  if (solve->parsed()) return run_solve(ocp, *solve);
  if (check_cmd->parsed()) return run_check(check_file, check_overrides);
  std::cout << app.help() << std::flush;
  print_error("no command given: use 'fesd simulate FILE', 'fesd solve FILE' or 'fesd check FILE'");
  return kExitBadInput;
}

/// run() with every exception turned into its exit code and one line on stderr.
int run_and_catch(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const fesd::IoError& e) {
    print_error(e.what());
    return kExitIo;
  } catch (
      const fesd::Error& e) {  // InvalidOption, ProblemFileError, ExpressionError, InvalidModel
    print_error(e.what());
    return kExitBadInput;
  } catch (const UsageError& e) {
    print_error(e.what());
    return kExitBadInput;
  } catch (const fesd::InternalError& e) {  // "internal: ..."
    print_error(std::string("internal error: ") + e.what());
    return kExitInternal;
  } catch (const std::bad_alloc&) {
    print_error("internal error: out of memory");
    return kExitInternal;
  } catch (const std::exception& e) {
    print_error(std::string("internal error: ") + e.what());
    return kExitInternal;
  } catch (...) {
    print_error("internal error: unknown exception");
    return kExitInternal;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // `fesd simulate ... | head -1`: a reader that goes away makes writes fail (EPIPE) instead of
  // killing the program, so the run finishes and writes its --json/--csv/--plot files.
  std::signal(SIGPIPE, SIG_IGN);
  const int code = run_and_catch(argc, argv);
  if (!stdout_ok() && code != kExitBadInput && code != kExitInternal) {
    // Also `fesd check FILE > /dev/full`: what was printed is lost, so nothing succeeded.
    std::cerr << "fesd: error: cannot write to standard output: " << std::strerror(stdout_errno)
              << std::endl;
    return kExitIo;
  }
  return code;
}
