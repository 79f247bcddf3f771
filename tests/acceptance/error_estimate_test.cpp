// tests/acceptance/error_estimate_test.cpp: fesd::simulate() (src/integrator/tolerance.cpp):
// N_sim chosen for a target accuracy tol_sim, and the error estimate every simulation carries,
// against three systems with closed-form solutions. The estimate must lie within a factor 10 of the
// true error ||x(T) - x_exact(T)|| (0.1 <= true / estimate <= 10), and a run for tol_sim must meet
// it. The measured numbers are in docs/formulation.md, "Accuracy by tolerance". Small T and
// tolerances of 1e-5 .. 1e-6 keep the whole file at about 10 s (no timing is asserted).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fesd/error.hpp>
#include <fesd/integrator.hpp>
#include <fesd/io.hpp>
#include <fesd/problem_file.hpp>

#include "support/temp_dir.hpp"

namespace {

using std::numbers::pi;

// ---- the systems and their exact solutions ------------------------------------------------------

// Relay feedback oscillator x1'' + x1 = -sign(x1), x(0) = (1, 0), written x1' = x2,
// x2' = -x1 - sign(x1) with c = x1 (region 0: x1 > 0, region 1: x1 < 0). Each half-wave is a
// circle of radius 2 around (-1, 0) (x1 > 0) or (1, 0) (x1 < 0):
//   x1 > 0, from (1, 0):        x = (2 cos t - 1, -2 sin t), reaching x1 = 0 at t = pi/3 with
//                               x2 = -sqrt(3) (a crossing: x1' != 0);
//   x1 < 0, from (0, -sqrt(3)): x = (1 + 2 cos(s + 2pi/3), -2 sin(s + 2pi/3)), s = t - t_k,
//                               reaching x1 = 0 after s = 2pi/3 with x2 = +sqrt(3);
//   x1 > 0, from (0, sqrt(3)):  x = (2 cos(s - pi/3) - 1, -2 sin(s - pi/3)), again 2pi/3 long.
// So the crossings are t_k = pi/3 + 2k pi/3 (pi/3, pi, 5pi/3, ...), the amplitude stays 1.
constexpr const char* kRelay = R"toml(
name = "relay"
[model]
x = ["x1", "x2"]
c = ["x1"]
F = [["x2", "-x1 - 1"], ["x2", "-x1 + 1"]]
x0 = [1.0, 0.0]
[simulation]
T_sim = 4.0
)toml";

Eigen::VectorXd relay_exact(double t) {
  Eigen::VectorXd x(2);
  if (t <= pi / 3) {
    x << 2 * std::cos(t) - 1, -2 * std::sin(t);
    return x;
  }
  const int k = static_cast<int>(std::floor((t - pi / 3) / (2 * pi / 3)));
  const double s = t - pi / 3 - k * 2 * pi / 3;
  if (k % 2 == 0)
    x << 1 + 2 * std::cos(s + 2 * pi / 3), -2 * std::sin(s + 2 * pi / 3);
  else
    x << 2 * std::cos(s - pi / 3) - 1, -2 * std::sin(s - pi / 3);
  return x;
}

std::vector<double> relay_switches(double T) {
  std::vector<double> t;
  for (double s = pi / 3; s < T; s += 2 * pi / 3) t.push_back(s);
  return t;
}

// Block on a belt moving at 0.25: q' = v, v' = -q - sign(v - 0.25), x0 = (0, 0); c = v - 0.25
// (region 0: v > 0.25, region 1: v < 0.25). In region 1 q = 1 - cos t, v = sin t until
// t_1 = asin(1/4); the block sticks (slides on v = 0.25, q = 1 - cos t_1 + (t - t_1) / 4) while
// |q| <= 1, i.e. until t_e = t_1 + 4 cos t_1 = asin(1/4) + sqrt(15) = 4.1256636013 (q = 1); then
// q = 1 + sin(t - t_e) / 4, v = cos(t - t_e) / 4 in region 1 again.
constexpr const char* kBelt = R"toml(
name = "belt"
[model]
x = ["q", "v"]
c = ["v - 0.25"]
F = [["v", "-q - 1"], ["v", "-q + 1"]]
x0 = [0.0, 0.0]
[simulation]
T_sim = 5.0
tol_sim = 1e-5
N_sim = 5       # with tol_sim: the first step count tried
)toml";

