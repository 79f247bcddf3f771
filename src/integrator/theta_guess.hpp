// The input rules of IntegratorOptions::theta_guess, shared by integrate() and the problem-file
// reader (which reports them with the file's line).
#pragma once

#include <fmt/format.h>

#include <string>
#include <vector>

#include "fesd/model.hpp"
#include "fesd/options.hpp"

namespace fesd::integrator {

/// Empty if theta_guess is empty or valid for `model`, else one line per broken rule.
inline std::vector<std::string> theta_guess_errors(const Pss& model, const IntegratorOptions& o) {
  std::vector<std::string> e;
  const Eigen::VectorXd& th = o.theta_guess;
  if (th.size() == 0) return e;
  if (o.discretization.dcs_mode != DcsMode::Stewart)
    e.push_back(
        "simulation.theta_guess: guesses Stewart's theta, but dcs_mode = \"step\" has alpha "
        "instead (remove theta_guess or use dcs_mode = \"stewart\")");
  if (th.size() != model.n_theta()) {
    e.push_back(fmt::format("simulation.theta_guess has {} entries, expected n_theta = {}",
                            th.size(), model.n_theta()));
    return e;
  }
  for (Eigen::Index r = 0; r < th.size(); ++r)
    if (!(th[r] >= 0.0 && th[r] <= 1.0))
      e.push_back(
          fmt::format("simulation.theta_guess[{}] = {}: a weight theta lies in [0, 1]", r, th[r]));
  return e;
}

}  // namespace fesd::integrator
