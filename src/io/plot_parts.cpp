// src/io/plot_parts.cpp: the shared parts of the integrator and OCP plots (plot_parts.hpp).
#include "io/plot_parts.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <exception>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "io/gnuplot.hpp"

namespace fesd::io_detail {
namespace {

/// Approximate width of one character of the labels (Sans 10) in pixels.
constexpr double kCharPx = 7.0;

/// Colours of the switching surfaces, one per function (cycled).
constexpr std::array<const char*, 6> kSurfaceColors{"#d62728", "#2ca02c", "#9467bd",
                                                    "#8c564b", "#e377c2", "#17becf"};

std::string number(double v) {
  return gp_number(v);
}

}  // namespace

// ---- the h_n axis ------------------------------------------------------------------------------

StepAxis step_axis(double h_min, double h_max) {
  if (!std::isfinite(h_min) || !std::isfinite(h_max) || !(h_max > h_min)) return {};
  const double scale = std::max(std::abs(h_min), std::abs(h_max));
  const double reference = 0.5 * (h_min + h_max);
  if (h_max - h_min > kRelativeSpan * scale || reference == 0) return {};
  return {true, reference};
}

std::string step_column(const StepAxis& axis, int column) {
  if (!axis.relative) return std::to_string(column);
  return fmt::format("(${}/{} - 1)", column, number(axis.reference));
}

std::string step_ylabel(const StepAxis& axis) {
  return axis.relative ? "set ylabel 'h_n / h_{ref} - 1' enhanced\n"
                       : "set ylabel 'h_n' enhanced\n";
}

std::string step_reference_label(const StepAxis& axis, double graph_y) {
  if (!axis.relative) return "";
  return fmt::format(
      "set label \"relative scale:\\nh_ref = {:.9g}\" at graph 1.03, graph {} left noenhanced "
      "textcolor rgb '#404040'\n",
      axis.reference, number(graph_y));
}

// ---- the model as the plots see it --------------------------------------------------------------

PlotModel::PlotModel(const Pss& model)
    : state_names(model.state_names),
      control_names(model.control_names),
      n_x(model.n_x()),
      p(model.p_default),
      shaded_name("sliding"),
      shaded([&model](const std::vector<int>& a) { return is_sliding(model, a); }),
      surfaces([&model](const Eigen::VectorXd& params, double xlo, double xhi, double ylo,
                        double yhi, int n_grid) {
        return switching_surfaces(model, params, xlo, xhi, ylo, yhi, n_grid);
      }) {}

PlotModel::PlotModel(const Pds& model)
    : state_names(model.state_names),
      control_names(model.control_names),
      n_x(model.n_x()),
      p(model.p_default),
      shaded_name("contact"),
      shaded([](const std::vector<int>& a) { return !a.empty(); }),
      surfaces([&model](const Eigen::VectorXd& params, double xlo, double xhi, double ylo,
                        double yhi, int n_grid) {
        return switching_surfaces(model, params, xlo, xhi, ylo, yhi, n_grid);
      }) {}

// ---- sliding intervals -------------------------------------------------------------------------

bool is_sliding(const Pss& model, const std::vector<int>& active_set) {
  for (int k = 0; k < model.n_sys(); ++k) {
    const int first = model.region_offset(k), last = model.region_offset(k + 1);
    const auto n = std::count_if(active_set.begin(), active_set.end(),
                                 [&](int r) { return r >= first && r < last; });
    if (n > 1) return true;
  }
  return false;
}

std::vector<std::pair<double, double>> sliding_intervals(
    const PlotModel& model, const std::vector<double>& t,
    const std::vector<std::vector<int>>& active_set) {
  std::vector<std::pair<double, double>> out;
  const std::size_t n_el = std::min(active_set.size(), t.empty() ? 0 : t.size() - 1);
  for (std::size_t n = 0; n < n_el; ++n) {
    if (!model.shaded(active_set[n]) || !std::isfinite(t[n]) || !std::isfinite(t[n + 1])) continue;
    if (!out.empty() && out.back().second == t[n]) {
      out.back().second = t[n + 1];
    } else {
      out.emplace_back(t[n], t[n + 1]);
    }
  }
  return out;
}

std::string shade_intervals(const std::vector<std::pair<double, double>>& intervals) {
  std::string s;
  int tag = 1;
  for (const auto& [a, b] : intervals) {
    s += fmt::format(
        "set object {} rect from {}, graph 0 to {}, graph 1 behind fillcolor rgb '{}' "
        "fillstyle solid 0.35 noborder\n",
        tag++, number(a), number(b), kSlidingColor);
  }
  return s;
}

std::string sliding_key_entry(const std::string& name) {
  return fmt::format(
      ", keyentry with boxes fillstyle solid 0.35 noborder fillcolor rgb '{}' title '{}'",
      kSlidingColor, name);
}

// ---- switches ----------------------------------------------------------------------------------

std::string region_set(const std::vector<int>& regions) {
  std::string s = "{";
  for (std::size_t i = 0; i < regions.size(); ++i) {
    if (i > 0) s += ',';
    s += std::to_string(regions[i]);
  }
  return s + "}";
}

std::string switch_label(const SwitchEvent& e) {
  return region_set(e.before) + "->" + region_set(e.after);
}

std::vector<int> label_rows(const std::vector<double>& x, const std::vector<double>& width,
                            double gap, int max_rows) {
  std::vector<int> rows(x.size(), -1);
  std::vector<double> right_end(static_cast<std::size_t>(std::max(max_rows, 0)), -INFINITY);
  // Left to right by centre, each label in the first row where it clears the previous one.
  std::vector<std::size_t> order(x.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return x[a] < x[b]; });
  for (std::size_t i : order) {
    const double w = i < width.size() ? width[i] : 0.0;
    const double left = x[i] - w / 2;
    for (std::size_t r = 0; r < right_end.size(); ++r) {
      if (left >= right_end[r] + gap) {
        rows[i] = static_cast<int>(r);
        right_end[r] = x[i] + w / 2;
        break;
      }
    }
  }
  return rows;
}

