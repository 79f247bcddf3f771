// OCP modelling features of nosnoc (issue "every nosnoc_py example", second slice): global decision
// variables (OcpData::v_global, [ocp] v_global), time-optimal problems with a speed of time
// (time_optimal_problem, T_final bounds, rho_sot), time freezing (time_freezing, clock_state), path
// complementarity constraints (g_path_comp) and the two-sided elastic MPCC mode (mpcc_mode =
// elastic_two_sided), each against a problem with a known answer
// (examples/ocp_global_variable.toml, ocp_time_optimal.toml, ocp_time_freezing.toml,
// ocp_path_complementarity.toml, the sensitivity OCP (56) and the sliding-mode OCP of Sect. 5.3).
// docs/ocp-features.md.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fstream>
#include <iterator>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <fesd/error.hpp>
#include <fesd/io.hpp>
#include <fesd/ocp.hpp>
#include <fesd/problem_file.hpp>
#include <nlohmann/json.hpp>

#include "support/temp_dir.hpp"

#include "../../bench/sensitivity_ocp.hpp"

namespace fesd {
namespace {

OcpProblem example(const std::string& name) {
  return load_ocp_problem(std::string(FESD_SOURCE_DIR) + "/examples/" + name);
}

// ---- global decision variables -----------------------------------------------------------------

// a* = (1 + sqrt 5) / 2 reaches x(2) = 1 (objective 0); the crossing at 1 / (a* + 1). The
// trajectory is piecewise linear, so the scheme is exact once the crossing is an element boundary:
// measured |a - a*| ~ 1e-9 (the Mayer term's gradient vanishes at the optimum, so a is as
// accurate as IPOPT's tolerance allows: 1e-6).
TEST(OcpGlobalVariable, ParameterReachesTheGoldenRatio) {
  const OcpProblem p = example("ocp_global_variable.toml");
  ASSERT_EQ(p.ocp.v_global.size(), 1u);
  EXPECT_EQ(p.ocp.v_global[0].index, 0);
  EXPECT_EQ(p.ocp.v_global[0].lb, 1.2);
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  const double a_star = (1 + std::sqrt(5.0)) / 2;
  ASSERT_EQ(r.v_global.size(), 1);
  EXPECT_EQ(r.v_global_names, std::vector<std::string>{"a"});
  EXPECT_NEAR(r.v_global[0], a_star, 1e-6);
  EXPECT_NEAR(r.objective, 0.0, 1e-10);
  EXPECT_NEAR(r.x_final()[0], 1.0, 1e-6);
  ASSERT_EQ(r.switches.size(), 1u);
  EXPECT_NEAR(r.switches[0].t, 1 / (a_star + 1), 1e-6);
  EXPECT_NE(r.brief_report().find("a = 1.618"), std::string::npos) << r.brief_report();
}

// With ub = 1.5 the bound is active: x(2) = 0.5 * 4 / 2.5 = 0.8, objective 0.04 (exact to the
// scheme: 1e-8).
TEST(OcpGlobalVariable, UpperBoundIsActive) {
  OcpProblem p = example("ocp_global_variable.toml");
  p.ocp.v_global[0].ub = 1.5;
  p.ocp.p[0] = 1.4;
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.v_global[0], 1.5, 1e-8);
  EXPECT_NEAR(r.x_final()[0], 0.8, 1e-8);
  EXPECT_NEAR(r.objective, 0.04, 1e-8);
}

// Time-varying parameters next to a global one: the global one is one variable for every
// interval (a per interval would reach x(2) = 1 in many ways; one a only in one).
TEST(OcpGlobalVariable, OneValueForEveryInterval) {
  OcpProblem p = example("ocp_global_variable.toml");
  p.ocp.N_stages = 2;
  p.ocp.p_stage = {Eigen::VectorXd::Constant(1, 2.0), Eigen::VectorXd::Constant(1, 2.5)};
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.v_global[0], (1 + std::sqrt(5.0)) / 2, 1e-6);
}

