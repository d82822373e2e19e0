// The headlight shading of a sphere, in one place: a light along the view ray, Lambert diffuse
// plus a Blinn-Phong highlight, for a hit whose normal makes cosine `lambert` with the ray:
//
//   color = base * (kAmbient + kDiffuse * lambert) + kSpecular * lambert^kShininess,  clamped.
//
// Every renderer takes its constants from here - the OpenGL impostor shader (sphere_shaders.h,
// where they are injected into the GLSL source), the CPU ray-cast raster (cpu_sphere_raster.cpp)
// and the CPU point splats (point_splats.cpp) - and all must use the same values, or their images
// stop agreeing pixel for pixel. Change them here only.
//
// Each constant is a variable template: kAmbient<double> is the double nearest the value written
// below, kAmbient<float> the float nearest that (for these values also the float nearest the
// decimal itself, i.e. the float literal 0.2f). The float paths (GLSL, CPU raster) use <float>,
// the double path (point splats) <double>.
#pragma once

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

}  // namespace lantern::shading