std::string switch_markup(const std::vector<SwitchEvent>& switches, double t0, double t_end,
                          double plot_width_px, int first_tag, int& next_tag, int& rows) {
  std::string s;
  int tag = first_tag;
  std::vector<double> x, width;
  std::vector<std::string> text;
  for (const SwitchEvent& e : switches) {
    if (!std::isfinite(e.t)) continue;
    s += fmt::format(
        "set arrow {} from {}, graph 0 to {}, graph 1 nohead dashtype 2 linewidth 1 "
        "linecolor rgb '#707070' back\n",
        tag++, number(e.t), number(e.t));
    x.push_back(e.t);
    text.push_back(switch_label(e));
  }
  next_tag = tag;
  rows = 0;
  const double span = t_end - t0;
  if (x.empty() || x.size() > 20 || !(span > 0) || !(plot_width_px > 0)) return s;
  const double t_per_px = span / plot_width_px;
  for (const std::string& label : text)
    width.push_back(static_cast<double>(label.size()) * kCharPx * t_per_px);
  const std::vector<int> row = label_rows(x, width, kCharPx * t_per_px, 4);
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (row[i] < 0) continue;
    rows = std::max(rows, row[i] + 1);
    s += fmt::format(
        "set label {} {} at {}, graph 1 offset 0,{:g} center noenhanced textcolor rgb '#404040'\n",
        i + 1, gp_string(text[i]), number(x[i]), 0.7 + 1.2 * row[i]);
  }
  return s;
}

// ---- phase portrait ----------------------------------------------------------------------------

