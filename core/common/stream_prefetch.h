// Software prefetches for the passes that stream the host's positions in index order (the brick
// build's key pass, the refit's and the build's scan through the index runs, the extent scan).
//
// Why: those passes do enough work per particle (a dozen to twenty instructions) that the
// processor's window holds the loads of only a few cache lines ahead, and a core's share of
// memory bandwidth went unused: each asks for its lines kStreamFarBytes ahead into L2, which took
// a refit's scan of 5 M fcc particles from 17.8 to 10.9 ms (a streaming pass 9.8), and again
// kStreamNearBytes ahead into L1, since loads that found their line in L2 still waited on it
// there (the scan of 19 M 52.3-55.2 -> 48.7-51.6 ms, the key pass 68-72 -> 59-62 ms;
// docs/benchmarks.md, Scale). Prefetches change no value and do not fault, so lines past an
// array's end are harmless.
//
// Thread-safety: pure functions.
#pragma once

#include <cstdint>

#if defined(__x86_64__) && defined(__SSE__)
#include <xmmintrin.h>
#define LANTERN_STREAM_PREFETCH 1
#else
#define LANTERN_STREAM_PREFETCH 0
#endif

namespace lantern {

inline constexpr uintptr_t kStreamFarBytes = 4096;   // asked into L2
inline constexpr uintptr_t kStreamNearBytes = 1024;  // asked (again) into L1

// Asks for the cache line at address `line` + kStreamFarBytes into L2 and the one at `line` +
// kStreamNearBytes (asked into L2 earlier) into L1.
inline void ask_stream_line(uintptr_t line) {
#if LANTERN_STREAM_PREFETCH
  _mm_prefetch(reinterpret_cast<const char *>(line + kStreamFarBytes), _MM_HINT_T1);
  _mm_prefetch(reinterpret_cast<const char *>(line + kStreamNearBytes), _MM_HINT_T0);
#else
  (void)line;
#endif
}

// ask_stream_line() for the `lines` cache lines from p on.
inline void ask_stream_ahead(const void *p, int lines) {
  const auto at = reinterpret_cast<uintptr_t>(p);
  for (int k = 0; k < lines; ++k) ask_stream_line(at + 64 * uintptr_t(k));
}

}  // namespace lantern
