// Pds: size checks and default names.
#include <fmt/format.h>

#include "fesd/error.hpp"
#include "fesd/pds.hpp"

namespace fesd {

Pds::Pds(PdsDims dims, std::shared_ptr<const PdsFunctions> functions)
    : dims_(dims), functions_(std::move(functions)) {
  if (!functions_) throw InvalidModel("model: no functions given");
  if (dims_.n_x < 1) throw InvalidModel(fmt::format("model: n_x = {}: must be >= 1", dims_.n_x));
  if (dims_.n_u < 0) throw InvalidModel(fmt::format("model: n_u = {}: must be >= 0", dims_.n_u));
  if (dims_.n_p < 0) throw InvalidModel(fmt::format("model: n_p = {}: must be >= 0", dims_.n_p));
  if (dims_.n_c < 1)
    throw InvalidModel(
        fmt::format("model: n_c = {}: a projected dynamical system needs >= 1 constraint c(x) >= 0",
                    dims_.n_c));
  for (int i = 0; i < dims_.n_x; ++i) state_names.push_back(fmt::format("x{}", i + 1));
  for (int i = 0; i < dims_.n_u; ++i) control_names.push_back(fmt::format("u{}", i + 1));
  for (int i = 0; i < dims_.n_p; ++i) parameter_names.push_back(fmt::format("p{}", i + 1));
  p_default = Eigen::VectorXd::Zero(dims_.n_p);
}

}  // namespace fesd