TEST(OcpGlobalVariable, BadInput) {
  OcpProblem p = example("ocp_global_variable.toml");
  p.ocp.v_global[0].index = 3;
  EXPECT_THROW(
      {
        try {
          solve(p.ocp, p.options);
        } catch (const InvalidModel& e) {
          EXPECT_NE(std::string(e.what()).find("ocp.v_global[0].index = 3: not a parameter"),
                    std::string::npos)
              << e.what();
          throw;
        }
      },
      InvalidModel);
  p = example("ocp_global_variable.toml");
  p.ocp.p[0] = 5;  // the guess
  EXPECT_THROW(solve(p.ocp, p.options), InvalidModel);
  p = example("ocp_global_variable.toml");
  p.ocp.v_global.push_back(p.ocp.v_global[0]);
  EXPECT_THROW(solve(p.ocp, p.options), InvalidModel);
}

// ---- time-optimal problems ---------------------------------------------------------------------

// x' in 2 - sign(x) + u from -1 to 1 with |u| <= 1: T* = 3/4 with u = 1, crossing at t = 1/4
// (physical time). Piecewise linear: exact up to IPOPT's tolerance (measured ~1e-10; 1e-7).
TEST(OcpTimeOptimal, SwitchedSystemReachesTheMinimalTime) {
  const OcpProblem p = example("ocp_time_optimal.toml");
  EXPECT_TRUE(p.ocp.time_optimal_problem);
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.T_final, 0.75, 1e-7);
  ASSERT_EQ(r.s_sot.size(), 1u);  // one per control interval
  EXPECT_NEAR(r.s_sot[0], 0.75, 1e-7);
  EXPECT_NEAR(r.objective, 0.75, 1e-7);
  EXPECT_NEAR(r.u[0][0], 1.0, 1e-6);
  EXPECT_NEAR(r.t.back(), r.T_final, 1e-12);
  EXPECT_NEAR(r.t_ctrl.back(), r.T_final, 1e-12);
  EXPECT_NEAR(r.x_final()[0], 1.0, 1e-8);
  ASSERT_EQ(r.switches.size(), 1u);
  EXPECT_NEAR(r.switches[0].t, 0.25, 1e-7);
  double sum_h = 0;
  for (double h : r.h) sum_h += h;
  EXPECT_NEAR(sum_h, r.T_final, 1e-12);
}

/// x1' = x2, x2' = u (one region; the switching function x2 + 100 is never reached).
struct DoubleIntegrator {
  template <class T>
  void c(const T* x, const T*, T* out) const {
    out[0] = x[1] + 100.0;
  }
  template <class T>
  void f(int, const T* x, const T* u, const T*, T* out) const {
    out[0] = x[1];
    out[1] = u[0];
  }
};
/// Rest to rest over the distance 1: x(T) = (1, 0).
struct RestToRest {
  template <class T>
  void g_terminal(const T* x, const T*, T* out) const {
    out[0] = x[0] - 1.0;
    out[1] = x[1];
  }
};

Ocp double_integrator(bool local) {
  Ocp ocp;
  ocp.model = make_pss(DoubleIntegrator{}, PssDims{2, 1, 0, {Subsystem::from_c(1)}});
  ocp.functions = make_ocp_functions(RestToRest{});
  ocp.T = 1;
  ocp.N_stages = 2;
  ocp.x0 = Eigen::Vector2d(0, 0);
  ocp.lbu = Eigen::VectorXd::Constant(1, -1);
  ocp.ubu = Eigen::VectorXd::Constant(1, 1);
  ocp.u_guess_stage = {Eigen::VectorXd::Constant(1, 0.5), Eigen::VectorXd::Constant(1, -0.5)};
  ocp.n_g_terminal = 2;
  ocp.lbg_terminal = ocp.ubg_terminal = Eigen::Vector2d::Zero();
  ocp.time_optimal_problem = true;
  ocp.local_speed_of_time_variable = local;
  return ocp;
}

