#include "core/render/density_splat.h"

#include <algorithm>
#include <cmath>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define LANTERN_DENSITY_X86 1
#endif

namespace lantern {
namespace {

constexpr double kCutoffSigmas = 3.0;
constexpr double kPixelFilterSigma = 0.5;  // px: the reconstruction filter every footprint gets
// W of the header lies in [2^23, 2^24): times 256 or times an 8-bit colour it stays below 2^32,
// which is what a 32 x 32 -> 64-bit vector multiply (SSE2 pmuludq) takes.
constexpr int kWeightMantissaBits = 24;

// One footprint's factors: the four per-channel multipliers M (W 256, W c0, W c1, W c2, each
// < 2^32), and the shift that takes M p (p = tx ty) to 2^-24 units of weight (+ 8 bits for the
// 256 that lets the colour channels share it).
struct Factors {
  uint64_t m[4];
  int shift;
};

// The pixel loops: per pixel p = tx ty (a 32-bit product), then per channel (M p + half) >>
// shift, added into the int64 sums. The four channels of a pixel are one 256-bit vector (AVX2)
// or two 128-bit ones (SSE2); integer arithmetic, so every path gives the same bits. With the
// kernel table this replaced double products, float->int conversions and an exact rounded / 255
// per colour channel: fcc 1 M at 1024^2, r 0.5, 175 -> 128 ms CPU for the two together.
void add_scalar(int64_t *image, int width, int channels, const AxisTaps &ax, const AxisTaps &ay,
                const Factors &f) {
  const uint64_t half = uint64_t(1) << (f.shift - 1);
  for (int y = 0; y < ay.count; ++y) {
    int64_t *out =
        image + (size_t(ay.first + y) * size_t(width) + size_t(ax.first)) * size_t(channels);
    const uint32_t ty = ay.taps[y];
    for (int i = 0; i < ax.count; ++i, out += channels) {
      const uint64_t p = uint64_t(uint32_t(ax.taps[i]) * ty);
      for (int c = 0; c < channels; ++c) out[c] += int64_t((f.m[c] * p + half) >> f.shift);
    }
  }
}

#ifdef LANTERN_DENSITY_X86
void add4_sse2(int64_t *image, int width, const AxisTaps &ax, const AxisTaps &ay,
               const Factors &f) {
  const __m128i m01 = _mm_set_epi64x(int64_t(f.m[1]), int64_t(f.m[0]));
  const __m128i m23 = _mm_set_epi64x(int64_t(f.m[3]), int64_t(f.m[2]));
  const __m128i half = _mm_set1_epi64x(int64_t(1) << (f.shift - 1));
  const __m128i shift = _mm_cvtsi32_si128(f.shift);
  for (int y = 0; y < ay.count; ++y) {
    auto *out = reinterpret_cast<__m128i *>(
        image + (size_t(ay.first + y) * size_t(width) + size_t(ax.first)) * 4);
    const uint32_t ty = ay.taps[y];
    for (int i = 0; i < ax.count; ++i, out += 2) {
      const __m128i p = _mm_set1_epi64x(int64_t(uint32_t(ax.taps[i]) * ty));
      const __m128i a = _mm_srl_epi64(_mm_add_epi64(_mm_mul_epu32(m01, p), half), shift);
      const __m128i b = _mm_srl_epi64(_mm_add_epi64(_mm_mul_epu32(m23, p), half), shift);
      _mm_storeu_si128(out, _mm_add_epi64(_mm_loadu_si128(out), a));
      _mm_storeu_si128(out + 1, _mm_add_epi64(_mm_loadu_si128(out + 1), b));
    }
  }
}

__attribute__((target("avx2"))) void add4_avx2(int64_t *image, int width, const AxisTaps &ax,
                                               const AxisTaps &ay, const Factors &f) {
  const __m256i m =
      _mm256_set_epi64x(int64_t(f.m[3]), int64_t(f.m[2]), int64_t(f.m[1]), int64_t(f.m[0]));
  const __m256i half = _mm256_set1_epi64x(int64_t(1) << (f.shift - 1));
  const __m128i shift = _mm_cvtsi32_si128(f.shift);
  for (int y = 0; y < ay.count; ++y) {
    auto *out = reinterpret_cast<__m256i *>(
        image + (size_t(ay.first + y) * size_t(width) + size_t(ax.first)) * 4);
    const uint32_t ty = ay.taps[y];
    for (int i = 0; i < ax.count; ++i, ++out) {
      const __m256i p = _mm256_set1_epi64x(int64_t(uint32_t(ax.taps[i]) * ty));
      const __m256i v = _mm256_srl_epi64(_mm256_add_epi64(_mm256_mul_epu32(m, p), half), shift);
      _mm256_storeu_si256(out, _mm256_add_epi64(_mm256_loadu_si256(out), v));
    }
  }
}

bool has_avx2() {
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
}
#endif

void add_footprint(DensityPixelLoop loop, int64_t *image, int width, int channels,
                   const AxisTaps &ax, const AxisTaps &ay, const Factors &f) {
#ifdef LANTERN_DENSITY_X86
  if (channels == 4 && loop != DensityPixelLoop::kScalar)
    return loop == DensityPixelLoop::kAuto && has_avx2() ? add4_avx2(image, width, ax, ay, f)
                                                         : add4_sse2(image, width, ax, ay, f);
#endif
  add_scalar(image, width, channels, ax, ay, f);
}

}  // namespace

DensitySplatter::DensitySplatter(const ViewGeometry &g, DensityImage *image)
    : g_(g), image_(image), table_(DensityKernelTable::get()) {}

bool DensitySplatter::project(const glm::dvec3 &c, double r, DensityFootprint *out) const {
  const double d = -c.z;
  if (!(d > g_.near_plane)) return false;
  // One division per particle (perspective), not three.
  const double inv_d = g_.orthographic ? 1.0 : 1.0 / d;
  const double x_ndc = g_.orthographic ? g_.sx * c.x + g_.tx : g_.sx * c.x * inv_d;
  const double y_ndc = g_.orthographic ? g_.sy * c.y + g_.ty : g_.sy * c.y * inv_d;
  out->px = 0.5 * (x_ndc + 1.0) * g_.width;
  out->py = 0.5 * (1.0 - y_ndc) * g_.height;
  const double s = r / kCutoffSigmas * (0.5 * g_.height * g_.sy) * inv_d;  // pixels_per_unit(d)
  // The table is indexed by sigma^2: no square root on the common path (its latency was 14 % of
  // the splat's own samples on fcc 1 M).
  out->sigma2 = s * s + kPixelFilterSigma * kPixelFilterSigma;
  return true;
}

bool DensitySplatter::splat(const glm::dvec3 &c, double r, double weight, const Rgb8 &color) {
  DensityFootprint f;
  return project(c, r, &f) && deposit(f, weight, color);
}

bool DensitySplatter::deposit(const DensityFootprint &fp, double weight, const Rgb8 &color) {
  if (!(weight >= kDensityMinWeight && weight < kDensityMaxWeight)) return false;
  const double px = fp.px, py = fp.py, sigma2 = fp.sigma2;
  AxisTaps ax, ay;
  const int k = table_.index_of_variance(sigma2);
  if (k < kDensitySigmaCount) {
    // Table footprints reach 25 px at most: a centre 2^30 px away touches nothing (and this keeps
    // the int conversions in range; also false for a non-finite centre).
    constexpr double kFar = double(1 << 30);
    if (!(std::abs(px) < kFar && std::abs(py) < kFar)) return false;
    if (!table_.taps(px, k, g_.width, &ax) || !table_.taps(py, k, g_.height, &ay)) return false;
  } else {
    const double sigma = std::sqrt(sigma2);
    if (!(std::isfinite(px) && std::isfinite(py))) return false;
    if (!density_computed_taps(px, sigma, g_.width, &scratch_x_, &ax) ||
        !density_computed_taps(py, sigma, g_.height, &scratch_y_, &ay))
      return false;
  }
  pixels_written_ += int64_t(ax.count) * ay.count;
  // W = weight 2^F in [2^23, 2^24): F = 23 - floor(log2 weight). Weights repeat (1, or n / keep
  // for a whole brick), so the factors are kept from the previous particle when they can be.
  if (weight != last_weight_ || color != last_color_) {
    const int f = kWeightMantissaBits - 1 - std::ilogb(weight);
    // Rounded, but kept below 2^24 so that W 256 < 2^32.
    const uint64_t w = std::min(uint64_t(std::ldexp(weight, f) + 0.5), (uint64_t(1) << 24) - 1);
    factors_m_[0] = w << 8;
    for (int k3 = 0; k3 < 3; ++k3) factors_m_[1 + k3] = w * color[size_t(k3)];
    factors_shift_ = f + 2 * kDensityTapBits + 8 - kDensityFractionBits;
    last_weight_ = weight, last_color_ = color;
  }
  const Factors fac{{factors_m_[0], factors_m_[1], factors_m_[2], factors_m_[3]}, factors_shift_};
  add_footprint(loop_, image_->sum.data(), g_.width, image_->channels, ax, ay, fac);
  return true;
}

}  // namespace lantern
