// tests/io/plot_parts_test.cpp: the parts of the plots (src/io/plot_parts.hpp) and the gnuplot
// scripts they make, without running gnuplot: the h_n axis scale, sliding intervals, switch
// labels and their rows, the zero contours of the phase portrait, and what the scripts contain.
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fesd/integrator.hpp"
#include "fesd/model.hpp"
#include "fesd/ocp.hpp"
#include "io/plot_parts.hpp"

namespace {

using namespace fesd::io_detail;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

Eigen::VectorXd vec(std::initializer_list<double> values) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double d : values) v[i++] = d;
  return v;
}

// Subsystem 0: c = x1 (regions 0, 1); subsystem 1: g = (x2, -x2, x1 - 1) (regions 2, 3, 4: three
// rays from (1, 0): g[0] = g[1] on x2 = 0, x1 > 1; g[0] = g[2] on x2 = x1 - 1 <= 0; g[1] = g[2] on
// x2 = 1 - x1 >= 0).
struct TwoSubsystems {
  template <class T>
  void c(const T* x, const T*, T* c_out) const {
    c_out[0] = x[0];
  }
  template <class T>
  void g(const T* x, const T*, T* g_out) const {
    g_out[0] = x[1];
    g_out[1] = -x[1];
    g_out[2] = x[0] - 1.0;
  }
  template <class T>
  void f(int, const T*, const T*, const T*, T* f_out) const {
    f_out[0] = T(0.0);
    f_out[1] = T(0.0);
  }
};

fesd::Pss two_subsystems() {
  return fesd::make_pss(TwoSubsystems{}, fesd::PssDims{.n_x = 2,
                                                       .subsystems = {fesd::Subsystem::from_c(1),
                                                                      fesd::Subsystem::from_g(3)}});
}

// The unit circle, with a parameter r: c = x1^2 + x2^2 - r^2.
struct Circle {
  template <class T>
  void c(const T* x, const T* p, T* c_out) const {
    c_out[0] = x[0] * x[0] + x[1] * x[1] - p[0] * p[0];
  }
  template <class T>
  void f(int region, const T* x, const T*, const T*, T* f_out) const {
    f_out[0] = region == 0 ? -x[1] : x[1];
    f_out[1] = x[0];
  }
};

fesd::Pss circle(int n_x = 2) {
  fesd::Pss m = fesd::make_pss(
      Circle{}, fesd::PssDims{.n_x = n_x, .n_p = 1, .subsystems = {fesd::Subsystem::from_c(1)}});
  m.p_default = vec({1.0});
  return m;
}

TEST(StepAxis, RelativeOnlyWhenTheLabelsWouldAllReadTheSame) {
  // Issue 13: h_n = 1/6 +- 1e-9 gave every tick label 0.166667.
  const StepAxis tiny = step_axis(1.0 / 6 - 1e-9, 1.0 / 6 + 1e-9);
  EXPECT_TRUE(tiny.relative);
  EXPECT_DOUBLE_EQ(tiny.reference, 1.0 / 6);
  EXPECT_NEAR(tiny.value(1.0 / 6 + 1e-9), 6e-9, 1e-15);
  EXPECT_EQ(step_column(tiny, 2), "($2/0.16666666666666666 - 1)");
  EXPECT_EQ(step_ylabel(tiny), "set ylabel 'h_n / h_{ref} - 1' enhanced\n");
  EXPECT_TRUE(contains(step_reference_label(tiny, 0.7), "h_ref = 0.166666667"))
      << step_reference_label(tiny, 0.7);

  // At the threshold (relative span 1e-4) still relative, above it absolute.
  EXPECT_TRUE(step_axis(1.0, 1.0 + 0.99e-4).relative);
  EXPECT_FALSE(step_axis(1.0, 1.0 + 1.01e-4).relative);
  // Steps that visibly differ, constant steps, no steps: absolute.
  for (const auto& [lo, hi] : std::vector<std::pair<double, double>>{
           {0.05, 0.1}, {0.1, 0.1}, {INFINITY, -INFINITY}, {kNaN, 0.1}}) {
    const StepAxis a = step_axis(lo, hi);
    EXPECT_FALSE(a.relative) << lo << " " << hi;
    EXPECT_EQ(a.value(0.25), 0.25);
    EXPECT_EQ(step_column(a, 3), "3");
    EXPECT_EQ(step_ylabel(a), "set ylabel 'h_n' enhanced\n");
    EXPECT_EQ(step_reference_label(a, 0.7), "");
  }
}

