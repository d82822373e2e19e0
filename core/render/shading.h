// The headlight shading of a sphere, in one place: a light along the view ray, Lambert diffuse
// plus a Blinn-Phong highlight, for a hit whose normal makes cosine `lambert` with the ray:
//
//   color = base * (kAmbient + kDiffuse * lambert) + kSpecular * lambert^kShininess,  clamped.
//
// Every renderer takes its constants from here - the OpenGL impostor shader (gl/sphere_shaders.h,
// where they are injected into the GLSL source), the CPU ray-cast raster (cpu_sphere_raster.cpp)
// and the CPU point splats (point_splats.cpp) - and all must use the same values, or their images
// stop agreeing pixel for pixel. Change them here only.
//
// Each constant is a variable template: kAmbient<double> is the double nearest the value written
// below, kAmbient<float> the float nearest that (for these values also the float nearest the
// decimal itself, i.e. the float literal 0.2f). The float paths (GLSL, CPU raster) use <float>,
// the double path (point splats) <double>.
//
// A scene's `lighting:` (core/config/lighting.h) may change the light. Its default is exactly the
// headlight below, and then every renderer keeps the code written for these constants (the
// constant-folded GLSL program, the CPU raster's squaring for the exponent 40): images without
// `lighting:` do not change by a bit. Any other lighting goes through LightModel.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/config/lighting.h"

namespace lantern::shading {

// Light reaching every lit pixel, whatever its normal: the fraction of the base color seen where
// the surface is edge-on to the light.
template <typename T>
inline constexpr T kAmbient = T(0.2);
// Lambert weight: the fraction of the base color added in proportion to cos(normal, light).
// kAmbient + kDiffuse = 1, so a surface facing the viewer shows its full base color.
template <typename T>
inline constexpr T kDiffuse = T(0.8);
// Strength of the white highlight, added to every channel at its peak (surface facing the viewer).
template <typename T>
inline constexpr T kSpecular = T(0.3);
// Exponent of the highlight: the larger, the smaller and sharper the highlight.
inline constexpr int kShininess = 40;

// Lighting's defaults are these constants: the default lighting is this headlight.
static_assert(Lighting{}.ambient == kAmbient<double> && Lighting{}.diffuse == kDiffuse<double> &&
                  Lighting{}.specular == kSpecular<double> &&
                  Lighting{}.shininess == double(kShininess),
              "Lighting's defaults (core/config/lighting.h) must be the headlight's constants");

// A lighting that is not the default, in precision T (float: CPU raster; double: point splats;
// the GLSL variant in gl/sphere_shaders.h follows the same steps). Holds copies; thread-safe to
// use.
template <typename T>
struct LightModel {
  explicit LightModel(const Lighting &l)
      : along_view(l.headlight()),
        lx(T(l.direction[0])),
        ly(T(l.direction[1])),
        lz(T(l.direction[2])),
        ambient(T(l.ambient)),
        diffuse(T(l.diffuse)),
        specular(T(l.specular)),
        shininess(T(l.shininess)) {}

  // For unit normal n and unit vector v towards the eye: the factor of the base color
  // (ambient + diffuse * max(0, n.l)) and the white highlight specular * max(0, n.h)^shininess,
  // h = normalize(l + v), none where n.l <= 0 (lighting.h).
  void terms(const T n[3], const T v[3], T *factor, T *highlight) const {
    const T l[3] = {along_view ? v[0] : lx, along_view ? v[1] : ly, along_view ? v[2] : lz};
    const T n_l = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
    *factor = ambient + diffuse * std::max(n_l, T(0));
    *highlight = T(0);
    const T h[3] = {l[0] + v[0], l[1] + v[1], l[2] + v[2]};
    const T h2 = h[0] * h[0] + h[1] * h[1] + h[2] * h[2];
    // h2 is 0 only for a light straight from behind (l = -v): then n.l <= 0 wherever n.v >= 0.
    if (!(n_l > T(0)) || !(h2 > T(0))) return;
    const T n_h = (n[0] * h[0] + n[1] * h[1] + n[2] * h[2]) / std::sqrt(h2);
    if (n_h > T(0)) *highlight = specular * std::pow(n_h, shininess);
  }

  bool along_view;  // direction [0, 0, 1]: l = v, the headlight
  T lx, ly, lz;     // the unit direction towards the light, camera space, when not along_view
  T ambient, diffuse, specular, shininess;
};

}  // namespace lantern::shading