// Rest to rest over d = 1 with |u| <= 1: bang-bang, T* = 2 sqrt(d) = 2, u = (1, -1), with one
// speed for the horizon or one per control interval (then s = (2, 2)). Quadratic trajectories:
// Radau IIA with n_s = 2 is exact (measured ~1e-10; 1e-7).
TEST(OcpTimeOptimal, DoubleIntegratorRestToRest) {
  OcpOptions o;
  o.discretization.N_FE = 2;
  for (bool local : {false, true}) {
    const OcpResult r = solve(double_integrator(local), o);
    ASSERT_EQ(r.status, Status::Success) << r.message;
    EXPECT_NEAR(r.T_final, 2.0, 1e-7) << "local " << local;
    EXPECT_NEAR(r.objective, 2.0, 1e-7);
    ASSERT_EQ(r.s_sot.size(), 2u);  // per control interval (equal with one global speed)
    for (double s : r.s_sot) EXPECT_NEAR(s, 2.0, 1e-6);
    EXPECT_NEAR(r.u[0][0], 1.0, 1e-6);
    EXPECT_NEAR(r.u[1][0], -1.0, 1e-6);
    EXPECT_NEAR(r.t_ctrl[1], 1.0, 1e-6);
    EXPECT_NEAR(r.x.back()[0], 1.0, 1e-8);
  }
}

TEST(OcpTimeOptimal, BadInput) {
  Ocp ocp = double_integrator(false);
  ocp.s_sot0 = 50;  // above s_sot_max = 25
  EXPECT_THROW(solve(ocp, OcpOptions{}), InvalidOption);
  ocp = double_integrator(false);
  ocp.s_sot_min = 0;
  EXPECT_THROW(solve(ocp, OcpOptions{}), InvalidOption);
}

// T_final bounds and the speed-of-time penalty: cost T_final + rho_sot sum (s - 1)^2. With
// T_final_min = 2.5 > T* the bound is active (T_final = 2.5, s = 2.5); with rho_sot the optimum
// stays s = 2 (the penalty's slope 2 rho_sot (s - 1) > 0 only adds to the cost's): objective
// 2 + rho_sot (one global speed) and 2 + 2 rho_sot (two local ones). Exact scheme: 1e-7.
TEST(OcpTimeOptimal, FinalTimeBoundsAndSpeedPenalty) {
  OcpOptions o;
  o.discretization.N_FE = 2;
  for (bool local : {false, true}) {
    Ocp ocp = double_integrator(local);
    ocp.T_final_min = 2.5;
    ocp.s_sot0 = 2.5;
    OcpResult r = solve(ocp, o);
    ASSERT_EQ(r.status, Status::Success) << r.message;
    EXPECT_NEAR(r.T_final, 2.5, 1e-7) << "local " << local;
    EXPECT_NEAR(r.objective, 2.5, 1e-7);
    EXPECT_NEAR(r.x.back()[0], 1.0, 1e-8);
    ocp = double_integrator(local);
    ocp.T_final_max = 1.5;  // below T* = 2: infeasible
    r = solve(ocp, o);
    EXPECT_NE(r.status, Status::Success) << "local " << local;
    ocp = double_integrator(local);
    ocp.rho_sot = 0.5;
    r = solve(ocp, o);
    ASSERT_EQ(r.status, Status::Success) << r.message;
    EXPECT_NEAR(r.T_final, 2.0, 1e-7) << "local " << local;
    EXPECT_NEAR(r.objective, 2.0 + (local ? 2 : 1) * 0.5, 1e-7);
  }
}

// ---- time freezing -----------------------------------------------------------------------------

/// The states at the end of every control interval (r.x after the interval's last element).
std::vector<Eigen::VectorXd> interval_ends(const OcpResult& r) {
  std::vector<Eigen::VectorXd> out;
  for (std::size_t e = 0; e < r.interval.size(); ++e)
    if (e + 1 == r.interval.size() || r.interval[e + 1] != r.interval[e]) out.push_back(r.x[e + 1]);
  return out;
}

