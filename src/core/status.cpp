#include "fesd/status.hpp"

namespace fesd {

std::string_view to_string(Status s) {
  switch (s) {
    case Status::NotRun:
      return "not_run";
    case Status::Success:
      return "success";
    case Status::ComplementarityNotMet:
      return "complementarity_not_met";
    case Status::NlpFailed:
      return "nlp_failed";
    case Status::EvaluationFailed:
      return "evaluation_failed";
    case Status::ToleranceNotMet:
      return "tolerance_not_met";
  }
  return "unknown";
}

std::string_view describe(Status s) {
  switch (s) {
    case Status::NotRun:
      return "nothing was computed";
    case Status::Success:
      return "solved: every step converged and complementarity_tol was reached";
    case Status::ComplementarityNotMet:
      return "the homotopy ended with the complementarity residual above complementarity_tol";
    case Status::NlpFailed:
      return "IPOPT did not converge";
    case Status::EvaluationFailed:
      return "a model function returned NaN or inf";
    case Status::ToleranceNotMet:
      return "the error estimate did not reach tol_sim within N_sim_max steps";
  }
  return "unknown status";
}

int exit_code(Status s) {
  return s == Status::Success ? 0 : 1;
}

}  // namespace fesd
