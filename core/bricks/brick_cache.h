// The bricks of the current step, kept between the scenes of a step and between steps.
//
// Bricks depend only on the particles, so they are built once per step and shared by every
// scene of that step. On a later step the z-order is kept and the bounds refit (particles moved a
// little); a rebuild happens when the host's arrays changed too much for a refit to pay.
//
// Ownership: owns the BrickSet (the permutation, 4 B per particle, and the bricks); remembers the
// host's array addresses only to notice that they changed, never reads through them outside
// for_step(). Thread-safety: one thread. Units: the simulation's.
#pragma once

#include <cstdint>
#include <string>

#include "core/bricks/brick_set.h"
#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"

namespace lantern {

class BrickCache {
 public:
  // The bricks of `particles` at `step`: the cached set when this step's bricks were already made
  // from the same arrays (same addresses, count and sampled contents), else refit or rebuilt
  // with `options` (threads, and the rank's scanned extent when known). Adds the time spent to
  // *build_ms - including a refit refit_first() made for this step - and says "cached", "refit"
  // or "built" in *how.
  const BrickSet &for_step(const ParticleArrays &particles, int64_t step,
                           const BrickOptions &options, double *build_ms, std::string *how);

  // Refits the bricks for `step` before anything else of the step, when it can: then the rank's
  // extent comes from the bricks' bounds instead of a pass of its own (extent_of_bricks) and the
  // step's first for_step() reports this refit ("refit", its time). False - and nothing kept, so
  // for_step() builds - when there is nothing to refit or the refit asks for a rebuild, or when
  // `step`'s bricks are already made. The time of options.tap (BrickOptions) is not counted.
  bool refit_first(const ParticleArrays &particles, int64_t step, const BrickOptions &options);
  const BrickSet &bricks() const { return set_; }

  // Marks the start of one call from the host (lantern_execute). The host's arrays do not change
  // during a call, so a fingerprint taken in it (by refit_first or for_step) is not taken again
  // by the call's later for_step()s: it costs about 0.2 ms at 1 M particles (4096 samples, each a
  // cache miss), once per scene. Callers that never mark calls get a fresh one every time.
  void begin_call() { ++call_; }

  int64_t refits() const { return refits_; }  // steps served by a refit instead of a rebuild

 private:
  void remember(const ParticleArrays &particles, int64_t step, uint64_t fingerprint);
  bool is_cached(const ParticleArrays &particles, int64_t step, uint64_t fingerprint) const;
  // Whether a refit for `step` is expected to leave the bricks too loose (their spread beyond
  // kMaxSpreadGrowth times that at build), from how fast the spread grew since the build.
  bool refit_expected_too_loose(int64_t step) const;
  // Notes the spread of the set just built or refit for `step`.
  void note_spread(int64_t step, bool built);

  int64_t step_ = 0;
  int64_t count_ = -1;  // -1: nothing built yet
  const void *positions_ = nullptr;
  const void *radii_ = nullptr;
  const void *mask_ = nullptr;  // the group: bricks hold only its members
  int64_t mask_bits_ = 0;
  uint64_t fingerprint_ = 0;
  // The spread after the last build or refit over the spread at build, the step it was made for,
  // and the step of the last build.
  double spread_ratio_ = 1.0;
  int64_t spread_step_ = 0;
  int64_t build_step_ = 0;
  uint64_t call_ = 0;              // begin_call()s so far
  uint64_t fingerprint_call_ = 0;  // the call fingerprint_ was taken in (0: none marked)
  int64_t refits_ = 0;
  BrickSet set_;
  // refit_first's refit, reported by the step's first for_step(): "" when none is pending.
  std::string pending_how_;
  double pending_ms_ = 0.0;
};

// The rank's extent (bounds, counts, largest radius) from bricks just refit for `particles`,
// bit for bit what scan_particles(particles, particles.has_radius(), 0.0) gives; false where the
// bricks cannot tell: a scalar array (its range needs a pass), a bound or radius of exactly zero
// (-0 and +0 depend on the order particles are met in).
bool extent_of_bricks(const BrickSet &bricks, const ParticleArrays &particles, Extent *out);

// A cheap guard against arrays rewritten in place under the same step number: a hash of the raw
// bytes of up to 4096 evenly spaced positions and radii (and whether they are in the group).
uint64_t sample_fingerprint(const ParticleArrays &particles);

}  // namespace lantern
