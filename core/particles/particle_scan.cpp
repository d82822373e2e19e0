#include "core/particles/particle_scan.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_EXTENT_AVX2 1
#include <immintrin.h>
#else
#define LANTERN_EXTENT_AVX2 0
#endif

#include "core/common/cpu_features.h"
#include "core/common/rank_threads.h"
#include "core/common/stream_prefetch.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

// The sign of a bound that came out exactly zero: the first kept, finite particle in [begin, end)
// whose coordinate c is zero, since a one-pass min (or max) keeps the first of equal values and
// -0 equals +0. Stops there, usually at once.
template <typename Positions, typename Keep>
double first_zero(const Positions &pos, const Keep &keep, int64_t begin, int64_t end, int c) {
  for (int64_t i = begin; i < end; ++i) {
    if (!keep.get(i)) continue;
    const glm::dvec3 p = pos.get(i);
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && p[c] == 0.0) return p[c];
  }
  return 0.0;
}

#if LANTERN_EXTENT_AVX2
// The bounds and finite count of packed xyz doubles [begin, begin + 8 * blocks), every particle
// kept, into lo/hi (folded into what they hold) and *finite. Why: the lanes below are scalar
// minsd/maxsd, six chains a particle and a finiteness test, about three passes' time over the
// positions (19 M fcc particles, one thread: 110-117 ms against a streaming pass of 36). Here
// eight particles' 24 coordinates are six vectors (x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3,
// twice), each lane always the same axis, so three min and three max accumulators need no
// shuffle until the end. Min and max give the values a pass in order gives, except which zero
// (-0 or +0) a bound keeps, which the caller settles (first_zero). A block of eight with a
// non-finite coordinate is taken one particle at a time, with the scalar path's test. The
// positions are asked for ahead (stream_prefetch.h).
__attribute__((target("avx2"))) void scan_packed_blocks(const double *xyz, int64_t begin,
                                                        int64_t blocks, double lo[3], double hi[3],
                                                        int64_t *finite) {
  const double inf = Extent::kInf;
  __m256d lo_a = _mm256_set1_pd(inf), lo_b = lo_a, lo_c = lo_a;
  __m256d hi_a = _mm256_set1_pd(-inf), hi_b = hi_a, hi_c = hi_a;
  int64_t count = 0;
  for (int64_t k = 0; k < blocks; ++k) {
    const double *p = xyz + 3 * (begin + 8 * k);
    ask_stream_ahead(p, 3);
    const __m256d a0 = _mm256_loadu_pd(p), b0 = _mm256_loadu_pd(p + 4);
    const __m256d c0 = _mm256_loadu_pd(p + 8), a1 = _mm256_loadu_pd(p + 12);
    const __m256d b1 = _mm256_loadu_pd(p + 16), c1 = _mm256_loadu_pd(p + 20);
    // v - v is +0 for finite v and NaN otherwise: no bit set anywhere means all finite.
    const __m256d nan =
        _mm256_or_pd(_mm256_or_pd(_mm256_or_pd(_mm256_sub_pd(a0, a0), _mm256_sub_pd(b0, b0)),
                                  _mm256_or_pd(_mm256_sub_pd(c0, c0), _mm256_sub_pd(a1, a1))),
                     _mm256_or_pd(_mm256_sub_pd(b1, b1), _mm256_sub_pd(c1, c1)));
    if (_mm256_testz_si256(_mm256_castpd_si256(nan), _mm256_castpd_si256(nan))) {
      lo_a = _mm256_min_pd(a1, _mm256_min_pd(a0, lo_a));
      lo_b = _mm256_min_pd(b1, _mm256_min_pd(b0, lo_b));
      lo_c = _mm256_min_pd(c1, _mm256_min_pd(c0, lo_c));
      hi_a = _mm256_max_pd(a1, _mm256_max_pd(a0, hi_a));
      hi_b = _mm256_max_pd(b1, _mm256_max_pd(b0, hi_b));
      hi_c = _mm256_max_pd(c1, _mm256_max_pd(c0, hi_c));
      count += 8;
      continue;
    }
    for (int j = 0; j < 8; ++j) {
      const double *q = p + 3 * j;
      if (!(std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]))) continue;
      for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], q[c]), hi[c] = std::max(hi[c], q[c]);
      ++count;
    }
  }
  alignas(32) double l[3][4], h[3][4];
  _mm256_store_pd(l[0], lo_a), _mm256_store_pd(l[1], lo_b), _mm256_store_pd(l[2], lo_c);
  _mm256_store_pd(h[0], hi_a), _mm256_store_pd(h[1], hi_b), _mm256_store_pd(h[2], hi_c);
  // Lane (v, k) of the three vectors holds axis (4 v + k) mod 3.
  for (int v = 0; v < 3; ++v)
    for (int k = 0; k < 4; ++k) {
      const int c = (4 * v + k) % 3;
      lo[c] = std::min(lo[c], l[v][k]), hi[c] = std::max(hi[c], h[v][k]);
    }
  *finite += count;
}
#endif