TEST(SlidingIntervals, MoreThanOneActiveRegionOfOneSubsystem) {
  const fesd::Pss m = two_subsystems();  // regions {0, 1} and {2, 3, 4}
  EXPECT_FALSE(is_sliding(m, {0, 2}));
  EXPECT_FALSE(is_sliding(m, {1, 4}));  // one region in each subsystem: no sliding
  EXPECT_TRUE(is_sliding(m, {0, 1, 3}));
  EXPECT_TRUE(is_sliding(m, {1, 2, 3}));
  EXPECT_TRUE(is_sliding(m, {0, 1, 2, 3, 4}));

  const std::vector<double> t{0, 1, 2, 3, 4, 5, 6};
  const std::vector<std::vector<int>> active{{0, 2}, {0, 1, 2}, {0, 1, 2, 3},
                                             {0, 2}, {1, 2, 3}, {1, 3}};
  const auto intervals = sliding_intervals(m, t, active);
  ASSERT_EQ(intervals.size(), 2U);
  EXPECT_EQ(intervals[0], (std::pair<double, double>{1, 3}));  // two elements merged
  EXPECT_EQ(intervals[1], (std::pair<double, double>{4, 5}));

  const std::string shade = shade_intervals(intervals);
  EXPECT_TRUE(contains(shade, "set object 1 rect from 1, graph 0 to 3, graph 1 behind")) << shade;
  EXPECT_TRUE(contains(shade, "set object 2 rect from 4, graph 0 to 5, graph 1 behind")) << shade;
  EXPECT_TRUE(shade_intervals({}).empty());
}

TEST(SwitchLabels, RegionsBeforeAndAfter) {
  EXPECT_EQ(region_set({}), "{}");
  EXPECT_EQ(region_set({0, 2}), "{0,2}");
  EXPECT_EQ(
      switch_label(fesd::SwitchEvent{.t = 1, .element = 3, .before = {0, 2}, .after = {0, 2, 3}}),
      "{0,2}->{0,2,3}");
}

TEST(SwitchLabels, RowsKeepLabelsApart) {
  // Widths 2, gap 0.5: [-1, 1] and [0, 2] overlap, [2, 4] clears [-1, 1], [2.2, 4.2] clears
  // neither of the first two rows.
  EXPECT_EQ(label_rows({0, 1, 3, 3.2, 10}, {2, 2, 2, 2, 2}, 0.5, 4),
            (std::vector<int>{0, 1, 0, 2, 0}));
  // More overlapping labels than rows: the last gets none.
  EXPECT_EQ(label_rows({0, 0.1, 0.2}, {2, 2, 2}, 0.5, 2), (std::vector<int>{0, 1, -1}));
  // Order of the input does not matter, rows go left to right.
  EXPECT_EQ(label_rows({3, 0}, {2, 2}, 0.5, 1), (std::vector<int>{0, 0}));
}

TEST(SwitchLabels, MarkupHasOneDashedLineAndOneLabelPerSwitch) {
  const std::vector<fesd::SwitchEvent> switches{
      {.t = 1.0, .element = 1, .before = {0}, .after = {0, 1}},
      {.t = 1.01, .element = 2, .before = {0, 1}, .after = {1}},  // too close: second row
      {.t = kNaN, .element = 3, .before = {1}, .after = {0}}};    // not drawn
  int next = 0, rows = 0;
  const std::string s = switch_markup(switches, 0, 2, 700, 5, next, rows);
  EXPECT_EQ(next, 7);
  EXPECT_EQ(rows, 2);
  EXPECT_TRUE(contains(s, "set arrow 5 from 1, graph 0 to 1, graph 1 nohead dashtype 2")) << s;
  EXPECT_TRUE(contains(s, "set arrow 6 from 1.01, graph 0")) << s;
  EXPECT_FALSE(contains(s, "set arrow 7")) << s;
  EXPECT_TRUE(contains(s, "set label 1 '{0}->{0,1}' at 1, graph 1 offset 0,0.7 center")) << s;
  EXPECT_TRUE(contains(s, "set label 2 '{0,1}->{1}' at 1.01, graph 1 offset 0,1.9 center")) << s;
  EXPECT_FALSE(contains(s, "t_s")) << s;
}

