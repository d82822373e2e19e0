#include "core/bricks/brick_set.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <limits>
#include <vector>

#include <glm/common.hpp>

#include "core/bricks/brick_steps.h"
#include "core/bricks/level_layout.h"
#include "core/bricks/morton.h"
#include "core/bricks/radix_sort.h"
#include "core/common/ms_since.h"
#include "core/particles/typed_access.h"

namespace lantern {

using namespace brick_steps;

namespace {

using Clock = std::chrono::steady_clock;

// Bounds, finite and non-finite counts of the kept centres in [begin, end) (particles outside the
// group are in neither count: no brick ever holds them).
struct RangeBounds {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()};
  glm::dvec3 hi{-std::numeric_limits<double>::infinity()};
  int64_t finite = 0;
  int64_t nonfinite = 0;
};

template <typename Positions, typename Keep>
RangeBounds find_bounds(const Positions &pos, const Keep &keep, int64_t begin, int64_t end) {
  RangeBounds r;
  for (int64_t i = begin; i < end; ++i) {
    if (!keep.get(i)) continue;
    const glm::dvec3 p = pos.get(i);
    if (!finite(p)) {
      ++r.nonfinite;
      continue;
    }
    ++r.finite;
    r.lo = glm::min(r.lo, p);
    r.hi = glm::max(r.hi, p);
  }
  return r;
}

// Key words of the kept finite particles of [begin, end), written from `out` on.
template <typename Positions, typename Keep>
void fill_words(const Positions &pos, const Keep &keep, int64_t begin, int64_t end,
                const MortonQuantiser &q, uint64_t *out) {
  for (int64_t i = begin; i < end; ++i) {
    if (!keep.get(i)) continue;
    const glm::dvec3 p = pos.get(i);
    if (finite(p)) *out++ = make_word(q.key(p), uint32_t(i));
  }
}

}  // namespace

namespace brick_steps {

// Described in brick_steps.h (refit_bricks cuts its strays' words with it too).
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

}  // namespace brick_steps

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
    visit_kept(particles, [&](const auto &keep) {
      RangeBounds half[2];
      const bool two = n >= kTwoThreadsFrom;
      in_two(
          n, [&](int part, int64_t b, int64_t e) { half[part] = find_bounds(pos, keep, b, e); },
          two);
      set.lo = glm::min(half[0].lo, half[1].lo);
      set.hi = glm::max(half[0].hi, half[1].hi);
      set.nonfinite = half[0].nonfinite + half[1].nonfinite;
      words.resize(size_t(half[0].finite + half[1].finite));
      q = MortonQuantiser::for_bounds(set.lo, set.hi);
      // The second half's words start after the first half's kept finite particles.
      in_two(
          n,
          [&](int part, int64_t b, int64_t e) {
            fill_words(pos, keep, b, e, q, words.data() + (part == 0 ? 0 : half[0].finite));
          },
          two);
    });
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
  const auto bricks = int64_t(set.bricks.size());
  const bool two = int64_t(set.order.size()) >= kTwoThreadsFrom;
  if (options.level_layout) {
    in_two(
        bricks,
        [&](int, int64_t first, int64_t last) {
          std::vector<uint32_t> scratch;
          for (int64_t k = first; k < last; ++k) {
            const Brick &br = set.bricks[size_t(k)];
            apply_level_layout(set.order.data() + br.first, br.count, &scratch);
          }
        },
        two);
  }
  t.layout_ms = ms_since(t0);

  t0 = Clock::now();
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, true, 0.0, [&](const auto &radius) {
      in_two(
          bricks,
          [&](int, int64_t first, int64_t last) {
            brick_bounds(pos, radius, set.has_radius, first, last, &set);
          },
          two);
    });
  });
  t.bounds_ms = ms_since(t0);
  set.spread_at_build = set.spread();
  set.generation = next_brick_generation();
  if (timings) *timings = t;
  return set;
}

uint64_t next_brick_generation() {
  static std::atomic<uint64_t> last{0};
  return ++last;
}

}  // namespace lantern
