#include "core/culling/occlusion_estimate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace lantern {
namespace {

constexpr int kGrid = 64;                 // coarse cells per image side
constexpr int64_t kFewParticles = 20000;  // below this the GPU is cheaper than any culling pass
constexpr double kHiddenWorthIt = 0.5;    // hzb pays when at least half is expected hidden

std::string percent(double f) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f%%", 100.0 * f);
  return buf;
}

}  // namespace

CoarseTransmittance::CoarseTransmittance(const ViewGeometry &g)
    : transmittance_(size_t(kGrid) * kGrid, 1.0),
      cell_w_(double(g.width) / kGrid),
      cell_h_(double(g.height) / kGrid) {}

double CoarseTransmittance::splat(const VisibleBrick &v, const ViewGeometry &g) {
  if (v.rect.empty()) return 0.0;
  const double r_px =
      v.radius * v.radius_scale * g.pixels_per_unit(std::max(v.near_depth, g.near_plane));
  const double area = double(v.rect.area());
  const double a = double(v.keep) * 3.14159265 * r_px * r_px / area;  // optical depth
  const int cx0 = int(v.rect.x0 / cell_w_), cx1 = std::min(kGrid - 1, int(v.rect.x1 / cell_w_));
  const int cy0 = int(v.rect.y0 / cell_h_), cy1 = std::min(kGrid - 1, int(v.rect.y1 / cell_h_));
  double t_sum = 0.0;
  for (int y = cy0; y <= cy1; ++y)
    for (int x = cx0; x <= cx1; ++x) t_sum += transmittance_[size_t(y) * kGrid + x];
  const double t_mean = t_sum / double((cx1 - cx0 + 1) * (cy1 - cy0 + 1));
  // Inside a slab of optical depth a, a share (1 - e^-a) / a of the spheres shows.
  const double self = a > 1e-6 ? (1.0 - std::exp(-a)) / a : 1.0;
  const double pass = std::exp(-a);
  for (int y = cy0; y <= cy1; ++y)
    for (int x = cx0; x <= cx1; ++x) transmittance_[size_t(y) * kGrid + x] *= pass;
  return double(v.keep) * t_mean * self;
}

OcclusionChoice choose_occlusion(const VisibleBricks &visible, const ViewGeometry &g) {
  OcclusionChoice c;
  int64_t candidates = 0;
  double weighted_px = 0.0;
  for (const VisibleBrick &v : visible) {
    candidates += v.keep;
    weighted_px += double(v.keep) * v.radius * v.radius_scale *
                   g.pixels_per_unit(std::max(v.near_depth, g.near_plane));
  }
  if (candidates == 0) {
    c.reason = "nothing in view";
    return c;
  }
  c.sphere_pixels = weighted_px / double(candidates);

  CoarseTransmittance grid(g);
  double expected_visible = 0.0;
  for (const VisibleBrick &v : visible) expected_visible += grid.splat(v, g);
  c.hidden_estimate = std::clamp(1.0 - expected_visible / double(candidates), 0.0, 1.0);
  char px[32];
  std::snprintf(px, sizeof px, "%.2f", c.sphere_pixels);
  if (candidates < kFewParticles) {
    c.reason = "few particles in view (" + std::to_string(candidates) + ")";
  } else if (c.hidden_estimate < kHiddenWorthIt) {
    c.reason = "sparse: est. " + percent(c.hidden_estimate) + " hidden, r ~ " + px + " px";
  } else {
    // Sub-pixel spheres still hide each other once enough of them cover each pixel centre
    // (the estimate already counts coverage by area), so size alone does not rule hzb out.
    c.mode = OcclusionMode::kHzb;
    c.reason = "dense: est. " + percent(c.hidden_estimate) + " hidden, r ~ " + px + " px";
  }
  return c;
}

}  // namespace lantern
