// The input rules of an optimal control problem (ocp_input.hpp). The ranges of the scalar options
// come from the option registry (src/core/option_registry.cpp); this file adds the rules about the
// problem's data and the per-interval numbers of finite elements.
#include "ocp/ocp_input.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "core/option_registry.hpp"
#include "discretization/pds_interval.hpp"
#include "fesd/error.hpp"
#include "ocp/ocp_checks.hpp"
#include "ocp/ocp_terms.hpp"

namespace fesd::ocp_detail {
namespace {

std::string numbers(Eigen::Index n) {
  return fmt::format("{} number{}", n, n == 1 ? "" : "s");
}

/// Length n (what: "one per state"); entries finite, or (allow_inf) anything but NaN.
bool check_vector(std::vector<std::string>& e, const Eigen::VectorXd& v, Eigen::Index n,
                  std::string_view path, std::string_view what, bool allow_inf) {
  if (v.size() != n) {
    e.push_back(fmt::format("{}: wrong length (expected {}, {}, got {})", path, numbers(n), what,
                            v.size()));
    return false;
  }
  bool ok = true;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (std::isnan(v[i]) || (!allow_inf && !std::isfinite(v[i]))) {
      e.push_back(
          fmt::format("{}[{}] = {}: must be {}", path, i, v[i],
                      allow_inf ? "a number (inf and -inf are allowed, nan is not)" : "finite"));
      ok = false;
    }
  return ok;
}

/// Bounds [lb, ub] of the [ocp] keys lb_key/ub_key: empty = unbounded; else n entries, no NaN,
/// lb <= ub. True if both are usable entry by entry.
bool check_bounds(std::vector<std::string>& e, const Eigen::VectorXd& lb, const Eigen::VectorXd& ub,
                  Eigen::Index n, std::string_view lb_key, std::string_view ub_key,
                  std::string_view what) {
  const bool lb_ok =
      lb.size() == 0 || check_vector(e, lb, n, fmt::format("ocp.{}", lb_key), what, true);
  const bool ub_ok =
      ub.size() == 0 || check_vector(e, ub, n, fmt::format("ocp.{}", ub_key), what, true);
  if (!lb_ok || !ub_ok) return false;
  if (lb.size() == 0 || ub.size() == 0) return true;
  for (Eigen::Index i = 0; i < n; ++i)
    if (lb[i] > ub[i])
      e.push_back(fmt::format("ocp.{}[{}] = {} > ocp.{}[{}] = {}: empty bounds (expected {} <= {})",
                              lb_key, i, lb[i], ub_key, i, ub[i], lb_key, ub_key));
  return true;
}

/// v[i] within [lb[i], ub[i]] (bounds checked before; empty = unbounded).
void check_within(std::vector<std::string>& e, const Eigen::VectorXd& v, const Eigen::VectorXd& lb,
                  const Eigen::VectorXd& ub, std::string_view path, std::string_view bounds,
                  std::string_view why) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    const double l = lb.size() > 0 ? lb[i] : -INFINITY, u = ub.size() > 0 ? ub[i] : INFINITY;
    if (v[i] < l || v[i] > u)
      e.push_back(fmt::format("{}[{}]: {} is outside [{}] = [{}, {}] ({})", path, i, v[i], bounds,
                              l, u, why));
  }
}

std::string list_of_ints(const std::vector<int>& v) {
  std::string s;
  for (int i : v) s += fmt::format("{}{}", s.empty() ? "" : ", ", i);
  return "[" + s + "]";
}

/// Ocp::N_FE: one number of finite elements per control interval, each within the range and
/// rule of [discretization] N_finite_elements.
void check_N_FE_list(std::vector<std::string>& e, const OcpData& ocp, const OcpOptions& o) {
  if (ocp.N_FE.empty()) return;
  const registry::Option& option =
      *registry::find(registry::Table::Discretization, "N_finite_elements");
  const std::string path = registry::path_of(option);
  if (static_cast<int>(ocp.N_FE.size()) != ocp.N_stages)
    e.push_back(fmt::format(
        "{} = {}: wrong length (expected {} {}, one per control interval (N_stages = {}), or one "
        "integer for all intervals)",
        path, list_of_ints(ocp.N_FE), ocp.N_stages, ocp.N_stages == 1 ? "entry" : "entries",
        ocp.N_stages));
  const registry::OptionTarget target = registry::target_of(o);
  for (std::size_t k = 0; k < ocp.N_FE.size(); ++k) {
    std::string m = registry::check(option, target, ocp.N_FE[k], fmt::format("{}[{}]", path, k));
    if (!m.empty()) e.push_back(std::move(m));
  }
}

