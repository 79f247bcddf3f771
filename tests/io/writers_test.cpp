// tests/io/writers_test.cpp: write_json, write_csv and write_plot on a small synthetic result.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/temp_dir.hpp"

#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/io.hpp"
#include "fesd/model.hpp"

namespace {

namespace fs = std::filesystem;

// x' = (1, -x1) for x1 < 0, (3, -x1) for x1 > 0: two states, one switching function.
struct TwoRegions {
  template <class T>
  void c(const T* x, const T*, T* c_out) const {
    c_out[0] = x[0];
  }
  template <class T>
  void f(int region, const T* x, const T*, const T*, T* f_out) const {
    f_out[0] = T(region == 0 ? 3.0 : 1.0);
    f_out[1] = -x[0];
  }
};

fesd::Pss make_model(std::vector<std::string> names) {
  fesd::Pss model = fesd::make_pss(
      TwoRegions{}, fesd::PssDims{.n_x = 2, .subsystems = {fesd::Subsystem::from_c(1)}});
  if (!names.empty()) model.state_names = std::move(names);
  return model;
}

Eigen::VectorXd vec(std::initializer_list<double> values) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double d : values) v[i++] = d;
  return v;
}

// Two integration steps of two finite elements each, one switch at t = 1/3, n_s = 1.
fesd::IntegratorResult make_result() {
  fesd::IntegratorResult r;
  r.status = fesd::Status::ComplementarityNotMet;
  r.message = "synthetic result with \"quotes\", a comma, and a line\nbreak";
  r.t = {0.0, 1.0 / 3.0, 0.5, 0.75, 1.0};
  r.x = {vec({-1.0, 0.0}), vec({1e-300, -1.0 / 7.0}), vec({1.0 / 6.0, -2.5e10}),
         vec({0.4166666666666667, 3.0}), vec({2.0 / 3.0, -0.1})};
  r.h = {1.0 / 3.0, 1.0 / 6.0, 0.25, 0.25};
  r.t_stage = {1.0 / 3.0, 0.5, 0.75, 1.0};
  r.x_stage = {r.x[1], r.x[2], r.x[3], r.x[4]};
  r.theta = {vec({0.0, 1.0}), vec({1.0, 0.0}), vec({1.0, 0.0}), vec({1.0, 0.0})};
  r.lambda = {vec({2.0, 0.0}), vec({0.0, 2.0}), vec({0.0, 2.0}), vec({0.0, 2.0})};
  r.mu = {vec({-3.0}), vec({-1.0}), vec({-1.0}), vec({std::numeric_limits<double>::quiet_NaN()})};
  r.active_set = {{1}, {0}, {0}, {0}};
  r.switches = {fesd::SwitchEvent{.t = 1.0 / 3.0, .element = 0, .before = {1}, .after = {0}}};
  r.homotopy = {
      {fesd::HomotopyRow{0, 1.0, 0.5, 0.25, 1e-12, 7, "Solve_Succeeded", 0.001, 0.001, "dense"},
       fesd::HomotopyRow{1, 0.1, 1e-10, 0.125, 2e-13, 3, "Solve_Succeeded", 0.0005, 0.0007,
                         "dense"}},
      {fesd::HomotopyRow{0, 1.0, std::numeric_limits<double>::infinity(), 0.0, 0.0, 500,
                         "Maximum_Iterations_Exceeded", 0.25, 0.25, "mumps"}},
  };
  r.summary = fesd::Summary{.homotopy_steps = 3,
                            .nlp_iterations = 510,
                            .wall_s = 0.5,
                            .derivative_s = 0.125,
                            .solver_s = 0.25,
                            .setup_s = 0.0625,
                            .max_comp_residual = 1e-10};
  return r;
}

using fesd::testing::TempDir;

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool gnuplot_available() {
  return std::system("command -v gnuplot >/dev/null 2>&1") == 0;
}

