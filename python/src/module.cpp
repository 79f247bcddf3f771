// python/src/module.cpp: the extension module fesd._fesd (pybind11). It holds problems as read by
// the problem-file loaders and runs fesd::simulate / fesd::solve without the GIL; results come
// back as plain Python data (dicts of numpy arrays, lists, strings), which the pure Python layer
// (python/fesd/__init__.py) wraps into picklable result objects. docs/python.md.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fstream>
#include <sstream>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "fesd/error.hpp"
#include "fesd/integrator.hpp"
#include "fesd/ocp.hpp"
#include "fesd/pds_problem_file.hpp"
#include "fesd/problem_file.hpp"
#include "fesd/status.hpp"
#include "fesd/summary.hpp"
#include "io/plot_parts.hpp"

namespace py = pybind11;

namespace {

using Overrides = fesd::OverrideList;

/// The model, initial state and parameter values of each kind of problem.
const fesd::Pss& model_of(const fesd::SimulationProblem& p) {
  return p.model;
}
const fesd::Pss& model_of(const fesd::OcpProblem& p) {
  return p.ocp.model;
}
const fesd::Pds& model_of(const fesd::PdsSimulationProblem& p) {
  return p.model;
}
const Eigen::VectorXd& x0_of(const fesd::SimulationProblem& p) {
  return p.x0;
}
const Eigen::VectorXd& x0_of(const fesd::OcpProblem& p) {
  return p.ocp.x0;
}
const Eigen::VectorXd& x0_of(const fesd::PdsSimulationProblem& p) {
  return p.x0;
}
/// The parameter values a run uses (an OCP's empty p means the model's defaults).
Eigen::VectorXd p_of(const fesd::SimulationProblem& p) {
  return p.p;
}
Eigen::VectorXd p_of(const fesd::OcpProblem& p) {
  return p.ocp.p.size() > 0 ? p.ocp.p : p.ocp.model.p_default;
}
Eigen::VectorXd p_of(const fesd::PdsSimulationProblem& p) {
  return p.p;
}

/// A problem file's content: a simulation or an optimal control problem of a piecewise smooth
/// system, or a simulation of a projected one ([model] kind = "projected", docs/pds.md), with the
/// text it was read from and the overrides applied since, so that it pickles (read again from
/// both).
struct Problem {
  std::variant<fesd::SimulationProblem, fesd::OcpProblem, fesd::PdsSimulationProblem> value;
  std::string text;         ///< the TOML text (empty: the file could not be read again)
  std::string source_name;  ///< the file or the name given for a dict
  Overrides overrides;      ///< applied in this order after reading

  bool is_ocp() const { return std::holds_alternative<fesd::OcpProblem>(value); }
  bool is_projected() const { return std::holds_alternative<fesd::PdsSimulationProblem>(value); }
  template <class F>
  decltype(auto) visit(F&& f) const {
    return std::visit(std::forward<F>(f), value);
  }
};

/// Overrides of a problem, as the program applies them (fesd::apply_overrides).
template <class P>
void apply_problem_overrides(P& problem, const Overrides& overrides) {
  fesd::apply_overrides(problem, overrides);
}

py::array_t<double> vector_array(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::array_t<double> vector_array(const Eigen::VectorXd& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.data(), v.data() + v.size(), a.mutable_data());
  return a;
}

/// Rows of equal length as an (N, n) array; n = `width` when there are no rows.
py::array_t<double> matrix_array(const std::vector<Eigen::VectorXd>& rows, Eigen::Index width) {
  const Eigen::Index n = rows.empty() ? width : rows.front().size();
  py::array_t<double> a({static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(n)});
  auto m = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != n)
      throw fesd::InternalError("internal: rows of different lengths in a result");
    for (Eigen::Index j = 0; j < n; ++j)
      m(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(j)) = rows[i][j];
  }
  return a;
}

/// An Eigen matrix as an (rows, cols) array.
py::array_t<double> dense_array(const Eigen::MatrixXd& M) {
  py::array_t<double> a({static_cast<py::ssize_t>(M.rows()), static_cast<py::ssize_t>(M.cols())});
  auto m = a.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < M.rows(); ++i)
    for (Eigen::Index j = 0; j < M.cols(); ++j)
      m(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(j)) = M(i, j);
  return a;
}

