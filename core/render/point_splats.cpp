#include "core/render/point_splats.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/culling/draw_list.h"
#include "core/particles/typed_access.h"
#include "core/render/screen_door.h"
#include "core/render/shading.h"

namespace lantern {
namespace {

// The impostor shader's color for a hit whose normal makes `lambert` with the view ray: Lambert
// diffuse plus a Blinn-Phong highlight (shading.h), clamped, then stored as unorm8.
uint8_t shade(uint8_t c, double lambert) {
  using shading::kAmbient, shading::kDiffuse, shading::kSpecular, shading::kShininess;
  const double v = c / 255.0 * (kAmbient<double> + kDiffuse<double> * lambert) +
                   kSpecular<double> * std::pow(lambert, double(kShininess));
  return uint8_t(std::lround(std::min(v, 1.0) * 255.0));
}

// The same for a lighting other than the default (shading.h's LightModel), rounded as shade().
uint8_t shade_lit(uint8_t c, double factor, double highlight) {
  return uint8_t(std::lround(std::min(c / 255.0 * factor + highlight, 1.0) * 255.0));
}

// Casts the shader's ray through the centre of pixel (x, y) at the sphere (view-space centre c,
// radius r). On a hit returns true with the view-space hit point and the unit ray direction.
bool cast(const ViewGeometry &g, int x, int y, const glm::dvec3 &c, double r, glm::dvec3 *hit,
          glm::dvec3 *dir) {
  glm::dvec3 origin(0.0), d(0.0, 0.0, -1.0);
  if (g.orthographic)
    origin = {g.ray_x(x), g.ray_y(y), 0.0};
  else
    d = glm::normalize(glm::dvec3(g.ray_x(x), g.ray_y(y), -1.0));
  const glm::dvec3 oc = c - origin;
  const double b = glm::dot(oc, d);
  const glm::dvec3 q = oc - b * d;
  const double h2 = r * r - glm::dot(q, q);
  if (h2 < 0.0) return false;
  *hit = origin + (b - std::sqrt(h2)) * d;
  *dir = d;
  return true;
}

}  // namespace

void splat_points(const ParticleArrays &particles, bool per_particle, double radius,
                  const PageVector<uint64_t> &entries, const ViewGeometry &g, const ColorOf &color,
                  Frame *frame, const AlphaOf &alpha, const Lighting &lighting) {
  // Default lighting: the original headlight code below, bit for bit.
  std::optional<shading::LightModel<double>> light;
  if (!lighting.is_default()) light.emplace(lighting);
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
        // A silhouette under a pixel across holds at most one pixel centre, one of the four
        // around the projected centre: ray-cast those, as the shader would.
        const double px = (xn + 1.0) * 0.5 * g.width - 0.5, py = (1.0 - yn) * 0.5 * g.height - 0.5;
        if (!(px > -2.0 && py > -2.0 && px < g.width + 1.0 && py < g.height + 1.0)) continue;
        const int x0 = int(std::floor(px)), y0 = int(std::floor(py));
        for (int k = 0; k < 4; ++k) {
          const int x = x0 + (k & 1), y = y0 + (k >> 1);
          if (x < 0 || y < 0 || x >= g.width || y >= g.height) continue;
          if (alpha && !screen_door_keeps(x, y, alpha(int64_t(i)))) continue;
          glm::dvec3 hit, dir;
          if (!cast(g, x, y, c, r, &hit, &dir)) continue;
          const double depth = -hit.z;
          if (depth < g.near_plane || depth > g.far_plane) continue;
          const auto wd = float(g.window_depth(depth));
          const size_t p = frame->index(x, y);
          if (!(wd <= frame->depth[p])) continue;
          const Rgb8 rgb = color(int64_t(i));
          uint8_t shaded[4] = {0, 0, 0, 255};
          if (light) {
            const glm::dvec3 normal = glm::normalize(hit - c);
            const double n[3] = {normal.x, normal.y, normal.z}, v[3] = {-dir.x, -dir.y, -dir.z};
            double factor, highlight;
            light->terms(n, v, &factor, &highlight);
            for (int ch = 0; ch < 3; ++ch) shaded[ch] = shade_lit(rgb[ch], factor, highlight);
          } else {
            const double lambert = std::max(glm::dot((hit - c) / r, -dir), 0.0);
            for (int ch = 0; ch < 3; ++ch) shaded[ch] = shade(rgb[ch], lambert);
          }
          uint8_t *out = &frame->rgba[4 * p];
          // An equal depth goes to the smaller color (R, then G, B, A), as in compositing.
          if (!(wd < frame->depth[p]) &&
              !std::lexicographical_compare(shaded, shaded + 4, out, out + 4))
            continue;
          frame->depth[p] = wd;
          std::copy(shaded, shaded + 4, out);
        }
      }
    });
  });
}

}  // namespace lantern
