// src/io/option_target.hpp: where the registry's options live in a problem read from a file
// (src/core/option_registry.hpp). Light: no TOML, for the loaders and the tests.
#pragma once
#include "core/option_registry.hpp"
#include "fesd/pds_problem_file.hpp"
#include "fesd/problem_file.hpp"

namespace fesd::io_detail {

inline registry::OptionTarget target_of(SimulationProblem& q) {
  registry::OptionTarget t = registry::target_of(q.options);
  t.T_sim = &q.T_sim;
  t.N_sim = &q.N_sim;
  t.tol_sim = &q.tol_sim;
  t.N_sim_max = &q.N_sim_max;
  t.error_estimate = &q.error_estimate;
  return t;
}

inline registry::OptionTarget target_of(PdsOcpProblem& q) {
  registry::OptionTarget t = registry::target_of(q.options);
  t.ocp = &q.ocp;
  return t;
}

inline registry::OptionTarget target_of(OcpProblem& q) {
  registry::OptionTarget t = registry::target_of(q.options);
  t.ocp = &q.ocp;
  return t;
}

}  // namespace fesd::io_detail
