// The bricks' particles as runs of consecutive indices, in index order: what lets a refit (and
// the build's bounds) read the simulation's positions in one streaming pass instead of brick by
// brick.
//
// Why: a brick's particles lie in a few dozen separate stretches of the host's arrays (a
// simulation that keeps its atoms spatially sorted, as LAMMPS and most MD codes do, stores a
// brick's x-rows one after another), and gathering brick after brick costs about twice a
// streaming pass. Listing those stretches in index order - runs of (first index, count, brick) -
// turns the gather into a stream at about 12 bytes per run. Where runs are short (particles in
// random order) they cost more than they save, and the set keeps none (the refit then gathers).
//
// Bounds computed through runs visit a brick's particles in index order rather than in the
// brick's order; min and max give the same values either way, and where a bound is exactly zero
// (the only value with two encodings, -0 and +0) the brick is bounded again in its own order, so
// the bits are those of the brick-order pass.
//
// Thread-safety: pure functions; the streaming pass runs in parts on its own threads.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "core/bricks/brick_set.h"
#include "core/common/rank_threads.h"

namespace lantern {

// Runs shorter than this on average are not kept (8 bytes a run: 2 bytes per particle). A
// crystal in lattice order gives about 5 (a brick's x-rows, cut where the basis atoms straddle a
// brick boundary).
inline constexpr uint32_t kMinMeanRun = 4;

// The owner of an index that no brick holds.
inline constexpr uint32_t kNoBrick = ~0u;

// The runs of owner[0, n) (a brick number per index, kNoBrick for none) in index order, each
// run's `brick` the owner, closed by a run of no brick at n; none when the runs of a brick would
// average fewer than kMinMeanRun of the `held` indices that have an owner.
std::vector<IndexRun> runs_of_owners(const uint32_t *owner, int64_t n, int64_t held);

// The runs of `set` from scratch (after a refit moved particles between bricks), or none when
// their mean length is below kMinMeanRun. Needs a temporary of 4 bytes per index below `bound`.
std::vector<IndexRun> runs_of(const BrickSet &set, int64_t bound);

// What the streaming pass finds for one brick.
struct BrickScan {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()};
  glm::dvec3 hi{-std::numeric_limits<double>::infinity()};
  double r = 0.0;             // largest radius (0 without a radius array)
  bool all_published = true;  // every index below the particle count and in the group
  bool finite = true;         // every such position finite
};

// One streaming pass over the positions through set.runs: each brick's bounds, radius and
// checks, for particles with index below `count` that are in the group (`keep`). In parts on up
// to `threads` threads, merged in part order (min and max keep the first of equal values, so the
// result is the one-thread result).
template <typename Positions, typename Radii, typename Keep>
std::vector<BrickScan> scan_runs(const Positions &pos, const Radii &radius, const Keep &keep,
                                 bool has_radius, int64_t count, const BrickSet &set, int threads) {
  const std::vector<IndexRun> &runs = set.runs;
  const int parts = parts_for(threads, set.particle_count(), int64_t(1) << 16);
  std::vector<std::vector<BrickScan>> part(static_cast<size_t>(parts));
  const int64_t stretches = runs.empty() ? 0 : int64_t(runs.size()) - 1;  // the last closes
  run_in_parts(parts, stretches, [&](int p, int64_t begin, int64_t end) {
    std::vector<BrickScan> &acc = part[size_t(p)];
    acc.assign(set.bricks.size(), BrickScan{});
    for (int64_t k = begin; k < end; ++k) {
      const IndexRun &run = runs[size_t(k)];
      if (run.brick == kNoBrick) continue;
      BrickScan &a = acc[run.brick];
      glm::dvec3 lo = a.lo, hi = a.hi;
      double r = a.r;
      bool finite = true;
      const int64_t first = run.first, stop = runs[size_t(k) + 1].first;
      const int64_t last = std::min<int64_t>(stop, count);
      if (last < stop) a.all_published = false;
      for (int64_t i = first; i < last; ++i) {
        if (!keep.get(i)) {
          a.all_published = false;
          continue;
        }
        const glm::dvec3 x = pos.get(i);
        // x - x is 0 for finite x and NaN otherwise: a test without branches.
        finite &= (x.x - x.x == 0.0) & (x.y - x.y == 0.0) & (x.z - x.z == 0.0);
        lo = glm::min(lo, x), hi = glm::max(hi, x);
        if (has_radius) r = std::max(r, radius.get(i));
      }
      a.lo = lo, a.hi = hi, a.r = r;
      a.finite &= finite;
    }
  });
  std::vector<BrickScan> all = std::move(part[0]);
  for (size_t p = 1; p < part.size(); ++p)
    for (size_t b = 0; b < all.size(); ++b) {
      BrickScan &a = all[b];
      const BrickScan &l = part[p][b];
      a.lo = glm::min(a.lo, l.lo), a.hi = glm::max(a.hi, l.hi);
      a.r = std::max(a.r, l.r);
      a.all_published &= l.all_published;
      a.finite &= l.finite;
    }
  return all;
}

// True when a bound of `s` is exactly zero: -0 and +0 compare equal, so which one min or max
// kept depends on the order the particles were visited in.
inline bool has_zero_bound(const BrickScan &s) {
  return s.lo.x == 0.0 || s.lo.y == 0.0 || s.lo.z == 0.0 || s.hi.x == 0.0 || s.hi.y == 0.0 ||
         s.hi.z == 0.0;
}

}  // namespace lantern
