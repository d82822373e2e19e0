// Level of detail, lod.select: nearest: which `keep` particles an opaque brick
// keeps. What an opaque brick shows is its front, so it keeps the particles it shows first, then
// the nearest of the rest, all at their own radius (the dropped ones are behind them).
//
// "The particles it shows": a coarse depth buffer of the brick's own spheres. Each sphere covers,
// at its front depth (view depth of the centre minus the radius), the sample points inside its
// projected disc; the samples are the pixel centres when spheres are under 2 px in radius, else a
// grid half a radius apart. A sphere nearest at some sample is a front particle, unless the
// caller's depth pyramid (hzb, or the CPU raster's, holding the bricks drawn before this one)
// proves it hidden: a brick on the surface of a solid shows one face, not the three its own buffer
// sees. A sub-pixel sphere that covers no pixel centre shows nowhere and is not a front particle.
// Priority: front particles, then the rest, then the proven hidden, each by front depth, ties by
// brick slot, so the choice is deterministic (the pyramid is, bricks being walked in one order).
//
// A brick that is not opaque at this budget keeps the uniform prefix and its growth instead
// (select_front returns false): one whose front particles outnumber `keep` kFrontOverflow times
// or more (a gas or a cloud's outskirts, where every particle is a front one, or a budget far
// below the brick's visible surface: keeping part of the front would leave holes). Between 1 and
// kFrontOverflow times, it keeps the nearest of its front particles. (A cheaper test before any
// per-particle work - summed disc area over footprint - was tried and dropped: sub-pixel blobs
// whose bricks are each thin but stack up opaque fell back, 15.9 dB instead of 24.1 at 25 % on
// the clustered cloud.)
//
// Ownership: FrontScratch owns buffers reused from brick to brick and frame to frame (no
// allocation per brick once grown). Thread-safety: one scratch per thread.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/culling/visible_brick.h"
#include "core/view/view_geometry.h"

