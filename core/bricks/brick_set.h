// Bricks: this rank's finite particles in z-order, cut into octree cells of bounded particle
// count, each with its bounds; the unit of culling and of level of detail.
//
// The simulation's arrays are never moved: a BrickSet holds a permutation of uint32 indices into
// them (4 bytes per particle), the runs of consecutive indices per brick when they are long enough
// to pay (8 bytes a run and a bit per particle, at most 2.1 bytes per particle; index_runs.h)
// and a few dozen bytes per brick.
// Building it peaks at 8 bytes per particle (each particle's key, later its brick; the
// permutation, which first holds the indices scattered to their top octree cells) plus the runs.
// Bricks depend only on the particles, not on a camera: build
// once per step and reuse for every scene of that step.
//
// Brick size: octree leaves of at most 1024 particles (uniform data: 128..1024). Smaller bricks
// cull more finely at the brick level (a thinner shell of per-particle tests behind the visible
// surface); 1024 measured best on 1 M and 10 M fcc crystals (lantern-bench) and costs 64 bytes
// per brick (< 0.5 B per particle) on top of the permutation.
//
// Ownership: a BrickSet owns its permutation and bricks; it refers to the particles only by
// index, so it stays valid as long as the published arrays keep their order and count.
// Thread-safety: immutable after build_bricks(); concurrent readers are fine.
// Units: bounds in the simulation's length unit.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/common/page_allocator.h"
#include "core/common/uninitialized_buffer.h"
#include "core/particles/particle_arrays.h"

namespace lantern {

struct Extent;      // core/particles/global_extent.h
class PositionTap;  // core/particles/position_tap.h

struct Brick {
  uint32_t first = 0;  // offset into BrickSet::order
  uint32_t count = 0;
  glm::dvec3 lo{0.0}, hi{0.0};  // bounds of the particle CENTRES; add the radius to cull
  double max_radius = 0.0;      // largest published radius in the brick (0 without radius array)
};

// The start of a stretch of consecutive particle indices whose particles belong to one or two
// bricks (`other` ~0u: one; else BrickSet::in_other says which), or to none (brick ~0u); it ends
// where the next run starts (index_runs.h).
struct IndexRun {
  uint32_t first = 0, brick = 0, other = ~0u;
};

// A list of IndexRun in index order, 8 bytes a run (12 unpacked): each run's start as an offset
// into its block of kBlock indices, its brick and other brick in kBrickBits each, and the first
// run of every block in a table. Runs never cross a block boundary (a run that would is cut
// there, at most one extra run per kBlock indices), so every block starts a run. Bricks numbered
// above kLargestBrick cannot be stored (the set then keeps no runs and a refit gathers).
class IndexRuns {
 public:
  static constexpr int kOffsetBits = 12;
  static constexpr int kBrickBits = 26;
  static constexpr uint32_t kBlock = 1u << kOffsetBits;
  static constexpr uint32_t kLargestBrick = (1u << kBrickBits) - 2;  // all ones: no brick

  size_t size() const { return packed_.size(); }
  bool empty() const { return packed_.empty(); }
  // Run k, unpacked (a search over the blocks: for loops, visit()).
  IndexRun operator[](size_t k) const;
  IndexRun front() const { return (*this)[0]; }
  // Run k's brick and other brick, without its first index (no search): for looking ahead.
  void bricks_of(size_t k, uint32_t *brick, uint32_t *other) const {
    *brick = unpack_brick(packed_[k], kOffsetBits);
    *other = unpack_brick(packed_[k], kOffsetBits + kBrickBits);
  }
  IndexRun back() const { return (*this)[size() - 1]; }
  // f(first, stop, brick, other) for runs [begin, end) (each needs its successor: end < size()).
  template <typename F>
  void visit(size_t begin, size_t end, const F &f) const;
  // Runs from run k on, one per next(), as visit() gives them: for a loop compiled for wider
  // instructions than its caller (a function with a target attribute), into which visit()'s
  // callback could not be inlined (it would cost a call per run).
  class Reader {
   public:
    Reader(const IndexRuns &runs, size_t k)
        : runs_(&runs),
          k_(k),
          block_(runs.block_of(k)),
          first_(block_ << kOffsetBits | uint32_t(runs.packed_[k] & (kBlock - 1))) {}
    // Run k's first index, stop (its successor's first), brick and other brick; then k + 1.
    void next(uint32_t *first, uint32_t *stop, uint32_t *brick, uint32_t *other) {
      const uint64_t w = runs_->packed_[k_], following = runs_->packed_[k_ + 1];
      const auto offset = uint32_t(following & (kBlock - 1));
      if (offset == 0) ++block_;  // the next run starts the next block
      *first = first_;
      *stop = first_ = block_ << kOffsetBits | offset;
      *brick = unpack_brick(w, kOffsetBits);
      *other = unpack_brick(w, kOffsetBits + kBrickBits);
      ++k_;
    }

