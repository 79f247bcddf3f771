// tests/bad_input/problem_file_errors_test.cpp: every mistake in a problem file is one exception
// with a one-line message that names the file, the line and the key.
//
// Problem files: tests/bad_input/files/<mistake>.toml, one per mistake. Each starts with
//   # expect: <ProblemFileError | ExpressionError | InvalidOption | InvalidModel>
//   # message: <a substring the message must contain>      (one or more lines)
//   # loader: ocp                                          (optional: load_ocp_problem)
//   # loader: pds_ocp                                      (optional: load_pds_ocp_problem)
// and the test loads it (with load_simulation_problem unless the header names the OCP loader) and
// checks both. Overrides (apply_override) are checked inline below.
#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <fesd/error.hpp>
#include <fesd/pds_problem_file.hpp>
#include <fesd/problem_file.hpp>

namespace fesd {
namespace {

const std::string kFilesDir = std::string(FESD_SOURCE_DIR) + "/tests/bad_input/files";

/// The most specific fesd exception class of `e`.
std::string kind_of(const Error& e) {
  if (dynamic_cast<const ProblemFileError*>(&e) != nullptr) return "ProblemFileError";
  if (dynamic_cast<const ExpressionError*>(&e) != nullptr) return "ExpressionError";
  if (dynamic_cast<const InvalidOption*>(&e) != nullptr) return "InvalidOption";
  if (dynamic_cast<const InvalidModel*>(&e) != nullptr) return "InvalidModel";
  return "Error";
}

struct Outcome {
  std::string kind = "<no exception>";
  std::string message;
};

template <class F>
Outcome outcome_of(F&& f) {
  Outcome o;
  try {
    f();
  } catch (const Error& e) {
    o.kind = kind_of(e);
    o.message = e.what();
  }
  return o;
}

// ---- one file per mistake -------------------------------------------------------------------

std::vector<std::string> bad_files() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(kFilesDir))
    if (entry.path().extension() == ".toml") names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

class BadProblemFile : public ::testing::TestWithParam<std::string> {};

TEST_P(BadProblemFile, ThrowsWithMessage) {
  const std::string path = kFilesDir + "/" + GetParam();
  std::ifstream in(path);
  ASSERT_TRUE(in) << path;
  std::string expect_kind, loader = "simulation";
  std::vector<std::string> expect_messages;
  for (std::string line; std::getline(in, line) && line.rfind('#', 0) == 0;) {
    if (line.rfind("# expect: ", 0) == 0) expect_kind = line.substr(10);
    if (line.rfind("# message: ", 0) == 0) expect_messages.push_back(line.substr(11));
    if (line.rfind("# loader: ", 0) == 0) loader = line.substr(10);
  }
  ASSERT_FALSE(expect_kind.empty()) << path << ": no '# expect:' header";
  ASSERT_FALSE(expect_messages.empty()) << path << ": no '# message:' header";
  ASSERT_TRUE(loader == "simulation" || loader == "ocp" || loader == "pds_ocp")
      << path << ": unknown loader " << loader;

  const Outcome o = outcome_of([&] {
    if (loader == "ocp")
      load_ocp_problem(path);
    else if (loader == "pds_ocp")
      load_pds_ocp_problem(path);
    else
      load_simulation_problem(path);
  });
  EXPECT_EQ(o.kind, expect_kind) << o.message;
  for (const std::string& m : expect_messages)
    EXPECT_NE(o.message.find(m), std::string::npos)
        << "message:  " << o.message << "\nexpected: " << m;
  EXPECT_EQ(o.message.find('\n'), std::string::npos) << "one line: " << o.message;
  EXPECT_EQ(o.message.rfind(path, 0), 0U) << "starts with the file name: " << o.message;
}

INSTANTIATE_TEST_SUITE_P(Files, BadProblemFile, ::testing::ValuesIn(bad_files()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) {
                           return param_info.param.substr(0, param_info.param.find('.'));
                         });

TEST(BadProblemFileDirectory, HasOneFilePerMistake) {
  // Guards against the parameterised test silently running nothing.
  EXPECT_GE(bad_files().size(), 50U);
}

// ---- reading the file itself ----------------------------------------------------------------

TEST(BadProblemFileIo, MissingFile) {
  const Outcome o = outcome_of([] { load_simulation_problem("/nonexistent/dir/model.toml"); });
  EXPECT_EQ(o.kind, "ProblemFileError");
  EXPECT_EQ(o.message, "/nonexistent/dir/model.toml: cannot read problem file (no such file)");
}

TEST(BadProblemFileIo, DirectoryInsteadOfFile) {
  const Outcome o = outcome_of([] { load_simulation_problem(kFilesDir); });
  EXPECT_EQ(o.kind, "ProblemFileError");
  EXPECT_NE(o.message.find("not a regular file"), std::string::npos) << o.message;
}

TEST(BadProblemFileText, SyntaxErrorHasLineAndColumn) {
  const Outcome o = outcome_of(
      [] { parse_simulation_problem("[model]\nx = [\"x1\"]\nx0 = [1.0,, 2.0]\n", "inline.toml"); });
  EXPECT_EQ(o.kind, "ProblemFileError");
  EXPECT_EQ(o.message.rfind("inline.toml:3:", 0), 0U) << o.message;
  EXPECT_NE(o.message.find("TOML syntax error"), std::string::npos) << o.message;
}

TEST(BadProblemFileText, DuplicateKeyIsASyntaxError) {
  const Outcome o = outcome_of(
      [] { parse_simulation_problem("[simulation]\nT_sim = 1\nT_sim = 2\n", "dup.toml"); });
  EXPECT_EQ(o.kind, "ProblemFileError");
  EXPECT_EQ(o.message.rfind("dup.toml:3:", 0), 0U) << o.message;
}

TEST(BadProblemFileText, SeveralOptionErrorsAreReportedTogether) {
  const Outcome o = outcome_of([] {
    parse_simulation_problem(R"toml(
[model]
x = ["x"]
c = ["x"]
F = [["1"], ["-1"]]
x0 = [0]
[simulation]
T_sim = 1
[homotopy]
sigma_0 = -1.0
N_homotopy = -1
)toml",
                             "two.toml");
  });
  EXPECT_EQ(o.kind, "InvalidOption");
  EXPECT_NE(o.message.find("two.toml:10: homotopy.sigma_0 = -1: must be > 0"), std::string::npos)
      << o.message;
  EXPECT_NE(o.message.find("two.toml:11: homotopy.N_homotopy = -1: must be in 0..1000"),
            std::string::npos)
      << o.message;
}