namespace lantern {

// Sample spacing: a pixel, or this many projected sphere radii (at the brick's nearest depth)
// when that is wider.
inline constexpr double kFrontSampleRadii = 0.5;
// Most samples per brick particle: a large footprint gets a coarser grid, not a large buffer.
inline constexpr int64_t kFrontSamplesPerParticle = 4;
// Front particles this many times `keep` or more: not opaque at this budget. Measured at 25 %
// (lantern-bench --opaque-lod, 256^2): 1.5 gave 20.9 dB on fcc 1 M, 2 gave 23.3 dB and
// 3 the same; on void_impact at 1024^2, 3 lost 0.5 dB against 1.5.
inline constexpr double kFrontOverflow = 2.0;

// A brick keeping fewer particles than this is not worth a pass over all of its particles (the
// brick is expected hidden, or the budget is tiny): it keeps the uniform prefix.
inline constexpr uint32_t kMinFrontKeep = 8;

struct FrontScratch {
  std::vector<uint64_t> keys;      // per slot: (class, front depth, slot), smallest first
  std::vector<uint64_t> nearest;   // per sample: smallest (front depth, slot) covering it
  std::vector<float> disc;         // per slot: projected centre x, y and radius in samples
  std::vector<glm::dvec3> centre;  // per slot: view-space centre
  std::vector<uint32_t> kept;      // the kept particles, in brick order
};

// A 32-bit key that sorts like `depth` (any sign): the float's bits, flipped for negatives.
inline uint32_t depth_order_key(double depth) {
  const float f = float(depth);
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits & 0x80000000u ? ~bits : bits | 0x80000000u;
}

// Calls f(sample index) for each sample of the nx x ny grid inside the disc (centre x, y,
// radius r, in samples; sample (i, j) at (i + 0.5, j + 0.5)).
// The bounds are clamped to the grid (and one past it) before the conversion: a disc far off the
// grid (a sphere at a tiny near plane) may lie beyond int64's range, or be NaN.
template <typename F>
void for_samples_in_disc(float x, float y, float r, int64_t nx, int64_t ny, F &&f) {
  const auto clamped = [](float v, int64_t lo, int64_t hi) {
    return v > float(lo) ? (v < float(hi) ? int64_t(v) : hi) : lo;
  };
  const int64_t i0 = clamped(std::ceil(x - r - 0.5f), 0, nx);
  const int64_t i1 = clamped(std::floor(x + r - 0.5f), -1, nx - 1);
  const int64_t j0 = clamped(std::ceil(y - r - 0.5f), 0, ny);
  const int64_t j1 = clamped(std::floor(y + r - 0.5f), -1, ny - 1);
  for (int64_t j = j0; j <= j1; ++j)
    for (int64_t i = i0; i <= i1; ++i) {
      const float dx = float(i) + 0.5f - x, dy = float(j) + 0.5f - y;
      if (dx * dx + dy * dy <= r * r) f(size_t(j * nx + i));
    }
}

// Fills s->kept with the v.keep particles brick `v` keeps under lod.select: nearest, in brick
// order, and returns true; returns false (s->kept unspecified) when the brick's front particles
// do not fit in v.keep. `pos` and `radius` are typed readers (core/particles/typed_access.h);
// hidden(view centre, radius) says the caller's pyramid proves that sphere hidden.
template <typename Positions, typename Radii, typename Hidden>
bool select_front(const Positions &pos, const Radii &radius, const ViewGeometry &g,
                  const BrickSet &bricks, const VisibleBrick &v, const Hidden &hidden,
                  FrontScratch *s) {
  const Brick &brick = bricks.bricks[v.brick];
  const uint32_t *idx = bricks.order.data() + brick.first;
  const PixelRect &rect = v.rect;
  if (rect.empty() || v.keep < kMinFrontKeep) return false;
  const double r_px = v.radius * g.pixels_per_unit(std::max(v.near_depth, g.near_plane));
  double step = std::max(1.0, kFrontSampleRadii * r_px);
  const auto along = [&](int lo, int hi) { return int64_t(std::ceil((hi - lo + 1) / step)); };
  const int64_t most = std::max<int64_t>(64, kFrontSamplesPerParticle * brick.count);
  while (along(rect.x0, rect.x1) * along(rect.y0, rect.y1) > most) step *= 2.0;
  const int64_t nx = along(rect.x0, rect.x1), ny = along(rect.y0, rect.y1);
  s->nearest.assign(size_t(nx * ny), UINT64_MAX);
  s->keys.resize(brick.count);
  s->disc.resize(3 * size_t(brick.count));
  s->centre.resize(brick.count);
  for (uint32_t k = 0; k < brick.count; ++k) {
    const uint32_t i = idx[k];
    const glm::dvec3 c = g.to_view(pos.get(i));
    s->centre[k] = c;
    const double r = radius.get(i);
    // (class: 2 bits, depth: 31 bits, slot: 31 bits); the depth key's lowest bit is dropped.
    const uint64_t key = uint64_t(depth_order_key(-c.z - r) >> 1) << 31 | k;
    s->keys[k] = key;
    float *d = &s->disc[3 * size_t(k)];
    d[2] = -1.0f;  // covers nothing
    double x, y;
    if (!g.pixel_position(c, &x, &y)) continue;
    d[0] = float((x - rect.x0) / step), d[1] = float((y - rect.y0) / step);
    d[2] = float(r * g.pixels_per_unit(-c.z) / step);
    for_samples_in_disc(d[0], d[1], d[2], nx, ny,
                        [&](size_t at) { s->nearest[at] = std::min(s->nearest[at], key); });
  }
  uint32_t fronts = 0;
  for (uint32_t k = 0; k < brick.count; ++k) {
    const float *d = &s->disc[3 * size_t(k)];
    bool front = false;
    if (d[2] >= 0.0f)
      for_samples_in_disc(d[0], d[1], d[2], nx, ny,
                          [&](size_t at) { front |= s->nearest[at] == s->keys[k]; });
    if (front && hidden(s->centre[k], radius.get(idx[k]))) {
      s->keys[k] |= uint64_t(3) << 62;  // last: it would be culled anyway
      continue;
    }
    fronts += front;
    if (!front) s->keys[k] |= uint64_t(1) << 62;
  }
  if (double(fronts) >= kFrontOverflow * double(v.keep)) return false;
  std::nth_element(s->keys.begin(), s->keys.begin() + (v.keep - 1), s->keys.end());
  s->kept.resize(v.keep);
  for (uint32_t k = 0; k < v.keep; ++k) s->kept[k] = uint32_t(s->keys[k] & 0x7fffffffu);
  std::sort(s->kept.begin(), s->kept.end());
  for (uint32_t &k : s->kept) k = idx[k];
  return true;
}

}  // namespace lantern