   private:
    const IndexRuns *runs_;
    size_t k_;
    uint32_t block_, first_;
  };
  // Run after run, unpacked (range-for).
  class Iterator {
   public:
    Iterator(const IndexRuns *runs, size_t k) : runs_(runs), k_(k) {}
    IndexRun operator*() const { return (*runs_)[k_]; }
    Iterator &operator++() {
      ++k_;
      return *this;
    }
    bool operator!=(const Iterator &o) const { return k_ != o.k_; }

   private:
    const IndexRuns *runs_;
    size_t k_;
  };
  Iterator begin() const { return {this, 0}; }
  Iterator end() const { return {this, size()}; }

  // Blocks of kBlock indices, and the run that starts block b (at index b kBlock).
  size_t blocks() const { return block_first_.size(); }
  size_t block_start(size_t b) const { return block_first_[b]; }

  void clear() {
    PageVector<uint64_t>().swap(packed_);
    std::vector<uint32_t>().swap(block_first_);
  }
  void reserve(size_t runs) { packed_.reserve(runs); }
  // Appends a run starting after the last one, in the same block or at the start of the next;
  // brick and other at most kLargestBrick or ~0u.
  void push_back(const IndexRun &run) {
    const uint32_t offset = run.first & (kBlock - 1);
    if (offset == 0) block_first_.push_back(uint32_t(packed_.size()));
    packed_.push_back(uint64_t(offset) | uint64_t(run.brick & kMask) << kOffsetBits |
                      uint64_t(run.other & kMask) << (kOffsetBits + kBrickBits));
  }

 private:
  static constexpr uint32_t kMask = (1u << kBrickBits) - 1;
  static uint32_t unpack_brick(uint64_t w, int shift) {
    const auto b = uint32_t(w >> shift) & kMask;
    return b == kMask ? ~0u : b;
  }
  // The block of run k: the last block whose first run is at or before k.
  uint32_t block_of(size_t k) const;

  PageVector<uint64_t> packed_;
  std::vector<uint32_t> block_first_;  // the first run of each block
};

inline uint32_t IndexRuns::block_of(size_t k) const {
  size_t lo = 0, hi = block_first_.size();  // block_first_[0] == 0 <= k
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    if (block_first_[mid] <= k)
      lo = mid;
    else
      hi = mid;
  }
  return uint32_t(lo);
}

inline IndexRun IndexRuns::operator[](size_t k) const {
  const uint64_t w = packed_[k];
  IndexRun r;
  r.first = block_of(k) << kOffsetBits | uint32_t(w & (kBlock - 1));
  r.brick = unpack_brick(w, kOffsetBits);
  r.other = unpack_brick(w, kOffsetBits + kBrickBits);
  return r;
}

template <typename F>
void IndexRuns::visit(size_t begin, size_t end, const F &f) const {
  if (begin >= end) return;
  Reader reader(*this, begin);
  for (size_t k = begin; k < end; ++k) {
    uint32_t first, stop, brick, other;
    reader.next(&first, &stop, &brick, &other);
    f(first, stop, brick, other);
  }
}

struct BrickOptions {
  uint32_t max_particles = 1024;  // a brick never holds more (see the note on BrickSet)
  bool level_layout = true;       // z-order level layout inside bricks (prefix = uniform sample)
  int threads = 1;                // threads the build or refit may use (the result is the same)
  // The bounds and finite count of the kept particles when the caller already scanned them
  // (scan_particles of this rank, as the pipeline does every step): saves the build a pass.
  const Extent *known_extent = nullptr;
  // A refit that streams packed xyz doubles on one thread hands them to this tap as it goes
  // (position_tap.h); nullptr: none.
  PositionTap *tap = nullptr;
};

