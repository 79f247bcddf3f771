// tests/support/compare.hpp: the one way tests compare arrays and report the worst entry.
#pragma once
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

namespace fesd::testing {

/// Passes if |a_i - b_i| <= abs_tol + rel_tol * |b_i| for all i; otherwise names the worst entry.
inline ::testing::AssertionResult near_arrays(const std::vector<double>& a,
                                              const std::vector<double>& b, double abs_tol,
                                              double rel_tol = 0.0) {
  if (a.size() != b.size())
    return ::testing::AssertionFailure() << "sizes differ: " << a.size() << " vs " << b.size();
  double worst = 0;
  std::size_t at = 0;
  bool ok = true;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double err = std::abs(a[i] - b[i]);
    const double allowed = abs_tol + rel_tol * std::abs(b[i]);
    if (!(err <= allowed)) ok = false;
    if (!(err <= worst)) {
      worst = err;
      at = i;
    }
  }
  if (ok) return ::testing::AssertionSuccess();
  std::ostringstream os;
  os.precision(17);
  os << "worst entry " << at << ": " << a[at] << " vs " << b[at] << " (|diff| = " << worst
     << ", abs_tol " << abs_tol << ", rel_tol " << rel_tol << ")";
  return ::testing::AssertionFailure() << os.str();
}

inline ::testing::AssertionResult near_arrays(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                              double abs_tol, double rel_tol = 0.0) {
  return near_arrays(std::vector<double>(a.data(), a.data() + a.size()),
                     std::vector<double>(b.data(), b.data() + b.size()), abs_tol, rel_tol);
}

}  // namespace fesd::testing