// examples/ocp_time_freezing.toml: an elastic bounce written with time freezing (clock t frozen
// in the auxiliary region q < 0, v' = a), min int u^2 dt (the state E) to q(1) = v(1) = 1/2 from
// (q, v) = (1, -5/2). Closed form (the file's header): E* = 4 with u = 2 before the impact at
// t = 1/2 and u = -2 after; the impact freezes the clock for 2 w / a = 0.2 of s tau (w = 3/2,
// a = 15). One global speed: s* T / 2 = 1/2 + 0.1, s* = 1.2, the impact from tau = 5/12 to 7/12.
// Every trajectory is polynomial of degree <= 2: Radau IIA 2 is exact (measured errors ~1e-15).
TEST(OcpTimeFreezing, ElasticBounceGlobalSpeedOfTime) {
  const OcpProblem p = example("ocp_time_freezing.toml");
  EXPECT_TRUE(p.ocp.time_freezing);
  EXPECT_EQ(p.ocp.clock_state, 2);
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.objective, 4.0, 1e-8);
  EXPECT_NEAR(r.x_final()[3], 4.0, 1e-8);  // E(T) = int u^2 dt
  EXPECT_NEAR(r.x_final()[0], 0.5, 1e-8);
  EXPECT_NEAR(r.x_final()[1], 0.5, 1e-8);
  const std::vector<Eigen::VectorXd> ends = interval_ends(r);
  ASSERT_EQ(ends.size(), 2u);
  for (std::size_t k = 0; k < ends.size(); ++k)  // the clock constraints t(tau_k) = k T / N
    EXPECT_NEAR(ends[k][2], 0.5 * static_cast<double>(k + 1), 1e-8) << k;
  ASSERT_EQ(r.s_sot.size(), 2u);
  for (double s : r.s_sot) EXPECT_NEAR(s, 1.2, 1e-8);
  EXPECT_EQ(r.T_final, 1.0);            // the physical horizon
  EXPECT_NEAR(r.t.back(), 1.0, 1e-12);  // the grid is the numerical time tau
  EXPECT_NEAR(r.u[0][0], 2.0, 1e-6);
  EXPECT_NEAR(r.u[1][0], -2.0, 1e-6);
  ASSERT_EQ(r.switches.size(), 2u);
  EXPECT_NEAR(r.switches[0].t, 5.0 / 12, 1e-8);
  EXPECT_NEAR(r.switches[1].t, 7.0 / 12, 1e-8);
  double q_min = 1;
  for (const Eigen::VectorXd& x : r.x) q_min = std::min(q_min, x[0]);
  EXPECT_NEAR(q_min, -1.5 * 1.5 / (2 * 15), 1e-8);  // -w^2 / (2a): at an element boundary
}

// The same with rho_sot = 0.1: s is fixed by the clock constraints (u_1, u_2 by the two terminal
// conditions), so the objective is E* + rho_sot (s* - 1)^2 = 4 + 0.1 * 0.04 = 4.004 (one global
// speed: one penalty term).
TEST(OcpTimeFreezing, SpeedOfTimePenalty) {
  OcpProblem p = example("ocp_time_freezing.toml");
  p.ocp.rho_sot = 0.1;
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.objective, 4.004, 1e-8);
  EXPECT_NEAR(r.x_final()[3], 4.0, 1e-8);
}

// Four control intervals with one speed per interval (local_speed_of_time_variable): the optimum
// u = (2, 2, -2, -2) is piecewise constant on this grid too (the impact at t = 1/2 is a grid
// point), so E* = 4 is the discrete optimum, now over four controls; the speeds add up to the
// numerical time: sum_k s_k T / 4 = T + 0.2, sum s_k = 4.8 (how the frozen 0.2 is split between
// intervals 2 and 3 is not unique). Exact scheme: 1e-8.
TEST(OcpTimeFreezing, ElasticBounceLocalSpeedsOfTime) {
  OcpProblem p = example("ocp_time_freezing.toml");
  p.ocp.N_stages = 4;
  p.ocp.local_speed_of_time_variable = true;
  p.ocp.u_guess_stage.clear();
  p.ocp.u_guess = Eigen::VectorXd::Zero(1);
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.objective, 4.0, 1e-8);
  const std::vector<Eigen::VectorXd> ends = interval_ends(r);
  ASSERT_EQ(ends.size(), 4u);
  for (std::size_t k = 0; k < ends.size(); ++k)
    EXPECT_NEAR(ends[k][2], 0.25 * static_cast<double>(k + 1), 1e-8) << k;
  ASSERT_EQ(r.s_sot.size(), 4u);
  double sum = 0;
  for (double s : r.s_sot) sum += s;
  EXPECT_NEAR(sum, 4.8, 1e-8);
  EXPECT_NEAR(r.s_sot[0], 1.0, 1e-8);  // no impact in the first and last interval
  EXPECT_NEAR(r.s_sot[3], 1.0, 1e-8);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(r.u[k][0], k < 2 ? 2.0 : -2.0, 1e-6) << k;
}