std::vector<Segment> zero_contour(const Eigen::MatrixXd& v, double xlo, double xhi, double ylo,
                                  double yhi) {
  std::vector<Segment> out;
  const Eigen::Index nx = v.rows(), ny = v.cols();
  if (nx < 2 || ny < 2) return out;
  const double dx = (xhi - xlo) / static_cast<double>(nx - 1);
  const double dy = (yhi - ylo) / static_cast<double>(ny - 1);
  struct P {
    double x, y;
  };
  // The point where the value crosses 0 on the edge from (xa, ya, a) to (xb, yb, b).
  const auto cross = [](double xa, double ya, double a, double xb, double yb, double b) {
    const double s = a / (a - b);
    return P{xa + s * (xb - xa), ya + s * (yb - ya)};
  };
  for (Eigen::Index i = 0; i + 1 < nx; ++i) {
    for (Eigen::Index j = 0; j + 1 < ny; ++j) {
      const double v00 = v(i, j), v10 = v(i + 1, j), v11 = v(i + 1, j + 1), v01 = v(i, j + 1);
      if (!std::isfinite(v00) || !std::isfinite(v10) || !std::isfinite(v11) || !std::isfinite(v01))
        continue;
      const bool p00 = v00 >= 0, p10 = v10 >= 0, p11 = v11 >= 0, p01 = v01 >= 0;
      const double x0 = xlo + static_cast<double>(i) * dx, x1 = x0 + dx;
      const double y0 = ylo + static_cast<double>(j) * dy, y1 = y0 + dy;
      // Crossings on the edges bottom, right, top, left (in this order).
      std::array<P, 4> e{};
      std::array<bool, 4> has{p00 != p10, p10 != p11, p01 != p11, p00 != p01};
      if (has[0]) e[0] = cross(x0, y0, v00, x1, y0, v10);
      if (has[1]) e[1] = cross(x1, y0, v10, x1, y1, v11);
      if (has[2]) e[2] = cross(x0, y1, v01, x1, y1, v11);
      if (has[3]) e[3] = cross(x0, y0, v00, x0, y1, v01);
      const int n = has[0] + has[1] + has[2] + has[3];
      const auto add = [&](int a, int b) { out.push_back({e[a].x, e[a].y, e[b].x, e[b].y}); };
      if (n == 2) {
        int a = -1, b = -1;
        for (int k = 0; k < 4; ++k)
          if (has[k]) (a < 0 ? a : b) = k;
        add(a, b);
      } else if (n == 4) {  // a saddle: the centre value decides which corners are joined
        const bool centre = (v00 + v10 + v11 + v01) / 4 >= 0;
        if (centre == p00) {  // 00 and 11 joined: cut off the corners 10 and 01
          add(0, 1);
          add(2, 3);
        } else {  // cut off the corners 00 and 11
          add(0, 3);
          add(1, 2);
        }
      }
    }
  }
  return out;
}

bool wants_phase_portrait(const PlotModel& model, int n_x) {
  if (n_x != 2) return false;
  for (int i = 0; i < 2; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (k < model.state_names.size() && model.state_names[k] == "t") return false;
  }
  return true;
}

PhaseData phase_data(const IntegratorResult& r, const PlotModel& model) {
  return {r.t, r.x, r.t_stage, r.x_stage, r.active_set, r.switches, model.p};
}

PhaseData phase_data(const OcpResult& r, const PlotModel& model) {
  return {r.t, r.x, r.t_stage, r.x_stage, r.active_set, r.switches, model.p};
}