py::dict sensitivities_dict(const fesd::Sensitivities& s) {
  py::dict d;
  d["requested"] = s.requested;
  d["available"] = s.available;
  d["message"] = s.message;
  d["x0"] = dense_array(s.x0);
  d["u"] = dense_array(s.u);
  d["p"] = dense_array(s.p);
  return d;
}

py::dict homotopy_row(const fesd::HomotopyRow& r) {
  py::dict d;
  d["k"] = r.k;
  d["sigma"] = r.sigma;
  d["comp_residual"] = r.comp_residual;
  d["objective"] = r.objective;
  d["inf_pr"] = r.inf_pr;
  d["nlp_iterations"] = r.nlp_iterations;
  d["nlp_status"] = r.nlp_status;
  d["cpu_s"] = r.cpu_s;
  d["wall_s"] = r.wall_s;
  d["linear_solver"] = r.linear_solver;
  d["factor_s"] = r.factor_s;
  d["factorizations"] = r.factorizations;
  d["active_set_fixed"] = r.active_set_fixed;
  d["pinned_exits"] = r.pinned_exits;
  d["retried"] = r.retried;
  d["restarted"] = r.restarted;
  d["stalled"] = r.stalled;
  d["cold_start"] = r.cold_start;
  return d;
}

py::list homotopy_rows(const std::vector<fesd::HomotopyRow>& rows) {
  py::list l;
  for (const fesd::HomotopyRow& r : rows) l.append(homotopy_row(r));
  return l;
}

py::list switch_events(const std::vector<fesd::SwitchEvent>& switches) {
  py::list l;
  for (const fesd::SwitchEvent& s : switches) {
    py::dict d;
    d["t"] = s.t;
    d["element"] = s.element;
    d["before"] = s.before;
    d["after"] = s.after;
    d["located"] = s.located;
    l.append(d);
  }
  return l;
}

py::array_t<double> switch_times(const std::vector<fesd::SwitchEvent>& switches) {
  std::vector<double> t;
  for (const fesd::SwitchEvent& s : switches) t.push_back(s.t);
  return vector_array(t);
}

py::dict summary_dict(const fesd::Summary& s) {
  py::dict d;
  d["homotopy_steps"] = s.homotopy_steps;
  d["nlp_iterations"] = s.nlp_iterations;
  d["wall_s"] = s.wall_s;
  d["derivative_s"] = s.derivative_s;
  d["solver_s"] = s.solver_s;
  d["setup_s"] = s.setup_s;
  d["max_comp_residual"] = s.max_comp_residual;
  d["n_variables"] = s.n_variables;
  d["n_constraints"] = s.n_constraints;
  d["fallback_steps"] = s.fallback_steps;
  d["refine_attempts"] = s.refine_attempts;
  d["refined_steps"] = s.refined_steps;
  d["split_steps"] = s.split_steps;
  d["active_set_path_steps"] = s.active_set_path_steps;
  d["homotopy_path_steps"] = s.homotopy_path_steps;
  d["newton_iterations"] = s.newton_iterations;
  d["newton_factorizations"] = s.newton_factorizations;
  d["active_set_tries"] = s.active_set_tries;
  d["active_set_s"] = s.active_set_s;
  d["active_set_solves"] = s.active_set_solves;
  d["active_set_failures"] = s.active_set_failures;
  d["rescued_steps"] = s.rescued_steps;
  d["pinned_exits"] = s.pinned_exits;
  d["pin_failures"] = s.pin_failures;
  d["grid_moves"] = s.grid_moves;
  d["born_switches"] = s.born_switches;
  d["allocation_solves"] = s.allocation_solves;
  d["allocation_moves"] = s.allocation_moves;
  d["held_switches"] = s.held_switches;
  d["warnings"] = s.warnings;
  return d;
}

