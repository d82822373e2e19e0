#include "core/finish/depth_cue.h"

#include <algorithm>
#include <cmath>

#include "core/common/cpu_features.h"
#include "core/common/rank_threads.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_DEPTH_CUE_AVX2 1
#include <immintrin.h>
#else
#define LANTERN_DEPTH_CUE_AVX2 0
#endif

namespace lantern {

namespace {

// The fewest rows a thread takes: a thread costs tens of microseconds to start, a row of 1024
// pixels about one.
constexpr int64_t kMinRowsPerThread = 64;

float fade_fraction(const DepthCueStyle &style, float z) {
  if (!(style.end > style.start)) return z > style.start ? 1.0f : 0.0f;
  return std::clamp((z - style.start) / (style.end - style.start), 0.0f, 1.0f);
}

// Pixels [x0, x1) of one row, one at a time.
void fade_row(const float *z, const DepthCueStyle &style, int x0, int x1, uint8_t *rgba) {
  for (int x = x0; x < x1; ++x) {
    if (z[x] == ViewPositions::kBackground) continue;
    const float f = fade_fraction(style, z[x]);
    if (style.fade_alpha) {
      rgba[4 * x + 3] = uint8_t(float(rgba[4 * x + 3]) * (1.0f - f) + 0.5f);
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      const float from = rgba[4 * x + c];
      // Rounded to nearest: the blend lies in [0, 255].
      rgba[4 * x + c] = uint8_t(from + f * (float(style.color[c]) - from) + 0.5f);
    }
  }
}

#if LANTERN_DEPTH_CUE_AVX2
// fade_row eight pixels at a time: the same float operations in the same order (no FMA in this
// target), std::clamp's comparisons as blends (a NaN stays NaN), a pixel's RGBA as one 32-bit
// lane; the tail one at a time. Why: one at a time it took about a millisecond of each rank's
// half of a 1024^2 frame, as long as the rest of the depth cue's stage.
__attribute__((target("avx2"))) void fade_row_avx2(const float *z, const DepthCueStyle &style,
                                                   int w, uint8_t *rgba) {
  const __m256 background = _mm256_set1_ps(ViewPositions::kBackground);
  const __m256 start = _mm256_set1_ps(style.start), span = _mm256_set1_ps(style.end - style.start);
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f), half = _mm256_set1_ps(0.5f);
  const bool ramp = style.end > style.start;
  const __m256i byte = _mm256_set1_epi32(0xff);
  int x = 0;
  for (; x + 8 <= w; x += 8) {
    const __m256 d = _mm256_loadu_ps(z + x);
    const __m256 drawn = _mm256_cmp_ps(d, background, _CMP_NEQ_UQ);
    if (_mm256_movemask_ps(drawn) == 0) continue;
    __m256 f;
    if (ramp) {
      const __m256 v = _mm256_div_ps(_mm256_sub_ps(d, start), span);
      f = _mm256_blendv_ps(v, one, _mm256_cmp_ps(one, v, _CMP_LT_OQ));
      f = _mm256_blendv_ps(f, zero, _mm256_cmp_ps(v, zero, _CMP_LT_OQ));
    } else {
      f = _mm256_and_ps(_mm256_cmp_ps(d, start, _CMP_GT_OQ), one);
    }
    auto *pixels = reinterpret_cast<__m256i *>(rgba + 4 * size_t(x));
    const __m256i old = _mm256_loadu_si256(pixels);
    __m256i faded;
    if (style.fade_alpha) {
      const __m256 a = _mm256_cvtepi32_ps(_mm256_srli_epi32(old, 24));
      const __m256i out =
          _mm256_cvttps_epi32(_mm256_add_ps(_mm256_mul_ps(a, _mm256_sub_ps(one, f)), half));
      faded = _mm256_or_si256(_mm256_and_si256(old, _mm256_set1_epi32(0x00ffffff)),
                              _mm256_slli_epi32(_mm256_and_si256(out, byte), 24));
    } else {
      faded = _mm256_and_si256(old, _mm256_set1_epi32(int32_t(0xff000000u)));
      for (int c = 0; c < 3; ++c) {
        const __m256 from =
            _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srli_epi32(old, 8 * c), byte));
        const __m256 to = _mm256_set1_ps(float(style.color[c]));
        const __m256i out = _mm256_cvttps_epi32(
            _mm256_add_ps(_mm256_add_ps(from, _mm256_mul_ps(f, _mm256_sub_ps(to, from))), half));
        faded = _mm256_or_si256(faded, _mm256_slli_epi32(_mm256_and_si256(out, byte), 8 * c));
      }
    }
    _mm256_storeu_si256(pixels, _mm256_blendv_epi8(old, faded, _mm256_castps_si256(drawn)));
  }
  fade_row(z, style, x, w, rgba);
}
#endif

}  // namespace

void apply_depth_cue(const ViewPositions &positions, const DepthCueStyle &style, BandFrame *band,
                     bool vector, int threads) {
  const int w = positions.width();
#if LANTERN_DEPTH_CUE_AVX2
  const bool avx2 = vector && cpu_has_avx2();
#else
  const bool avx2 = false;
  (void)vector;
#endif
  const int y0 = band->owned.y0;
  const auto fade_rows = [&](int, int64_t y_begin, int64_t y_end) {  // each row on its own
    for (int y = y0 + int(y_begin); y < y0 + int(y_end); ++y) {
      uint8_t *rgba = &band->frame.rgba[size_t(y - band->first) * size_t(w) * 4];
#if LANTERN_DEPTH_CUE_AVX2
      if (avx2) {
        fade_row_avx2(positions.row(y), style, w, rgba);
        continue;
      }
#endif
      fade_row(positions.row(y), style, 0, w, rgba);
    }
  };
  const int64_t owned = std::max(0, band->owned.y1 - y0);
  run_in_parts(parts_for(threads, owned, kMinRowsPerThread), owned, fade_rows);
}

}  // namespace lantern