// ---- overrides ------------------------------------------------------------------------------

constexpr const char* kValid = R"toml(
[model]
x = ["x"]
u = ["u1"]
c = ["x"]
F = [["u1"], ["-1"]]
x0 = [0]
[simulation]
T_sim = 1
)toml";

struct OverrideCase {
  const char* key;
  const char* value;
  const char* message;  // a substring of the InvalidOption message
};

class BadOverride : public ::testing::TestWithParam<OverrideCase> {};

TEST_P(BadOverride, ThrowsInvalidOptionAndLeavesProblemUnchanged) {
  const OverrideCase& c = GetParam();
  SimulationProblem q = parse_simulation_problem(kValid, "valid.toml");
  const Outcome o = outcome_of([&] { apply_override(q, c.key, c.value); });
  EXPECT_EQ(o.kind, "InvalidOption") << o.message;
  EXPECT_NE(o.message.find(c.message), std::string::npos)
      << "message:  " << o.message << "\nexpected: " << c.message;
  // Nothing was changed by the failed override.
  const SimulationProblem fresh = parse_simulation_problem(kValid, "valid.toml");
  EXPECT_EQ(q.options.discretization.n_s, fresh.options.discretization.n_s);
  EXPECT_EQ(q.options.discretization.N_FE, fresh.options.discretization.N_FE);
  EXPECT_EQ(q.options.discretization.use_fesd, fresh.options.discretization.use_fesd);
  EXPECT_EQ(q.options.homotopy.sigma_0, fresh.options.homotopy.sigma_0);
  EXPECT_EQ(q.T_sim, fresh.T_sim);
  EXPECT_EQ(q.N_sim, fresh.N_sim);
  EXPECT_EQ(q.u, fresh.u);
  EXPECT_EQ(q.x0, fresh.x0);
}

// Parameters: a model with one (issue 13, 3).
TEST(BadParameterOverride, ThrowsInvalidOptionAndLeavesProblemUnchanged) {
  constexpr const char* kWithP = R"toml(
[model]
x = ["x"]
p = { omega = 2.0, zeta = 0.1 }
c = ["x"]
F = [["-omega"], ["zeta"]]
x0 = [0]
[simulation]
T_sim = 1
)toml";
  SimulationProblem q = parse_simulation_problem(kWithP, "p.toml");
  for (const auto& [key, value, message] : std::vector<std::array<const char*, 3>>{
           {"p", "omgea=3", "--p omgea=3: unknown parameter 'omgea' (did you mean 'omega'?)"},
           {"p", "xi=3", "--p xi=3: unknown parameter 'xi' (parameters in model.p: omega, zeta)"},
           {"p", "omega",
            "--p omega: expected NAME=VALUE, a parameter of model.p and its value "
            "(e.g. --p omega=2.5)"},
           {"p", "=3", "--p =3: expected NAME=VALUE"},
           {"p", "omega=nan", "--p omega=nan: model.p.omega = nan: must be finite"},
           {"p", "omega=", "--p omega=: model.p.omega: expected a number, got \"\""},
           {"p", "omega=1,2", "--p omega=1,2: model.p.omega: expected a number, got \"1,2\""},
           {"zeta", "0.05",
            "--zeta = 0.05: unknown option 'zeta' ('zeta' is a parameter of model.p: write "
            "--p zeta=0.05)"}}) {
    const Outcome o = outcome_of([&] { apply_override(q, key, value); });
    EXPECT_EQ(o.kind, "InvalidOption") << o.message;
    EXPECT_NE(o.message.find(message), std::string::npos)
        << "message:  " << o.message << "\nexpected: " << message;
  }
  EXPECT_EQ(q.p, parse_simulation_problem(kWithP, "p.toml").p);
  EXPECT_EQ(q.model.p_default, q.p);
}

