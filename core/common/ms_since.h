// Wall-clock milliseconds since a moment: the stage times of the stats line, the renderer's
// timings and the benchmarks' tables all measure with this one clock and unit. The steady clock
// never jumps with the system time, so a difference is never negative.
#pragma once

#include <chrono>

namespace lantern {

inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace lantern