py::dict accuracy_dict(const fesd::Accuracy& a) {
  py::dict d;
  d["error_estimate"] = a.error_estimate;
  d["switch_time_estimate"] = a.switch_time_estimate;
  d["switch_times_consistent"] = a.switch_times_consistent;
  d["noise_floor"] = a.noise_floor;
  d["at_noise_floor"] = a.at_noise_floor;
  d["consistent"] = a.consistent;
  d["order"] = a.order;
  d["tol_sim"] = a.tol_sim;
  d["met"] = a.met;
  d["N_sim"] = a.N_sim;
  d["note"] = a.note;
  py::list runs;
  for (const fesd::AccuracyRun& r : a.runs) {
    py::dict run;
    run["N_sim"] = r.N_sim;
    run["status"] = std::string(fesd::to_string(r.status));
    run["x_final"] = vector_array(r.x_final);
    run["switch_times"] = vector_array(r.switch_times);
    run["error_estimate"] = r.error_estimate;
    run["wall_s"] = r.wall_s;
    runs.append(run);
  }
  d["runs"] = runs;
  return d;
}

/// "x3" for ("x", 2): names the model leaves out are numbered from 1 (as in the CLI's outputs).
std::string numbered(const char* prefix, int i) {
  std::string name(prefix);
  name += std::to_string(i + 1);
  return name;
}

template <class Model>  // fesd::Pss or fesd::Pds
std::vector<std::string> state_names(const Model& model) {
  std::vector<std::string> names = model.state_names;
  for (int i = static_cast<int>(names.size()); i < model.n_x(); ++i)
    names.push_back(numbered("x", i));
  return names;
}

template <class Model>
std::vector<std::string> control_names(const Model& model) {
  std::vector<std::string> names = model.control_names;
  for (int i = static_cast<int>(names.size()); i < model.n_u(); ++i)
    names.push_back(numbered("u", i));
  return names;
}

/// The subsystem of every region (region r belongs to subsystem k if region_offset(k) <= r <
/// region_offset(k + 1)): a subsystem with two or more active regions slides.
std::vector<int> region_subsystem(const fesd::Pss& model) {
  std::vector<int> out(static_cast<std::size_t>(model.n_theta()), 0);
  for (int k = 0; k < model.n_sys(); ++k) {
    const int end = k + 1 < model.n_sys() ? model.region_offset(k + 1) : model.n_theta();
    for (int r = model.region_offset(k); r < end; ++r) out[static_cast<std::size_t>(r)] = k;
  }
  return out;
}

/// Widths of a simulation result's stage arrays: theta and lambda (Stewart: n_theta each), mu
/// (n_sys); a projected model has no theta or mu and one lambda per constraint.
struct StageWidths {
  Eigen::Index theta, lambda, mu;
};
StageWidths stage_widths(const fesd::Pss& m) {
  return {m.n_theta(), m.n_theta(), m.n_sys()};
}
StageWidths stage_widths(const fesd::Pds& m) {
  return {0, m.n_c(), 0};
}
std::vector<int> region_subsystem(const fesd::Pds&) {
  return {};
}

template <class SimProblem>  // fesd::SimulationProblem or fesd::PdsSimulationProblem
py::dict simulation_dict(const SimProblem& problem, const fesd::IntegratorResult& r) {
  const auto& m = problem.model;
  const StageWidths w = stage_widths(m);
  py::dict d;
  d["kind"] = "simulation";
  d["projected"] = std::is_same_v<SimProblem, fesd::PdsSimulationProblem>;
  d["name"] = problem.name;
  d["state_names"] = state_names(m);
  d["region_subsystem"] = region_subsystem(m);
  d["status"] = std::string(fesd::to_string(r.status));
  d["message"] = r.message;
  d["t"] = vector_array(r.t);
  d["x"] = matrix_array(r.x, m.n_x());
  d["h"] = vector_array(r.h);
  d["t_stage"] = vector_array(r.t_stage);
  d["x_stage"] = matrix_array(r.x_stage, m.n_x());
  d["theta"] = matrix_array(r.theta, w.theta);
  d["lambda_"] = matrix_array(r.lambda, w.lambda);
  d["mu"] = matrix_array(r.mu, w.mu);
  d["active_set"] = r.active_set;
  d["switches"] = switch_events(r.switches);
  d["switch_times"] = switch_times(r.switches);
  py::list homotopy;
  for (const auto& rows : r.homotopy) homotopy.append(homotopy_rows(rows));
  d["homotopy"] = homotopy;
  d["summary"] = summary_dict(r.summary);
  d["accuracy"] = accuracy_dict(r.accuracy);
  d["sensitivities"] = sensitivities_dict(r.sensitivities);
  py::list step_path;
  for (fesd::StepSolver s : r.step_path) step_path.append(std::string(fesd::to_string(s)));
  d["step_path"] = step_path;
  d["x_final"] = vector_array(r.x_final());
  d["brief_report"] = r.brief_report();
  d["full_report"] = r.full_report();
  return d;
}

