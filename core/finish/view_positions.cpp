#include "core/finish/view_positions.h"

#include "core/common/cpu_features.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_POSITIONS_AVX2 1
#include <immintrin.h>
#else
#define LANTERN_POSITIONS_AVX2 0
#endif

namespace lantern {
namespace {

#if LANTERN_POSITIONS_AVX2
// Perspective distances of depth[0, count) (count a multiple of 4): Camera::
// window_depth_to_distance's operations lane by lane in the same order, 2 n f / (f + n - (2 d - 1)
// (f - n)) (no FMA: the target is AVX2 alone), and the background where d >= kBackgroundDepth,
// so the same floats. Why: a division a pixel, one at a time through a call, took 0.8 ms of each
// rank's half of a 1024^2 frame before every screen-space cue; the divider takes four lanes
// about as fast as one.
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
    const __m256d d = _mm256_cvtps_pd(d4);
    const __m256d z_ndc = _mm256_sub_pd(_mm256_mul_pd(two, d), one);
    const __m256d distance =
        _mm256_div_pd(numerator, _mm256_sub_pd(sum, _mm256_mul_pd(z_ndc, span)));
    const __m128 drawn = _mm_cmpnge_ps(d4, drawn_below);  // !(d >= background): NaN too
    _mm_storeu_ps(z + i, _mm_blendv_ps(background, _mm256_cvtpd_ps(distance), drawn));
  }
}
#endif

}  // namespace

void ViewPositions::build(const BandFrame &band, const Camera &camera, bool vector) {
  width_ = band.frame.width;
  height_ = camera.height;
  first_ = band.first;
  rows_ = band.frame.height;
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
  z_.resize(band.frame.pixel_count());
  size_t i = 0;
#if LANTERN_POSITIONS_AVX2
  if (vector && !orthographic_ && cpu_has_avx2()) {
    i = z_.size() / 4 * 4;
    perspective_distances_avx2(camera, band.frame.depth.data(), i, z_.data());
  }
#endif
  (void)vector;
  for (; i < z_.size(); ++i) {
    const float d = band.frame.depth[i];
    z_[i] = d >= kBackgroundDepth ? kBackground : float(camera.window_depth_to_distance(d));
  }
}

}  // namespace lantern
