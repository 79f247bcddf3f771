// bench/cvode/cvode_oscillator.hpp: the oscillator (47) of papers/fesd-filippov.txt integrated by
// SUNDIALS CVODE with root finding on c(x) = |x|^2 - 1 (what a user picks for a crossing-only
// problem): the comparison row of bench/active_set_step.cpp (issue 15 item 3). Built only when
// CMake finds Debian's libsundials-dev (FESD_BENCH_CVODE).
#pragma once

namespace fesd_bench {

/// One CVODE configuration, solved `repeat` times in this process.
struct CvodeRun {
  double rtol = 0, atol = 0;
  bool bdf = false;      ///< BDF + dense Newton; false: Adams + fixed-point iteration
  double setup_s = 0;    ///< median: context, vectors, CVodeCreate/Init, tolerances, roots
  double solve_s = 0;    ///< median: the CVode calls from t = 0 to T, root restarts included
  double error_x = 0;    ///< ||x(T) - x_exact(T)||_2 (REFERENCE.md)
  double error_t_s = 0;  ///< |t_s - 1| of the root found
  long steps = 0, rhs_evals = 0, root_evals = 0;
  bool ok = false;
};

/// Integrates (47) from x0 = (e^-1, 0) over [0, pi/2], switching the vector field at the root
/// of c (CVodeReInit there); CPU time of this process, medians over `repeat` runs.
CvodeRun cvode_oscillator(double rtol, double atol, bool bdf, int repeat);

}  // namespace fesd_bench
