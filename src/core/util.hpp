// Small helpers shared by the layers: timing, index ranges, gathers from a variable vector and
// finiteness checks of inputs. Internal (not installed).
#pragma once
#include <chrono>
#include <cmath>
#include <ctime>
#include <numeric>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "core/thread_clock.hpp"
#include "fesd/error.hpp"

namespace fesd::util {

using Clock = std::chrono::steady_clock;

/// Wall seconds since t0.
inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// first, first + 1, ..., first + n - 1.
inline std::vector<int> range_of(int first, int n) {
  std::vector<int> v(static_cast<std::size_t>(n));
  std::iota(v.begin(), v.end(), first);
  return v;
}

/// w[first .. first + n) as a vector.
inline Eigen::VectorXd gather(const std::vector<double>& w, int first, int n) {
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = w[static_cast<std::size_t>(first + i)];
  return v;
}

/// Throws InvalidModel naming `name`[i] if an entry of v is NaN or inf.
inline void check_finite(const Eigen::VectorXd& v, const char* name) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw InvalidModel(fmt::format("{}[{}] = {}: must be finite", name, i, v[i]));
}

}  // namespace fesd::util
