// src/io/describe.cpp: the model and problem as text for `fesd check` (describe.hpp).
#include "io/describe.hpp"

#include <cmath>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "io/ocp_expression_functions.hpp"
#include "model/expression_model.hpp"
#include "model/expression_pds.hpp"

namespace fesd::io_detail {
namespace {

/// Lines longer than this are split: a region's sign pattern on one line, its field below.
constexpr std::size_t kLineWidth = 100;
/// Column of the text after the label ("  label       text").
constexpr std::size_t kIndent = 14;

/// "  <label padded to 12> <text>\n"; a longer label gets one space.
std::string line(std::string_view label, std::string_view text) {
  return fmt::format("  {:<11} {}\n", label, text);
}

std::string continuation(std::string_view text) {
  return std::string(kIndent, ' ') + std::string(text) + "\n";
}

std::string join(const std::vector<std::string>& items, std::string_view sep) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += sep;
    out += items[i];
  }
  return out;
}

std::string state_name(const Pss& m, int i) {
  const auto k = static_cast<std::size_t>(i);
  return k < m.state_names.size() && !m.state_names[k].empty() ? m.state_names[k]
                                                               : fmt::format("x{}", i + 1);
}

/// "c[0] < 0, c[1] > 0": the sign pattern of row `row` of S.
std::string sign_pattern(const Eigen::MatrixXd& S, Eigen::Index row) {
  std::vector<std::string> parts;
  for (Eigen::Index j = 0; j < S.cols(); ++j)
    parts.push_back(fmt::format("c[{}] {} 0", j, S(row, j) > 0 ? ">" : "<"));
  return join(parts, ", ");
}

/// The region line(s): "region 3    c[0] > 0:  x1' = ..., x2' = ..." (or split when long).
std::string region_lines(const Pss& m, int region, const std::string& pattern,
                         const std::vector<expr::Expression>* field) {
  const std::string label = fmt::format("region {}", region);
  if (field == nullptr) return line(label, pattern + ":  (vector field given in C++)");
  std::vector<std::string> parts;
  for (std::size_t i = 0; i < field->size(); ++i)
    parts.push_back(
        fmt::format("{}' = {}", state_name(m, static_cast<int>(i)), (*field)[i].text()));
  const std::string one = pattern + ":  " + join(parts, ",  ");
  if (kIndent + one.size() <= kLineWidth) return line(label, one);
  std::string out = line(label, pattern + ":");
  for (const std::string& p : parts) out += continuation("  " + p);
  return out;
}

/// A hint text wrapped at kLineWidth under the label column.
std::string wrapped(std::string_view label, std::string_view text) {
  std::string out, current;
  std::size_t start = 0;
  bool first = true;
  auto flush = [&] {
    out += first ? line(label, current) : continuation(current);
    first = false;
    current.clear();
  };
  while (start < text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view word = text.substr(start, end - start);
    if (!current.empty() && kIndent + current.size() + 1 + word.size() > kLineWidth) flush();
    if (!current.empty()) current += ' ';
    current += word;
    start = end + 1;
  }
  if (!current.empty()) flush();
  return out;
}

std::string bounds(const Eigen::VectorXd& lb, const Eigen::VectorXd& ub, Eigen::Index i) {
  const double l = i < lb.size() ? lb[i] : -INFINITY, u = i < ub.size() ? ub[i] : INFINITY;
  if (l == u) return fmt::format("= {:g}", l);
  return fmt::format("in [{:g}, {:g}]", l, u);
}

}  // namespace

