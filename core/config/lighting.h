// The light of a scene (`lighting:`), a value shared by every renderer: the CPU ray-cast
// raster, the point splats and the OpenGL impostor shader all shade from it.
//
// Model, for a hit with unit normal n, unit vector v towards the eye and unit light vector l:
//
//   color = base * (ambient + diffuse * max(0, n.l)) + specular * max(0, n.h)^shininess,
//   h = normalize(l + v) (Blinn-Phong; no highlight where n.l <= 0),
//
// each channel clamped to 1 (only above: every term is >= 0) and rounded to 8 bits. ambient +
// diffuse may exceed 1; the clamp then saturates the brightest part of the sphere.
//
// Directions are camera-relative: x right, y up, z towards the viewer. The default light,
// direction [0, 0, 1], is the headlight: l = v along each pixel's view ray (so h = v and the
// highlight is max(0, n.v)^shininess), exactly today's shading. Any other direction is a
// directional light fixed in camera space, the same l for every pixel; in an orthographic view
// the headlight is that too, in a perspective one it differs by the ray's angle off the axis.
//
// The default values are shading.h's constants (checked there): a scene without `lighting:`
// renders through the renderers' original headlight code, bit for bit as before.
#pragma once

#include <array>

namespace lantern {

struct Lighting {
  std::array<double, 3> direction{0.0, 0.0, 1.0};  // direction: unit, camera-relative, to light
  double ambient = 0.2;                            // ambient: [0, 1]
  double diffuse = 0.8;                            // diffuse: [0, 1]
  double specular = 0.3;                           // specular: [0, 1]
  double shininess = 40.0;                         // shininess: [1, 1024]

  // The light along each view ray (direction exactly [0, 0, 1]).
  bool headlight() const { return direction == std::array<double, 3>{0.0, 0.0, 1.0}; }
  // Every value is the default: renderers keep their original, constant-folded code path.
  bool is_default() const { return *this == Lighting(); }

  bool operator==(const Lighting &o) const {
    return direction == o.direction && ambient == o.ambient && diffuse == o.diffuse &&
           specular == o.specular && shininess == o.shininess;
  }
  bool operator!=(const Lighting &o) const { return !(*this == o); }
};

// Allowed ranges of the keys (config_loader.cpp checks them; README documents them).
inline constexpr double kMinShininess = 1.0;
inline constexpr double kMaxShininess = 1024.0;

}  // namespace lantern
