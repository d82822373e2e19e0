#include "core/culling/point_splats.h"

#include <algorithm>
#include <cmath>

#include "core/bricks/typed_access.h"
#include "core/culling/draw_list.h"

namespace lantern {
namespace {

// The impostor shader at the sphere's centre: lambert = 1, so rgb + 0.3, clamped.
uint8_t shade_centre(uint8_t c) {
  const double v = std::min(c / 255.0 + 0.3, 1.0);
  return uint8_t(std::lround(v * 255.0));
}

}  // namespace

void splat_points(const ParticleArrays &particles, bool per_particle, double radius,
                  const std::vector<uint64_t> &entries, const ViewGeometry &g,
                  const ColourOf &colour, Frame *frame) {
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, per_particle, radius, [&](const auto &rad) {
      for (const uint64_t e : entries) {
        const uint32_t i = entry_index(e);
        const glm::dvec3 c = g.to_view(pos.get(i));
        const double d = -c.z, r = rad.get(i) * entry_scale(e);
        double xn, yn;
        if (g.orthographic) {
          xn = g.sx * c.x + g.tx, yn = g.sy * c.y + g.ty;
        } else {
          xn = g.sx * c.x / d, yn = g.sy * c.y / d;
        }
        const double fx = std::floor((xn + 1.0) * 0.5 * g.width);
        const double fy = std::floor((1.0 - yn) * 0.5 * g.height);
        if (!(fx >= 0 && fy >= 0 && fx < g.width && fy < g.height)) continue;
        const float wd = float(g.window_depth(std::max(d - r, g.near_plane)));
        if (!(wd >= 0.0f && wd < 1.0f)) continue;
        const size_t px = frame->index(int(fx), int(fy));
        if (!(wd < frame->depth[px])) continue;
        frame->depth[px] = wd;
        const Rgb8 rgb = colour(int64_t(i));
        for (int k = 0; k < 3; ++k) frame->rgba[4 * px + k] = shade_centre(rgb[k]);
        frame->rgba[4 * px + 3] = 255;
      }
    });
  });
}

}  // namespace lantern