Eigen::VectorXd belt_exact(double t) {
  const double t1 = std::asin(0.25), te = t1 + std::sqrt(15.0);
  Eigen::VectorXd x(2);
  if (t <= t1)
    x << 1 - std::cos(t), std::sin(t);
  else if (t <= te)
    x << 1 - std::cos(t1) + 0.25 * (t - t1), 0.25;
  else
    x << 1 + 0.25 * std::sin(t - te), 0.25 * std::cos(t - te);
  return x;
}

const std::string kOscillator = FESD_SOURCE_DIR "/examples/oscillator.toml";

/// x(pi/2) of (47) as printed, and its one crossing at t = 1 (REFERENCE.md).
Eigen::VectorXd oscillator_exact() {
  Eigen::VectorXd x(2);
  x << -1.5974603774506984, -0.7614936206060108;
  return x;
}

// ---- checks -----------------------------------------------------------------------------------

double max_switch_error(const fesd::IntegratorResult& r, const std::vector<double>& exact) {
  const std::vector<double> t = r.switch_times();
  EXPECT_EQ(t.size(), exact.size());
  double e = 0;
  for (std::size_t i = 0; i < std::min(t.size(), exact.size()); ++i)
    e = std::max(e, std::abs(t[i] - exact[i]));
  return e;
}

/// 0.1 <= true / estimate <= 10, with both numbers in the message.
::testing::AssertionResult within_factor_10(double truth, double estimate, const char* what) {
  const double ratio = truth / estimate;
  std::printf("  %-12s true %.2e  estimate %.2e  true/estimate %.2f\n", what, truth, estimate,
              ratio);
  if (std::isfinite(ratio) && ratio >= 0.1 && ratio <= 10) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << what << ": true error " << truth << ", estimate "
                                       << estimate << " (true / estimate = " << ratio << ")";
}

std::vector<int> run_sizes(const fesd::Accuracy& a) {
  std::vector<int> n;
  for (const fesd::AccuracyRun& r : a.runs) n.push_back(r.N_sim);
  return n;
}

// ---- tolerance: N_sim chosen ------------------------------------------------------------------

// A file without N_sim and tol_sim: the default tol_sim = 1e-6 chooses N_sim (it used to take one
// step: the relay over 10 s then ended 0.14 off with "success"). Radau IIA n_s = 3 (order 5):
// measured N_sim = 10, 20, 40, true error 5.4e-10 (estimate 1.2e-9), switch times 1.3e-10
// (estimate 2.6e-10).
TEST(ErrorEstimate, DefaultToleranceChoosesNSimForTheRelay) {
  fesd::SimulationProblem q = fesd::parse_simulation_problem(kRelay, "relay.toml");
  fesd::apply_override(q, "n_s", "3");
  ASSERT_EQ(q.N_sim, 0);  // not given: chosen
  const fesd::IntegratorResult r = fesd::simulate(q);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  const fesd::Accuracy& a = r.accuracy;
  EXPECT_EQ(a.tol_sim, fesd::kDefaultTolSim);
  EXPECT_TRUE(a.met) << a.note;
  EXPECT_TRUE(a.consistent) << a.note;
  EXPECT_EQ(a.order, 5);
  ASSERT_GE(a.runs.size(), 3u);  // acceptance needs three runs that agree
  EXPECT_EQ(a.runs.front().N_sim, 10);
  EXPECT_EQ(a.N_sim, a.runs.back().N_sim);
  EXPECT_EQ(static_cast<int>(r.h.size()), 2 * a.N_sim);  // N_FE = 2 elements per step
  EXPECT_LE(a.error_estimate, fesd::kDefaultTolSim);
  const double err = (r.x_final() - relay_exact(4.0)).norm();
  EXPECT_LE(err, fesd::kDefaultTolSim);
  EXPECT_TRUE(within_factor_10(err, a.error_estimate, "x(T)"));
  EXPECT_TRUE(within_factor_10(max_switch_error(r, relay_switches(4.0)), a.switch_time_estimate,
                               "switch times"));
  // The report says what was estimated and from which runs.
  const std::string report = r.full_report();
  EXPECT_NE(report.find("error estimate"), std::string::npos) << report;
  EXPECT_NE(report.find("tol_sim 1e-06 met"), std::string::npos) << report;
  EXPECT_NE(r.brief_report().find("error estimate"), std::string::npos);
}