TEST(PhasePortrait, ZeroContourOfACircle) {
  const int n = 81;
  Eigen::MatrixXd v(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = -2 + 4.0 * i / (n - 1), y = -2 + 4.0 * j / (n - 1);
      v(i, j) = x * x + y * y - 1;
    }
  const std::vector<Segment> seg = zero_contour(v, -2, 2, -2, 2);
  ASSERT_GT(seg.size(), 50U);
  double length = 0;
  for (const Segment& s : seg) {
    EXPECT_NEAR(std::hypot(s.x0, s.y0), 1.0, 2e-3);
    EXPECT_NEAR(std::hypot(s.x1, s.y1), 1.0, 2e-3);
    length += std::hypot(s.x1 - s.x0, s.y1 - s.y0);
  }
  EXPECT_NEAR(length, 2 * std::numbers::pi, 2e-3 * 2 * std::numbers::pi);

  // No zero in the box, or a non-finite corner: no segment from that cell.
  EXPECT_TRUE(zero_contour(Eigen::MatrixXd::Ones(5, 5), 0, 1, 0, 1).empty());
  Eigen::MatrixXd half = Eigen::MatrixXd::Constant(2, 2, -1.0);
  half(1, 0) = half(1, 1) = 1.0;  // a vertical line at x = 0.5
  const std::vector<Segment> line = zero_contour(half, 0, 1, 0, 1);
  ASSERT_EQ(line.size(), 1U);
  EXPECT_DOUBLE_EQ(line[0].x0, 0.5);
  EXPECT_DOUBLE_EQ(line[0].x1, 0.5);
  half(0, 0) = kNaN;
  EXPECT_TRUE(zero_contour(half, 0, 1, 0, 1).empty());
}

TEST(PhasePortrait, SwitchingSurfacesOfCAndGSubsystems) {
  // The parameter is used: a circle of radius 2.
  const auto circles = switching_surfaces(circle(), vec({2.0}), -3, 3, -3, 3, 121);
  ASSERT_EQ(circles.size(), 1U);
  EXPECT_EQ(circles[0].first, "c[0] = 0");
  for (const Segment& s : circles[0].second) EXPECT_NEAR(std::hypot(s.x0, s.y0), 2.0, 1e-2);
  // p of the wrong size: nothing (the plot is still drawn, without surfaces).
  EXPECT_TRUE(switching_surfaces(circle(), Eigen::VectorXd(), -3, 3, -3, 3).empty());

  // x1 = 0 (c-form); the three rays of the g-form subsystem, each only where its two g are the
  // smallest (within one grid cell of the corner (1, 0)).
  const auto lines = switching_surfaces(two_subsystems(), Eigen::VectorXd(), -2, 2, -2, 2, 41);
  ASSERT_EQ(lines.size(), 4U);
  EXPECT_EQ(lines[0].first, "c[0] = 0 (subsys. 0)");
  for (const Segment& s : lines[0].second) {
    EXPECT_NEAR(s.x0, 0.0, 1e-12);
    EXPECT_NEAR(s.x1, 0.0, 1e-12);
  }
  EXPECT_EQ(lines[1].first, "g[0] = g[1] (subsys. 1)");
  for (const Segment& s : lines[1].second) {
    EXPECT_NEAR(s.y0, 0.0, 1e-12);
    EXPECT_GE(std::min(s.x0, s.x1), 0.9);
  }
  EXPECT_EQ(lines[2].first, "g[0] = g[2] (subsys. 1)");
  for (const Segment& s : lines[2].second) {
    EXPECT_NEAR(s.y0, s.x0 - 1, 1e-12);
    EXPECT_LE(std::max(s.y0, s.y1), 0.1);
  }
  EXPECT_EQ(lines[3].first, "g[1] = g[2] (subsys. 1)");
  for (const Segment& s : lines[3].second) {
    EXPECT_NEAR(s.y0, 1 - s.x0, 1e-12);
    EXPECT_GE(std::min(s.y0, s.y1), -0.1);
  }
  EXPECT_NEAR(static_cast<double>(lines[1].second.size()), 10, 1);  // x1 in [1, 2]: 10 cells
}

TEST(PhasePortrait, OnlyForTwoStatesWithoutAClock) {
  fesd::Pss m = circle();
  EXPECT_TRUE(wants_phase_portrait(m, 2));
  EXPECT_FALSE(wants_phase_portrait(m, 3));
  m.state_names = {"x", "t"};  // x and the clock of a problem file
  EXPECT_FALSE(wants_phase_portrait(m, 2));
}

