// tests/io/ocp_writers_test.cpp: write_json, write_csv and write_plot of an OcpResult, on a small
// synthetic result (no solve).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/temp_dir.hpp"

#include "fesd/error.hpp"
#include "fesd/io.hpp"
#include "fesd/model.hpp"
#include "fesd/ocp.hpp"

namespace {

using fesd::testing::TempDir;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct OneSwitch {
  template <class T>
  void c(const T* x, const T*, T* c_out) const {
    c_out[0] = x[0];
  }
  template <class T>
  void f(int region, const T* x, const T* u, const T*, T* f_out) const {
    f_out[0] = T(region == 0 ? 1.0 : 3.0) + u[0];
    f_out[1] = -x[0];
  }
};

fesd::Pss make_model() {
  fesd::Pss m = fesd::make_pss(
      OneSwitch{}, fesd::PssDims{.n_x = 2, .n_u = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
  m.state_names = {"q", "v"};
  m.control_names = {"force"};
  return m;
}

Eigen::VectorXd vec(std::initializer_list<double> values) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double d : values) v[i++] = d;
  return v;
}

// Two control intervals of length 1 with two elements each; a switch at t = 0.25.
fesd::OcpResult make_result() {
  fesd::OcpResult r;
  r.status = fesd::Status::Success;
  r.message = "synthetic";
  r.objective = 1.25;
  r.comp_residual = 1e-10;
  r.mpcc_mode = fesd::MpccMode::ScholtesEq;
  r.t = {0.0, 0.25, 1.0, 1.5, 2.0};
  r.x = {vec({-1.0, 0.0}), vec({0.0, 0.1}), vec({1.0, 0.2}), vec({1.5, 0.3}), vec({2.0, 0.4})};
  r.h = {0.25, 0.75, 0.5, 0.5};
  r.interval = {0, 0, 1, 1};
  r.t_ctrl = {0.0, 1.0, 2.0};
  r.u = {vec({0.5}), vec({-0.5})};
  r.eta = {kNaN, 0.0, kNaN, 2.5};
  r.active_set = {{1}, {0}, {0}, {0}};
  r.switches = {fesd::SwitchEvent{.t = 0.25, .element = 0, .before = {1}, .after = {0}}};
  r.t_stage = {0.25, 1.0, 1.5, 2.0};
  r.x_stage = {r.x[1], r.x[2], r.x[3], r.x[4]};
  r.theta = {vec({0.0, 1.0}), vec({1.0, 0.0}), vec({1.0, 0.0}), vec({1.0, 0.0})};
  r.lambda = {vec({2.0, 0.0}), vec({0.0, 2.0}), vec({0.0, 2.0}), vec({0.0, 2.0})};
  r.homotopy = {
      fesd::HomotopyRow{0, 1.0, 0.5, 2.0, 1e-12, 7, "Solve_Succeeded", 0.001, 0.001, "mumps"},
      fesd::HomotopyRow{1, 0.1, 1e-10, 1.25, 2e-13, 3, "Solve_Succeeded", 0.002, 0.002, "mumps"}};
  r.homotopy[0].retried = true;
  r.homotopy[0].restarted = true;
  r.homotopy[1].cold_start = true;
  r.summary.homotopy_steps = 2;
  r.summary.nlp_iterations = 10;
  r.summary.n_variables = 100;
  r.summary.n_constraints = 90;
  r.summary.wall_s = 0.5;
  r.summary.derivative_s = 0.125;
  r.summary.solver_s = 0.25;
  r.summary.setup_s = 0.0625;
  return r;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(WriteOcpJson, KeysInOrderAndValues) {
  TempDir dir;
  const std::string path = dir.file("ocp.json");
  fesd::write_json(make_result(), make_model(), path);
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(read_file(path));
  std::vector<std::string> keys;
  for (auto it = j.begin(); it != j.end(); ++it) keys.push_back(it.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"status",
                                            "message",
                                            "objective",
                                            "t",
                                            "x",
                                            "t_ctrl",
                                            "u",
                                            "h",
                                            "interval",
                                            "eta",
                                            "switch_times",
                                            "x0",
                                            "x_final",
                                            "T_final",
                                            "homotopy",
                                            "stats",
                                            "t_stage",
                                            "x_stage",
                                            "theta",
                                            "lambda",
                                            "active_set",
                                            "switches",
                                            "state_names",
                                            "control_names"}));
  EXPECT_EQ(j["status"], "success");
  EXPECT_EQ(j["objective"].get<double>(), 1.25);
  EXPECT_EQ(j["t"].get<std::vector<double>>(), (std::vector<double>{0.0, 0.25, 1.0, 1.5, 2.0}));
  EXPECT_EQ(j["x"][1].get<std::vector<double>>(), (std::vector<double>{0.0, 0.1}));
  EXPECT_EQ(j["t_ctrl"].get<std::vector<double>>(), (std::vector<double>{0.0, 1.0, 2.0}));
  EXPECT_EQ(j["u"].size(), 2u);
  EXPECT_EQ(j["u"][1][0].get<double>(), -0.5);
  EXPECT_EQ(j["h"].get<std::vector<double>>(), (std::vector<double>{0.25, 0.75, 0.5, 0.5}));
  EXPECT_EQ(j["interval"].get<std::vector<int>>(), (std::vector<int>{0, 0, 1, 1}));
  ASSERT_EQ(j["eta"].size(), 4u);
  EXPECT_TRUE(j["eta"][0].is_null());  // NaN at an interval start
  EXPECT_EQ(j["eta"][1].get<double>(), 0.0);
  EXPECT_EQ(j["switch_times"].get<std::vector<double>>(), (std::vector<double>{0.25}));
  EXPECT_EQ(j["x0"].get<std::vector<double>>(), (std::vector<double>{-1.0, 0.0}));
  EXPECT_EQ(j["x_final"].get<std::vector<double>>(), (std::vector<double>{2.0, 0.4}));
  ASSERT_EQ(j["homotopy"].size(), 2u);
  EXPECT_EQ(j["homotopy"][1]["sigma"].get<double>(), 0.1);
  EXPECT_EQ(j["homotopy"][1]["nlp_status"], "Solve_Succeeded");
  EXPECT_EQ(j["homotopy"][0]["retried"], true);
  EXPECT_EQ(j["homotopy"][1]["retried"], false);
  EXPECT_EQ(j["homotopy"][0]["restarted"], true);
  EXPECT_EQ(j["homotopy"][1]["restarted"], false);
  EXPECT_EQ(j["homotopy"][0]["cold_start"], false);
  EXPECT_EQ(j["homotopy"][1]["cold_start"], true);
  const auto& stats = j["stats"];
  EXPECT_EQ(stats["homotopy_steps"], 2);
  EXPECT_EQ(stats["nlp_iterations"], 10);
  EXPECT_EQ(stats["n_variables"], 100);
  EXPECT_EQ(stats["n_constraints"], 90);
  EXPECT_EQ(stats["comp_residual"].get<double>(), 1e-10);
  EXPECT_EQ(stats["mpcc_mode"], "scholtes_eq");
  EXPECT_EQ(stats["wall_s"].get<double>(), 0.5);
  EXPECT_EQ(j["active_set"][0].get<std::vector<int>>(), std::vector<int>{1});
  EXPECT_EQ(j["switches"][0]["t"].get<double>(), 0.25);
  EXPECT_EQ(j["state_names"].get<std::vector<std::string>>(), (std::vector<std::string>{"q", "v"}));
  EXPECT_EQ(j["control_names"].get<std::vector<std::string>>(), std::vector<std::string>{"force"});
}