std::vector<std::pair<std::string, std::vector<Segment>>> switching_surfaces(
    const Pss& model, const Eigen::VectorXd& p, double xlo, double xhi, double ylo, double yhi,
    int n_grid) {
  std::vector<std::pair<std::string, std::vector<Segment>>> out;
  if (model.n_x() != 2 || p.size() != model.n_p() || n_grid < 2) return out;
  const PssFunctions& f = model.functions();
  const auto n_c = static_cast<std::size_t>(model.n_c()),
             n_g = static_cast<std::size_t>(model.n_g());
  std::vector<double> c(n_c), g(n_g);
  const double* pp = p.size() > 0 ? p.data() : nullptr;
  const auto eval = [&](double x1, double x2) {
    const std::array<double, 2> x{x1, x2};
    if (n_c > 0) f.c(x.data(), pp, c.data());
    if (n_g > 0) f.g(x.data(), pp, g.data());
  };
  try {
    // Values of every c and g on the grid.
    std::vector<Eigen::MatrixXd> cv(n_c, Eigen::MatrixXd(n_grid, n_grid));
    std::vector<Eigen::MatrixXd> gv(n_g, Eigen::MatrixXd(n_grid, n_grid));
    for (int i = 0; i < n_grid; ++i) {
      for (int j = 0; j < n_grid; ++j) {
        eval(xlo + (xhi - xlo) * i / (n_grid - 1), ylo + (yhi - ylo) * j / (n_grid - 1));
        for (std::size_t k = 0; k < n_c; ++k) cv[k](i, j) = c[k];
        for (std::size_t k = 0; k < n_g; ++k) gv[k](i, j) = g[k];
      }
    }
    const bool several = model.n_sys() > 1;
    int c_off = 0, g_off = 0;
    for (int k = 0; k < model.n_sys(); ++k) {
      const Subsystem& sub = model.dims().subsystems[static_cast<std::size_t>(k)];
      const std::string suffix = several ? fmt::format(" (subsys. {})", k) : "";
      for (int j = 0; j < sub.n_c; ++j) {
        std::vector<Segment> seg =
            zero_contour(cv[static_cast<std::size_t>(c_off + j)], xlo, xhi, ylo, yhi);
        if (!seg.empty()) out.emplace_back(fmt::format("c[{}] = 0{}", j, suffix), std::move(seg));
      }
      // g-form: the boundary of regions i and j is g_i = g_j where both are the smallest.
      for (int a = 0; a < sub.n_g; ++a) {
        for (int b = a + 1; b < sub.n_g; ++b) {
          const auto ia = static_cast<std::size_t>(g_off + a),
                     ib = static_cast<std::size_t>(g_off + b);
          std::vector<Segment> seg = zero_contour(gv[ia] - gv[ib], xlo, xhi, ylo, yhi);
          std::erase_if(seg, [&](const Segment& s) {
            eval(0.5 * (s.x0 + s.x1), 0.5 * (s.y0 + s.y1));
            const double both = std::min(g[ia], g[ib]);
            double others = INFINITY;
            for (int m = 0; m < sub.n_g; ++m)
              if (m != a && m != b)
                others = std::min(others, g[static_cast<std::size_t>(g_off + m)]);
            return !(both <= others + 1e-9 * (1 + std::abs(others)));
          });
          if (!seg.empty())
            out.emplace_back(fmt::format("g[{}] = g[{}]{}", a, b, suffix), std::move(seg));
        }
      }
      c_off += sub.n_c;
      g_off += sub.n_g;
    }
  } catch (const std::exception&) {
    return {};  // a function that cannot be evaluated: no surfaces, the rest of the plot stays
  }
  return out;
}

Surfaces switching_surfaces(const Pds& model, const Eigen::VectorXd& p, double xlo, double xhi,
                            double ylo, double yhi, int n_grid) {
  Surfaces out;
  if (model.n_x() != 2 || p.size() != model.n_p() || n_grid < 2) return out;
  const auto n_c = static_cast<std::size_t>(model.n_c());
  std::vector<Eigen::MatrixXd> values(n_c, Eigen::MatrixXd(n_grid, n_grid));
  std::vector<double> c(n_c);
  try {
    for (int i = 0; i < n_grid; ++i)
      for (int j = 0; j < n_grid; ++j) {
        const std::array<double, 2> x{xlo + (xhi - xlo) * i / (n_grid - 1),
                                      ylo + (yhi - ylo) * j / (n_grid - 1)};
        model.functions().c(x.data(), p.size() > 0 ? p.data() : nullptr, c.data());
        for (std::size_t k = 0; k < n_c; ++k) values[k](i, j) = c[k];
      }
  } catch (const std::exception&) {
    return {};  // a function that cannot be evaluated: no curves, the rest of the plot stays
  }
  for (std::size_t k = 0; k < n_c; ++k) {
    std::vector<Segment> seg = zero_contour(values[k], xlo, xhi, ylo, yhi);
    if (!seg.empty()) out.emplace_back(fmt::format("c[{}] = 0", k), std::move(seg));
  }
  return out;
}

