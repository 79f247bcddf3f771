#include "core/limits.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace fesd::core {

std::string step_length_error(std::string_view T_key, double T, std::string_view N_key, int N,
                              double t0) {
  if (!(std::isfinite(T) && T > 0) || N < 1 || !std::isfinite(t0)) return {};
  const double step = T / N;
  const double min_step = kMinStep * std::max(1.0, std::abs(t0));
  if (step >= min_step) return {};
  const std::string_view T_name = T_key.substr(T_key.rfind('.') + 1);  // npos + 1 = 0
  const std::string_view N_name = N_key.substr(N_key.rfind('.') + 1);
  return fmt::format(
      "{} = {:g}: the step {} / {} = {:g} is shorter than {:g} (steps must be >= 1e-12 max(1, "
      "|t0|){}: IPOPT's tolerances are absolute; rescale time for faster dynamics)",
      T_key, T, T_name, N_name, step, min_step, t0 != 0.0 ? fmt::format(", t0 = {:g}", t0) : "");
}

}  // namespace fesd::core
