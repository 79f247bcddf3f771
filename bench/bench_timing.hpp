// bench/bench_timing.hpp: the CPU clock and the median shared by the bench programs.
#pragma once
#include <algorithm>
#include <cmath>
#include <ctime>
#include <vector>

namespace fesd_bench {

/// CPU time of this process (all threads), seconds.
inline double cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// The upper median (the middle value for odd sizes); NaN if empty.
inline double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace fesd_bench
