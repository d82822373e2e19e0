#include "core/culling/probabilistic/depth_confidence.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/culling/probabilistic/binomial_tail.h"

namespace lantern {
namespace {

constexpr float kUnknown = std::numeric_limits<float>::infinity();

// E(n(k)) of eq. 5: unique particles expected among k samples drawn from `nearer` particles.
double expected_unique(double k, double nearer) {
  if (nearer <= 1.0) return std::min(k, 1.0);
  const double m = 1.0 - 1.0 / nearer;
  return (1.0 - std::pow(m, k)) / (1.0 - m);
}

}  // namespace

double RayDensity::closer(double d) const {
  if (bins <= 0) return 0.0;
  const double t = (d - z0) / dz;
  if (!(t > 0.0)) return 0.0;
  if (t >= bins) return scale * cum[bins];
  const int i = int(t);
  const double f = t - i;
  return scale * (cum[i] + f * (cum[i + 1] - cum[i]));
}

double accumulate_confidence(double c, double alpha, uint32_t k, double nearer) {
  // n_k = Delta E(n(k)) = 1 - E(n(k-1)) / N (eq. 6): the share of this sample that is a new
  // particle; its uncovered area shrinks by (1 - alpha)^n_k (eq. 8).
  const double n = std::max(nearer, 1.0);  // the sample itself is one
  const double n_k = std::max(0.0, 1.0 - expected_unique(k - 1.0, n) / n);
  const double a = std::clamp(alpha, 0.0, 1.0);
  if (a >= 1.0) return n_k > 0.0 ? 1.0 : c;
  return 1.0 - (1.0 - c) * std::pow(1.0 - a, n_k);
}

double acceptance_probability(double d_s, double alpha, double d, double c, const RayDensity &ray) {
  if (!std::isfinite(d) || c <= 0.0) return 1.0;  // nothing to lose: any depth beats none
  const double behind_s = ray.behind(d_s);
  if (!(behind_s > 0.0)) return 0.0;  // eq. 13 unreachable: nothing behind the new depth
  const double target = ray.behind(d) / behind_s * c;  // eq. 13
  if (target >= 1.0) return 0.0;
  const double a = std::clamp(alpha, 1e-9, 1.0);
  // Eq. 15: unique particles needed; a particle covering the whole pixel needs one.
  const double n = a >= 1.0 ? 1.0 : std::log1p(-target) / std::log1p(-a);
  const double nearer = std::max(ray.closer(d_s), 1.0);  // the sample itself is nearer
  if (n > kUniqueShareMax * nearer) return 0.0;          // eq. 20 clamps: k(d_s) = infinity
  // Eq. 19 with M = 1 - 1 / N (eq. 18); N = 1 means every sample is the same particle.
  double k = 1.0;
  if (nearer > 1.0) k = std::ceil(std::log1p(-n / nearer) / std::log1p(-1.0 / nearer));
  k = std::max(k, 1.0);
  if (k > kSampleBudget) return 0.0;
  const double total = ray.total();
  const double p = total > 0.0 ? std::clamp(ray.closer(d_s) / total, 0.0, 1.0) : 0.0;  // eq. 22
  return binomial_tail(kSampleBudget, p, int(k));                                      // eq. 21
}

ConfidencePixel ConfidencePixel::empty() {
  return {kUnknown, 0.0f, kUnknown, 0.0f, 0, 0};
}

void update_pixel(ConfidencePixel *px, double d_s, double alpha, const RayDensity &ray, double u,
                  bool coin) {
  if (d_s <= px->d_cull) {  // lines 9-11
    px->c_cull =
        float(accumulate_confidence(px->c_cull, alpha, px->k_cull + 1, ray.closer(px->d_cull)));
    ++px->k_cull;
  }
  if (d_s <= px->d) {  // lines 12-14: updateAccumulationBuffer
    // Line 3 needs P(d_s) only for a nearer sample (eqs. 13-22 are the costly part of a sample).
    if (d_s < px->d && u <= (coin ? 0.5 : acceptance_probability(d_s, alpha, px->d, px->c, ray))) {
      px->d = float(d_s), px->c = float(std::clamp(alpha, 0.0, 1.0)), px->k = 1;
    } else {
      px->c = float(accumulate_confidence(px->c, alpha, px->k + 1, ray.closer(px->d)));
      ++px->k;
    }
  }
  // Lines 15-17; an empty cull buffer takes any depth.
  if (!std::isfinite(px->d_cull) ||
      occluded_particles(ray, px->d_cull, px->c_cull) < occluded_particles(ray, px->d, px->c))
    if (std::isfinite(px->d)) px->d_cull = px->d, px->c_cull = px->c, px->k_cull = px->k;
}

void ConfidencePyramid::build(const std::vector<ConfidencePixel> &pixels, int width, int height) {
  levels_.resize(1);
  Level &l0 = levels_[0];
  l0.w = width, l0.h = height;
  l0.d.resize(pixels.size()), l0.c.resize(pixels.size());
  for (size_t i = 0; i < pixels.size(); ++i) l0.d[i] = pixels[i].d_cull, l0.c[i] = pixels[i].c_cull;
  while (levels_.back().w > 1 || levels_.back().h > 1) {
    const Level &f = levels_.back();
    Level n;
    n.w = (f.w + 1) / 2, n.h = (f.h + 1) / 2;
    n.d.resize(size_t(n.w) * n.h), n.c.resize(size_t(n.w) * n.h);
    for (int y = 0; y < n.h; ++y)
      for (int x = 0; x < n.w; ++x) {
        float dmax = -kUnknown, csum = 0.0f;
        int count = 0;
        for (int yy = 2 * y; yy < std::min(2 * y + 2, f.h); ++yy)
          for (int xx = 2 * x; xx < std::min(2 * x + 2, f.w); ++xx) {
            const size_t i = size_t(yy) * f.w + xx;
            dmax = std::max(dmax, f.d[i]), csum += f.c[i], ++count;
          }
        n.d[size_t(y) * n.w + x] = dmax, n.c[size_t(y) * n.w + x] = csum / float(count);
      }
    levels_.push_back(std::move(n));
  }
}

ConfidencePyramid::Verdict ConfidencePyramid::test(const PixelRect &rect, double near) const {
  Verdict v;
  if (rect.empty() || levels_.empty()) return v;
  int level = 0;
  while (level + 1 < int(levels_.size()) &&
         std::max(rect.x1 - rect.x0, rect.y1 - rect.y0) >> level >= 8)
    ++level;
  const Level &l = levels_[size_t(level)];
  const int x0 = rect.x0 >> level, x1 = rect.x1 >> level, y0 = rect.y0 >> level,
            y1 = rect.y1 >> level;
  // The depth test first, stopping at the first texel as far as the box: a box that passes is
  // class P whatever its confidence, so most visible boxes cost a texel or two.
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x)
      if (!(double(l.d[size_t(y) * l.w + x]) < near)) return v;
  double csum = 0.0;
  int count = 0;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) csum += l.c[size_t(y) * l.w + x], ++count;
  v.failed = true;
  v.confidence = csum / count;
  return v;
}

}  // namespace lantern
