// src/cli/main.cpp: the `fesd` program.
//
//   fesd simulate FILE [--json OUT] [--csv OUT] [--plot OUT.png|OUT.svg] [--quiet] [overrides]
//   fesd check FILE [overrides]
//
// Exit codes: 0 solved, 1 numerical failure (outputs are still written), 2 bad input, 3 I/O
// failure, 4 internal error. Every error is one line on stderr: "fesd: error: <message>".
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <iostream>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/io.hpp"
#include "fesd/options.hpp"
#include "fesd/problem_file.hpp"
#include "fesd/status.hpp"
#include "fesd/tableau.hpp"

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

void print_error(std::string_view message) {
  std::fflush(stdout);
  std::cerr << "fesd: error: " << one_line(message) << std::endl;
}

// ---- overrides -------------------------------------------------------------------------------

struct OverrideKey {
  const char* key;    ///< apply_override key
  const char* names;  ///< CLI11 option names
  const char* help;
};

constexpr OverrideKey kOverrideKeys[] = {
    {"T_sim", "--T_sim", "[simulation] end time T_sim > 0"},
    {"N_sim", "--N_sim", "[simulation] number of integration steps"},
    {"rk_scheme", "--rk_scheme",
     "radau_iia, gauss_legendre, lobatto_iiia, lobatto_iiic or explicit_rk"},
    {"n_s", "--n_s", "Runge-Kutta stages per finite element"},
    {"N_finite_elements", "--N_finite_elements,--N_FE", "finite elements per integration step"},
    {"use_fesd", "--use_fesd", "1: FESD (32), 0: standard time-stepping (26)"},
    {"cross_comp_mode", "--cross_comp_mode", "sparse, stage_sum, element or neighbor"},
    {"step_equilibration", "--step_equilibration",
     "none, eta, eta_tanh, heuristic_mean or l2_relaxed"},
    {"stage_lambda_sign", "--stage_lambda_sign",
     "where lambda >= 0 holds: all (stages), boundary (element ends) or auto"},
    {"gamma_h", "--gamma_h", "step size freedom in (0, 1]"},
    {"rho_h", "--rho_h", "weight of the heuristic_mean penalty"},
    {"mpcc_mode", "--mpcc_mode",
     "scholtes_ineq, scholtes_eq, fischer_burmeister, ell_1_penalty or elastic_ineq"},
    {"sigma_0", "--sigma_0", "first homotopy relaxation"},
    {"homotopy_update_slope", "--homotopy_update_slope", "sigma_{k+1} = slope * sigma_k"},
    {"sigma_N", "--sigma_N", "smallest sigma"},
    {"complementarity_tol", "--complementarity_tol", "stop when the residual is below this"},
    {"N_homotopy", "--N_homotopy", "maximum number of NLPs per step"},
    {"tol", "--tol", "IPOPT tol"},
    {"acceptable_tol", "--acceptable_tol", "IPOPT acceptable_tol"},
    {"max_iter", "--max_iter", "IPOPT iterations per NLP"},
    {"print_level", "--print_level", "IPOPT print_level 0..12"},
};
constexpr std::size_t kNumOverrideKeys = sizeof kOverrideKeys / sizeof kOverrideKeys[0];

/// The override options of one subcommand and their values after parsing.
struct Overrides {
  std::vector<std::string> values = std::vector<std::string>(kNumOverrideKeys);
  std::vector<CLI::Option*> options = std::vector<CLI::Option*>(kNumOverrideKeys, nullptr);
  std::vector<std::string> ipopt;