TEST(WriteOcpCsv, StatesAndTheControlOfEachRowsInterval) {
  TempDir dir;
  const std::string path = dir.file("ocp.csv");
  fesd::write_csv(make_result(), make_model(), path);
  const std::string text = read_file(path);
  EXPECT_EQ(text,
            "t,q,v,interval,force\n"
            "0,-1,0,0,0.5\n"
            "0.25,0,0.10000000000000001,0,0.5\n"
            "1,1,0.20000000000000001,1,-0.5\n"
            "1.5,1.5,0.29999999999999999,1,-0.5\n"
            "2,2,0.40000000000000002,1,-0.5\n");

  // Without names: x1.., u1...
  fesd::Pss unnamed = make_model();
  unnamed.state_names.clear();
  unnamed.control_names.clear();
  fesd::write_csv(make_result(), unnamed, path);
  EXPECT_EQ(read_file(path).substr(0, 19), "t,x1,x2,interval,u1");
}

TEST(WriteOcpPlot, SvgAndErrors) {
  TempDir dir;
  EXPECT_THROW(fesd::write_plot(make_result(), make_model(), dir.file("p.pdf")), fesd::IoError);
  EXPECT_THROW(fesd::write_plot(fesd::OcpResult{}, make_model(), dir.file("e.svg")), fesd::IoError);
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "gnuplot is not installed";
  const std::string svg = dir.file("p.svg");
  fesd::write_plot(make_result(), make_model(), svg, "it's an \"OCP\"");
  EXPECT_NE(read_file(svg).find("<svg"), std::string::npos);

  // No controls, one control interval, no positive eta: still a plot.
  fesd::OcpResult r = make_result();
  r.u = {Eigen::VectorXd(), Eigen::VectorXd()};
  r.eta = {kNaN, 0.0, 0.0, 0.0};
  r.t_ctrl = {0.0, 2.0};
  r.interval = {0, 0, 0, 0};
  fesd::write_plot(r, make_model(), svg);
  EXPECT_NE(read_file(svg).find("<svg"), std::string::npos);
  std::vector<std::string> entries = dir.entries();
  EXPECT_EQ(entries, std::vector<std::string>{"p.svg"});
}

}  // namespace

// The progress table says which NLP the cold restart discarded and which one started cold
// (homotopy_cold_restart), and a plain row says neither.
TEST(HomotopyRowText, MarksTheColdRestart) {
  fesd::HomotopyRow failed;
  failed.sigma = 1e-3;
  failed.nlp_status = "Infeasible_Problem_Detected";
  failed.restarted = true;
  fesd::HomotopyRow cold;
  cold.sigma = 1e-3;
  cold.nlp_status = "Solve_Succeeded";
  cold.cold_start = true;
  fesd::HomotopyRow plain;
  plain.nlp_status = "Solve_Succeeded";
  EXPECT_NE(fesd::format_homotopy_row(failed).find("path replaced by the cold restart"),
            std::string::npos);
  fesd::HomotopyRow stalled = cold;
  stalled.cold_start = false;
  stalled.stalled = true;
  EXPECT_NE(fesd::format_homotopy_row(stalled).find(
                "residual stalled: a stationary point of the penalty"),
            std::string::npos);
  // (The live table printed the replaced rows before the restart: the cold row says which.)
  EXPECT_NE(fesd::format_homotopy_row(cold).find(
                "cold restart from the initial guess; replaces the rows from the first failure"),
            std::string::npos);
  const std::string p = fesd::format_homotopy_row(plain);
  EXPECT_EQ(p.find("initial guess"), std::string::npos);
  EXPECT_EQ(p.find("retried"), std::string::npos);
  EXPECT_EQ(p.find("stalled"), std::string::npos);
}
