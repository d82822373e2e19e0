// The threads one rank may use for its per-particle passes (the run-wide `threads:` key), and
// running a pass over them.
//
// A hybrid MPI + threads code gives each rank several cores; brick building, refitting, the
// particle scan and the CPU raster then cut their work into that many contiguous parts. Every
// such pass writes disjoint outputs per part and combines parts in part order (or with exact
// operations: min, max, integer sums), so its result never depends on the thread count.
//
// No global state: the count is resolved once per Runtime from its configuration and passed down.
// Thread-safety: run_in_parts starts and joins its own threads; f must be safe to call
// concurrently on different parts.
#pragma once

#include <algorithm>
#include <cstdint>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

namespace lantern {

// What `threads: auto` resolves to: OMP_NUM_THREADS (its first entry) when set to a positive
// number, else the number of CPUs this process may run on (its affinity mask, which mpiexec's
// binding narrows), else 1. Reads the process environment.
int default_thread_count();

// How many parts to cut n items into: at most `threads`, and none smaller than min_per_part
// items (a thread costs tens of microseconds to start); at least 1.
inline int parts_for(int threads, int64_t n, int64_t min_per_part) {
  const int64_t most = min_per_part > 0 ? n / min_per_part : n;
  return int(std::max<int64_t>(1, std::min<int64_t>(threads, most)));
}

// The first item of part p of `parts` over [0, n): contiguous parts whose sizes differ by <= 1.
inline int64_t part_begin(int p, int parts, int64_t n) {
  return n * p / parts;
}

// Runs f(part, begin, end) for every part of [0, n) cut into `parts`, part 0 on the calling thread
// and the others on their own threads, all joined before it returns. Where a thread cannot be
// started, the calling thread runs that part itself: the results are the same.
template <typename F>
void run_in_parts(int parts, int64_t n, F &&f) {
  parts = std::max(1, parts);
  std::vector<std::thread> helpers;
  int started = 1;
  try {
    helpers.reserve(size_t(parts - 1));
    for (; started < parts; ++started)
      helpers.emplace_back([&f, started, parts, n] {
        f(started, part_begin(started, parts, n), part_begin(started + 1, parts, n));
      });
  } catch (const std::system_error &) {  // no thread to be had: this one does the rest
  } catch (const std::bad_alloc &) {
  }
  for (int p = started; p < parts; ++p) f(p, part_begin(p, parts, n), part_begin(p + 1, parts, n));
  f(0, part_begin(0, parts, n), part_begin(1, parts, n));
  for (std::thread &t : helpers) t.join();
}

}  // namespace lantern