py::dict ocp_dict(const fesd::OcpProblem& problem, const fesd::OcpResult& r) {
  const fesd::Pss& m = problem.ocp.model;
  py::dict d;
  d["kind"] = "ocp";
  d["projected"] = false;
  d["name"] = problem.name;
  d["state_names"] = state_names(m);
  d["control_names"] = control_names(m);
  d["region_subsystem"] = region_subsystem(m);
  d["status"] = std::string(fesd::to_string(r.status));
  d["message"] = r.message;
  d["objective"] = r.objective;
  d["comp_residual"] = r.comp_residual;
  d["mpcc_mode"] = std::string(fesd::to_string(r.mpcc_mode));
  d["t"] = vector_array(r.t);
  d["x"] = matrix_array(r.x, m.n_x());
  d["h"] = vector_array(r.h);
  d["interval"] = r.interval;
  d["t_ctrl"] = vector_array(r.t_ctrl);
  d["u"] = matrix_array(r.u, m.n_u());
  d["active_set"] = r.active_set;
  d["switches"] = switch_events(r.switches);
  d["switch_times"] = switch_times(r.switches);
  d["eta"] = vector_array(r.eta);
  d["t_stage"] = vector_array(r.t_stage);
  d["x_stage"] = matrix_array(r.x_stage, m.n_x());
  d["theta"] = matrix_array(r.theta, m.n_theta());
  d["lambda_"] = matrix_array(r.lambda, m.n_theta());
  d["homotopy"] = homotopy_rows(r.homotopy);
  d["summary"] = summary_dict(r.summary);
  d["x0"] = vector_array(r.x0());
  d["x_final"] = vector_array(r.x_final());
  d["brief_report"] = r.brief_report();
  d["full_report"] = r.full_report();
  return d;
}

Problem load(const std::string& path) {
  Problem problem;
  if (fesd::is_projected_problem_file(path))
    problem.value = fesd::load_pds_simulation_problem(path);
  else if (fesd::problem_file_kind(path) == fesd::ProblemKind::Ocp)
    problem.value = fesd::load_ocp_problem(path);
  else
    problem.value = fesd::load_simulation_problem(path);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (in) problem.text = text.str();
  problem.source_name = path;
  return problem;
}

Problem parse(const std::string& text, const std::string& source_name, bool ocp, bool projected) {
  Problem problem;
  if (projected)
    problem.value = fesd::parse_pds_simulation_problem(text, source_name);
  else if (ocp)
    problem.value = fesd::parse_ocp_problem(text, source_name);
  else
    problem.value = fesd::parse_simulation_problem(text, source_name);
  problem.text = text;
  problem.source_name = source_name;
  return problem;
}

Problem with_overrides(const Problem& problem, const Overrides& overrides) {
  Problem copy = problem;
  std::visit([&](auto& p) { apply_problem_overrides(p, overrides); }, copy.value);
  copy.overrides.insert(copy.overrides.end(), overrides.begin(), overrides.end());
  return copy;
}

using ProblemState = std::tuple<std::string, std::string, bool, Overrides, bool>;

ProblemState problem_state(const Problem& p) {
  if (p.text.empty())
    throw fesd::IoError(p.source_name + ": cannot be read again to pickle the problem");
  return {p.text, p.source_name, p.is_ocp(), p.overrides, p.is_projected()};
}

