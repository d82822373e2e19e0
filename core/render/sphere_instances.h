// Turns particles into the renderer's SphereInstances: scene-relative float position, radius and
// color. The only per-particle conversion Lantern makes, streamed for the particles drawn.
#pragma once

#include <cstdint>
#include <vector>

#include "core/camera/camera.h"
#include "core/color/colormap.h"
#include "core/common/page_allocator.h"
#include "core/config/config.h"
#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"
#include "core/particles/radius_rule.h"
#include "core/render/gl/sphere_renderer.h"
#include "core/render/object_occlusion.h"
#include "core/render/shading_settings.h"

namespace lantern {

// How one scene colors particles, resolved against the global extent (same on every rank).
struct Coloring {
  ColorBy by = ColorBy::kSolid;
  Rgb8 solid{200, 200, 200};
  TypePalette palette{{}};
  Colormap map = *Colormap::named("viridis");
  double lo = 0.0, hi = 1.0;  // scalar range
};

Coloring make_coloring(const ColorConfig &config, const Extent &global);

// Everything needed to turn particle i into an instance.
struct InstanceRecipe {
  const ParticleArrays *particles = nullptr;
  glm::dvec3 origin{0.0};
  bool per_particle_radius = false;
  float radius = 0.5f;
  Coloring coloring;
  // Object-space ambient occlusion (object_occlusion.h): scales each particle's colour; null
  // (the default) leaves colours as they are. Borrowed.
  const OcclusionVolume *occlusion = nullptr;
  // 8-bit opacity by type (screen_door.h); empty (the default): every particle opaque.
  std::vector<uint8_t> alpha_by_type;

  SphereInstance make(int64_t i) const {
    const glm::dvec3 p = particles->position(i) - origin;
    SphereInstance s;
    s.x = float(p.x);
    s.y = float(p.y);
    s.z = float(p.z);
    s.radius = per_particle_radius ? float(particles->radius(i)) : radius;
    const Rgb8 c = color(i);
    s.rgba[0] = c[0];
    s.rgba[1] = c[1];
    s.rgba[2] = c[2];
    s.rgba[3] = alpha(i);
    return s;
  }

  // The particle's 8-bit opacity: 255 unless `opacity` lists its type.
  uint8_t alpha(int64_t i) const {
    if (alpha_by_type.empty()) return 255;
    const int64_t type = particles->has_type() ? particles->type(i) : 0;
    return type >= 0 && type < int64_t(alpha_by_type.size()) ? alpha_by_type[size_t(type)] : 255;
  }

  Rgb8 color(int64_t i) const {
    const Rgb8 c = base_color(i);
    if (!occlusion) return c;
    const float f = occlusion->factor(particles->position(i));
    // Rounded to nearest (the values are >= 0, f <= 1).
    return {uint8_t(float(c[0]) * f + 0.5f), uint8_t(float(c[1]) * f + 0.5f),
            uint8_t(float(c[2]) * f + 0.5f)};
  }

  // Asks for what color(i) and alpha(i) will read (type or scalar) ahead of the call: the draw
  // order is brick order, where a non-spatial published order (a gas) makes each a cache miss.
  // The arrays' addresses are resolved once (prefetcher()), so that asking costs a load or two.
  struct Prefetcher {
    const char *base[2] = {nullptr, nullptr};
    int64_t stride[2] = {0, 0};
    void operator()(int64_t i) const {
      if (base[0]) __builtin_prefetch(base[0] + i * stride[0], 0, 3);
      if (base[1]) __builtin_prefetch(base[1] + i * stride[1], 0, 3);
    }
  };
  Prefetcher prefetcher() const {
    Prefetcher p;
    const bool by_type = coloring.by == ColorBy::kType || !alpha_by_type.empty();
    if (by_type && particles->has_type()) {
      p.base[0] = static_cast<const char *>(particles->type_array().data());
      p.stride[0] = particles->type_array().stride_bytes();
    }
    if (coloring.by == ColorBy::kScalar && particles->has_scalar()) {
      p.base[1] = static_cast<const char *>(particles->scalar_array().data());
      p.stride[1] = particles->scalar_array().stride_bytes();
    }
    return p;
  }

  Rgb8 base_color(int64_t i) const {
    switch (coloring.by) {
      case ColorBy::kType:
        return coloring.palette.at(particles->has_type() ? particles->type(i) : 0);
      case ColorBy::kScalar:
        return coloring.map.at(
            particles->has_scalar() ? particles->scalar(i) : 0.5 * (coloring.lo + coloring.hi),
            coloring.lo, coloring.hi);
      default:
        return coloring.solid;
    }
  }
};

// Colors and opacity from `shading` (color ranges resolved against `global`), sizes by `radius`.
InstanceRecipe make_recipe(const ParticleArrays &particles, const ShadingSettings &shading,
                           const RadiusRule &radius, const Camera &camera, const Extent &global);

// Instances of every particle with finite coordinates, in published order.
void build_all_instances(const InstanceRecipe &recipe, std::vector<SphereInstance> *out);

// Instances of the culling stage's draw entries (core/culling/draw_list.h: particle index and
// level-of-detail radius scale), in the entries' order.
void build_selected_instances(const InstanceRecipe &recipe, const PageVector<uint64_t> &entries,
                              std::vector<SphereInstance> *out);

}  // namespace lantern