/// The sizes of the model the data must fit.
struct ModelSizes {
  int n_x, n_u, n_p;
  const Eigen::VectorXd& p_default;
};

void check_data(std::vector<std::string>& e, const OcpData& ocp, const ModelSizes& m) {
  if (m.n_x < 1) {
    e.push_back("ocp.model: empty (n_x = 0)");
    return;
  }
  const Eigen::Index n_x = m.n_x, n_u = m.n_u;
  const bool x0_ok = check_vector(e, ocp.x0, n_x, "model.x0", "one per state", false);
  if ((ocp.lbx0.size() > 0) != (ocp.ubx0.size() > 0))
    e.push_back("ocp.lbx0, ocp.ubx0: give both (x0 free) or neither (x0 fixed)");
  const bool x0_bounds_ok =
      check_bounds(e, ocp.lbx0, ocp.ubx0, n_x, "lbx0", "ubx0", "one per state");
  check_bounds(e, ocp.lbx, ocp.ubx, n_x, "lbx", "ubx", "one per state");
  const bool u_bounds_ok = check_bounds(e, ocp.lbu, ocp.ubu, n_u, "lbu", "ubu", "one per control");
  if (ocp.u_guess.size() > 0 &&
      check_vector(e, ocp.u_guess, n_u, "ocp.u_guess", "one per control", false) && u_bounds_ok)
    check_within(e, ocp.u_guess, ocp.lbu, ocp.ubu, "ocp.u_guess", "lbu, ubu",
                 "expected a guess within the control bounds");
  if (x0_ok && x0_bounds_ok && ocp.lbx0.size() > 0)
    check_within(e, ocp.x0, ocp.lbx0, ocp.ubx0, "model.x0", "lbx0, ubx0",
                 "with lbx0/ubx0, model.x0 is the guess of the free initial state and must "
                 "satisfy its bounds");
  check_vector(e, ocp.p.size() > 0 ? ocp.p : m.p_default, m.n_p, "model.p", "one per parameter",
               false);
  // Per control interval / control grid point: N_stages (+ 1) vectors.
  const auto check_rows = [&](const std::vector<Eigen::VectorXd>& rows, int expected,
                              std::string_view path, std::string_view rows_what, Eigen::Index n,
                              std::string_view what, auto&& each) {
    if (rows.empty()) return;
    if (static_cast<int>(rows.size()) != expected) {
      e.push_back(
          fmt::format("{}: {} rows, expected {} ({})", path, rows.size(), expected, rows_what));
      return;
    }
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const std::string row = fmt::format("{}[{}]", path, k);
      if (check_vector(e, rows[k], n, row, what, false)) each(rows[k], row);
    }
  };
  const auto nothing = [](const Eigen::VectorXd&, const std::string&) {};
  check_rows(ocp.p_stage, ocp.N_stages, "ocp.p_stage", "one per control interval (N_stages)", m.n_p,
             "one per parameter", nothing);
  check_rows(ocp.u_guess_stage, ocp.N_stages, "ocp.u_guess", "one per control interval (N_stages)",
             n_u, "one per control", [&](const Eigen::VectorXd& v, const std::string& row) {
               if (u_bounds_ok)
                 check_within(e, v, ocp.lbu, ocp.ubu, row, "lbu, ubu",
                              "expected a guess within the control bounds");
             });
  check_rows(ocp.x_guess, ocp.N_stages + 1, "ocp.x_guess",
             "one per control grid point t_k = k T / N_stages, k = 0..N_stages", n_x,
             "one per state", nothing);
  // Global variables: distinct parameters, bounds, the parameter's value (their guess) within.
  const Eigen::VectorXd& p = ocp.p.size() > 0 ? ocp.p : m.p_default;
  for (std::size_t i = 0; i < ocp.v_global.size(); ++i) {
    const GlobalVariable& v = ocp.v_global[i];
    const std::string path = fmt::format("ocp.v_global[{}]", i);
    if (v.index < 0 || v.index >= m.n_p) {
      e.push_back(
          fmt::format("{}.index = {}: not a parameter of the model (expected 0 <= index < "
                      "n_p = {})",
                      path, v.index, m.n_p));
      continue;
    }
    for (std::size_t j = 0; j < i; ++j)
      if (ocp.v_global[j].index == v.index)
        e.push_back(
            fmt::format("{}: parameter {} is already global variable {} (expected each "
                        "parameter once)",
                        path, v.index, j));
    if (std::isnan(v.lb) || std::isnan(v.ub) || v.lb > v.ub) {
      e.push_back(fmt::format("{}: bounds [lb, ub] = [{}, {}] are empty or NaN (expected lb <= ub)",
                              path, v.lb, v.ub));
      continue;
    }
    const double guess = ocp.p_stage.empty() || ocp.p_stage.front().size() != m.n_p
                             ? (p.size() == m.n_p ? p[v.index] : 0.0)
                             : ocp.p_stage.front()[v.index];
    if (guess < v.lb || guess > v.ub)
      e.push_back(
          fmt::format("{}: its guess {} (the parameter's value) is outside [lb, ub] = [{}, "
                      "{}]",
                      path, guess, v.lb, v.ub));
  }
  if (ocp.n_g_path_comp < 0)
    e.push_back(fmt::format("ocp.n_g_path_comp = {}: must be >= 0", ocp.n_g_path_comp));
  if (ocp.n_g_path_comp > 0 && !ocp.functions)
    e.push_back(
        "ocp.functions: none, but path complementarity pairs are declared (n_g_path_comp "
        "> 0)");
  if (ocp.n_g_rk_comp < 0)
    e.push_back(fmt::format("ocp.n_g_rk_comp = {}: must be >= 0", ocp.n_g_rk_comp));
  if (ocp.n_g_rk_comp > 0 && !ocp.functions)
    e.push_back(
        "ocp.functions: none, but stage complementarity pairs are declared (n_g_rk_comp > 0)");
  if (ocp.n_g_path < 0) e.push_back(fmt::format("ocp.n_g_path = {}: must be >= 0", ocp.n_g_path));
  if (ocp.n_g_terminal < 0)
    e.push_back(fmt::format("ocp.n_g_terminal = {}: must be >= 0", ocp.n_g_terminal));
  if ((ocp.n_g_path > 0 || ocp.n_g_terminal > 0) && !ocp.functions)
    e.push_back("ocp.functions: none, but constraints are declared (n_g_path / n_g_terminal > 0)");
  check_bounds(e, ocp.lbg_path, ocp.ubg_path, std::max(ocp.n_g_path, 0), "lbg_path", "ubg_path",
               "one per path constraint");
  check_bounds(e, ocp.lbg_terminal, ocp.ubg_terminal, std::max(ocp.n_g_terminal, 0), "lbg_terminal",
               "ubg_terminal", "one per terminal constraint");
}