// Around the unit circle: a crossing at t = 1 ({0} -> {1}), then sliding on it from t = 2
// ({1} -> {0,1}); the steps agree to 1e-9.
fesd::IntegratorResult circle_result() {
  fesd::IntegratorResult r;
  r.status = fesd::Status::Success;
  r.t = {0, 1, 2, 3};
  r.x = {vec({0.5, 0}), vec({1, 0}), vec({0, 1.2}), vec({-1, 0})};
  r.h = {1 - 1e-9, 1 + 1e-9, 1};
  r.t_stage = {1, 2, 3};
  r.x_stage = {r.x[1], r.x[2], r.x[3]};
  r.active_set = {{0}, {1}, {0, 1}};
  r.switches = {{.t = 1, .element = 0, .before = {0}, .after = {1}},
                {.t = 2, .element = 1, .before = {1}, .after = {0, 1}}};
  return r;
}

TEST(PlotScript, SimulationShowsSlidingSwitchesRelativeStepsAndThePhasePortrait) {
  const std::string s = plot_script(circle_result(), circle(), "out.png", "circle");
  EXPECT_TRUE(contains(s, "set terminal pngcairo size 1500,700")) << s;  // room for the portrait
  EXPECT_TRUE(contains(s, "set object 1 rect from 2, graph 0 to 3, graph 1 behind")) << s;
  EXPECT_TRUE(contains(s, "keyentry with boxes")) << s;
  EXPECT_TRUE(contains(s, "'{0}->{1}' at 1, graph 1")) << s;
  EXPECT_TRUE(contains(s, "'{1}->{0,1}' at 2, graph 1")) << s;
  EXPECT_TRUE(contains(s, "set ylabel 'h_n / h_{ref} - 1' enhanced")) << s;
  EXPECT_TRUE(contains(s, "h_ref = 1")) << s;
  EXPECT_TRUE(contains(s, "plot $steps using 1:($2/1 - 1) with steps")) << s;
  EXPECT_TRUE(contains(s, "set title 'phase portrait'")) << s;
  EXPECT_TRUE(contains(s,
                       "$surface0 using 1:2 with lines linewidth 2 linecolor rgb '#d62728' "
                       "title 'c[0] = 0'"))
      << s;
  EXPECT_TRUE(contains(s, "$phase_sliding using 1:2")) << s;
  // The sliding part of the trajectory: from x(2) to x(3).
  EXPECT_TRUE(contains(s, "$phase_sliding << EOD\n0 1.2\n0 1.2\n-1 0\n-1 0\n\nEOD")) << s;
  EXPECT_EQ(s.find("'t_s'"), std::string::npos) << s;

  // One state more: no portrait, the old picture size.
  fesd::IntegratorResult three = circle_result();
  for (Eigen::VectorXd& x : three.x) x = vec({x[0], x[1], 0});
  const std::string no_portrait = plot_script(three, circle(3), "out.svg", "");
  EXPECT_TRUE(contains(no_portrait, "set terminal svg size 1000,700")) << no_portrait;
  EXPECT_FALSE(contains(no_portrait, "phase portrait")) << no_portrait;
}

TEST(PlotScript, OcpExplainsEtaAndShadesSliding) {
  fesd::OcpResult r;
  r.status = fesd::Status::Success;
  r.t = {0, 1, 2, 3};
  r.x = {vec({0.5, 0}), vec({1, 0}), vec({0, 1.2}), vec({-1, 0})};
  r.h = {1, 1, 1};
  r.interval = {0, 0, 0};
  r.t_ctrl = {0, 3};
  r.u = {};
  r.eta = {kNaN, 0.0, 2.5};
  r.active_set = {{0}, {1}, {0, 1}};
  r.switches = {{.t = 1, .element = 0, .before = {0}, .after = {1}},
                {.t = 2, .element = 1, .before = {1}, .after = {0, 1}}};
  const std::string s = plot_script(r, circle(), "out.png", "ocp");
  EXPECT_TRUE(contains(s,
                       "switching indicator (31)\\neta_n = 0: active set\\nchanges at t_n "
                       "(switch)\\neta_n > 0: step\\nequilibration holds\\nh_n = h_{n-1}"))
      << s;
  EXPECT_TRUE(contains(s, "set object 1 rect from 2, graph 0 to 3, graph 1 behind")) << s;
  EXPECT_TRUE(contains(s, "'{1}->{0,1}' at 2, graph 1")) << s;
  EXPECT_TRUE(contains(s, "set ylabel 'h_n' enhanced")) << s;  // equal steps: absolute
  EXPECT_TRUE(contains(s, "set title 'phase portrait'")) << s;
}

}  // namespace
