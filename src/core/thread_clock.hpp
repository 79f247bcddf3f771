// src/core/thread_clock.hpp: the calling thread's CPU time, in a header of its own so that the
// standalone KKT module (libfesd_kkt, no Eigen or fmt) and the library share one clock.
// Internal (not installed).
#pragma once
#include <ctime>

namespace fesd::util {

/// CPU seconds of the calling thread (CLOCK_THREAD_CPUTIME_ID): on a shared machine, wall time
/// would count other processes' time slices.
inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace fesd::util