/// The rules of time freezing and of the speed of time's extras (rho_sot, T_final bounds) that
/// are not a range of one option.
void check_time_freezing(std::vector<std::string>& e, const OcpData& ocp, int n_x) {
  constexpr double kNoBound = std::numeric_limits<double>::infinity();
  if (ocp.time_freezing) {
    if (ocp.clock_state < 0)
      e.push_back(
          "ocp.time_freezing = true: needs clock_state (the state that reads the physical time)");
    else if (ocp.clock_state >= n_x)
      e.push_back(fmt::format("ocp.clock_state = {}: out of range (the model has {} state{})",
                              ocp.clock_state, n_x, n_x == 1 ? "" : "s"));
    if (ocp.time_optimal_problem)
      e.push_back(
          "ocp.time_freezing = true: not supported with time_optimal_problem yet (time freezing "
          "fixes the physical horizon to T)");
  }
  if (!ocp.use_speed_of_time_variables && !ocp.time_freezing)
    e.push_back(
        "ocp.use_speed_of_time_variables = false: used only with time_freezing (a time-optimal "
        "problem needs its speed of time)");
  if (!ocp.time_freezing && ocp.clock_state != -1) {
    e.push_back(fmt::format("ocp.clock_state = {}: given but used only with time_freezing = true",
                            ocp.clock_state));
  }
  if (std::isnan(ocp.T_final_min) || ocp.T_final_min < 0 || !std::isfinite(ocp.T_final_min))
    e.push_back(fmt::format("ocp.T_final_min = {}: must be finite and >= 0", ocp.T_final_min));
  if (std::isnan(ocp.T_final_max) || ocp.T_final_max <= 0)
    e.push_back(fmt::format("ocp.T_final_max = {}: must be > 0 (inf: no bound)", ocp.T_final_max));
  if (!ocp.time_optimal_problem && (ocp.T_final_min != 0 || ocp.T_final_max != kNoBound))
    e.push_back(fmt::format("ocp.{} = {}: given but used only with time_optimal_problem",
                            ocp.T_final_min != 0 ? "T_final_min" : "T_final_max",
                            ocp.T_final_min != 0 ? ocp.T_final_min : ocp.T_final_max));
  if (!(ocp.T_final_min <= ocp.T_final_max))
    e.push_back(fmt::format("ocp.T_final_min = {} > ocp.T_final_max = {}: empty bounds",
                            ocp.T_final_min, ocp.T_final_max));
  if (!ocp.time_optimal_problem && !(ocp.time_freezing && ocp.use_speed_of_time_variables) &&
      ocp.rho_sot != 0)
    e.push_back(fmt::format(
        "ocp.rho_sot = {}: given but used only with a speed of time (time_optimal_problem, or "
        "time_freezing with use_speed_of_time_variables)",
        ocp.rho_sot));
}

