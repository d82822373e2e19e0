#include "core/finish/view_positions.h"

#include <algorithm>
#include <cstdint>

#include "core/common/cpu_features.h"
#include "core/common/rank_threads.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_POSITIONS_AVX2 1
#include <immintrin.h>
#else
#define LANTERN_POSITIONS_AVX2 0
#endif

namespace lantern {
namespace {

// The fewest rows a thread takes: a thread costs tens of microseconds to start, a row of 1024
// distances about one.
constexpr int64_t kMinRowsPerThread = 64;

#if LANTERN_POSITIONS_AVX2
// Perspective distances of depth[0, count) (count a multiple of 4): Camera::
// window_depth_to_distance's operations lane by lane in the same order, 2 n f / (f + n - (2 d - 1)
// (f - n)) (no FMA: the target is AVX2 alone), and the background where d >= kBackgroundDepth,
// so the same floats. Why: a division a pixel, one at a time through a call, took 0.8 ms of each
// rank's half of a 1024^2 frame before every screen-space cue; the divider takes four lanes
// about as fast as one. Four background pixels skip the division: the whole frame's distances
// 1.1-1.3 -> 0.8-1.0 ms on fcc 1 M and void_impact (lantern-bench-cues --kernels).
__attribute__((target("avx2"))) void perspective_distances_avx2(const Camera &camera,
                                                                const float *depth, size_t count,
                                                                float *z) {
  const double n = camera.near_plane, f = camera.far_plane;
  const __m256d numerator = _mm256_set1_pd(2.0 * n * f), sum = _mm256_set1_pd(f + n);
  const __m256d span = _mm256_set1_pd(f - n), two = _mm256_set1_pd(2.0), one = _mm256_set1_pd(1.0);
  const __m128 background = _mm_set1_ps(ViewPositions::kBackground);
  const __m128 drawn_below = _mm_set1_ps(kBackgroundDepth);
  for (size_t i = 0; i < count; i += 4) {
    const __m128 d4 = _mm_loadu_ps(depth + i);
    const __m128 drawn = _mm_cmpnge_ps(d4, drawn_below);  // !(d >= background): NaN too
    if (_mm_movemask_ps(drawn) == 0) {
      _mm_storeu_ps(z + i, background);
      continue;
    }
    const __m256d d = _mm256_cvtps_pd(d4);
    const __m256d z_ndc = _mm256_sub_pd(_mm256_mul_pd(two, d), one);
    const __m256d distance =
        _mm256_div_pd(numerator, _mm256_sub_pd(sum, _mm256_mul_pd(z_ndc, span)));
    _mm_storeu_ps(z + i, _mm_blendv_ps(background, _mm256_cvtpd_ps(distance), drawn));
  }
}

// Orthographic distances, alike: n + d (f - n) lane by lane, where the one-at-a-time loop makes
// a call and two conversions a pixel, as the perspective loop did before its kernel (not timed
// on its own: the cue bench's cameras are perspective).
__attribute__((target("avx2"))) void orthographic_distances_avx2(const Camera &camera,
                                                                 const float *depth, size_t count,
                                                                 float *z) {
  const double n = camera.near_plane, f = camera.far_plane;
  const __m256d near = _mm256_set1_pd(n), span = _mm256_set1_pd(f - n);
  const __m128 background = _mm_set1_ps(ViewPositions::kBackground);
  const __m128 drawn_below = _mm_set1_ps(kBackgroundDepth);
  for (size_t i = 0; i < count; i += 4) {
    const __m128 d4 = _mm_loadu_ps(depth + i);
    const __m256d distance = _mm256_add_pd(near, _mm256_mul_pd(_mm256_cvtps_pd(d4), span));
    const __m128 drawn = _mm_cmpnge_ps(d4, drawn_below);
    _mm_storeu_ps(z + i, _mm_blendv_ps(background, _mm256_cvtpd_ps(distance), drawn));
  }
}

// ViewPositions::drawn_minima of `rows` rows of `width` distances from row `z` on, `stride`
// apart: eight lanes of each minimum, _mm256_min_ps(v, m) being (v < m) ? v : m as std::min(m,
// v) is, and the background's negation masked to +infinity (the one-at-a-time loop skips it).
// Min is exact, so the lanes' order changes nothing. Why: the one-at-a-time loop took 1.5-1.6 ms
// of each rank's half of void_impact's 1024^2 frame, half the depth cue's stage.
__attribute__((target("avx2"))) void drawn_minima_avx2(const float *z, size_t stride, int rows,
                                                       int width, float minima[2]) {
  const __m256 background = _mm256_set1_ps(ViewPositions::kBackground);
  const __m256 sign = _mm256_set1_ps(-0.0f);
  __m256 nearest = background, negated = background;
  for (int y = 0; y < rows; ++y) {
    const float *row = z + size_t(y) * stride;
    int x = 0;
    for (; x + 8 <= width; x += 8) {
      const __m256 v = _mm256_loadu_ps(row + x);
      nearest = _mm256_min_ps(v, nearest);
      const __m256 drawn = _mm256_cmp_ps(v, background, _CMP_NEQ_UQ);
      negated = _mm256_min_ps(_mm256_blendv_ps(background, _mm256_xor_ps(v, sign), drawn), negated);
    }
    for (; x < width; ++x) {
      if (row[x] == ViewPositions::kBackground) continue;
      minima[0] = std::min(minima[0], row[x]);
      minima[1] = std::min(minima[1], -row[x]);
    }
  }
  alignas(32) float lanes[2][8];
  _mm256_store_ps(lanes[0], nearest);
  _mm256_store_ps(lanes[1], negated);
  for (int k = 0; k < 8; ++k) {
    minima[0] = std::min(minima[0], lanes[0][k]);
    minima[1] = std::min(minima[1], lanes[1][k]);
  }
}
#endif

}  // namespace

std::array<float, 2> ViewPositions::drawn_minima(const RowBand &rows, bool vector) const {
  std::array<float, 2> minima = {kBackground, kBackground};
  if (rows.rows() <= 0) return minima;
#if LANTERN_POSITIONS_AVX2
  if (vector && cpu_has_avx2()) {
    drawn_minima_avx2(row(rows.y0), stride(), rows.rows(), width_, minima.data());
    return minima;
  }
#endif
  (void)vector;
  for (int y = rows.y0; y < rows.y1; ++y)
    for (int x = 0; x < width_; ++x) {
      const float v = z(x, y);
      if (v == kBackground) continue;
      minima[0] = std::min(minima[0], v);
      minima[1] = std::min(minima[1], -v);
    }
  return minima;
}

void ViewPositions::begin(const BandFrame &band, const Camera &camera) {
  const RowBand held = band.held_rows();
  width_ = band.frame.width;
  height_ = camera.height;
  first_ = held.y0;
  rows_ = std::max(0, held.rows());
  orthographic_ = camera.orthographic;
  // A pixel centre's normalised device x is 2 (x + 0.5) / W - 1 (y flipped: row 0 is the top).
  // Perspective: x_view = (x_ndc + P[2][0]) * z / P[0][0]; orthographic: (x_ndc - P[3][0]) /
  // P[0][0]. glm's matrices are column-major: P[column][row].
  const glm::dmat4 &p = camera.projection;
  const double sx = 1.0 / p[0][0], sy = 1.0 / p[1][1];
  const double shift_x = orthographic_ ? -p[3][0] : p[2][0];
  const double shift_y = orthographic_ ? -p[3][1] : p[2][1];
  x_scale_ = float(2.0 / camera.width * sx);
  x_offset_ = float((shift_x - 1.0) * sx);
  y_scale_ = float(-2.0 / camera.height * sy);
  y_offset_ = float((shift_y + 1.0) * sy);
  ppu_ = float(0.5 * camera.height * p[1][1]);
  // The border's background (kept from the last build of the same size: only the held rows'
  // distances are ever written).
  const bool border_kept = border_rows_ == rows_ && border_width_ == width_;
  z_.resize(size_t(rows_ + 2 * kBorder) * stride());
  const size_t border_rows = size_t(kBorder) * stride(), width = size_t(width_);
  if (!border_kept) {
    std::fill(z_.begin(), z_.begin() + ptrdiff_t(border_rows), kBackground);
    std::fill(z_.end() - ptrdiff_t(border_rows), z_.end(), kBackground);
    for (int r = 0; r < rows_; ++r) {
      float *out = &z_[size_t(r + kBorder) * stride() + size_t(kBorder)];
      std::fill(out - kBorder, out, kBackground);
      std::fill(out + width, out + width + kBorder, kBackground);
    }
    border_rows_ = rows_, border_width_ = width_;
  }
}

void ViewPositions::build_rows(const BandFrame &band, const Camera &camera, int y0, int y1,
                               bool vector, int threads) {
  const size_t width = size_t(width_);
  const int first = std::max(y0, first_), count = std::max(0, std::min(y1, last_row()) - first);
  // Each row on its own: any number of parts gives the same distances.
  run_in_parts(
      parts_for(threads, count, kMinRowsPerThread), count, [&](int, int64_t r0, int64_t r1) {
        for (int y = first + int(r0); y < first + int(r1); ++y) {
          float *out = &z_[size_t(y - first_ + kBorder) * stride() + size_t(kBorder)];
          const float *depth = &band.frame.depth[size_t(y - band.first) * width];
          size_t i = 0;
#if LANTERN_POSITIONS_AVX2
          if (vector && cpu_has_avx2()) {
            i = width / 4 * 4;
            if (orthographic_)
              orthographic_distances_avx2(camera, depth, i, out);
            else
              perspective_distances_avx2(camera, depth, i, out);
          }
#endif
          for (; i < width; ++i) {
            const float d = depth[i];
            out[i] =
                d >= kBackgroundDepth ? kBackground : float(camera.window_depth_to_distance(d));
          }
        }
      });
  (void)vector;
}

void ViewPositions::build(const BandFrame &band, const Camera &camera, bool vector, int threads) {
  begin(band, camera);
  build_rows(band, camera, first_, last_row(), vector, threads);
}

}  // namespace lantern
