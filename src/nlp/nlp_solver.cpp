// src/nlp/nlp_solver.cpp: the one place that chooses the NLP solver backend.
#include "nlp/nlp_solver.hpp"

#include "nlp/ipopt_solver.hpp"

namespace fesd::nlp {

std::unique_ptr<NlpSolver> make_solver(const NlpOptions& options) {
  return std::make_unique<IpoptSolver>(options);
}

}  // namespace fesd::nlp