/// The rules common to both kinds of OCP; `data_rules` adds the model's own when the rest holds.
template <class Problem, class DataRules>
OcpInputErrors check_common(const Problem& ocp, const OcpOptions& options, const ModelSizes& sizes,
                            const DataRules& data_rules) {
  OcpInputErrors e;
  registry::OptionTarget target = registry::target_of(options);
  target.ocp = const_cast<Problem*>(&ocp);  // read only
  e.options = registry::check(registry::Table::Ocp, target);
  check_N_FE_list(e.options, ocp, options);
  for (std::string& s : validate(options)) e.options.push_back(std::move(s));
  if (e.options.empty())  // the smallest control interval, docs/problem-files.md "Limits"
    if (std::string s = step_length_error(ocp); !s.empty()) e.options.push_back(std::move(s));
  check_data(e.data, ocp, sizes);
  const bool external = options.initialization == OcpInitialization::External;
  if (external && ocp.x_guess.empty())
    e.options.push_back(
        "ocp.initialization = external: needs x_guess (the states at the control grid points)");
  check_time_freezing(e.options, ocp, sizes.n_x);
  if ((ocp.time_optimal_problem || ocp.time_freezing) && ocp.s_sot_min > 0 &&
      !(ocp.s_sot_min <= ocp.s_sot0 && ocp.s_sot0 <= ocp.s_sot_max))
    e.options.push_back(fmt::format(
        "ocp.s_sot0 = {}: the guess of the speed of time must lie within [s_sot_min, s_sot_max] "
        "= [{}, {}]",
        ocp.s_sot0, ocp.s_sot_min, ocp.s_sot_max));
  if (!external && !ocp.x_guess.empty())
    e.options.push_back(
        fmt::format("ocp.initialization = {}: x_guess is given but used only with initialization = "
                    "external",
                    to_string(options.initialization)));
  if (e.options.empty() && e.data.empty()) data_rules(e);
  return e;
}

template <class Problem>
void require(const Problem& ocp, const OcpOptions& options) {
  const OcpInputErrors e = check_input(ocp, options);
  if (!e.options.empty()) throw InvalidOption(registry::join(e.options));
  if (!e.data.empty()) throw InvalidModel(registry::join(e.data));
}

}  // namespace

OcpInputErrors check_input(const Ocp& ocp, const OcpOptions& options) {
  const Pss& m = ocp.model;
  return check_common(ocp, options, {m.n_x(), m.n_u(), m.n_p(), m.p_default},
                      [&](OcpInputErrors& e) {  // the limits of the NLP's blocks
                        e.data = block_size_errors(ocp, options);
                      });
}

