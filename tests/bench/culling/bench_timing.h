// lantern-bench's timing helpers, shared by its tables (culling, super-sampling, density, opaque
// level of detail): wall-clock milliseconds, the thread's CPU milliseconds and the median of runs.
#pragma once

#include <time.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "core/common/ms_since.h"

namespace lantern::bench {

using Clock = std::chrono::steady_clock;
using lantern::ms_since;  // core/common/ms_since.h

// CPU time of the calling thread: what a single-threaded stage costs per core, without the
// waiting a loaded machine adds to wall-clock time.
inline double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

// The median (the mean of the two middle values for an even count); 0 for no values.
inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace lantern::bench
