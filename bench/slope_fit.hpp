// bench/slope_fit.hpp: the convergence slope the order benches print (fig8_accuracy, irma_order,
// pds_example1): least squares of log(err) over log(h), with its standard error and, optionally,
// the slopes of the coarser and the finer half of the points (pre-asymptotic vs. asymptotic).
// Which points enter (error windows, round-off floors, failed runs) is each program's choice.
#pragma once
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace fesd_bench {

struct SlopeFit {
  int points = 0;
  double slope = NAN;               // >= 2 points
  double se = NAN;                  // standard error of the slope from the residuals, >= 3 points
  double coarse = NAN, fine = NAN;  // the slopes of the first and the second half of the points
  std::vector<double> local;        // slopes between consecutive points
};

/// Least-squares slope of y over x through the points [b, e); its standard error in *se.
inline double ls_slope(const std::vector<double>& x, const std::vector<double>& y, std::size_t b,
                       std::size_t e, double* se = nullptr) {
  const double n = static_cast<double>(e - b);
  if (e - b < 2) return NAN;
  double sx = 0, sy = 0;
  for (std::size_t i = b; i < e; ++i) sx += x[i], sy += y[i];
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = b; i < e; ++i)
    sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  const double k = sxy / sxx;
  if (se && e - b > 2) {
    double ss = 0;
    for (std::size_t i = b; i < e; ++i) ss += std::pow(y[i] - my - k * (x[i] - mx), 2);
    *se = std::sqrt(ss / (n - 2) / sxx);
  }
  return k;
}

/// The fit of log err over log h through the points (h, err), in the order given (the halves
/// are the first and the second half of that order); the halves only from halves_from points on
/// (0: never).
inline SlopeFit fit_log_log(const std::vector<std::pair<double, double>>& h_err,
                            std::size_t halves_from = 0) {
  std::vector<double> x, y;
  for (const auto& [h, err] : h_err) {
    x.push_back(std::log(h));
    y.push_back(std::log(err));
  }
  const std::size_t n = x.size();
  SlopeFit f;
  f.points = static_cast<int>(n);
  for (std::size_t i = 1; i < n; ++i) f.local.push_back((y[i] - y[i - 1]) / (x[i] - x[i - 1]));
  f.slope = ls_slope(x, y, 0, n, &f.se);
  if (halves_from > 0 && n >= halves_from) {
    f.coarse = ls_slope(x, y, 0, n / 2);
    f.fine = ls_slope(x, y, n / 2, n);
  }
  return f;
}

}  // namespace fesd_bench
