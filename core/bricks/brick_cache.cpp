#include "core/bricks/brick_cache.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <utility>

#include "core/common/content_hash.h"
#include "core/common/ms_since.h"
#include "core/particles/position_tap.h"

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;

// Bricks whose summed extents grew beyond this factor since the build are too loose to cull
// well: rebuild instead of refitting.
constexpr double kMaxSpreadGrowth = 1.25;

}  // namespace

// A refit costs about as much as a build where many bricks lost particles (the 1 M-atom LAMMPS
// melt rendered every 100 steps: 8-13 ms a rank, a build 8-12), and one that ends too loose is
// thrown away before the build: the two together cost twice a build, every other frame there.
// So a refit that the growth since the build says will end too loose is not tried. In a liquid
// the spread grows about as the square root of the steps, so the mean rate since the build errs
// towards building a little early; the rate of the last refit alone would not do: a host's
// re-neighbouring adds its strays' bricks at once (on the same melt rendered every 5 steps, a
// jump of 0.056 in 5 steps where the others grew 0.011-0.024), and extrapolating that jump built
// where the refit would have passed.
bool BrickCache::refit_expected_too_loose(int64_t step) const {
  if (spread_step_ <= build_step_ || step <= spread_step_) return false;  // no refit to go by
  // Step differences in double: a host's steps may lie anywhere in int64 (INT64_MIN, then 0), where
  // their difference overflowed.
  const double rate = (spread_ratio_ - 1.0) / (double(spread_step_) - double(build_step_));
  return spread_ratio_ + rate * (double(step) - double(spread_step_)) > kMaxSpreadGrowth;
}

void BrickCache::note_spread(int64_t step, bool built) {
  // The sum the refit or build just made: no second loop over every brick.
  spread_ratio_ = set_.spread_at_build > 0.0 ? set_.spread_now / set_.spread_at_build : 1.0;
  spread_step_ = step;
  if (built || set_.spread_at_build <= 0.0) build_step_ = step;  // no growth to go by
}

uint64_t sample_fingerprint(const ParticleArrays &p) {
  // Positions that change between steps nearly always change some of the sampled ones.
  uint64_t h = kContentHashBasis;
  const auto mix = [&h](double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    h = content_hash_step(h, bits);  // a word at a time: the raw bytes of the double
  };
  const int64_t n = p.count(), stride = std::max<int64_t>(1, n / 4096);
  for (int64_t i = 0; i < n; i += stride) {
    const glm::dvec3 x = p.position(i);
    mix(x.x), mix(x.y), mix(x.z);
    if (p.has_radius()) mix(p.radius(i));
    if (p.has_mask()) mix(double(p.kept(i)));
  }
  return h;
}

void BrickCache::remember(const ParticleArrays &p, int64_t step, uint64_t fingerprint) {
  positions_ = p.position_array(0).data();
  radii_ = p.radius_array().data();
  mask_ = p.mask_array().data();
  mask_bits_ = p.mask_bits();
  count_ = p.count();
  step_ = step;
  fingerprint_ = fingerprint;
  fingerprint_call_ = call_;
}

bool BrickCache::is_cached(const ParticleArrays &p, int64_t step, uint64_t fingerprint) const {
  return count_ == p.count() && step_ == step && positions_ == p.position_array(0).data() &&
         radii_ == p.radius_array().data() && mask_ == p.mask_array().data() &&
         mask_bits_ == p.mask_bits() && fingerprint_ == fingerprint;
}

bool BrickCache::refit_first(const ParticleArrays &p, int64_t step, const BrickOptions &options) {
  const uint64_t fingerprint = sample_fingerprint(p);
  if (count_ < 0 || is_cached(p, step, fingerprint) || refit_expected_too_loose(step)) return false;
  const auto t0 = Clock::now();
  const double tapped_before = options.tap ? options.tap->ms : 0.0;
  if (!refit_bricks(p, kMaxSpreadGrowth, &set_, options)) {
    set_ = BrickSet();  // unusable: for_step builds
    count_ = -1;
    return false;
  }
  ++refits_;
  note_spread(step, false);
  remember(p, step, fingerprint);
  pending_how_ = "refit";
  // The tap's time is its stage's, not the refit's.
  const double tapped = options.tap ? options.tap->ms - tapped_before : 0.0;
  pending_ms_ = std::chrono::duration<double, std::milli>(Clock::now() - t0).count() - tapped;
  return true;
}

const BrickSet &BrickCache::for_step(const ParticleArrays &p, int64_t step,
                                     const BrickOptions &options, double *build_ms,
                                     std::string *how) {
  // Taken earlier in this call (begin_call()): the arrays are as they were then.
  const bool taken = call_ != 0 && fingerprint_call_ == call_;
  const uint64_t fingerprint = taken ? fingerprint_ : sample_fingerprint(p);
  if (is_cached(p, step, fingerprint)) {
    *how = pending_how_.empty() ? "cached" : std::exchange(pending_how_, std::string());
    *build_ms += std::exchange(pending_ms_, 0.0);
    return set_;
  }
  pending_how_.clear(), pending_ms_ = 0.0;
  const auto t0 = Clock::now();
  // A later step: particles moved a little, so keep the z-order and refit the bounds. The host
  // may have moved its arrays (LAMMPS reallocates when its ghost count grows), wrapped, dropped
  // or added particles (migration): refit_bricks re-sorts only the strays, recomputes every
  // bound from the particles themselves - culling stays exact whatever the indices now hold -
  // and asks for a rebuild when too much changed.
  if (count_ >= 0 && !refit_expected_too_loose(step) &&
      refit_bricks(p, kMaxSpreadGrowth, &set_, options)) {
    ++refits_;
    note_spread(step, false);
    *how = "refit";
  } else {
    set_ = BrickSet();  // free the old permutation before building: keeps the peak low
    set_ = build_bricks(p, options);
    note_spread(step, true);
    *how = "built";
  }
  remember(p, step, fingerprint);
  *build_ms += ms_since(t0);
  return set_;
}

}  // namespace lantern

namespace lantern {

bool extent_of_bricks(const BrickSet &bricks, const ParticleArrays &particles, Extent *out) {
  if (particles.has_scalar() || bricks.nonfinite != 0) return false;
  Extent e;
  e.finite_count = bricks.particle_count();
  e.nonfinite_count = 0;  // a refit keeps no brick with a non-finite position
  for (int k = 0; k < 3; ++k) {
    e.lo[size_t(k)] = bricks.lo[k], e.hi[size_t(k)] = bricks.hi[k];
    if (e.finite_count > 0 && (bricks.lo[k] == 0.0 || bricks.hi[k] == 0.0)) return false;
  }
  if (e.finite_count > 0) {
    // The scan's largest radius: the radius array's over the finite kept particles (the bricks
    // hold exactly those), else the scan's own radius argument, 0.
    double r = 0.0;
    if (particles.has_radius()) {
      for (const Brick &b : bricks.bricks) r = std::max(r, b.max_radius);
      if (r == 0.0) return false;
    }
    e.max_radius = r;
  }
  *out = e;
  return true;
}

}  // namespace lantern