// The C++ API with a target of its own and the scheme's default n_s = 2 (order 3): the first pair
// (10, 20) predicts the N_sim that meets tol_sim (measured: 10, 20, 70; true error 4.4e-6,
// estimate 5.5e-6, switch times 1.0e-6 / 1.3e-6).
TEST(ErrorEstimate, ToleranceOnTheRelayWithOrderThree) {
  const fesd::SimulationProblem q = fesd::parse_simulation_problem(kRelay, "relay.toml");
  fesd::AccuracyOptions acc;
  acc.tol_sim = 1e-5;
  std::vector<int> reported;
  acc.on_run = [&](const fesd::AccuracyRun& run) { reported.push_back(run.N_sim); };
  const fesd::IntegratorResult r = fesd::simulate(q.model, q.x0, q.T_sim, acc, q.options, q.u, q.p);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  const fesd::Accuracy& a = r.accuracy;
  EXPECT_TRUE(a.met) << a.note;
  EXPECT_EQ(a.order, 3);
  EXPECT_EQ(reported, run_sizes(a));  // one progress call per run
  for (std::size_t i = 1; i < a.runs.size(); ++i) {
    EXPECT_GE(a.runs[i].N_sim, 2 * a.runs[i - 1].N_sim);  // at least doubled,
    EXPECT_LE(a.runs[i].N_sim, 4 * a.runs[i - 1].N_sim);  // at most 4x per run
  }
  const double err = (r.x_final() - relay_exact(4.0)).norm();
  EXPECT_LE(err, 1e-5);
  EXPECT_TRUE(within_factor_10(err, a.error_estimate, "x(T)"));
  EXPECT_TRUE(within_factor_10(max_switch_error(r, relay_switches(4.0)), a.switch_time_estimate,
                               "switch times"));
}

// Stick-slip: a sliding mode entered and left. tol_sim = 1e-5 and a first N_sim = 5 from the
// file, n_s = 2. Only x(T) is asserted: the exit time of the stick phase is the subject of issue
// 13, 1.
TEST(ErrorEstimate, ToleranceOnTheBeltWithAStickPhase) {
  const fesd::SimulationProblem q = fesd::parse_simulation_problem(kBelt, "belt.toml");
  ASSERT_EQ(q.tol_sim, 1e-5);
  const fesd::IntegratorResult r = fesd::simulate(q);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_TRUE(r.accuracy.met) << r.accuracy.note;
  EXPECT_EQ(r.accuracy.runs.front().N_sim, 5);
  ASSERT_EQ(r.switches.size(), 2u);  // into the stick phase and out of it
  const double err = (r.x_final() - belt_exact(5.0)).norm();
  EXPECT_LE(err, 1e-5);
  EXPECT_TRUE(within_factor_10(err, r.accuracy.error_estimate, "x(T)"));
}

// ---- N_sim given: two companion runs ----------------------------------------------------------

