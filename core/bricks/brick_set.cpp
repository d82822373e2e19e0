#include "core/bricks/brick_set.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <glm/common.hpp>

#include "core/bricks/level_layout.h"
#include "core/bricks/morton.h"
#include "core/bricks/radix_sort.h"
#include "core/bricks/typed_access.h"

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

bool finite(const glm::dvec3 &p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// The sort word: the key's top 32 bits above the particle index. Sorting words by their upper
// half orders particles by key down to cells of 1/2^10.67 of the box; ties (rare) are broken by
// the full key afterwards. 8 bytes per particle, plus 8 of radix scratch: the 16-byte peak.
constexpr int kKeyShift = 2 * kMortonBitsPerAxis + kMortonBitsPerAxis - 32;  // 63 - 32 = 31
uint64_t make_word(uint64_t key, uint32_t index) {
  return (key >> kKeyShift) << 32 | index;
}
uint32_t word_index(uint64_t w) {
  return uint32_t(w);
}
uint32_t word_prefix(uint64_t w) {
  return uint32_t(w >> 32);
}

template <typename Positions>
void find_bounds(const Positions &pos, int64_t n, BrickSet *set) {
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  int64_t nonfinite = 0;
  for (int64_t i = 0; i < n; ++i) {
    const glm::dvec3 p = pos.get(i);
    if (!finite(p)) {
      ++nonfinite;
      continue;
    }
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  set->lo = lo;
  set->hi = hi;
  set->nonfinite = nonfinite;
}

template <typename Positions>
void fill_words(const Positions &pos, int64_t n, const MortonQuantiser &q,
                std::vector<uint64_t> *words) {
  uint64_t *out = words->data();
  for (int64_t i = 0; i < n; ++i) {
    const glm::dvec3 p = pos.get(i);
    if (finite(p)) *out++ = make_word(q.key(p), uint32_t(i));
  }
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
// octree depth of the cell [a, b) is known to share (its top 3*level key bits agree).
void split_cells(const std::vector<uint64_t> &words, uint32_t a, uint32_t b, int level,
                 uint32_t max, std::vector<Brick> *out) {
  constexpr int kMaxLevel = 10;  // 30 of the 32 prefix bits: cells of 1/1024 of the box
  if (b - a <= max || level >= kMaxLevel) {
    for (uint32_t s = a; s < b; s += max) {  // a crowded finest cell: cut it linearly
      Brick br;
      br.first = s;
      br.count = std::min(max, b - s);
      out->push_back(br);
    }
    return;
  }
  const int shift = 32 - 3 * (level + 1);
  const auto digit = [&](uint64_t w) { return (word_prefix(w) >> shift) & 7u; };
  uint32_t start = a;
  for (uint32_t child = 0; child < 8 && start < b; ++child) {
    const auto end = std::partition_point(words.begin() + start, words.begin() + b,
                                          [&](uint64_t w) { return digit(w) <= child; });
    const auto stop = uint32_t(end - words.begin());
    if (stop > start) split_cells(words, start, stop, level + 1, max, out);
    start = stop;
  }
}

template <typename Positions, typename Radii>
void brick_bounds(const Positions &pos, const Radii &radius, bool has_radius, BrickSet *set) {
  for (Brick &b : set->bricks) {
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

}  // namespace

BrickSet build_bricks(const ParticleArrays &particles, const BrickOptions &options,
                      BrickBuildTimings *timings) {
  BrickBuildTimings t;
  BrickSet set;
  const int64_t n = particles.count();
  set.has_radius = particles.has_radius();
  auto t0 = Clock::now();
  std::vector<uint64_t> words;
  MortonQuantiser q;
  visit_positions(particles, [&](const auto &pos) {
    find_bounds(pos, n, &set);
    words.resize(size_t(n - set.nonfinite));
    q = MortonQuantiser::for_bounds(set.lo, set.hi);
    fill_words(pos, n, q, &words);
  });
  t.keys_ms = ms_since(t0);

  t0 = Clock::now();
  {
    std::vector<uint64_t> scratch;
    radix_sort_words(&words, &scratch, 32, 64);
  }  // scratch freed before the permutation is allocated: the peak stays at 16 B/particle
  visit_positions(particles, [&](const auto &pos) { break_ties(pos, q, &words); });
  t.sort_ms = ms_since(t0);

  t0 = Clock::now();
  const uint32_t max = std::max<uint32_t>(1, options.max_particles);
  if (!words.empty()) split_cells(words, 0, uint32_t(words.size()), 0, max, &set.bricks);
  set.order.resize(words.size());
  for (size_t i = 0; i < words.size(); ++i) set.order[i] = word_index(words[i]);
  std::vector<uint64_t>().swap(words);
  t.split_ms = ms_since(t0);

  t0 = Clock::now();
  if (options.level_layout) {
    std::vector<uint32_t> scratch;
    for (const Brick &b : set.bricks)
      apply_level_layout(set.order.data() + b.first, b.count, &scratch);
  }
  t.layout_ms = ms_since(t0);

  t0 = Clock::now();
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, true, 0.0,
                [&](const auto &radius) { brick_bounds(pos, radius, set.has_radius, &set); });
  });
  t.bounds_ms = ms_since(t0);
  if (timings) *timings = t;
  return set;
}

}  // namespace lantern