// The common case (one radius, no coloring scalar): the same result as Extent::add_particle for
// every particle in order, bit for bit. Four lanes take every fourth particle so that the min and
// max chains run side by side; lanes give the same values as one pass, and where a bound is zero
// (-0 or +0, equal but two encodings) first_zero finds the one a single pass keeps.
// Particles outside the group (`keep`) are not counted at all, neither finite nor non-finite.
template <typename Positions, typename Keep>
Extent scan_positions(const Positions &pos, const Keep &keep, int64_t begin, int64_t end,
                      double radius) {
  constexpr int kLanes = 4;
  double lo[kLanes][3], hi[kLanes][3];
  for (int l = 0; l < kLanes; ++l)
    for (int c = 0; c < 3; ++c) lo[l][c] = Extent::kInf, hi[l][c] = -Extent::kInf;
  int64_t finite = 0, left_out = 0;
  const auto add = [&](int l, int64_t i) {
    if (!keep.get(i)) {
      ++left_out;
      return;
    }
    const glm::dvec3 p = pos.get(i);
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) return;
    lo[l][0] = std::min(lo[l][0], p.x), lo[l][1] = std::min(lo[l][1], p.y);
    lo[l][2] = std::min(lo[l][2], p.z);
    hi[l][0] = std::max(hi[l][0], p.x), hi[l][1] = std::max(hi[l][1], p.y);
    hi[l][2] = std::max(hi[l][2], p.z);
    ++finite;
  };
  int64_t i = begin;
#if LANTERN_EXTENT_AVX2
  if constexpr (std::is_same_v<Positions, InterleavedPositions<double>> &&
                std::is_same_v<Keep, KeepAll>) {
    if (pos.stride == int64_t(3 * sizeof(double)) &&
        reinterpret_cast<uintptr_t>(pos.base) % alignof(double) == 0 && cpu_has_avx2()) {
      const int64_t blocks = (end - begin) / 8;
      scan_packed_blocks(reinterpret_cast<const double *>(pos.base), begin, blocks, lo[0], hi[0],
                         &finite);
      i = begin + 8 * blocks;
    }
  }
#endif
  for (; i + kLanes <= end; i += kLanes)
    for (int l = 0; l < kLanes; ++l) add(l, i + l);
  for (; i < end; ++i) add(0, i);
  Extent e;
  for (int c = 0; c < 3; ++c) {
    double a = lo[0][c], b = hi[0][c];
    for (int l = 1; l < kLanes; ++l) a = std::min(a, lo[l][c]), b = std::max(b, hi[l][c]);
    if (a == 0.0) a = first_zero(pos, keep, begin, end, c);
    if (b == 0.0) b = first_zero(pos, keep, begin, end, c);
    e.lo[size_t(c)] = a, e.hi[size_t(c)] = b;
  }
  e.finite_count = finite;
  e.nonfinite_count = end - begin - left_out - finite;
  if (finite > 0 && std::isfinite(radius)) e.max_radius = radius;
  return e;
}

// Later parts into the first: min and max keep the first of equal values (std::min/max), so
// merging in part order gives one pass's bits, -0 and +0 included.
void merge_part(const Extent &later, Extent *e) {
  for (size_t k = 0; k < 3; ++k) {
    e->lo[k] = std::min(e->lo[k], later.lo[k]);
    e->hi[k] = std::max(e->hi[k], later.hi[k]);
  }
  e->finite_count += later.finite_count;
  e->nonfinite_count += later.nonfinite_count;
  e->max_radius = std::max(e->max_radius, later.max_radius);
}

}  // namespace

Extent scan_particles(const ParticleArrays &particles, bool per_particle_radius, double radius,
                      int threads) {
  const bool use_radius_array = per_particle_radius && particles.has_radius();
  const bool has_scalar = particles.has_scalar();
  if (!use_radius_array && !has_scalar)
    return visit_positions(particles, [&](const auto &pos) {
      return visit_kept(particles, [&](const auto &keep) {
        const int parts = parts_for(threads, particles.count(), int64_t(1) << 16);
        std::vector<Extent> part(static_cast<size_t>(parts));
        run_in_parts(parts, particles.count(), [&](int p, int64_t b, int64_t e) {
          part[size_t(p)] = scan_positions(pos, keep, b, e, radius);
        });
        for (size_t p = 1; p < part.size(); ++p) merge_part(part[p], &part[0]);
        return part[0];
      });
    });
  Extent e;
  for (int64_t i = 0; i < particles.count(); ++i) {
    if (!particles.kept(i)) continue;
    const glm::dvec3 p = particles.position(i);
    const double r = use_radius_array ? particles.radius(i) : radius;
    if (e.add_particle(p.x, p.y, p.z, r) && has_scalar) e.add_scalar(particles.scalar(i));
  }
  return e;
}

}  // namespace lantern