// The oscillator (47) with N_sim = 16 as asked (Radau IIA n_s = 3 from the file): the companions
// run N_sim = 8 and 4; measured true error 3.5e-5, estimate 5.2e-5; t_s 1.6e-6 / 2.2e-6.
TEST(ErrorEstimate, GivenNSimOnTheOscillatorCarriesAnEstimate) {
  fesd::SimulationProblem q = fesd::load_simulation_problem(kOscillator);
  fesd::apply_override(q, "N_sim", "16");
  const fesd::IntegratorResult r = fesd::simulate(q);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  const fesd::Accuracy& a = r.accuracy;
  EXPECT_EQ(run_sizes(a), (std::vector<int>{16, 8, 4}));
  EXPECT_EQ(a.N_sim, 16);
  EXPECT_EQ(static_cast<int>(r.h.size()), 2 * 16);  // the run asked for is the result
  EXPECT_EQ(a.tol_sim, 0.0);                        // no target
  EXPECT_FALSE(a.met);
  EXPECT_TRUE(a.consistent) << a.note;
  const double err = (r.x_final() - oscillator_exact()).norm();
  EXPECT_TRUE(within_factor_10(err, a.error_estimate, "x(T)"));
  EXPECT_TRUE(within_factor_10(max_switch_error(r, {1.0}), a.switch_time_estimate, "t_s"));

  // The JSON carries the estimate and the runs.
  const fesd::testing::TempDir dir;
  fesd::write_json(r, q.model, dir.file("r.json"));
  std::ifstream in(dir.file("r.json"));
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_DOUBLE_EQ(j.at("error_estimate").get<double>(), a.error_estimate);
  EXPECT_DOUBLE_EQ(j.at("switch_time_estimate").get<double>(), a.switch_time_estimate);
  EXPECT_EQ(j.at("accuracy").at("N_sim").get<int>(), 16);
  EXPECT_EQ(j.at("accuracy").at("runs").size(), 3u);
  EXPECT_EQ(j.at("accuracy").at("runs").at(1).at("N_sim").get<int>(), 8);
}

// error_estimate = false: only the run at N_sim, the same result as with the companions, no
// estimate; without N_sim (or with tol_sim) there is nothing to choose N_sim by: rejected.
TEST(ErrorEstimate, NoEstimateRunsOnlyNSim) {
  fesd::SimulationProblem q = fesd::load_simulation_problem(kOscillator);
  fesd::apply_override(q, "N_sim", "16");
  const fesd::IntegratorResult with = fesd::simulate(q);
  fesd::apply_override(q, "error_estimate", "false");
  const fesd::IntegratorResult r = fesd::simulate(q);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  EXPECT_EQ(run_sizes(r.accuracy), (std::vector<int>{16}));
  EXPECT_TRUE(std::isnan(r.accuracy.error_estimate));
  EXPECT_NE(r.accuracy.note.find("error_estimate = false"), std::string::npos) << r.accuracy.note;
  EXPECT_EQ(r.x_final(), with.x_final());  // the same run, bit for bit
  EXPECT_EQ(r.h.size(), with.h.size());

  try {
    fesd::apply_override(q, "N_sim", "0");
    ADD_FAILURE() << "error_estimate = false without N_sim accepted";
  } catch (const fesd::InvalidOption& e) {
    EXPECT_NE(std::string(e.what()).find("simulation.error_estimate = false: needs N_sim"),
              std::string::npos)
        << e.what();
  }
  fesd::AccuracyOptions acc;  // the library call checks the same rule
  acc.N_sim = 16;
  acc.tol_sim = 1e-6;
  acc.error_estimate = false;
  EXPECT_THROW(fesd::simulate(q.model, q.x0, q.T_sim, acc, q.options), fesd::InvalidOption);
}