  void add_to(CLI::App& app) {
    for (std::size_t i = 0; i < kNumOverrideKeys; ++i) {
      options[i] = app.add_option(kOverrideKeys[i].names, values[i], kOverrideKeys[i].help)
                       ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast)
                       ->group("Overrides (as if written in the problem file)");
    }
    app.add_option("--ipopt", ipopt, "any IPOPT option, NAME=VALUE (repeatable)")
        ->type_name("NAME=VALUE")
        ->allow_extra_args(false)
        ->group("Overrides (as if written in the problem file)");
  }

  /// (key, value) pairs in a fixed order, the --ipopt ones last (as keys "ipopt.NAME", so that
  /// any IPOPT option name is accepted).
  std::vector<std::pair<std::string, std::string>> pairs() const {
    std::vector<std::pair<std::string, std::string>> out;
    for (std::size_t i = 0; i < kNumOverrideKeys; ++i) {
      if (options[i] != nullptr && options[i]->count() > 0) {
        out.emplace_back(kOverrideKeys[i].key, values[i]);
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

/// Applies the overrides. apply_override re-validates after every key, so a combination that is
/// valid only as a whole (e.g. rk_scheme = lobatto_iiia together with n_s = 2 when the file has
/// n_s = 1) may fail in one order and succeed in another: keys that fail are retried as long as
/// others succeed; the first remaining failure is reported.
void apply_overrides(fesd::SimulationProblem& problem, const Overrides& overrides) {
  std::vector<std::pair<std::string, std::string>> pending = overrides.pairs();
  while (!pending.empty()) {
    std::vector<std::pair<std::string, std::string>> failed;
    std::string first_error;
    for (const auto& [key, value] : pending) {
      try {
        fesd::apply_override(problem, key, value);
      } catch (const fesd::InvalidOption& e) {
        if (failed.empty()) first_error = e.what();
        failed.emplace_back(key, value);
      }
    }
    if (failed.size() == pending.size()) throw fesd::InvalidOption(first_error);
    pending = std::move(failed);
  }
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

bool gnuplot_on_path() {
  const char* env = std::getenv("PATH");
  std::string_view dirs = env != nullptr ? env : "/usr/local/bin:/usr/bin:/bin";
  while (true) {
    const std::size_t colon = dirs.find(':');
    std::string candidate(dirs.substr(0, colon));
    if (candidate.empty()) candidate.push_back('.');
    candidate += "/gnuplot";
    struct stat st {};
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
        ::access(candidate.c_str(), X_OK) == 0) {
      return true;
    }
    if (colon == std::string_view::npos) return false;
    dirs.remove_prefix(colon + 1);
  }
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

void print_header(const fesd::SimulationProblem& problem) {
  const fesd::Pss& m = problem.model;
  const fesd::IntegratorOptions& o = problem.options;
  const fesd::DiscretizationOptions& d = o.discretization;
  const fesd::HomotopyOptions& h = o.homotopy;
  const fesd::NlpOptions& nlp = o.nlp;

  std::string names;
  for (int i = 0; i < m.n_x(); ++i) {
    const std::string name = static_cast<std::size_t>(i) < m.state_names.size()
                                 ? m.state_names[static_cast<std::size_t>(i)]
                                 : fmt::format("x{}", i + 1);
    names += (i ? ", " : "") + name;
  }
  std::string regions;
  for (int k = 0; k < m.n_sys(); ++k) {
    const fesd::Subsystem& sub = m.dims().subsystems[static_cast<std::size_t>(k)];
    const int n_f = m.region_offset(k + 1) - m.region_offset(k);
    regions += fmt::format(
        "{}{} ({})", k ? ", " : "", n_f,
        sub.n_c > 0 ? fmt::format("n_c = {}", sub.n_c) : fmt::format("n_g = {}", sub.n_g));
  }

  fmt::print("fesd {}: {} ({})\n", FESD_VERSION, problem.name, problem.source);
  if (!problem.description.empty()) fmt::print("  {}\n", one_line(problem.description));
  fmt::print("  model       n_x = {} ({}), n_u = {}, n_p = {}{}\n", m.n_x(), names, m.n_u(),
             m.n_p(), problem.has_clock ? ", with clock state t" : "");
  fmt::print("  regions     {} subsystem{}, regions per subsystem: {} (n_theta = {})\n", m.n_sys(),
             m.n_sys() == 1 ? "" : "s", regions, m.n_theta());
  fmt::print("  x0          {}\n", join_vector(problem.x0));
  if (problem.p.size() > 0)
    fmt::print("  p           {}\n", join_vector(problem.p, m.parameter_names));
  if (problem.u.size() > 0)
    fmt::print("  u           {}\n", join_vector(problem.u, m.control_names));
  fmt::print("  scheme      {}, n_s = {}, N_FE = {}, use_fesd = {}", fesd::to_string(d.rk_scheme),
             d.n_s, d.N_FE, yes_no(d.use_fesd));
  if (d.use_fesd) {
    fmt::print(" (cross_comp_mode = {}, step_equilibration = {})", fesd::to_string(d.cross_comp),
               fesd::to_string(d.step_eq));
  }
  fmt::print("\n");
  fmt::print(
      "  homotopy    mpcc_mode = {}, sigma_0 = {:g}, slope = {:g}, sigma_N = {:g}, "
      "complementarity_tol = {:g}, N_homotopy = {}\n",
      fesd::to_string(h.mpcc_mode), h.sigma_0, h.homotopy_update_slope, h.sigma_N,
      h.complementarity_tol, h.max_homotopy_steps);
  fmt::print("  ipopt       tol = {:g}, acceptable_tol = {:g}, max_iter = {}, print_level = {}",
             nlp.tol, nlp.acceptable_tol, nlp.max_iter, nlp.print_level);
  for (const auto& [name, value] : nlp.extra) fmt::print(", {} = {}", name, value);
  fmt::print("\n");
  fmt::print("  simulation  T_sim = {:g}, N_sim = {} (step {:g})\n", problem.T_sim, problem.N_sim,
             problem.N_sim > 0 ? problem.T_sim / problem.N_sim : 0.0);
  std::fflush(stdout);
}

fesd::SimulationProblem load(const std::string& file, const Overrides& overrides) {
  check_input_file(file);
  fesd::SimulationProblem problem = fesd::load_simulation_problem(file);
  apply_overrides(problem, overrides);
  fesd::check(problem.options);
  return problem;
}

// ---- subcommands -------------------------------------------------------------------------------

struct SimulateArgs {
  std::string file, json, csv, plot;
  bool quiet = false;
  Overrides overrides;
};

int run_check(const std::string& file, const Overrides& overrides) {
  const fesd::SimulationProblem problem = load(file, overrides);
  print_header(problem);
  fmt::print("check: '{}' is valid (nothing was solved)\n", file);
  return kExitSolved;
}

int run_simulate(const SimulateArgs& args, const CLI::App& cmd) {
  const bool want_json = cmd.count("--json") > 0, want_csv = cmd.count("--csv") > 0,
             want_plot = cmd.count("--plot") > 0;
  fesd::SimulationProblem problem = load(args.file, args.overrides);

  // Everything that can be checked before solving is checked before solving.
  if (want_plot) {
    const std::string ext = lower_extension(args.plot);
    if (ext != ".png" && ext != ".svg") {
      throw UsageError(
          "--plot '" + args.plot + "': unsupported " +
          (ext.empty() ? std::string("missing extension") : "extension '" + ext + "'") +
          " (supported: .png, .svg)");
    }
    check_output_path("--plot", args.plot);
    if (!gnuplot_on_path()) {
      throw fesd::IoError("gnuplot not found: install gnuplot-nox (scripts/install-deps.sh)");
    }
  }
  if (want_json) check_output_path("--json", args.json);
  if (want_csv) check_output_path("--csv", args.csv);

  if (!args.quiet) {
    print_header(problem);
    fmt::print("\n");
    std::fflush(stdout);
  }
  problem.options.progress = !args.quiet;
  const fesd::IntegratorResult result =
      fesd::integrate(problem.model, problem.x0, problem.T_sim, problem.N_sim, problem.options,
                      problem.u, problem.p);
  std::fflush(stderr);
  const std::string report = result.full_report();
  fmt::print("{}", report);
  if (!report.empty() && report.back() != '\n') fmt::print("\n");

  // Write what was asked for, also after a numerical failure (then say so).
  const bool solved = result.status == fesd::Status::Success;
  const std::string note =
      solved ? "" : fmt::format(" (from an unsolved result: {})", fesd::to_string(result.status));
  std::vector<std::string> io_errors;
  auto write = [&](bool wanted, const std::string& path, const char* what, auto&& writer) {
    if (!wanted) return;
    try {
      writer();
      fmt::print("wrote {} {}{}\n", what, path, note);
    } catch (const fesd::IoError& e) {
      io_errors.emplace_back(e.what());
    }
  };
  write(want_json, args.json, "JSON", [&] { fesd::write_json(result, problem.model, args.json); });
  write(want_csv, args.csv, "CSV ", [&] { fesd::write_csv(result, problem.model, args.csv); });
  write(want_plot, args.plot, "plot",
        [&] { fesd::write_plot(result, problem.model, args.plot, problem.name); });
  std::fflush(stdout);

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
    print_error(fmt::format("the simulation failed ({}): {}", fesd::to_string(result.status),
                            result.message));
  }
  return fesd::exit_code(result.status);
}

int run(int argc, char** argv) {
  CLI::App app{
      "fesd: simulate piecewise smooth (Filippov) systems with Finite Elements with "
      "Switch Detection",
      "fesd"};
  app.set_version_flag("--version", std::string("fesd ") + FESD_VERSION);
  app.require_subcommand(0, 1);

  SimulateArgs sim;
  CLI::App* simulate = app.add_subcommand("simulate", "solve a problem file and report the result");
  simulate->add_option("FILE", sim.file, "problem file (TOML)")->required();
  simulate->add_option("--json", sim.json, "write the full result as JSON")->type_name("OUT");
  simulate->add_option("--csv", sim.csv, "write t and x at the element boundaries as CSV")
      ->type_name("OUT");
  simulate->add_option("--plot", sim.plot, "plot states and step sizes with gnuplot")
      ->type_name("OUT.png|OUT.svg");
  simulate->add_flag("-q,--quiet", sim.quiet, "no header, no progress lines");
  sim.overrides.add_to(*simulate);

  std::string check_file;
  Overrides check_overrides;
  CLI::App* check_cmd =
      app.add_subcommand("check", "load and validate a problem file, do not solve");
  check_cmd->add_option("FILE", check_file, "problem file (TOML)")->required();
  check_overrides.add_to(*check_cmd);

  // The first word that is not an option must be a command (the main program has only flags).
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg.empty() || arg.front() == '-') continue;
    if (arg != "simulate" && arg != "check") {
      print_error(
          fmt::format("unknown command '{}' (commands: simulate, check; see fesd --help)", arg));
      return kExitBadInput;
    }
    break;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    print_error(std::string(e.what()) + " (see fesd --help)");
    return kExitBadInput;
  }

  if (simulate->parsed()) return run_simulate(sim, *simulate);
  if (check_cmd->parsed()) return run_check(check_file, check_overrides);
  std::cout << app.help() << std::flush;
  print_error("no command given: use 'fesd simulate FILE' or 'fesd check FILE'");
  return kExitBadInput;
}

}  // namespace

int main(int argc, char** argv) {
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