Problem problem_from_state(const ProblemState& s) {
  return with_overrides(parse(std::get<0>(s), std::get<1>(s), std::get<2>(s), std::get<4>(s)),
                        std::get<3>(s));
}

py::dict simulate(const Problem& problem, const Overrides& overrides) {
  if (problem.is_ocp())
    throw fesd::InvalidOption(
        "an optimal control problem ([ocp] table): use fesd.solve, not fesd.simulate");
  return problem.visit([&](const auto& q) -> py::dict {
    using P = std::decay_t<decltype(q)>;
    if constexpr (std::is_same_v<P, fesd::OcpProblem>) {
      return {};  // rejected above
    } else {
      P p = q;
      apply_problem_overrides(p, overrides);
      fesd::IntegratorResult r;
      {
        py::gil_scoped_release release;
        r = fesd::simulate(p);
      }
      return simulation_dict(p, r);
    }
  });
}

py::dict solve(const Problem& problem, const Overrides& overrides) {
  if (!problem.is_ocp())
    throw fesd::InvalidOption(
        "a simulation problem (no [ocp] table): use fesd.simulate, not fesd.solve");
  fesd::OcpProblem p = std::get<fesd::OcpProblem>(problem.value);
  apply_problem_overrides(p, overrides);
  fesd::OcpResult r;
  {
    py::gil_scoped_release release;
    r = fesd::solve(p.ocp, p.options);
  }
  return ocp_dict(p, r);
}

/// The switching surfaces of a two-state model in the box [xlo, xhi] x [ylo, yhi], as the
/// program's phase portrait draws them (a projected model: the boundary of C): (label, (k, 4)
/// array of segments x0, y0, x1, y1) per surface; empty for other models.
py::list switching_surfaces(const Problem& problem, double xlo, double xhi, double ylo, double yhi,
                            int n_grid) {
  const fesd::io_detail::Surfaces surfaces = problem.visit([&](const auto& q) {
    return fesd::io_detail::switching_surfaces(model_of(q), p_of(q), xlo, xhi, ylo, yhi, n_grid);
  });
  py::list out;
  for (const auto& [label, segments] : surfaces) {
    py::array_t<double> a({static_cast<py::ssize_t>(segments.size()), py::ssize_t{4}});
    auto m = a.mutable_unchecked<2>();
    for (std::size_t i = 0; i < segments.size(); ++i) {
      const auto k = static_cast<py::ssize_t>(i);
      m(k, 0) = segments[i].x0;
      m(k, 1) = segments[i].y0;
      m(k, 2) = segments[i].x1;
      m(k, 3) = segments[i].y1;
    }
    out.append(py::make_tuple(label, a));
  }
  return out;
}

}  // namespace