TEST(OcpTimeFreezing, BadInput) {
  const OcpProblem good = example("ocp_time_freezing.toml");
  Ocp ocp = good.ocp;
  ocp.clock_state = -1;  // time freezing without a clock
  EXPECT_THROW(solve(ocp, good.options), InvalidOption);
  ocp.clock_state = 4;  // n_x = 4
  EXPECT_THROW(solve(ocp, good.options), InvalidOption);
  ocp = good.ocp;
  ocp.time_freezing_tolerance = -1;
  EXPECT_THROW(solve(ocp, good.options), InvalidOption);
  ocp.time_freezing_tolerance = NAN;
  EXPECT_THROW(solve(ocp, good.options), InvalidOption);
  ocp = good.ocp;
  ocp.time_optimal_problem = true;
  EXPECT_THROW(solve(ocp, good.options), InvalidOption);
  ocp = good.ocp;
  ocp.time_freezing = false;  // clock_state without time freezing
  EXPECT_THROW(solve(ocp, good.options), InvalidOption);
  ocp = good.ocp;
  ocp.rho_sot = -1;
  EXPECT_THROW(solve(ocp, good.options), InvalidOption);
  ocp = good.ocp;
  ocp.T_final_max = 3;  // only with time_optimal_problem
  EXPECT_THROW(solve(ocp, good.options), InvalidOption);
  ocp = good.ocp;
  PdsOcp pds;
  pds.time_freezing = true;
  pds.clock_state = 0;
  pds.T = 1;
  pds.x0 = Eigen::VectorXd::Zero(1);
  EXPECT_ANY_THROW(solve(pds, OcpOptions{}));
}

// The JSON result names the new values: T_final, s_sot, v_global (name = value).
TEST(OcpFeaturesJson, FinalTimeAndGlobalVariables) {
  testing::TempDir dir;
  const auto read = [](const std::string& path) {
    std::ifstream in(path);
    return nlohmann::ordered_json::parse(
        std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
  };
  const OcpProblem t = example("ocp_time_optimal.toml");
  write_json(solve(t.ocp, t.options), t.ocp.model, dir.file("t.json"));
  const auto jt = read(dir.file("t.json"));
  EXPECT_NEAR(jt["T_final"].get<double>(), 0.75, 1e-7);
  ASSERT_EQ(jt["s_sot"].size(), 1u);
  EXPECT_FALSE(jt.contains("v_global"));
  const OcpProblem g = example("ocp_global_variable.toml");
  write_json(solve(g.ocp, g.options), g.ocp.model, dir.file("g.json"));
  const auto jg = read(dir.file("g.json"));
  EXPECT_NEAR(jg["v_global"]["a"].get<double>(), (1 + std::sqrt(5.0)) / 2, 1e-6);
  EXPECT_EQ(jg["T_final"].get<double>(), 2.0);
  EXPECT_FALSE(jg.contains("s_sot"));
}

// ---- path complementarity ----------------------------------------------------------------------

// 0 <= x perp u >= 0 leaves one feasible control, u = (0, 1): objective 1 (constant controls,
// exact quadrature; measured ~1e-9, tolerance 1e-6 from the relaxation's sigma_N).
TEST(OcpPathComplementarity, SelectsTheKnownOptimum) {
  const OcpProblem p = example("ocp_path_complementarity.toml");
  EXPECT_EQ(p.ocp.n_g_path_comp, 1);
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.objective, 1.0, 1e-6);
  EXPECT_NEAR(r.u[0][0], 0.0, 1e-6);
  EXPECT_NEAR(r.u[1][0], 1.0, 1e-6);
  for (const Eigen::VectorXd& x : r.x) EXPECT_GE(x[0], -1e-8);
  EXPECT_NEAR(r.x_final()[0], 0.0, 1e-6);
  EXPECT_LE(r.comp_residual, p.options.homotopy.complementarity_tol);
}

