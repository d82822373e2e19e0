#include "core/finish/outline.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include "core/common/cpu_features.h"
#include "core/common/rank_threads.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_OUTLINE_AVX2 1
#include <immintrin.h>
#else
#define LANTERN_OUTLINE_AVX2 0
#endif

namespace lantern {
namespace {

// The fewest rows a thread takes: a thread costs tens of microseconds to start, a row of 1024
// pixels one or two.
constexpr int64_t kMinRowsPerThread = 64;

// Both passes fold a pixel's neighbours into its own distance in one order, m = std::max(m, v)
// ((m < v) ? v : m: a NaN pixel stays NaN, a NaN neighbour is passed over); the vector loops
// below fold the same values in the same order, _mm256_max_ps(v, m) being that comparison.

// Row pass of pixels [x0, x1) of one row: the farthest distance within `reach` columns.
void row_max_of(const float *z, int w, int reach, int x0, int x1, float *out) {
  for (int x = x0; x < x1; ++x) {
    float m = z[x];
    const int last = std::min(w - 1, x + reach);
    for (int k = std::max(0, x - reach); k <= last; ++k) m = std::max(m, z[k]);
    out[x] = m;
  }
}

// Column pass of pixels [x0, x1) of row y: outlined where drawn and the farthest distance within
// `reach` rows (rows[k]: the row pass of row y0 + k, k < count) is farther by more than the jump.
void outline_row(const float *z, const float *const *rows, int count, const OutlineStyle &style,
                 int x0, int x1, uint8_t *rgba) {
  for (int x = x0; x < x1; ++x) {
    if (z[x] == ViewPositions::kBackground) continue;
    float far = z[x];
    for (int k = 0; k < count; ++k) far = std::max(far, rows[k][x]);
    if (far - z[x] > style.jump) std::copy(style.color, style.color + 3, rgba + 4 * size_t(x));
  }
}

#if LANTERN_OUTLINE_AVX2
// row_max_of for the columns whose whole neighbourhood lies in the row ([reach, w - reach)),
// eight at a time, then the rest one at a time. Why: one pixel at a time the two passes took
// 2.5-2.8 ms of each rank's half of void_impact's 1024^2 frame (2 ranks, width 1).
__attribute__((target("avx2"))) void row_max_avx2(const float *z, int w, int reach, float *out) {
  int x = reach;
  for (; x + 8 <= w - reach; x += 8) {
    __m256 m = _mm256_loadu_ps(z + x);
    for (int k = -reach; k <= reach; ++k) m = _mm256_max_ps(_mm256_loadu_ps(z + x + k), m);
    _mm256_storeu_ps(out + x, m);
  }
  row_max_of(z, w, reach, 0, std::min(reach, w), out);
  row_max_of(z, w, reach, std::max(x, std::min(reach, w)), w, out);
}

// outline_row eight pixels at a time: a pixel's RGBA as one 32-bit lane, the colour written
// under the mask of outlined pixels (alpha kept).
__attribute__((target("avx2"))) void outline_row_avx2(const float *z, const float *const *rows,
                                                      int count, const OutlineStyle &style, int w,
                                                      uint8_t *rgba) {
  uint32_t colour = 0;
  std::memcpy(&colour, style.color, 3);  // bytes R, G, B, then the kept alpha's byte as 0
  const __m256i rgb = _mm256_set1_epi32(int32_t(colour));
  const __m256i alpha = _mm256_set1_epi32(int32_t(0xff000000u));
  const __m256 background = _mm256_set1_ps(ViewPositions::kBackground);
  const __m256 jump = _mm256_set1_ps(style.jump);
  int x = 0;
  for (; x + 8 <= w; x += 8) {
    const __m256 near = _mm256_loadu_ps(z + x);
    __m256 far = near;
    for (int k = 0; k < count; ++k) far = _mm256_max_ps(_mm256_loadu_ps(rows[k] + x), far);
    const __m256 outlined =
        _mm256_and_ps(_mm256_cmp_ps(near, background, _CMP_NEQ_UQ),
                      _mm256_cmp_ps(_mm256_sub_ps(far, near), jump, _CMP_GT_OQ));
    const int bits = _mm256_movemask_ps(outlined);
    if (bits == 0) continue;
    auto *pixels = reinterpret_cast<__m256i *>(rgba + 4 * size_t(x));
    const __m256i old = _mm256_loadu_si256(pixels);
    const __m256i coloured = _mm256_or_si256(_mm256_and_si256(old, alpha), rgb);
    _mm256_storeu_si256(pixels, _mm256_blendv_epi8(old, coloured, _mm256_castps_si256(outlined)));
  }
  outline_row(z, rows, count, style, x, w, rgba);
}
#endif

}  // namespace

void draw_outlines(const ViewPositions &positions, const OutlineStyle &style, BandFrame *band,
                   bool vector, int threads) {
  const int w = positions.width(), first = positions.first_row(), last = positions.last_row();
  const int reach = style.width;
#if LANTERN_OUTLINE_AVX2
  const bool avx2 = vector && cpu_has_avx2();
#else
  const bool avx2 = false;
  (void)vector;
#endif
  // The farthest distance within `reach` columns, for every held row; then the farthest of those
  // within `reach` rows: the square neighbourhood's maximum in O(reach) per pixel. Each row on
  // its own in both passes: any number of parts gives the same bytes.
  std::vector<float> row_max(size_t(last - first) * size_t(w));
  const auto row_maxima = [&](int, int64_t y_begin, int64_t y_end) {
    for (int y = first + int(y_begin); y < first + int(y_end); ++y) {
      float *out = &row_max[size_t(y - first) * size_t(w)];
#if LANTERN_OUTLINE_AVX2
      if (avx2) {
        row_max_avx2(positions.row(y), w, reach, out);
        continue;
      }
#endif
      row_max_of(positions.row(y), w, reach, 0, w, out);
    }
  };
  const int64_t held = std::max(0, last - first);
  run_in_parts(parts_for(threads, held, kMinRowsPerThread), held, row_maxima);
  const int y0 = band->owned.y0;
  const auto outline_rows = [&](int, int64_t y_begin, int64_t y_end) {
    std::vector<const float *> rows;
    for (int y = y0 + int(y_begin); y < y0 + int(y_end); ++y) {
      const int r0 = std::max(first, y - reach), r1 = std::min(last - 1, y + reach);
      rows.clear();
      for (int k = r0; k <= r1; ++k) rows.push_back(&row_max[size_t(k - first) * size_t(w)]);
      uint8_t *rgba = &band->frame.rgba[size_t(y - band->first) * size_t(w) * 4];
#if LANTERN_OUTLINE_AVX2
      if (avx2) {
        outline_row_avx2(positions.row(y), rows.data(), int(rows.size()), style, w, rgba);
        continue;
      }
#endif
      outline_row(positions.row(y), rows.data(), int(rows.size()), style, 0, w, rgba);
    }
  };
  const int64_t owned = std::max(0, band->owned.y1 - y0);
  run_in_parts(parts_for(threads, owned, kMinRowsPerThread), owned, outline_rows);
}

}  // namespace lantern