// A model every Runge-Kutta scheme integrates exactly (x' = 2 - sign(x), piecewise linear): the
// runs agree to round-off, so the estimate is the NLP noise floor 10 ipopt.tol max(1, |x(T)|),
// and says so.
TEST(ErrorEstimate, ExactRunsGiveTheNoiseFloor) {
  fesd::SimulationProblem q =
      fesd::load_simulation_problem(FESD_SOURCE_DIR "/examples/crossing.toml");
  fesd::apply_override(q, "N_sim", "4");
  fesd::apply_override(q, "T_sim", "1");
  const fesd::IntegratorResult r = fesd::simulate(q);
  ASSERT_EQ(r.status, fesd::Status::Success) << r.message;
  const fesd::Accuracy& a = r.accuracy;
  EXPECT_TRUE(a.at_noise_floor) << a.note;
  EXPECT_DOUBLE_EQ(a.error_estimate, 10 * q.options.nlp.tol * 1.0);  // |x(1)| = 2/3 < 1
  EXPECT_EQ(a.error_estimate, a.noise_floor);
  EXPECT_NE(a.note.find("noise floor"), std::string::npos) << a.note;
  EXPECT_NEAR(r.x_final()[0], 1.0 - 1.0 / 3.0, 1e-10);
  EXPECT_NE(r.full_report().find("<= 1.0e-11"), std::string::npos) << r.full_report();

  // A target below the floor cannot be shown: the search stops once three runs agree to the
  // floor (doubling from N_sim = 2), and says so.
  fesd::apply_override(q, "tol_sim", "1e-13");
  fesd::apply_override(q, "N_sim", "2");
  const fesd::IntegratorResult below = fesd::simulate(q);
  EXPECT_EQ(below.status, fesd::Status::ToleranceNotMet);
  EXPECT_EQ(run_sizes(below.accuracy), (std::vector<int>{2, 4, 8}));
  EXPECT_TRUE(below.accuracy.at_noise_floor);
  EXPECT_NE(below.message.find("tol_sim = 1e-13 is below the noise floor 1.0e-11"),
            std::string::npos)
      << below.message;
}

// A target that cannot be met within N_sim_max: the finest run is returned, with its estimate, as
// Status::ToleranceNotMet and a message that says so. Implicit Euler (order 1) on the relay before
// its first crossing, tol_sim 1e-9, N_sim_max = 20.
TEST(ErrorEstimate, UnreachableToleranceIsAStatus) {
  fesd::SimulationProblem q = fesd::parse_simulation_problem(kRelay, "relay.toml");
  fesd::apply_override(q, "n_s", "1");
  fesd::apply_override(q, "T_sim", "0.5");
  fesd::apply_override(q, "tol_sim", "1e-9");
  fesd::apply_override(q, "N_sim_max", "20");
  const fesd::IntegratorResult r = fesd::simulate(q);
  EXPECT_EQ(r.status, fesd::Status::ToleranceNotMet);
  EXPECT_EQ(fesd::exit_code(r.status), 1);
  EXPECT_EQ(run_sizes(r.accuracy), (std::vector<int>{10, 20}));
  EXPECT_EQ(r.accuracy.N_sim, 20);
  EXPECT_FALSE(r.accuracy.met);
  EXPECT_GT(r.accuracy.error_estimate, 1e-9);
  EXPECT_NE(r.message.find("tol_sim = 1e-09 not reached with N_sim up to 20 (N_sim_max)"),
            std::string::npos)
      << r.message;
  const double err = (r.x_final() - relay_exact(0.5)).norm();
  EXPECT_TRUE(within_factor_10(err, r.accuracy.error_estimate, "x(T)"));
}

TEST(ErrorEstimate, BadSettingsThrow) {
  const fesd::SimulationProblem q = fesd::parse_simulation_problem(kRelay, "relay.toml");
  fesd::AccuracyOptions acc;
  acc.tol_sim = -1;
  EXPECT_THROW(fesd::simulate(q.model, q.x0, q.T_sim, acc, q.options), fesd::InvalidOption);
  acc.tol_sim = 1e-6;
  acc.N_sim = 50;
  acc.N_sim_max = 20;
  EXPECT_THROW(fesd::simulate(q.model, q.x0, q.T_sim, acc, q.options), fesd::InvalidOption);
  // integrate() keeps its fixed step count: N_sim = 0 is no step count.
  EXPECT_THROW(fesd::integrate(q.model, q.x0, q.T_sim, 0, q.options), fesd::InvalidOption);
}

}  // namespace