INSTANTIATE_TEST_SUITE_P(
    Overrides, BadOverride,
    ::testing::Values(
        OverrideCase{"n_S", "3", "--n_S = 3: unknown option 'n_S' (did you mean 'n_s'?)"},
        OverrideCase{"discretization.sigma_0", "3", "unknown option 'sigma_0'"},
        OverrideCase{"solver.tol", "1", "--solver.tol = 1: unknown table 'solver'"},
        OverrideCase{"n_s", "0", "--n_s = 0: must be in 1..9 for radau_iia"},
        OverrideCase{"n_s", "three", "--n_s = three: expected an integer"},
        OverrideCase{"n_s", "2.5", "--n_s = 2.5: expected an integer"},
        OverrideCase{"N_FE", "1", "--N_FE = 1: FESD needs >= 2 finite elements"},
        OverrideCase{"use_fesd", "yes",
                     "--use_fesd = yes: expected a boolean (1, 0, true or false, got \"yes\")"},
        OverrideCase{"rk_scheme", "rk4",
                     "--rk_scheme = rk4: unknown name (expected one of radau_iia, "
                     "gauss_legendre, lobatto_iiia, lobatto_iiic, explicit_rk; got \"rk4\")"},
        OverrideCase{"cross_comp_mode", "all", "--cross_comp_mode = all: unknown name"},
        OverrideCase{"step_equilibration", "", "--step_equilibration = : unknown name"},
        OverrideCase{"T_sim", "nan", "--T_sim = nan: must be finite"},
        OverrideCase{"T_sim", "-2", "--T_sim = -2: must be > 0"},
        OverrideCase{"N_sim", "-1", "--N_sim = -1: must be >= 0 (0: chosen by tol_sim)"},
        OverrideCase{"tol_sim", "-1e-6", "--tol_sim = -1e-6: must be >= 0 (0: 1e-6 if N_sim"},
        OverrideCase{"N_sim_max", "0", "--N_sim_max = 0: must be >= 1"},
        OverrideCase{"sigma_0", "1e-20",
                     "--sigma_0 = 1e-20: homotopy.sigma_N = 1e-12: must be <= sigma_0"},
        OverrideCase{"print_level", "99", "--print_level = 99: must be in 0..12"},
        OverrideCase{"u", "1, 2",
                     "--u = 1, 2: wrong length (expected 1 number, one per control, got 2)"},
        OverrideCase{"u", "abc", "--u = abc: expected comma-separated numbers"},
        OverrideCase{"u", "nan", "--u = nan: simulation.u[0] = nan: must be finite"},
        // [model] x0 and p (issue 13, 3).
        OverrideCase{"x0", "1, 2",
                     "--x0 = 1, 2: wrong length (expected 1 number, one per state in model.x, "
                     "got 2)"},
        OverrideCase{"x0", "inf", "--x0 = inf: model.x0[0] = inf: must be finite"},
        OverrideCase{"model.x0", "one", "--model.x0 = one: expected comma-separated numbers"},
        OverrideCase{"p", "k=1",
                     "--p k=1: unknown parameter 'k' (the model has no parameters: model.p is "
                     "empty)"},
        OverrideCase{"model.F", "1",
                     "--model.F = 1: unknown option 'F' (model.F can only be set in the file; "
                     "the [model] overrides are x0 and p)"},
        OverrideCase{"c", "x", "--c = x: unknown option 'c' (model.c can only be set in the file"},
        OverrideCase{"model.x0s", "1",
                     "--model.x0s = 1: unknown option 'x0s' (did you mean 'x0'?)"},
        // Keys by meaning (issue 13, 4): the OCP's name, nosnoc's names.
        OverrideCase{"T", "2", "--T = 2: unknown option 'T' (did you mean 'T_sim'?)"},
        OverrideCase{"u_guess", "1", "--u_guess = 1: unknown option 'u_guess' (did you mean 'u'?)"},
        OverrideCase{"terminal_time", "2",
                     "--terminal_time = 2: unknown option 'terminal_time' (did you mean 'T_sim'?)"},
        OverrideCase{"Nfe_list", "2",
                     "--Nfe_list = 2: unknown option 'Nfe_list' (did you mean "
                     "'N_finite_elements'?)"},
        OverrideCase{"max_iter_homotopy", "5",
                     "--max_iter_homotopy = 5: unknown option 'max_iter_homotopy' (did you mean "
                     "'N_homotopy'?)"}),
    [](const ::testing::TestParamInfo<OverrideCase>& param_info) {
      return "case" + std::to_string(param_info.index);
    });

}  // namespace
}  // namespace fesd
