// include/fesd/status.hpp: the outcome of a solve. Numerical trouble is a status, never an
// exception.
#pragma once
#include <string_view>

namespace fesd {

enum class Status {
  NotRun,                 ///< nothing was computed yet
  Success,                ///< every step (Newton or NLP) converged, complementarity_tol reached
  ComplementarityNotMet,  ///< the homotopy ended with the complementarity residual above tol
  NlpFailed,              ///< IPOPT failed (infeasible, iteration limit, restoration failure, ...)
  EvaluationFailed,       ///< a user function returned NaN or inf at every trial point
  /// simulate(): every run succeeded, but the error estimate did not reach tol_sim within
  /// N_sim_max steps (the result is the finest run, with its estimate)
  ToleranceNotMet,
};

/// Short identifier, e.g. "success", "nlp_failed".
std::string_view to_string(Status s);
/// One sentence explaining the status.
std::string_view describe(Status s);
/// CLI exit code: 0 for Success, 1 for every numerical failure.
int exit_code(Status s);

}  // namespace fesd
