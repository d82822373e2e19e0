// Internal to core/bricks, not part of the API: the steps of a brick build that refit_bricks
// takes again for the particles that strayed from their bricks - z-order sort words, tie-breaking,
// the octree split, brick bounds - and the two-thread split both use. They live here, shared by
// brick_build.cpp and brick_refit.cpp, so that a refit makes its strays' bricks exactly as a build
// makes bricks, from one copy of the code.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <thread>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "core/bricks/brick_set.h"
#include "core/bricks/morton.h"

namespace lantern::brick_steps {

inline bool finite(const glm::dvec3 &p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// The sort word: the key's top 32 bits above the particle index. Sorting words by their upper
// half orders particles by key down to cells of 1/2^10.67 of the box; ties (rare) are broken by
// the full key afterwards. 8 bytes per particle, plus 8 of radix scratch: the 16-byte peak.
inline constexpr int kKeyShift = 2 * kMortonBitsPerAxis + kMortonBitsPerAxis - 32;  // 63 - 32 = 31
inline uint64_t make_word(uint64_t key, uint32_t index) {
  return (key >> kKeyShift) << 32 | index;
}
inline uint32_t word_index(uint64_t w) {
  return uint32_t(w);
}
inline uint32_t word_prefix(uint64_t w) {
  return uint32_t(w >> 32);
}

// Runs f(part, begin, end) over [0, n) cut in two halves, the second on a helper thread, when n
// is large enough to pay for a thread. Both halves write disjoint data; results are the same as
// with one thread.
inline constexpr int64_t kTwoThreadsFrom = 200000;  // particles
template <typename F>
void in_two(int64_t n, F &&f, bool worth_a_thread) {
  if (!worth_a_thread || n < 2) {
    f(0, int64_t(0), n);
    return;
  }
  const int64_t mid = n / 2;
  std::thread helper([&f, mid, n] { f(1, mid, n); });
  f(0, int64_t(0), mid);
  helper.join();
}

// Words with the same upper half are in index order; order them by the full key instead.
template <typename Positions>
void break_ties(const Positions &pos, const MortonQuantiser &q, std::vector<uint64_t> *words) {
  std::vector<std::pair<uint64_t, uint64_t>> run;
  uint64_t *w = words->data();
  const size_t n = words->size();
  for (size_t a = 0; a < n;) {
    size_t b = a + 1;
    while (b < n && word_prefix(w[b]) == word_prefix(w[a])) ++b;
    if (b - a > 1) {
      run.clear();
      for (size_t k = a; k < b; ++k) run.emplace_back(q.key(pos.get(word_index(w[k]))), w[k]);
      std::sort(run.begin(), run.end());
      for (size_t k = a; k < b; ++k) w[k] = run[k - a].second;
    }
    a = b;
  }
}

// Cuts [a, b) of the sorted words into octree cells of at most `max` particles. `level` is the
// octree depth of the cell [a, b) is known to share (its top 3*level key bits agree). Defined in
// brick_build.cpp.
void split_cells(const std::vector<uint64_t> &words, uint32_t a, uint32_t b, int level,
                 uint32_t max, std::vector<Brick> *out);

// Gives bricks [first, last) of *set the bounds and largest radius of their particles.
template <typename Positions, typename Radii>
void brick_bounds(const Positions &pos, const Radii &radius, bool has_radius, int64_t first,
                  int64_t last, BrickSet *set) {
  for (int64_t k = first; k < last; ++k) {
    Brick &b = set->bricks[size_t(k)];
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
    double r = 0.0;
    const uint32_t *idx = set->order.data() + b.first;
    for (uint32_t k = 0; k < b.count; ++k) {
      const glm::dvec3 p = pos.get(idx[k]);
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
      if (has_radius) r = std::max(r, radius.get(idx[k]));
    }
    b.lo = lo;
    b.hi = hi;
    b.max_radius = r;
  }
}

}  // namespace lantern::brick_steps