OcpInputErrors check_input(const PdsOcp& ocp, const OcpOptions& options) {
  const Pds& m = ocp.model;
  return check_common(
      ocp, options, {m.n_x(), m.n_u(), m.n_p(), m.p_default}, [&](OcpInputErrors& e) {
        const DiscretizationOptions& d = options.discretization;
        for (std::string& s :
             discretization::PdsInterval::errors(make_tableau(d.rk_scheme, d.n_s), d, ocp.pds))
          e.options.push_back(std::move(s));
        // Per-interval data of piecewise smooth OCPs that projected ones do not use yet.
        for (const auto& [given, key] :
             {std::pair{!ocp.p_stage.empty(), "p_time_var (ocp.p_stage)"},
              std::pair{!ocp.u_guess_stage.empty(), "u_guess per control interval"},
              std::pair{options.initialization == OcpInitialization::External,
                        "initialization = external (x_guess)"},
              std::pair{ocp.time_optimal_problem, "time_optimal_problem"},
              std::pair{ocp.time_freezing, "time_freezing"},
              std::pair{ocp.n_g_path_comp > 0, "g_path_comp (path complementarity)"},
              std::pair{ocp.n_g_rk_comp > 0,
                        "g_path_comp reading theta (stage complementarity, n_g_rk_comp)"}})
          if (given)
            e.options.push_back(fmt::format("ocp.{}: not supported for projected models yet", key));
        if (!ocp.N_FE.empty() && d.use_fesd)
          for (std::size_t k = 0; k < ocp.N_FE.size(); ++k)
            if (ocp.N_FE[k] < 2)
              e.options.push_back(fmt::format(
                  "discretization.N_finite_elements[{}] = {}: FESD needs >= 2", k, ocp.N_FE[k]));
        e.data = cost_block_size_errors(ocp, m.n_x(), m.n_u(), m.n_p(), d.n_s);
        // x0 in C (a fixed x0; a free one is only the guess)
        const Eigen::VectorXd p = ocp.p.size() > 0 ? ocp.p : m.p_default;
        if (ocp.lbx0.size() > 0 || !e.data.empty()) return;
        Eigen::VectorXd c(m.n_c());
        m.functions().c(ocp.x0.data(), p.data(), c.data());
        for (int k = 0; k < m.n_c(); ++k)
          if (!std::isfinite(c[k]) || c[k] < -m.x0_tol)
            e.data.push_back(
                fmt::format("model.x0 lies outside C = {{x : c(x) >= 0}}: constraints[{}](x0) = "
                            "{:.6g} < -x0_tol "
                            "= {:.3g}",
                            k, c[k], -m.x0_tol));
      });
}

void require_valid_input(const Ocp& ocp, const OcpOptions& options) {
  require(ocp, options);
}
void require_valid_input(const PdsOcp& ocp, const OcpOptions& options) {
  require(ocp, options);
}

}  // namespace fesd::ocp_detail

namespace fesd {

std::vector<std::string> warnings(const Ocp& ocp) {
  const Pss& m = ocp.model;
  const int c = ocp.clock_state;
  // (Models with algebraic variables z: their fields read z, which has no value here.)
  if (!ocp.time_freezing || c < 0 || c >= m.n_x() || m.n_z() > 0 || ocp.x0.size() != m.n_x())
    return {};
  if (ocp.N_stages < 1) return {};
  const Eigen::VectorXd p = ocp_detail::stage_parameters(ocp, m.p_default).front();
  // The first interval's control guess, inside the control bounds (where IPOPT moves it).
  Eigen::VectorXd u = ocp_detail::control_guess(ocp, 0, m.n_u());
  if (p.size() != m.n_p() || u.size() != m.n_u()) return {};
  for (Eigen::Index i = 0; i < u.size(); ++i) {
    if (i < ocp.lbu.size()) u[i] = std::max(u[i], ocp.lbu[i]);
    if (i < ocp.ubu.size()) u[i] = std::min(u[i], ocp.ubu[i]);
  }
  // The clock's rate in every region of every subsystem: if it differs between two regions of
  // one subsystem, that subsystem's theta changes it (freezes it, as time freezing means to).
  Eigen::VectorXd f(m.n_x());
  double rate = 0;
  for (int k = 0; k < m.n_sys(); ++k) {
    const int first = m.region_offset(k), n_f = m.dims().subsystems[k].n_f();
    double first_rate = 0;
    for (int r = first; r < first + n_f; ++r) {
      m.functions().f(r, ocp.x0.data(), u.data(), p.data(), f.data());
      if (!std::isfinite(f[c])) return {};
      if (r == first)
        first_rate = f[c];
      else if (std::abs(f[c] - first_rate) > 1e-12 * std::max(1.0, std::abs(first_rate)))
        return {};
    }
    rate += first_rate;
  }
  const std::string name =
      c < static_cast<int>(m.state_names.size()) ? m.state_names[c] : fmt::format("x{}", c + 1);
  return {fmt::format(
      "time_freezing: the clock state {} has the same rate ({:g} at x0 and the first control "
      "guess within its bounds) in every region, so no region freezes it; the clock constraints "
      "then fix that rate on every control interval, which can leave the NLP without interior "
      "(nosnoc_py's discs, docs/nosnoc-examples.md row 22)",
      name, rate)};
}

}  // namespace fesd