// Without the pairs the cheapest control is u = 0 (x drains below 0): objective 0.
TEST(OcpPathComplementarity, WithoutThePairsTheOptimumDiffers) {
  OcpProblem p = example("ocp_path_complementarity.toml");
  p.ocp.n_g_path_comp = 0;
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.objective, 0.0, 1e-8);
}

// The pairs are relaxed like FESD's own complementarity constraints, in every MPCC method.
class OcpPathComplementarityModes : public ::testing::TestWithParam<MpccMode> {};
TEST_P(OcpPathComplementarityModes, SameOptimum) {
  OcpProblem p = example("ocp_path_complementarity.toml");
  p.options.homotopy.mpcc_mode = GetParam();
  const OcpResult r = solve(p.ocp, p.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.objective, 1.0, 1e-5);
  EXPECT_NEAR(r.u[1][0], 1.0, 1e-5);
}
INSTANTIATE_TEST_SUITE_P(Modes, OcpPathComplementarityModes,
                         ::testing::Values(MpccMode::ScholtesIneq, MpccMode::ElasticIneq,
                                           MpccMode::ElasticTwoSided, MpccMode::L1Penalty));

// ---- elastic_two_sided -------------------------------------------------------------------------

// The sensitivity OCP (56) (examples/ocp_sensitivity.toml with the homotopy ending at 1e-9) reaches
// x0* = (9 - sqrt 417) / 8 from guesses on both sides of it (tolerance 1e-6 as for the other
// methods, tests/ocp/sensitivity_ocp_test.cpp; measured 1e-11).
class OcpElasticTwoSided : public ::testing::TestWithParam<double> {};
TEST_P(OcpElasticTwoSided, SensitivityOcpReachesTheMinimizer) {
  OcpProblem q = example("ocp_sensitivity.toml");
  q.ocp.x0[0] = GetParam();
  q.options.homotopy.mpcc_mode = MpccMode::ElasticTwoSided;
  q.options.homotopy.sigma_N = 1e-9;
  q.options.homotopy.complementarity_tol = 1e-9;
  const OcpResult r = solve(q.ocp, q.options);
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_EQ(r.mpcc_mode, MpccMode::ElasticTwoSided);
  EXPECT_NEAR(r.x0()[0], fesd_bench::kSensitivityX0Star, 1e-6);
  EXPECT_NEAR(r.objective, fesd_bench::kSensitivityVStar, 1e-6);
}
INSTANTIATE_TEST_SUITE_P(Guesses, OcpElasticTwoSided, ::testing::Values(-2.7, -1.0, -0.6));

// The sliding-mode OCP of Sect. 5.3 (nosnoc_py's settings): the objective of the default method
// to the homotopy's tolerance.
TEST(OcpElasticTwoSidedSliding, SameObjectiveAsTheDefault) {
  OcpProblem q = example("nosnoc/ocp_sliding_mode_nosnoc.toml");
  const OcpResult def = solve(q.ocp, q.options);
  q.options.homotopy.mpcc_mode = MpccMode::ElasticTwoSided;
  const OcpResult r = solve(q.ocp, q.options);
  ASSERT_EQ(def.status, Status::Success) << def.message;
  ASSERT_EQ(r.status, Status::Success) << r.message;
  EXPECT_NEAR(r.objective, def.objective, 1e-6);
  EXPECT_EQ(r.switches.size(), def.switches.size());
}