// Runs `f` and returns the IoError message, or nullopt if nothing (or something else) was thrown.
template <class F>
std::optional<std::string> io_error_of(F&& f) {
  try {
    f();
  } catch (const fesd::IoError& e) {
    return std::string(e.what());
  } catch (...) {
    return std::nullopt;
  }
  return std::nullopt;
}

void expect_rows(const nlohmann::json& rows, const std::vector<Eigen::VectorXd>& expected,
                 const char* key) {
  ASSERT_TRUE(rows.is_array()) << key;
  ASSERT_EQ(rows.size(), expected.size()) << key;
  for (std::size_t n = 0; n < expected.size(); ++n) {
    ASSERT_EQ(rows[n].size(), static_cast<std::size_t>(expected[n].size())) << key << " row " << n;
    for (Eigen::Index i = 0; i < expected[n].size(); ++i) {
      const double want = expected[n][i];
      if (std::isfinite(want)) {
        EXPECT_EQ(rows[n][static_cast<std::size_t>(i)].get<double>(), want)
            << key << "[" << n << "][" << i << "]";
      } else {
        EXPECT_TRUE(rows[n][static_cast<std::size_t>(i)].is_null()) << key << " non-finite";
      }
    }
  }
}

TEST(WriteJson, HasEveryKeyAndRoundTripsValues) {
  TempDir dir;
  const fesd::IntegratorResult r = make_result();
  const fesd::Pss model = make_model({"q", "v"});
  const std::string path = dir.file("result.json");
  fesd::write_json(r, model, path);

  const nlohmann::json j = nlohmann::json::parse(read_file(path));
  for (const char* key :
       {"status", "message", "t", "x", "h", "switch_times", "x_final", "stats", "t_stage",
        "x_stage", "theta", "lambda", "mu", "active_set", "switches", "homotopy", "state_names"}) {
    EXPECT_TRUE(j.contains(key)) << "missing key " << key;
  }
  EXPECT_EQ(j["status"], "complementarity_not_met");
  EXPECT_EQ(j["message"], r.message);
  EXPECT_EQ(j["t"].get<std::vector<double>>(), r.t);  // exact: doubles must round-trip
  EXPECT_EQ(j["h"].get<std::vector<double>>(), r.h);
  EXPECT_EQ(j["t_stage"].get<std::vector<double>>(), r.t_stage);
  expect_rows(j["x"], r.x, "x");
  expect_rows(j["x_stage"], r.x_stage, "x_stage");
  expect_rows(j["theta"], r.theta, "theta");
  expect_rows(j["lambda"], r.lambda, "lambda");
  expect_rows(j["mu"], r.mu, "mu");  // its NaN must be null
  EXPECT_EQ(j["x"][1][0].get<double>(), 1e-300);
  EXPECT_EQ(j["x_final"].get<std::vector<double>>(), (std::vector<double>{2.0 / 3.0, -0.1}));
  EXPECT_EQ(j["switch_times"].get<std::vector<double>>(), r.switch_times());
  EXPECT_EQ(j["active_set"].get<std::vector<std::vector<int>>>(), r.active_set);
  EXPECT_EQ(j["state_names"].get<std::vector<std::string>>(), (std::vector<std::string>{"q", "v"}));

  const nlohmann::json& stats = j["stats"];
  EXPECT_EQ(stats["homotopy_steps"], 3);
  EXPECT_EQ(stats["nlp_iterations"], 510);
  EXPECT_EQ(stats["wall_s"], 0.5);
  EXPECT_EQ(stats["derivative_s"], 0.125);
  EXPECT_EQ(stats["solver_s"], 0.25);
  EXPECT_EQ(stats["setup_s"], 0.0625);
  EXPECT_EQ(stats["max_comp_residual"], 1e-10);

  ASSERT_EQ(j["switches"].size(), 1u);
  EXPECT_EQ(j["switches"][0]["t"].get<double>(), 1.0 / 3.0);
  EXPECT_EQ(j["switches"][0]["element"], 0);
  EXPECT_EQ(j["switches"][0]["before"].get<std::vector<int>>(), std::vector<int>{1});
  EXPECT_EQ(j["switches"][0]["after"].get<std::vector<int>>(), std::vector<int>{0});

  ASSERT_EQ(j["homotopy"].size(), 2u);
  ASSERT_EQ(j["homotopy"][0].size(), 2u);
  const nlohmann::json& row = j["homotopy"][0][1];
  EXPECT_EQ(row["k"], 1);
  EXPECT_EQ(row["sigma"], 0.1);
  EXPECT_EQ(row["comp_residual"], 1e-10);
  EXPECT_EQ(row["objective"], 0.125);
  EXPECT_EQ(row["inf_pr"], 2e-13);
  EXPECT_EQ(row["nlp_iterations"], 3);
  EXPECT_EQ(row["nlp_status"], "Solve_Succeeded");
  EXPECT_EQ(row["cpu_s"], 0.0005);
  EXPECT_EQ(row["wall_s"], 0.0007);
  EXPECT_TRUE(j["homotopy"][1][0]["comp_residual"].is_null());  // inf
  EXPECT_EQ(j["homotopy"][1][0]["nlp_status"], "Maximum_Iterations_Exceeded");
}

