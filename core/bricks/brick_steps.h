// Internal to core/bricks, not part of the API: the steps of a brick build that refit_bricks
// takes again for the particles that strayed from their bricks - z-order sort words, tie-breaking,
// the octree split, the level layout and brick bounds. They live here, shared by brick_build.cpp
// and brick_refit.cpp, so that a refit makes its strays' bricks exactly as a build makes bricks,
// from one copy of the code.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "core/bricks/brick_set.h"
#include "core/bricks/level_layout.h"
#include "core/bricks/morton.h"

namespace lantern::brick_steps {

inline bool finite(const glm::dvec3 &p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// The sort word: the key's top 32 bits above the particle index. Sorting words by their upper
// half orders particles by key down to cells of 1/2^10.67 of the box; ties (rare) are broken by
// the full key afterwards. Sorting the words as numbers orders them by (key prefix, index).
inline constexpr int kKeyShift = 2 * kMortonBitsPerAxis + kMortonBitsPerAxis - 32;  // 63 - 32 = 31
inline uint32_t key_prefix(uint64_t key) {
  return uint32_t(key >> kKeyShift);
}
inline uint64_t make_word(uint64_t key, uint32_t index) {
  return uint64_t(key_prefix(key)) << 32 | index;
}
inline uint32_t word_index(uint64_t w) {
  return uint32_t(w);
}
inline uint32_t word_prefix(uint64_t w) {
  return uint32_t(w >> 32);
}

// Particles per thread below which a pass does not start another thread.
inline constexpr int64_t kParticlesPerThread = 1 << 16;

// Words [a, b), sorted by (prefix, index), with equal prefixes ordered by the full key instead
// (then by index): the order of (full key, index). `run` is scratch.
template <typename Positions>
void break_ties(const Positions &pos, const MortonQuantiser &q, uint64_t *w, size_t a, size_t b,
                std::vector<std::pair<uint64_t, uint64_t>> *run) {
  // Ties are rare (cells of 1/2^10.67 of the box): a plain scan for the next one first.
  for (size_t s = a; s + 1 < b;) {
    if (word_prefix(w[s + 1]) != word_prefix(w[s])) {
      ++s;
      continue;
    }
    size_t e = s + 2;
    while (e < b && word_prefix(w[e]) == word_prefix(w[s])) ++e;
    run->clear();
    for (size_t k = s; k < e; ++k) run->emplace_back(q.key(pos.get(word_index(w[k]))), w[k]);
    std::sort(run->begin(), run->end());
    for (size_t k = s; k < e; ++k) w[k] = (*run)[k - s].second;
    s = e;
  }
}

// The deepest octree level split_cells cuts at: 30 of the 32 prefix bits, cells of 1/1024 of the
// box; a finest cell with more particles is cut linearly.
inline constexpr int kMaxSplitLevel = 10;

// Cuts [a, b) of the sorted words into octree cells of at most `max` particles. `level` is the
// octree depth of the cell [a, b) is known to share (its top 3*level key bits agree). Defined in
// brick_build.cpp.
void split_cells(const uint64_t *words, uint32_t a, uint32_t b, int level, uint32_t max,
                 std::vector<Brick> *out);

// The bounds and largest radius of the `count` particles idx[0, count), into *b.
template <typename Positions, typename Radii>
void bound_brick(const Positions &pos, const Radii &radius, bool has_radius, const uint32_t *idx,
                 uint32_t count, Brick *b) {
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  double r = 0.0;
  for (uint32_t k = 0; k < count; ++k) {
    const glm::dvec3 p = pos.get(idx[k]);
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
    if (has_radius) r = std::max(r, radius.get(idx[k]));
  }
  b->lo = lo;
  b->hi = hi;
  b->max_radius = r;
}

// Brick `b` of sorted `words` (b.first and b.count index both words and *order) into *order: the
// particle indices in the level layout when `level_layout`, else in z-order.
inline void lay_out_brick(const uint64_t *words, const Brick &b, bool level_layout,
                          uint32_t *order) {
  const uint64_t *w = words + b.first;
  uint32_t *out = order + b.first;
  if (!level_layout) {
    for (uint32_t k = 0; k < b.count; ++k) out[k] = word_index(w[k]);
    return;
  }
  gather_in_level_layout(
      b.count, [w](uint32_t j) { return word_index(w[j]); }, out);
}

}  // namespace lantern::brick_steps