// [homotopy] s_elastic_max, s_elastic_0 (nosnoc's s_elastic_max, s_elastic_0): the elastic
// variable s lies in [0, s_elastic_max] and bounds every complementarity product, so a tiny bound
// makes the first NLP (sigma_0 = 1, weight 1) nearly complementary: residual <= 1e-9 (up to
// IPOPT's tolerance) instead of 0.48 with s unbounded (fesd's default). With nosnoc's values (10,
// 1) elastic_ineq reaches the default method's objective on the sliding-mode OCP.
TEST(OcpElasticVariable, BoundFromTheFileReachesTheNlp) {
  OcpProblem q = example("nosnoc/ocp_sliding_mode_nosnoc.toml");
  const OcpResult def = solve(q.ocp, q.options);
  ASSERT_EQ(def.status, Status::Success) << def.message;
  apply_override(q, "mpcc_mode", "elastic_ineq");
  const OcpResult unbounded = solve(q.ocp, q.options);
  ASSERT_FALSE(unbounded.homotopy.empty());
  EXPECT_GT(unbounded.homotopy.front().comp_residual, 0.4);
  apply_override(q, "s_elastic_max", "1e-9");
  EXPECT_EQ(q.options.homotopy.s_elastic_max, 1e-9);
  const OcpResult tiny = solve(q.ocp, q.options);
  ASSERT_FALSE(tiny.homotopy.empty());
  EXPECT_LE(tiny.homotopy.front().comp_residual, 1.1e-9);
  apply_override(q, "homotopy.s_elastic_max", "10");
  apply_override(q, "s_elastic_0", "1");
  EXPECT_EQ(q.options.homotopy.s_elastic_0, 1.0);
  const OcpResult nosnoc = solve(q.ocp, q.options);
  ASSERT_EQ(nosnoc.status, Status::Success) << nosnoc.message;
  EXPECT_NEAR(nosnoc.objective, def.objective, 1e-6);
  // nosnoc's inverse scaling (objective_scaling_direct = false, as nosnoc_py's hysteresis
  // examples): sigma J + s instead of J + s / sigma, the same optimum; the homotopy rows report
  // the NLP's objective, sigma times the direct one.
  apply_override(q, "objective_scaling_direct", "false");
  EXPECT_FALSE(q.options.homotopy.objective_scaling_direct);
  const OcpResult inverse = solve(q.ocp, q.options);
  ASSERT_EQ(inverse.status, Status::Success) << inverse.message;
  EXPECT_NEAR(inverse.objective, def.objective, 1e-6);
  ASSERT_FALSE(inverse.homotopy.empty());
  const HomotopyRow& last = inverse.homotopy.back();
  // sigma (J + s / sigma): J = 5.596 (cost and step equilibration, nosnoc_py's figure), s / sigma
  // small at the last sigma (1e-5 here).
  EXPECT_NEAR(last.objective / last.sigma, 5.596, 0.01);
  q.options.homotopy.objective_scaling_direct = true;
  // s_elastic_0 above s_elastic_max is refused, naming both.
  try {
    apply_override(q, "s_elastic_0", "20");
    ADD_FAILURE() << "s_elastic_0 > s_elastic_max accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("s_elastic_0 = 20: must be <= s_elastic_max = 10"),
              std::string::npos)
        << e.what();
  }
}

// [ocp] initial_theta (nosnoc's initial_theta): every theta of the first guess set to one value
// instead of the LP's. A guess only: the sliding-mode OCP reaches the same optimum, from another
// first point (the first NLP takes another number of iterations). Out of [0, 1] (but -1), or with
// the step form, it is refused naming the key.
TEST(OcpInitialTheta, SetsTheGuessNotTheOptimum) {
  OcpProblem q = example("nosnoc/ocp_sliding_mode_nosnoc.toml");
  const OcpResult def = solve(q.ocp, q.options);
  ASSERT_EQ(def.status, Status::Success) << def.message;
  apply_override(q, "initial_theta", "0.5");
  EXPECT_EQ(q.options.initial_theta, 0.5);
  const OcpResult half = solve(q.ocp, q.options);
  ASSERT_EQ(half.status, Status::Success) << half.message;
  EXPECT_NEAR(half.objective, def.objective, 1e-6);
  ASSERT_FALSE(half.homotopy.empty());
  EXPECT_NE(half.homotopy.front().nlp_iterations, def.homotopy.front().nlp_iterations);
  for (const char* bad : {"1.5", "-0.5"}) {
    try {
      apply_override(q, "initial_theta", bad);
      ADD_FAILURE() << "initial_theta = " << bad << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("initial_theta"), std::string::npos) << e.what();
    }
  }
  try {
    apply_override(q, "dcs_mode", "step");
    ADD_FAILURE() << "initial_theta with dcs_mode = step accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("initial_theta"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fesd