TEST(WriteJson, EmptyResultGivesEmptyArrays) {
  TempDir dir;
  const std::string path = dir.file("empty.json");
  fesd::write_json(fesd::IntegratorResult{}, make_model({}), path);
  const nlohmann::json j = nlohmann::json::parse(read_file(path));
  EXPECT_EQ(j["status"], "not_run");
  EXPECT_TRUE(j["t"].empty());
  EXPECT_TRUE(j["x_final"].empty());
  EXPECT_EQ(j["state_names"].get<std::vector<std::string>>(),
            (std::vector<std::string>{"x1", "x2"}));
}

TEST(WriteCsv, HeaderRowsAndValues) {
  TempDir dir;
  const fesd::IntegratorResult r = make_result();
  const std::string path = dir.file("result.csv");
  fesd::write_csv(r, make_model({"q", "v"}), path);

  std::istringstream in(read_file(path));
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "t,q,v");
  std::size_t n = 0;
  while (std::getline(in, line)) {
    ASSERT_LT(n, r.t.size()) << "too many rows";
    std::vector<double> values;
    std::istringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) values.push_back(std::strtod(field.c_str(), nullptr));
    ASSERT_EQ(values.size(), 3u) << line;
    EXPECT_EQ(values[0], r.t[n]) << line;  // %.17g round-trips exactly
    EXPECT_EQ(values[1], r.x[n][0]) << line;
    EXPECT_EQ(values[2], r.x[n][1]) << line;
    ++n;
  }
  EXPECT_EQ(n, r.t.size());
}

TEST(WriteCsv, DefaultNamesAndQuoting) {
  TempDir dir;
  const std::string path = dir.file("names.csv");
  fesd::write_csv(make_result(), make_model({}), path);
  EXPECT_EQ(read_file(path).substr(0, 8), "t,x1,x2\n");
  fesd::write_csv(make_result(), make_model({"a,b", "c"}), path);
  EXPECT_EQ(read_file(path).substr(0, 11), "t,\"a,b\",c\n0");
}

TEST(Writers, UnwritablePathThrowsIoError) {
  const fesd::IntegratorResult r = make_result();
  const fesd::Pss model = make_model({});
  for (const std::string path : {"/nonexistent/dir/x.json", "/nonexistent/dir/x.csv"}) {
    const auto message = io_error_of([&] {
      if (path.ends_with(".json")) {
        fesd::write_json(r, model, path);
      } else {
        fesd::write_csv(r, model, path);
      }
    });
    ASSERT_TRUE(message.has_value()) << path;
    EXPECT_NE(message->find("cannot write '" + path + "'"), std::string::npos) << *message;
  }
  if (gnuplot_available()) {
    const auto message = io_error_of([&] { fesd::write_plot(r, model, "/nonexistent/d/x.png"); });
    ASSERT_TRUE(message.has_value());
    EXPECT_NE(message->find("/nonexistent/d/x.png"), std::string::npos) << *message;
  }
}

