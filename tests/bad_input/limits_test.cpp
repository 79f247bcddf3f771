// tests/bad_input/limits_test.cpp: the size and step limits (docs/problem-files.md, "Limits").
// A problem file loads (and `fesd check` says valid) exactly when its NLP can be built: sums over
// elements have no input limit (N_FE up to 1000), the blocks that grow with n_x and the number of
// regions are rejected up front with a message naming the key. Steps shorter than 1e-12
// max(1, |t0|) are rejected by the files, integrate() and solve().
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "discretization/fesd_interval.hpp"
#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/ocp.hpp"
#include "fesd/problem_file.hpp"
#include "mpcc/relaxation.hpp"
#include "nlp/block_nlp.hpp"

namespace {

/// A simulation file with n_x states and n_regions regions given by indicator functions
/// g_r = x1 - r (g-form, so any number of regions), every vector field constant.
std::string g_form_file(int n_x, int n_regions, const std::string& discretization = "") {
  std::string x, x0, g, F;
  for (int i = 0; i < n_x; ++i) {
    x += fmt::format("{}\"x{}\"", i ? ", " : "", i + 1);
    x0 += fmt::format("{}0", i ? ", " : "");
  }
  for (int r = 0; r < n_regions; ++r) {
    g += fmt::format("{}\"x1 - {}\"", r ? ", " : "", r);
    std::string row;
    for (int i = 0; i < n_x; ++i) row += fmt::format("{}\"{}\"", i ? ", " : "", r + 1);
    F += fmt::format("{}[{}]", r ? ",\n     " : "", row);
  }
  return fmt::format(
      "[model]\nx = [{}]\ng = [{}]\nF = [{}]\nx0 = [{}]\n[simulation]\nT_sim = 1\n"
      "[discretization]\n{}\n",
      x, g, F, x0, discretization);
}

/// The message of the fesd::Error of loading `text`, or "" if it loads.
std::string load_error(const std::string& text) {
  try {
    fesd::parse_simulation_problem(text, "limits.toml");
  } catch (const fesd::Error& e) {
    return e.what();
  }
  return "";
}

/// A model of any size: n_x states, n_regions regions from g_r = x1 - r, f_r = r + 1.
struct Sized {
  int n_x, n_regions;
  template <class T>
  void g(const T* x, const T*, T* g) const {
    for (int r = 0; r < n_regions; ++r) g[r] = x[0] - double(r);
  }
  template <class T>
  void f(int r, const T*, const T*, const T*, T* f) const {
    for (int i = 0; i < n_x; ++i) f[i] = T(r + 1.0);
  }
};

fesd::Pss sized(int n_x, int n_regions) {
  return fesd::make_pss(
      Sized{n_x, n_regions},
      fesd::PssDims{.n_x = n_x, .subsystems = {fesd::Subsystem::from_g(n_regions)}});
}

/// Builds the NLP of one step as integrate() does (without solving): "" or the error.
std::string build_error(const fesd::Pss& m, const fesd::DiscretizationOptions& d, double T) {
  try {
    fesd::nlp::BlockNlp nlp;
    fesd::discretization::IntervalInputs in;
    auto vars = [&](int n) {
      std::vector<int> v;
      const int first = nlp.add_variables(n, 0.0, 0.0, 0.0);
      for (int i = 0; i < n; ++i) v.push_back(first + i);
      return v;
    };
    in.s0 = vars(m.n_x());
    in.q = vars(m.n_u());
    in.p = vars(m.n_p());
    in.lambda_start = vars(m.n_theta());
    in.mu_start = vars(m.n_sys());
    in.lp_at_start = true;
    in.boundary_at_end = true;
    in.T = T;
    fesd::discretization::FesdInterval iv(m, fesd::make_tableau(d.rk_scheme, d.n_s), d);
    iv.build(nlp, in);
    const fesd::mpcc::Relaxation relaxation(nlp, iv.groups(), fesd::MpccMode::ScholtesIneq);
    nlp.finalize();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(Limits, RegionsAndStatesAreRejectedExactlyWhenTheNlpCannotBeBuilt) {
  // The largest block is the dynamics (25), 2 n_x + n_theta inputs here, the LP (9),
  // n_x + n_theta + 1, or with eta (31), 2 + 4 n_theta; at most ad::kMaxInputs = 128.
  struct Case {
    int n_x, n_regions;
    fesd::StepEq step_eq;
    const char* step_eq_name;
    const char* key;  // named in the message when rejected
  };
  using fesd::StepEq;
  const Case cases[] = {
      {1, 126, StepEq::HeuristicMean, "heuristic_mean", "model.F = 127 regions"},
      {1, 127, StepEq::HeuristicMean, "heuristic_mean", "model.F = 127 regions"},
      {1, 31, StepEq::Eta, "eta", "discretization.step_equilibration = eta"},
      {1, 32, StepEq::Eta, "eta", "discretization.step_equilibration = eta"},
      {1, 32, StepEq::L2Relaxed, "l2_relaxed", "discretization.step_equilibration = l2_relaxed"},
      {1, 32, StepEq::EtaTanh, "eta_tanh", "discretization.step_equilibration = eta_tanh"},
      {1, 32, StepEq::None, "none", ""},
      {63, 2, StepEq::HeuristicMean, "heuristic_mean", "model.x = 63 states"},
      {64, 2, StepEq::HeuristicMean, "heuristic_mean", "model.x = 64 states"},
  };
  int rejected = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(::testing::Message() << "n_x = " << c.n_x << ", regions = " << c.n_regions
                                      << ", step_equilibration = " << c.step_eq_name);
    fesd::DiscretizationOptions d;
    d.step_eq = c.step_eq;
    const std::vector<std::string> errors =
        fesd::discretization::FesdInterval::block_size_errors(sized(c.n_x, c.n_regions), d);
    const std::string build = build_error(sized(c.n_x, c.n_regions), d, 1.0);
    EXPECT_EQ(errors.empty(), build.empty()) << build;  // rejected exactly when building fails
    const std::string load = load_error(g_form_file(
        c.n_x, c.n_regions, fmt::format("step_equilibration = \"{}\"", c.step_eq_name)));
    EXPECT_EQ(load.empty(), errors.empty()) << load;
    if (!load.empty()) {
      ++rejected;
      EXPECT_NE(load.find(c.key), std::string::npos) << load;
      EXPECT_NE(load.find("at most 128 inputs per block"), std::string::npos) << load;
      EXPECT_EQ(load.rfind("limits.toml:", 0), 0U) << load;  // with the key's line
      // integrate() says the same before computing.
      try {
        fesd::IntegratorOptions o;
        o.discretization = d;
        fesd::integrate(sized(c.n_x, c.n_regions), Eigen::VectorXd::Zero(c.n_x), 1.0, 1, o);
        ADD_FAILURE() << "integrate() did not throw";
      } catch (const fesd::InvalidModel& e) {
        EXPECT_NE(std::string(e.what()).find(c.key), std::string::npos) << e.what();
      }
    }
  }
  EXPECT_EQ(rejected, 5);
}

TEST(Limits, TenSwitchingFunctionsWithoutSAreRejectedByName) {
  // 2^10 = 1024 regions: the loader says which key and what to do.
  std::string c, F;
  for (int i = 0; i < 10; ++i) c += fmt::format("{}\"x - {}\"", i ? ", " : "", i);
  for (int r = 0; r < 1024; ++r) F += fmt::format("{}[\"1\"]", r ? ", " : "");
  const std::string load = load_error(fmt::format(
      "[model]\nx = [\"x\"]\nc = [{}]\nF = [{}]\nx0 = [0.5]\n[simulation]\nT_sim = 1\n", c, F));
  EXPECT_NE(load.find("limits.toml:4: model.F = 1024 regions"), std::string::npos) << load;
  EXPECT_NE(load.find("give S with only the regions that can occur"), std::string::npos) << load;
}

TEST(Limits, TwoThousandStatesAreRejectedByName) {
  const std::string load = load_error(g_form_file(2000, 2));
  EXPECT_NE(load.find("model.x = 2000 states"), std::string::npos) << load.substr(0, 300);
  EXPECT_NE(load.find("4002 inputs"), std::string::npos) << load.substr(0, 300);
}

TEST(Limits, AThousandFiniteElementsBuild) {
  // sum h_n = T is one hand-written block of N_FE inputs: no limit (was 128).
  for (const char* step_eq : {"heuristic_mean", "eta", "l2_relaxed"}) {
    const std::string text = g_form_file(
        2, 3, fmt::format("N_finite_elements = 1000\nstep_equilibration = \"{}\"", step_eq));
    ASSERT_EQ(load_error(text), "") << step_eq;
    const fesd::SimulationProblem q = fesd::parse_simulation_problem(text, "fe.toml");
    EXPECT_EQ(build_error(q.model, q.options.discretization, 1.0), "") << step_eq;
  }
  // The element cross complementarity sums all products of an element: no limit either.
  fesd::DiscretizationOptions d;
  d.n_s = 9;
  d.cross_comp = fesd::CrossComp::Element;
  EXPECT_EQ(build_error(sized(1, 20), d, 1.0), "");  // 9 * 20 + 11 * 20 inputs in one row
}

TEST(Limits, FourHundredElementsSimulateEndToEnd) {
  // One FESD step with 400 elements (the projected-systems work needs up to 400): Example 3(a),
  // x' in 2 - sign(x), x(0) = -1, switch at t = 1/3, x(1) = 2/3.
  const std::string text = R"toml(
[model]
x = ["x"]
c = ["x"]
S = [[-1], [1]]
F = [["3"], ["1"]]
x0 = [-1.0]
[simulation]
T_sim = 1.0
N_sim = 1
[discretization]
N_finite_elements = 400
n_s = 1
)toml";
  const fesd::SimulationProblem q = fesd::parse_simulation_problem(text, "fe400.toml");
  const fesd::IntegratorResult r = fesd::integrate(q.model, q.x0, q.T_sim, q.N_sim, q.options);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  ASSERT_EQ(r.h.size(), 400U);
  // Radau IIA n_s = 1 is implicit Euler; with the switch on an element boundary and constant
  // fields the solution is exact up to the solver tolerances.
  EXPECT_NEAR(r.x.back()[0], 2.0 / 3.0, 1e-6);
  ASSERT_EQ(r.switches.size(), 1U);
  EXPECT_NEAR(r.switches[0].t, 1.0 / 3.0, 1e-6);
}

// ---- step length ---------------------------------------------------------------------------

TEST(Limits, StepsShorterThan1e12AreRejected) {
  const std::string file = R"toml(
[model]
x = ["x"]
c = ["x"]
F = [["1"], ["-1"]]
x0 = [0.5]
[simulation]
T_sim = {}
N_sim = {}
)toml";
  // Issue 12, 6(c): T_sim = 5e-324 ended "success" with every h = 0.
  const std::string tiny = load_error(fmt::format(fmt::runtime(file), "5e-324", 1));
  EXPECT_NE(tiny.find("limits.toml:8: simulation.T_sim = 4.94066e-324: the step T_sim / N_sim = "
                      "4.94066e-324 is shorter than 1e-12"),
            std::string::npos)
      << tiny;
  EXPECT_NE(
      load_error(fmt::format(fmt::runtime(file), "1e-10", 1000)).find("T_sim / N_sim = 1e-13"),
      std::string::npos);
  EXPECT_EQ(load_error(fmt::format(fmt::runtime(file), "1e-9", 1000)), "");
  // Relative to the start time: with a clock starting at t0 = 1e6 a step must be >= 1e-6.
  const std::string clock = R"toml(
[model]
x = ["x"]
c = ["x - t"]
F = [["1"], ["-1"]]
x0 = [0.5]
[simulation]
T_sim = {}
t0 = 1e6
)toml";
  EXPECT_NE(load_error(fmt::format(fmt::runtime(clock), "1e-7")).find("shorter than 1e-06"),
            std::string::npos)
      << load_error(fmt::format(fmt::runtime(clock), "1e-7"));
  EXPECT_EQ(load_error(fmt::format(fmt::runtime(clock), "1e-5")), "");
  // Overrides are checked too.
  fesd::SimulationProblem q =
      fesd::parse_simulation_problem(fmt::format(fmt::runtime(file), "1e-3", 1), "ok.toml");
  EXPECT_THROW(fesd::apply_override(q, "T_sim", "1e-300"), fesd::InvalidOption);
  EXPECT_THROW(fesd::apply_override(q, "N_sim", "2000000000"), fesd::InvalidOption);  // 5e-13
  EXPECT_NO_THROW(fesd::apply_override(q, "N_sim", "100000000"));                     // 1e-11
  // integrate() itself.
  try {
    fesd::integrate(q.model, q.x0, 5e-324, 1);
    ADD_FAILURE() << "no exception";
  } catch (const fesd::InvalidOption& e) {
    EXPECT_NE(std::string(e.what()).find("T_sim = 4.94066e-324: the step T_sim / N_sim"),
              std::string::npos)
        << e.what();
  }
}

