// src/io/json_csv.cpp: integrator and OCP results as JSON (every field of IntegratorResult /
// OcpResult) and as CSV (the states at the finite-element boundaries, for OCPs with the controls).
// See include/fesd/io.hpp.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fesd/error.hpp"
#include "fesd/io.hpp"

namespace fesd {
namespace {

// ordered_json keeps the keys in the documented order.
using json = nlohmann::ordered_json;

// Non-finite numbers have no JSON spelling: they become null.
json number(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

json array(const std::vector<double>& v) {
  json a = json::array();
  for (double d : v) a.push_back(number(d));
  return a;
}

json array(const Eigen::VectorXd& v) {
  json a = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(number(v[i]));
  return a;
}

// One row per entry (one row per time point or stage point).
json rows(const std::vector<Eigen::VectorXd>& v) {
  json a = json::array();
  for (const Eigen::VectorXd& row : v) a.push_back(array(row));
  return a;
}

json stats(const Summary& s) {
  return json{{"homotopy_steps", s.homotopy_steps},
              {"nlp_iterations", s.nlp_iterations},
              {"wall_s", number(s.wall_s)},
              {"derivative_s", number(s.derivative_s)},
              {"solver_s", number(s.solver_s)},
              {"setup_s", number(s.setup_s)},
              {"n_variables", s.n_variables},
              {"n_constraints", s.n_constraints},
              {"max_comp_residual", number(s.max_comp_residual)},
              {"fallback_steps", s.fallback_steps},
              {"refined_steps", s.refined_steps},
              {"split_steps", s.split_steps},
              {"active_set_solves", s.active_set_solves},
              {"active_set_failures", s.active_set_failures},
              {"rescued_steps", s.rescued_steps},
              {"active_set_path_steps", s.active_set_path_steps},
              {"homotopy_path_steps", s.homotopy_path_steps},
              {"newton_iterations", s.newton_iterations},
              {"newton_factorizations", s.newton_factorizations},
              {"active_set_tries", s.active_set_tries},
              {"active_set_s", number(s.active_set_s)},
              {"pinned_exits", s.pinned_exits},
              {"pin_failures", s.pin_failures},
              {"grid_moves", s.grid_moves},
              {"born_switches", s.born_switches},
              {"allocation_solves", s.allocation_solves},
              {"allocation_moves", s.allocation_moves},
              {"held_switches", s.held_switches},
              {"warnings", s.warnings}};
}

json accuracy(const Accuracy& a) {
  json runs = json::array();
  for (const AccuracyRun& r : a.runs) {
    runs.push_back(json{{"N_sim", r.N_sim},
                        {"status", std::string(to_string(r.status))},
                        {"x_final", array(r.x_final)},
                        {"switch_times", array(r.switch_times)},
                        {"error_estimate", number(r.error_estimate)},
                        {"wall_s", number(r.wall_s)}});
  }
  return json{{"N_sim", a.N_sim},
              {"tol_sim", number(a.tol_sim)},
              {"met", a.met},
              {"order", a.order},
              {"consistent", a.consistent},
              {"switch_times_consistent", a.switch_times_consistent},
              {"noise_floor", number(a.noise_floor)},
              {"at_noise_floor", a.at_noise_floor},
              {"note", a.note},
              {"runs", std::move(runs)}};
}

json switches(const std::vector<SwitchEvent>& events) {
  json a = json::array();
  for (const SwitchEvent& e : events) {
    a.push_back(json{{"t", number(e.t)},
                     {"element", e.element},
                     {"before", e.before},
                     {"after", e.after},
                     {"located", e.located}});
  }
  return a;
}

/// The matrix as rows (row-major nested arrays).
json matrix(const Eigen::MatrixXd& m) {
  json out = json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    out.push_back(array(Eigen::VectorXd(m.row(i).transpose())));
  return out;
}

json sensitivities(const Sensitivities& s) {
  json j;
  j["available"] = s.available;
  j["message"] = s.message;
  j["x0"] = matrix(s.x0);
  j["u"] = matrix(s.u);
  j["p"] = matrix(s.p);
  return j;
}

json homotopy_row(const HomotopyRow& r) {
  return json{{"k", r.k},
              {"sigma", number(r.sigma)},
              {"comp_residual", number(r.comp_residual)},
              {"objective", number(r.objective)},
              {"inf_pr", number(r.inf_pr)},
              {"nlp_iterations", r.nlp_iterations},
              {"nlp_status", r.nlp_status},
              {"cpu_s", number(r.cpu_s)},
              {"wall_s", number(r.wall_s)},
              {"linear_solver", r.linear_solver},
              {"factor_s", number(r.factor_s)},
              {"factorizations", r.factorizations},
              {"active_set_fixed", r.active_set_fixed},
              {"pinned_exits", r.pinned_exits},
              {"retried", r.retried},
              {"restarted", r.restarted},
              {"stalled", r.stalled},
              {"cold_start", r.cold_start}};
}

json homotopy(const std::vector<std::vector<HomotopyRow>>& steps) {
  json a = json::array();
  for (const std::vector<HomotopyRow>& step : steps) {
    json rows_of_step = json::array();
    for (const HomotopyRow& r : step) rows_of_step.push_back(homotopy_row(r));
    a.push_back(std::move(rows_of_step));
  }
  return a;
}

// RFC 4180 quoting, needed only if a state name contains a comma, a quote or a line break.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"') out += '"';
    out += ch;
  }
  out += '"';
  return out;
}

void append_number(std::string& out, double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  out += buf;
}

std::string compact(const json& j) {
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

bool is_container(const json& j) {
  return j.is_array() || j.is_object();
}

// Readable without being huge: the top-level keys one per line, arrays of arrays or objects one
// element per line (a row of x, a homotopy row), everything else on one line. Invalid UTF-8 in
// messages and names is replaced instead of throwing.
void pretty(const json& j, int depth, std::string& out) {
  const std::string pad(static_cast<std::size_t>(2 * (depth + 1)), ' ');
  const std::string close_pad(static_cast<std::size_t>(2 * depth), ' ');
  if (j.is_object() && depth == 0 && !j.empty()) {
    out += "{\n";
    bool first = true;
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (!first) out += ",\n";
      first = false;
      out += pad;
      out += compact(json(it.key()));
      out += ": ";
      pretty(it.value(), depth + 1, out);
    }
    out += "\n";
    out += close_pad;
    out += '}';
  } else if (j.is_array() && !j.empty() &&
             std::all_of(j.begin(), j.end(), [](const json& e) { return is_container(e); })) {
    out += "[\n";
    bool first = true;
    for (const json& e : j) {
      if (!first) out += ",\n";
      first = false;
      out += pad;
      pretty(e, depth + 1, out);
    }
    out += "\n";
    out += close_pad;
    out += ']';
  } else {
    out += compact(j);
  }
}

/// `given[i]` where present and non-empty, else prefix + (i + 1). n: the length of the first row
/// of `rows` if any, else `n_default`.
std::vector<std::string> names_of(const std::vector<std::string>& given,
                                  const std::vector<Eigen::VectorXd>& rows, int n_default,
                                  char prefix) {
  std::size_t n = static_cast<std::size_t>(n_default);
  if (!rows.empty()) n = static_cast<std::size_t>(rows.front().size());
  std::vector<std::string> names(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i < given.size() && !given[i].empty()) {
      names[i] = given[i];
    } else {
      names[i] = prefix + std::to_string(i + 1);
    }
  }
  return names;
}