struct BrickSet {
  // Particle indices, brick after brick. Not zero-filled when it grows: the build and the refit
  // write every slot they add; zero-filling it first cost a 5 M-particle build about 1 ms of its
  // 12 ms scatter.
  UninitializedBuffer<uint32_t> order;
  std::vector<Brick> bricks;  // in z-order along the curve
  // The bricks' particles as runs of consecutive indices, in index order and closed by a run of
  // no brick, for refits that stream the positions (index_runs.h); empty where runs would be too
  // short to pay. in_other: a bit per index, set where a run's particle is in its `other` brick.
  IndexRuns runs;
  PageVector<uint64_t> in_other;
  glm::dvec3 lo{0.0}, hi{0.0};  // bounds of the finite centres (lo > hi when there are none)
  int64_t nonfinite = 0;        // kept particles left out for a NaN or infinite coordinate
  bool has_radius = false;      // bricks carry max_radius from the published radius array

  double spread_at_build = 0.0;  // spread() when built: how tight z-order made the bricks
  double spread_now = 0.0;       // spread() as the last build or refit left it
  // The mean edge of the bricks when built (spread_at_build over three edges a brick): the
  // smallest slack a refit gives a brick, however thin it is (refit_bricks).
  double mean_edge_at_build = 0.0;
  // A process-unique stamp of the build or refit that made these bounds (0: made by hand). State
  // derived from the bounds (culling's per-brick cut counts) is valid while the stamp is the same.
  uint64_t generation = 0;
  // A process-unique stamp of the build or re-sort that made `order` and the bricks' slices (0:
  // made by hand). A refit that keeps every particle in its brick keeps it, so state filed by
  // slot (the half-bonds by brick, brick_bonds.h) is valid while it is the same.
  uint64_t order_generation = 0;

  int64_t particle_count() const { return int64_t(order.size()); }
  // Sum of the bricks' bound extents (x + y + z): grows as particles drift out of their cells.
  double spread() const;
};

// A fresh BrickSet::generation, never 0 and never the same twice in a process; thread-safe.
uint64_t next_brick_generation();

// Timings of one build, milliseconds: the passes that bound the set (none with a known extent)
// and its bricks, the pass that computes the keys and counts the top octree cells, the pass that
// scatters the particles to those cells, and the work inside the cells (sorting, splitting, level
// layout, runs).
struct BrickBuildTimings {
  double bounds_ms = 0, keys_ms = 0, scatter_ms = 0, cells_ms = 0;
};

// Builds the bricks of `particles` (count must be < 2^32). Particles with a non-finite
// coordinate are left out (counted in `nonfinite`), and so are those outside the published group
// (mask): bricks hold only the indices of kept particles, so every later stage skips the others
// at no cost.
BrickSet build_bricks(const ParticleArrays &particles, const BrickOptions &options,
                      BrickBuildTimings *timings = nullptr);

// Keeps the bricks (the z-order permutation) of an earlier step for particles that moved a
// little, instead of sorting again: one pass over the particles. A particle stays in its brick
// if it lies within the brick's last bounds grown on each axis by a quarter of its size there, or
// by a quarter of the mean edge at build where that is more; the others (moved
// far, wrapped through a periodic boundary, or an index the host now gives another particle, as
// LAMMPS does when atoms migrate) and indices beyond the old count are sorted in z-order among
// themselves into extra bricks; indices beyond the new count are dropped. Every bound is then
// recomputed from the current positions, so culling stays exact whatever the indices now hold.
// Particles that left the group (mask) are dropped like unpublished indices; one that joined it
// under an index the bricks do not hold forces a rebuild.
// Returns false - and leaves *set unusable, to be rebuilt - when the radius array appeared or
// went, a position is not finite, more than a tenth of the particles strayed, or the summed
// brick extents grew beyond max_growth times those at build (bricks too loose to cull well).
// Either way the set gets a new generation; a new order_generation unless every particle stayed
// in its brick (order and slices unchanged).
bool refit_bricks(const ParticleArrays &particles, double max_growth, BrickSet *set,
                  const BrickOptions &options = {});
}  // namespace lantern
