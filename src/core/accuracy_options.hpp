// The accuracy rule of a simulation problem file (tol_sim, N_sim, N_sim_max, error_estimate) as
// AccuracyOptions: one place for the piecewise smooth and the projected SimulationProblem, the
// CLI's headers and simulate(). Internal (not installed).
#pragma once
#include "fesd/integrator.hpp"

namespace fesd {

template <class Problem>
AccuracyOptions accuracy_options(const Problem& q) {
  AccuracyOptions a;
  a.tol_sim = q.tol_sim;
  a.N_sim = q.N_sim;
  a.N_sim_max = q.N_sim_max;
  a.error_estimate = q.error_estimate;
  return a;
}

}  // namespace fesd