std::string describe_model(const Pss& m, bool has_clock) {
  const auto* expressions = dynamic_cast<const ExpressionModel*>(&m.functions());
  std::string s;
  if (m.n_u() > 0) {
    std::vector<std::string> names;
    for (int i = 0; i < m.n_u(); ++i) {
      const auto k = static_cast<std::size_t>(i);
      names.push_back(k < m.control_names.size() ? m.control_names[k] : fmt::format("u{}", i + 1));
    }
    s += line("controls", join(names, ", "));
  }
  if (has_clock)
    s += line("clock", fmt::format("{}' = 1 (the time t, appended to the states)",
                                   state_name(m, m.n_x() - 1)));

  const bool several = m.n_sys() > 1;
  int c_offset = 0, g_offset = 0;  // into the concatenated c and g expressions
  for (int k = 0; k < m.n_sys(); ++k) {
    const Subsystem& sub = m.dims().subsystems[static_cast<std::size_t>(k)];
    const int first = m.region_offset(k), last = m.region_offset(k + 1);  // [first, last)
    if (several) {
      s +=
          line(fmt::format("subsystem {}", k),
               fmt::format("regions {}..{}, {} {} function{}", first, last - 1,
                           sub.n_c > 0 ? sub.n_c : sub.n_g, sub.n_c > 0 ? "switching" : "indicator",
                           (sub.n_c > 0 ? sub.n_c : sub.n_g) == 1 ? "" : "s"));
    }
    const int n_fun = sub.n_c > 0 ? sub.n_c : sub.n_g;
    for (int j = 0; j < n_fun; ++j) {
      const std::string name = fmt::format("{}[{}]", sub.n_c > 0 ? "c" : "g", j);
      std::string text = "(given in C++)";
      if (expressions != nullptr) {
        const auto& list =
            sub.n_c > 0 ? expressions->c_expressions() : expressions->g_expressions();
        const auto at = static_cast<std::size_t>((sub.n_c > 0 ? c_offset : g_offset) + j);
        if (at < list.size()) text = list[at].text();
      }
      s += line(name, text);
    }
    for (int r = first; r < last; ++r) {
      const std::string pattern =
          sub.n_c > 0 ? sign_pattern(m.S(k), r - first)
                      : (sub.n_g == 2 ? fmt::format("g[{}] < g[{}]", r - first, 1 - (r - first))
                                      : fmt::format("g[{}] smallest", r - first));
      const std::vector<expr::Expression>* field =
          expressions != nullptr && static_cast<std::size_t>(r) < expressions->fields().size()
              ? &expressions->fields()[static_cast<std::size_t>(r)]
              : nullptr;
      s += region_lines(m, r, pattern, field);
    }
    c_offset += sub.n_c;
    g_offset += sub.n_g;
  }
  if (several) {
    s += wrapped("dynamics",
                 fmt::format("x' = the sum of one active region's field per subsystem (21a), e.g. "
                             "f_{} + f_{} in regions {} and {}",
                             m.region_offset(0), m.region_offset(1), m.region_offset(0),
                             m.region_offset(1)));
  }

  // nosnoc's F has one column per region, fesd's one row. With as many user states as regions in
  // a subsystem the transposed matrix has the same shape and passes every check.
  const int n_x_user = m.n_x() - (has_clock ? 1 : 0);
  for (int k = 0; k < m.n_sys(); ++k) {
    const int n_f = m.region_offset(k + 1) - m.region_offset(k);
    if (n_x_user >= 2 && n_f == n_x_user) {
      s += wrapped("hint",
                   fmt::format("F has one row per region (F[i] = the {} components of region i's "
                               "field); nosnoc's F has one column per region. With n_x = {} = "
                               "the number of regions{}, a transposed F passes every check: "
                               "compare the fields above with the sign patterns.",
                               n_x_user, n_x_user, several ? " of a subsystem" : ""));
      break;
    }
  }
  return s;
}

std::string describe_discretization(const DiscretizationOptions& d) {
  // (the step form is named, Stewart's default form is not)
  const std::string step = d.dcs_mode == DcsMode::Step
                               ? line("dcs",
                                      "dcs_mode = step (Heaviside step form: alpha per "
                                      "switching function, theta = theta(alpha))")
                               : "";
  if (!d.use_fesd) return step;
  return step + line("fesd", fmt::format("gamma_h = {:g}, rho_h = {:g}, stage_lambda_sign = {}, "
                                         "pin_sliding_exits = {}",
                                         d.gamma_h, d.rho_h, to_string(d.stage_lambda_sign),
                                         d.pin_sliding_exits ? 1 : 0));
}

std::string describe_ocp_functions(const OcpData& ocp) {
  const auto* f = dynamic_cast<const ExpressionOcpFunctions*>(ocp.functions.get());
  if (f == nullptr) return "";
  const OcpExpressions& e = f->expressions();
  std::string s;
  if (e.f_q) s += line("f_q", e.f_q->text());
  if (e.f_q_T) s += line("f_q_T", e.f_q_T->text());
  for (std::size_t i = 0; i < e.g_path.size(); ++i) {
    s += line(fmt::format("g_path[{}]", i),
              fmt::format("{} {}", e.g_path[i].text(),
                          bounds(ocp.lbg_path, ocp.ubg_path, static_cast<Eigen::Index>(i))));
  }
  for (std::size_t i = 0; i < e.g_terminal.size(); ++i) {
    s +=
        line(fmt::format("g_terminal[{}]", i),
             fmt::format("{} {}", e.g_terminal[i].text(),
                         bounds(ocp.lbg_terminal, ocp.ubg_terminal, static_cast<Eigen::Index>(i))));
  }
  // Complementarity pairs: a_1 .. a_n, then b_1 .. b_n; at the element boundaries, or (reading
  // theta, ...) at the RK stage points.
  for (const auto& [list, where] :
       {std::pair{&e.g_path_comp, "boundaries"}, std::pair{&e.g_rk_comp, "RK stage points"}}) {
    const std::size_t n = list->size() / 2;
    for (std::size_t i = 0; i < n; ++i)
      s += line("g_path_comp", fmt::format("0 <= {} perp {} >= 0 (at the {})", (*list)[i].text(),
                                           (*list)[n + i].text(), where));
  }
  return s;
}