TEST(Limits, OcpControlIntervalsShorterThan1e12AreRejected) {
  const std::string file = R"toml(
[model]
x = ["x"]
c = ["x"]
F = [["1"], ["3"]]
x0 = [-2.0]
[ocp]
T = {}
N_stages = 10
f_q = "x^2"
)toml";
  try {
    fesd::parse_ocp_problem(fmt::format(fmt::runtime(file), "1e-12"), "ocp.toml");
    ADD_FAILURE() << "no exception";
  } catch (const fesd::InvalidOption& e) {
    EXPECT_NE(std::string(e.what()).find("ocp.toml:8: ocp.T = 1e-12: the step T / N_stages = "
                                         "1e-13 is shorter than 1e-12"),
              std::string::npos)
        << e.what();
  }
  fesd::OcpProblem q = fesd::parse_ocp_problem(fmt::format(fmt::runtime(file), "2"), "ocp.toml");
  q.ocp.T = 1e-300;
  EXPECT_THROW(fesd::solve(q.ocp, q.options), fesd::InvalidOption);
}

TEST(Limits, OcpLagrangeTermOverAnElementIsOneBlock) {
  // 1 + n_s n_x + n_u + n_p inputs: n_s = 9, 14 states (127 inputs) build, 15 (136) do not.
  auto file = [](int n_x) {
    std::string x, x0, F1, F2;
    for (int i = 0; i < n_x; ++i) {
      x += fmt::format("{}\"x{}\"", i ? ", " : "", i + 1);
      x0 += fmt::format("{}-1", i ? ", " : "");
      F1 += fmt::format("{}\"1\"", i ? ", " : "");
      F2 += fmt::format("{}\"3\"", i ? ", " : "");
    }
    return fmt::format(
        "[model]\nx = [{}]\nc = [\"x1\"]\nF = [[{}], [{}]]\nx0 = [{}]\n[ocp]\nT = 1\n"
        "N_stages = 1\nf_q = \"x1^2\"\n[discretization]\nn_s = 9\n",
        x, F1, F2, x0);
  };
  EXPECT_NO_THROW(fesd::parse_ocp_problem(file(14), "ocp.toml"));
  try {
    fesd::parse_ocp_problem(file(15), "ocp.toml");
    ADD_FAILURE() << "no exception";
  } catch (const fesd::Error& e) {
    EXPECT_NE(std::string(e.what()).find("ocp.toml:9: ocp.f_q = Lagrange term"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("136 inputs"), std::string::npos) << e.what();
  }
  // The accepted one builds: one short solve runs (no InternalError from a block).
  fesd::OcpProblem q = fesd::parse_ocp_problem(file(14), "ocp.toml");
  q.options.homotopy.max_homotopy_steps = 1;
  q.options.nlp.max_iter = 1;
  EXPECT_NO_THROW(fesd::solve(q.ocp, q.options));
}

}  // namespace
