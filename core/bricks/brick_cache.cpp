#include "core/bricks/brick_cache.h"

#include <algorithm>
#include <chrono>
#include <cstring>

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;

// Bricks whose summed extents grew beyond this factor since the build are too loose to cull
// well: rebuild instead of refitting.
constexpr double kMaxSpreadGrowth = 1.25;

}  // namespace

uint64_t sample_fingerprint(const ParticleArrays &p) {
  // Positions that change between steps nearly always change some of the sampled ones.
  uint64_t h = 1469598103934665603ull;
  const auto mix = [&h](double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    h = (h ^ bits) * 1099511628211ull;
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
}

const BrickSet &BrickCache::for_step(const ParticleArrays &p, int64_t step,
                                     const BrickOptions &options, double *build_ms,
                                     std::string *how) {
  const uint64_t fingerprint = sample_fingerprint(p);
  if (count_ == p.count() && step_ == step && positions_ == p.position_array(0).data() &&
      radii_ == p.radius_array().data() && mask_ == p.mask_array().data() &&
      mask_bits_ == p.mask_bits() && fingerprint_ == fingerprint) {
    *how = "cached";
    return set_;
  }
  const auto t0 = Clock::now();
  // A later step: particles moved a little, so keep the z-order and refit the bounds. The host
  // may have moved its arrays (LAMMPS reallocates when its ghost count grows), wrapped, dropped
  // or added particles (migration): refit_bricks re-sorts only the strays, recomputes every
  // bound from the particles themselves - culling stays exact whatever the indices now hold -
  // and asks for a rebuild when too much changed.
  if (count_ >= 0 && refit_bricks(p, kMaxSpreadGrowth, &set_, options)) {
    ++refits_;
    *how = "refit";
  } else {
    set_ = BrickSet();  // free the old permutation before building: keeps the peak low
    set_ = build_bricks(p, options);
    *how = "built";
  }
  remember(p, step, fingerprint);
  *build_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  return set_;
}

}  // namespace lantern
