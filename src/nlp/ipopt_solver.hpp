// src/nlp/ipopt_solver.hpp: NlpSolver backed by IPOPT (Debian's 3.11.9 with MUMPS).
#pragma once
#include <memory>

#include "nlp/nlp_solver.hpp"

namespace fesd::nlp {

class IpoptSolver final : public NlpSolver {
 public:
  /// Creates and initializes one IPOPT application, reused for every solve. Throws
  /// fesd::InvalidOption if IPOPT rejects an option (the message names it).
  explicit IpoptSolver(const NlpOptions& options);
  ~IpoptSolver() override;
  NlpResult solve(const BlockNlp& nlp, Iterate& start, bool warm_start, double tol, int max_iter,
                  const CallerHandles& caller_handles) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fesd::nlp