PYBIND11_MODULE(_fesd, m) {
  m.doc() =
      "The compiled core of the fesd package (pybind11). Use the package `fesd` itself: "
      "fesd.load, fesd.simulate, fesd.solve (docs/python.md).";

  static py::exception<fesd::Error> input_error(m, "InputError", PyExc_ValueError);
  input_error.doc() =
      "Bad input: a malformed problem file or dict, an unknown option or a value out of range. "
      "The message is the one line the fesd program prints, e.g. \"unknown option 'n_S' (did you "
      "mean 'n_s'?)\". A ValueError.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const fesd::Error& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const fesd::InternalError& e) {
      PyErr_SetString(PyExc_RuntimeError, (std::string("internal error: ") + e.what()).c_str());
    }
  });

  py::class_<Problem>(m, "Problem",
                      "A problem as read from a problem file or a dict: a simulation ([simulation] "
                      "table) or an optimal control problem ([ocp] table). Made by fesd.load; "
                      "run it with fesd.simulate or fesd.solve.")
      .def_property_readonly(
          "kind", [](const Problem& p) { return p.is_ocp() ? "ocp" : "simulation"; },
          "\"simulation\" or \"ocp\".")
      .def_property_readonly(
          "projected", &Problem::is_projected,
          "True for a projected dynamical system ([model] kind = \"projected\", docs/pds.md).")
      .def_property_readonly(
          "name", [](const Problem& p) { return p.visit([](const auto& q) { return q.name; }); },
          "The problem's `name`, or the file's stem.")
      .def_property_readonly(
          "description",
          [](const Problem& p) { return p.visit([](const auto& q) { return q.description; }); },
          "The problem's `description` (may be empty).")
      .def_property_readonly(
          "source",
          [](const Problem& p) { return p.visit([](const auto& q) { return q.source; }); },
          "The file it was read from (or the name given for a dict).")
      .def_property_readonly(
          "state_names",
          [](const Problem& p) {
            return p.visit([](const auto& q) { return state_names(model_of(q)); });
          },
          "Names of the states (a clock state \"t\" last if the model uses the time t).")
      .def_property_readonly(
          "control_names",
          [](const Problem& p) {
            return p.visit([](const auto& q) { return control_names(model_of(q)); });
          },
          "Names of the controls.")
      .def_property_readonly(
          "parameters",
          [](const Problem& p) {
            const Eigen::VectorXd values = p.visit([](const auto& q) { return p_of(q); });
            const std::vector<std::string> names =
                p.visit([](const auto& q) { return model_of(q).parameter_names; });
            py::dict d;
            for (Eigen::Index i = 0; i < values.size(); ++i) {
              const auto k = static_cast<std::size_t>(i);
              d[py::str(k < names.size() ? names[k] : numbered("p", static_cast<int>(i)))] =
                  values[i];
            }
            return d;
          },
          "The parameter values {name: value} ([model] p).")
      .def_property_readonly(
          "x0",
          [](const Problem& p) {
            return vector_array(p.visit([](const auto& q) { return x0_of(q); }));
          },
          "The initial state (the guess of x0 for an OCP with a free x0).")
      .def_property_readonly(
          "n_regions",
          [](const Problem& p) {
            return p.is_projected() ? 0 : p.visit([](const auto& q) {
              if constexpr (std::is_same_v<std::decay_t<decltype(q)>, fesd::PdsSimulationProblem>)
                return 0;
              else
                return model_of(q).n_theta();
            });
          },
          "Number of regions (rows of the stacked sign matrices); 0 for a projected model.")
      .def_property_readonly(
          "n_constraints",
          [](const Problem& p) {
            return p.visit([](const auto& q) {
              if constexpr (std::is_same_v<std::decay_t<decltype(q)>, fesd::PdsSimulationProblem>)
                return model_of(q).n_c();
              else
                return 0;
            });
          },
          "Number of constraints c of a projected model (C = {x : c(x) >= 0}); 0 otherwise.")
      .def(py::pickle(&problem_state, &problem_from_state))
      .def("__repr__", [](const Problem& p) {
        return p.visit([&](const auto& q) {
          return "<fesd.Problem " + std::string(p.is_ocp() ? "ocp" : "simulation") + " '" + q.name +
                 "' from " + q.source + ">";
        });
      });

  m.def("_load", &load, py::arg("path"),
        "Reads a problem file (simulation or OCP); raises InputError on bad input.");
  m.def("_parse", &parse, py::arg("text"), py::arg("source_name"), py::arg("ocp"),
        py::arg("projected") = false,
        "Reads a problem from TOML text; `source_name` is used in messages.");
  m.def("_with_overrides", &with_overrides, py::arg("problem"), py::arg("overrides"),
        "A copy of the problem with (key, value) overrides applied as the CLI applies them.");
  m.def("_simulate", &simulate, py::arg("problem"), py::arg("overrides"),
        "Simulates (the GIL released) and returns the result as a dict of plain data.");
  m.def("_solve", &solve, py::arg("problem"), py::arg("overrides"),
        "Solves the OCP (the GIL released) and returns the result as a dict of plain data.");
  m.def("_switching_surfaces", &switching_surfaces, py::arg("problem"), py::arg("xlo"),
        py::arg("xhi"), py::arg("ylo"), py::arg("yhi"), py::arg("n_grid") = 161,
        "The switching surfaces c = 0 (g_i = g_j) of a two-state model in a box: a list of "
        "(label, (k, 4) array of segments x0, y0, x1, y1).");
}