template <class Model>
std::vector<std::string> state_names_of(const IntegratorResult& result, const Model& model) {
  return names_of(model.state_names, result.x, model.n_x(), 'x');
}

void write_output_file(const std::string& path, const std::string& content) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) throw IoError("cannot write '" + path + "': " + std::strerror(errno));
  const std::size_t written = std::fwrite(content.data(), 1, content.size(), f);
  const int write_errno = errno;
  const bool failed = written != content.size() || std::ferror(f) != 0;
  if (std::fclose(f) != 0 || failed) {
    const int e = failed ? write_errno : errno;
    throw IoError("cannot write '" + path + "': " + std::strerror(e != 0 ? e : EIO));
  }
}

}  // namespace

// The writers need only the model's names and sizes: one template for Pss and Pds.
template <class Model>
void json_of_simulation(const IntegratorResult& result, const Model& model,
                        const std::string& path) {
  json j;
  j["status"] = std::string(to_string(result.status));
  j["message"] = result.message;
  j["t"] = array(result.t);
  j["x"] = rows(result.x);
  j["h"] = array(result.h);
  j["switch_times"] = array(result.switch_times());
  j["x_final"] = array(result.x_final());
  j["error_estimate"] = number(result.accuracy.error_estimate);
  j["switch_time_estimate"] = number(result.accuracy.switch_time_estimate);
  j["accuracy"] = accuracy(result.accuracy);
  j["stats"] = stats(result.summary);
  j["t_stage"] = array(result.t_stage);
  j["x_stage"] = rows(result.x_stage);
  j["theta"] = rows(result.theta);
  j["lambda"] = rows(result.lambda);
  j["mu"] = rows(result.mu);
  if (!result.alpha.empty()) {  // the Heaviside step form (dcs_mode = step)
    j["alpha"] = rows(result.alpha);
    j["lambda_p"] = rows(result.lambda_p);
    j["lambda_n"] = rows(result.lambda_n);
  }
  if (!result.z.empty()) {  // algebraic variables z at the stage points
    j["z"] = rows(result.z);
    if constexpr (requires { model.algebraic_names; }) j["algebraic_names"] = model.algebraic_names;
  }
  j["active_set"] = result.active_set;
  j["switches"] = switches(result.switches);
  j["homotopy"] = homotopy(result.homotopy);
  j["step_path"] = json::array();
  for (StepSolver s : result.step_path) j["step_path"].push_back(std::string(to_string(s)));
  j["state_names"] = state_names_of(result, model);
  if (result.sensitivities.requested) j["sensitivities"] = sensitivities(result.sensitivities);
  std::string text;
  pretty(j, 0, text);
  text += '\n';
  write_output_file(path, text);
}