std::string phase_portrait(const PlotModel& model, const PhaseData& d, double origin_x,
                           double origin_y, double width, double height, int canvas_w,
                           int canvas_h) {
  // The trajectory through the boundary and stage points, in time order.
  std::vector<std::tuple<double, double, double>> pts;
  const auto add = [&](const std::vector<double>& t, const std::vector<Eigen::VectorXd>& x) {
    for (std::size_t n = 0; n < std::min(t.size(), x.size()); ++n)
      if (x[n].size() >= 2 && std::isfinite(t[n]) && std::isfinite(x[n][0]) &&
          std::isfinite(x[n][1]))
        pts.emplace_back(t[n], x[n][0], x[n][1]);
  };
  add(d.t, d.x);
  add(d.t_stage, d.x_stage);
  std::stable_sort(pts.begin(), pts.end(),
                   [](const auto& a, const auto& b) { return std::get<0>(a) < std::get<0>(b); });

  double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY;
  for (const auto& [t, x1, x2] : pts) {
    xlo = std::min(xlo, x1);
    xhi = std::max(xhi, x1);
    ylo = std::min(ylo, x2);
    yhi = std::max(yhi, x2);
  }
  const auto pad = [](double& lo, double& hi) {
    if (!(hi >= lo)) {
      lo = -1;
      hi = 1;
      return;
    }
    double w = 0.1 * (hi - lo);
    if (!(w > 1e-12 * (1 + std::max(std::abs(lo), std::abs(hi)))))
      w = std::max(0.1 * std::max(std::abs(lo), std::abs(hi)), 1e-3);
    lo -= w;
    hi += w;
  };
  pad(xlo, xhi);
  pad(ylo, yhi);

  const std::vector<std::string> names = names_or_default(model.state_names, 2, "x");
  std::string s = "$phase << EOD\n";
  for (const auto& [t, x1, x2] : pts) s += number(x1) + ' ' + number(x2) + '\n';
  s += "EOD\n";

  // The sliding parts: the points inside sliding intervals, one line per interval.
  const std::vector<std::pair<double, double>> sliding =
      sliding_intervals(model, d.t, d.active_set);
  s += "$phase_sliding << EOD\n";
  bool any_sliding = false;
  for (const auto& [a, b] : sliding) {
    for (const auto& [t, x1, x2] : pts) {
      if (t >= a && t <= b) {
        s += number(x1) + ' ' + number(x2) + '\n';
        any_sliding = true;
      }
    }
    s += '\n';
  }
  s += "EOD\n";

  s += "$phase_switches << EOD\n";
  bool any_switch = false;
  for (const SwitchEvent& e : d.switches) {
    const auto n = static_cast<std::size_t>(e.element) + 1;
    if (e.element >= 0 && n < d.x.size() && d.x[n].size() >= 2) {
      s += number(d.x[n][0]) + ' ' + number(d.x[n][1]) + '\n';
      any_switch = true;
    }
  }
  s += "EOD\n";

  const Surfaces surfaces = model.surfaces(d.p, xlo, xhi, ylo, yhi, 161);
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    s += fmt::format("$surface{} << EOD\n", i);
    for (const Segment& g : surfaces[i].second)
      s += number(g.x0) + ' ' + number(g.y0) + '\n' + number(g.x1) + ' ' + number(g.y1) + "\n\n";
    s += "EOD\n";
  }

  // Geometry in pixels: a square plot at the top of the area, the x label below it, then the key
  // in two columns. The margins are set in screen coordinates, so gnuplot's own layout (which
  // overlaps a key below a square plot with the x label) is not used.
  const int entries = static_cast<int>(surfaces.size()) + (any_sliding ? 1 : 0) + 1 +
                      (any_switch ? 1 : 0) + (pts.empty() ? 0 : 2);
  const int key_rows = (entries + 1) / 2;
  const double area_w = width * canvas_w, area_h = height * canvas_h;
  const double left_px = 75, right_px = 25, top_px = 40, xlabel_px = 62, row_px = 17;
  const double side = std::max(
      50.0,
      std::min(area_w - left_px - right_px, area_h - top_px - xlabel_px - key_rows * row_px - 10));
  const double x_left = origin_x * canvas_w + left_px + 0.5 * (area_w - left_px - right_px - side);
  const double y_top = (origin_y + height) * canvas_h - top_px;
  const double y_bottom = y_top - side;
  s += "unset arrow\nunset object\nunset label\nunset logscale\nset autoscale\n";
  s += "set origin " + number(origin_x) + "," + number(origin_y) + "\nset size " + number(width) +
       "," + number(height) + "\n";
  s += fmt::format(
      "set lmargin at screen {}\nset rmargin at screen {}\nset tmargin at screen {}\n"
      "set bmargin at screen {}\n",
      number(x_left / canvas_w), number((x_left + side) / canvas_w), number(y_top / canvas_h),
      number(y_bottom / canvas_h));
  s += "set offsets 0, 0, 0, 0\nset format x\nset format y\n";
  s += "set xrange [" + number(xlo) + ":" + number(xhi) + "]\n";
  s += "set yrange [" + number(ylo) + ":" + number(yhi) + "]\n";
  s += "set xlabel " + gp_string(names[0]) + " noenhanced\nset ylabel " + gp_string(names[1]) +
       " noenhanced\n";
  s += "set title 'phase portrait' noenhanced\n";
  s += fmt::format(
      "set key at screen {}, screen {} left top vertical maxrows {} samplen 2 reverse Left "
      "noenhanced\n",
      number((x_left - 40) / canvas_w), number((y_bottom - xlabel_px) / canvas_h), key_rows);

  std::string plot = "plot ";
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    plot += fmt::format("$surface{} using 1:2 with lines linewidth 2 linecolor rgb '{}' title {}, ",
                        i, kSurfaceColors[i % kSurfaceColors.size()], gp_string(surfaces[i].first));
  }
  if (any_sliding)
    plot += fmt::format(
        "$phase_sliding using 1:2 with lines linewidth 7 linecolor rgb '{}' title '{}', ",
        kSlidingColor, model.shaded_name);
  plot += "$phase using 1:2 with lines linewidth 2 linecolor rgb '#1f77b4' title 'x(t)', ";
  if (any_switch)
    plot +=
        "$phase_switches using 1:2 with points pointtype 2 pointsize 1.5 linecolor rgb "
        "'#505050' title 'switches', ";
  if (!pts.empty()) {
    s += "$phase_ends << EOD\n" + number(std::get<1>(pts.front())) + ' ' +
         number(std::get<2>(pts.front())) + '\n' + number(std::get<1>(pts.back())) + ' ' +
         number(std::get<2>(pts.back())) + "\nEOD\n";
    plot +=
        "$phase_ends every ::0::0 using 1:2 with points pointtype 7 pointsize 1.3 linecolor "
        "rgb '#1f77b4' title 'start', $phase_ends every ::1::1 using 1:2 with points "
        "pointtype 5 pointsize 1.3 linecolor rgb '#1f77b4' title 'end'";
  } else {
    plot += "NaN notitle";
  }
  s += plot + "\nunset title\n";
  return s;
}

}  // namespace fesd::io_detail