namespace {
std::string describe_common(const Pss& model, bool has_clock, const DiscretizationOptions& d) {
  return describe_discretization(d) + "\nmodel as read (region i: row i of S and of F)\n" +
         describe_model(model, has_clock);
}
}  // namespace

std::string describe(const SimulationProblem& problem) {
  return describe_common(problem.model, problem.has_clock, problem.options.discretization);
}

std::string describe(const OcpProblem& problem) {
  const std::string functions = describe_ocp_functions(problem.ocp);
  return describe_common(problem.ocp.model, problem.has_clock, problem.options.discretization) +
         (functions.empty() ? "" : "\ncosts and constraints as read\n" + functions);
}

std::string describe_model(const Pds& m) {
  const PdsExpressionView e = expressions_of(m);
  auto name = [](const std::vector<std::string>& names, int i, const char* prefix) {
    const auto k = static_cast<std::size_t>(i);
    return k < names.size() && !names[k].empty() ? names[k] : fmt::format("{}{}", prefix, i + 1);
  };
  std::string s;
  if (m.n_u() > 0) {
    std::vector<std::string> names;
    for (int i = 0; i < m.n_u(); ++i) names.push_back(name(m.control_names, i, "u"));
    s += line("controls", join(names, ", "));
  }
  if (m.n_p() > 0) {
    std::vector<std::string> values;
    for (int i = 0; i < m.n_p(); ++i)
      values.push_back(fmt::format("{} = {:g}", name(m.parameter_names, i, "p"),
                                   i < m.p_default.size() ? m.p_default[i] : 0.0));
    s += line("parameters", join(values, ", "));
  }
  s += wrapped("dynamics",
               "x' = f(x, u, p) + grad c(x) lambda, 0 <= c(x) perp lambda >= 0 (the projection of "
               "f onto the tangent cone of C = {x : c(x) >= 0}, (3))");
  for (int k = 0; k < m.n_c(); ++k) {
    const auto at = static_cast<std::size_t>(k);
    const std::string text =
        e.c != nullptr && at < e.c->size() ? (*e.c)[at].text() : std::string("(given in C++)");
    s += line(fmt::format("c[{}]", k), text + " >= 0");
  }
  if (e.f == nullptr) return s + line("f", "(given in C++)");
  std::vector<std::string> parts;
  for (std::size_t i = 0; i < e.f->size(); ++i)
    parts.push_back(
        fmt::format("{}' = {}", name(m.state_names, static_cast<int>(i), "x"), (*e.f)[i].text()));
  const std::string one = join(parts, ",  ");
  if (kIndent + one.size() <= kLineWidth) return s + line("f", one);
  s += line("f", parts.front());
  for (std::size_t i = 1; i < parts.size(); ++i) s += continuation(parts[i]);
  return s;
}

std::string describe_discretization(const DiscretizationOptions& d, const PdsOptions& pds) {
  if (!d.use_fesd) return "";
  return line(
      "fesd",
      fmt::format("gamma_h = {:g}, step equilibration M = {:g}, h_penalty = {} (rho_h = "
                  "{:g}), cross_comp_mode = {}",
                  d.gamma_h, pds.M, pds.h_penalty ? 1 : 0, d.rho_h, to_string(d.cross_comp)));
}

std::string describe(const PdsSimulationProblem& problem) {
  return describe_discretization(problem.options.discretization, problem.pds) +
         "\nmodel as read\n" + describe_model(problem.model);
}

std::string describe(const PdsOcpProblem& problem) {
  const std::string functions = describe_ocp_functions(problem.ocp);
  return describe_discretization(problem.options.discretization, problem.ocp.pds) +
         "\nmodel as read\n" + describe_model(problem.ocp.model) +
         (functions.empty() ? "" : "\ncosts and constraints as read\n" + functions);
}

}  // namespace fesd::io_detail