namespace {

/// ",name1,name2,..." (CSV-quoted where needed).
void append_csv_names(std::string& out, const std::vector<std::string>& names) {
  for (const std::string& name : names) {
    out += ',';
    out += csv_field(name);
  }
}

/// "t,x_1,...,x_n" of one CSV row, without the line end.
void append_csv_state_row(std::string& out, double t, const Eigen::VectorXd& x) {
  append_number(out, t);
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    out += ',';
    append_number(out, x[i]);
  }
}

}  // namespace

template <class Model>
void csv_of_simulation(const IntegratorResult& result, const Model& model,
                       const std::string& path) {
  const std::vector<std::string> names = state_names_of(result, model);
  std::string out = "t";
  append_csv_names(out, names);
  out += "\n";
  const std::size_t n_rows = std::min(result.t.size(), result.x.size());
  for (std::size_t n = 0; n < n_rows; ++n) {
    append_csv_state_row(out, result.t[n], result.x[n]);
    out += '\n';
  }
  write_output_file(path, out);
}

template <class Model>
void json_of_ocp(const OcpResult& result, const Model& model, const std::string& path) {
  json j;
  j["status"] = std::string(to_string(result.status));
  j["message"] = result.message;
  j["objective"] = number(result.objective);
  j["t"] = array(result.t);
  j["x"] = rows(result.x);
  j["t_ctrl"] = array(result.t_ctrl);
  j["u"] = rows(result.u);
  j["h"] = array(result.h);
  j["interval"] = result.interval;
  j["eta"] = array(result.eta);
  json switch_times = json::array();
  for (const SwitchEvent& e : result.switches) switch_times.push_back(number(e.t));
  j["switch_times"] = std::move(switch_times);
  j["x0"] = array(result.x0());
  j["x_final"] = array(result.x_final());
  j["T_final"] = number(result.T_final);
  if (!result.s_sot.empty()) j["s_sot"] = array(result.s_sot);
  if (result.v_global.size() > 0) {
    json v;
    for (Eigen::Index i = 0; i < result.v_global.size(); ++i)
      v[result.v_global_names[static_cast<std::size_t>(i)]] = number(result.v_global[i]);
    j["v_global"] = std::move(v);
  }
  json homotopy_rows = json::array();
  for (const HomotopyRow& r : result.homotopy) homotopy_rows.push_back(homotopy_row(r));
  j["homotopy"] = std::move(homotopy_rows);
  json st = stats(result.summary);
  st["comp_residual"] = number(result.comp_residual);
  st["mpcc_mode"] = std::string(to_string(result.mpcc_mode));
  j["stats"] = std::move(st);
  j["t_stage"] = array(result.t_stage);
  j["x_stage"] = rows(result.x_stage);
  j["theta"] = rows(result.theta);
  j["lambda"] = rows(result.lambda);
  if (!result.alpha.empty()) {  // the Heaviside step form (dcs_mode = step)
    j["alpha"] = rows(result.alpha);
    j["lambda_p"] = rows(result.lambda_p);
    j["lambda_n"] = rows(result.lambda_n);
  }
  if (!result.z.empty()) {  // algebraic variables z at the stage points
    j["z"] = rows(result.z);
    if constexpr (requires { model.algebraic_names; }) j["algebraic_names"] = model.algebraic_names;
  }
  j["active_set"] = result.active_set;
  j["switches"] = switches(result.switches);
  j["state_names"] = names_of(model.state_names, result.x, model.n_x(), 'x');
  j["control_names"] = names_of(model.control_names, result.u, model.n_u(), 'u');
  std::string text;
  pretty(j, 0, text);
  text += '\n';
  write_output_file(path, text);
}