TEST(WritePlot, UnknownExtensionThrowsIoError) {
  TempDir dir;
  const std::string path = dir.file("plot.pdf");
  const auto message = io_error_of([&] { fesd::write_plot(make_result(), make_model({}), path); });
  ASSERT_TRUE(message.has_value());
  EXPECT_NE(message->find(".pdf"), std::string::npos) << *message;
  EXPECT_NE(message->find(".png"), std::string::npos) << *message;
  EXPECT_NE(message->find(".svg"), std::string::npos) << *message;
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(io_error_of([&] {
                fesd::write_plot(make_result(), make_model({}), dir.file("noext"));
              }).has_value());
}

TEST(WritePlot, MissingGnuplotThrowsIoError) {
  TempDir dir;
  const char* old = std::getenv("PATH");
  const std::string saved = old != nullptr ? old : "";
  ::setenv("PATH", dir.file("empty_bin").c_str(), 1);
  const auto message =
      io_error_of([&] { fesd::write_plot(make_result(), make_model({}), dir.file("p.svg")); });
  if (old != nullptr) {
    ::setenv("PATH", saved.c_str(), 1);
  } else {
    ::unsetenv("PATH");
  }
  ASSERT_TRUE(message.has_value());
  EXPECT_NE(message->find("gnuplot not found"), std::string::npos) << *message;
  EXPECT_FALSE(fs::exists(dir.file("p.svg")));
}

TEST(WritePlot, SvgAndPng) {
  if (!gnuplot_available()) GTEST_SKIP() << "gnuplot is not installed";
  TempDir dir;
  const fesd::IntegratorResult r = make_result();
  // Quotes and underscores in the title and the names must not break the gnuplot script.
  const fesd::Pss model = make_model({"x_1 'pos'", "v\"el"});

  const std::string svg = dir.file("plot.svg");
  fesd::write_plot(r, model, svg, "it's a \"test\"");
  EXPECT_NE(read_file(svg).find("<svg"), std::string::npos);

  const std::string png = dir.file("plot.PNG");  // the extension is case-insensitive
  fesd::write_plot(r, model, png);
  const std::string bytes = read_file(png);
  ASSERT_GE(bytes.size(), 8u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));

  // The data went inline: nothing else was created.
  std::vector<std::string> entries = dir.entries();
  std::sort(entries.begin(), entries.end());
  EXPECT_EQ(entries, (std::vector<std::string>{"plot.PNG", "plot.svg"}));
}

TEST(WritePlot, SingleElementAndConstantSteps) {
  if (!gnuplot_available()) GTEST_SKIP() << "gnuplot is not installed";
  TempDir dir;
  fesd::IntegratorResult r;
  r.status = fesd::Status::Success;
  r.t = {0.0, 0.5, 1.0};
  r.x = {vec({0.0, 1.0}), vec({0.5, 1.0}), vec({1.0, 1.0})};
  r.h = {0.5, 0.5};
  const std::string path = dir.file("flat.svg");
  fesd::write_plot(r, make_model({}), path);
  EXPECT_NE(read_file(path).find("<svg"), std::string::npos);

  // Steps spanning more than two decades: log scale.
  r.h = {1e-6, 1.0 - 1e-6};
  r.t = {0.0, 1e-6, 1.0};
  fesd::write_plot(r, make_model({}), path);
  EXPECT_NE(read_file(path).find("<svg"), std::string::npos);

  EXPECT_TRUE(io_error_of([&] {
                fesd::write_plot(fesd::IntegratorResult{}, make_model({}), dir.file("e.svg"));
              }).has_value());
}

}  // namespace