template <class Model>
void csv_of_ocp(const OcpResult& result, const Model& model, const std::string& path) {
  const std::vector<std::string> states = names_of(model.state_names, result.x, model.n_x(), 'x');
  const std::vector<std::string> controls =
      names_of(model.control_names, result.u, model.n_u(), 'u');
  std::string out = "t";
  append_csv_names(out, states);
  out += ",interval";
  append_csv_names(out, controls);
  out += "\n";
  const std::size_t n_rows = std::min(result.t.size(), result.x.size());
  for (std::size_t n = 0; n < n_rows; ++n) {
    append_csv_state_row(out, result.t[n], result.x[n]);
    // Row n is the start of element n, which belongs to interval[n]; the final row (t = T)
    // belongs to the last interval.
    int k = -1;
    if (n < result.interval.size()) {
      k = result.interval[n];
    } else if (!result.interval.empty()) {
      k = result.interval.back();
    }
    out += ',';
    if (k >= 0) out += std::to_string(k);
    const bool has_u = k >= 0 && static_cast<std::size_t>(k) < result.u.size();
    for (std::size_t i = 0; i < controls.size(); ++i) {
      out += ',';
      if (has_u && static_cast<Eigen::Index>(i) < result.u[static_cast<std::size_t>(k)].size())
        append_number(out, result.u[static_cast<std::size_t>(k)][static_cast<Eigen::Index>(i)]);
    }
    out += '\n';
  }
  write_output_file(path, out);
}

void write_json(const IntegratorResult& result, const Pss& model, const std::string& path) {
  json_of_simulation(result, model, path);
}
void write_json(const IntegratorResult& result, const Pds& model, const std::string& path) {
  json_of_simulation(result, model, path);
}
void write_csv(const IntegratorResult& result, const Pss& model, const std::string& path) {
  csv_of_simulation(result, model, path);
}
void write_csv(const IntegratorResult& result, const Pds& model, const std::string& path) {
  csv_of_simulation(result, model, path);
}
void write_json(const OcpResult& result, const Pss& model, const std::string& path) {
  json_of_ocp(result, model, path);
}
void write_json(const OcpResult& result, const Pds& model, const std::string& path) {
  json_of_ocp(result, model, path);
}
void write_csv(const OcpResult& result, const Pss& model, const std::string& path) {
  csv_of_ocp(result, model, path);
}
void write_csv(const OcpResult& result, const Pds& model, const std::string& path) {
  csv_of_ocp(result, model, path);
}

}  // namespace fesd
