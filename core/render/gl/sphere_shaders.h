// GLSL of the ray-cast sphere impostor. Each sphere is one instanced quad that bounds its exact
// silhouette; the fragment shader casts the pixel-centre ray against the sphere, discards misses
// and writes the true per-pixel depth, so intersecting spheres cut each other correctly.
//
// Rays are built from gl_FragCoord and the FULL image's inverse projection (plus the tile's
// pixel origin), never from interpolated varyings: a pixel's color and depth then depend only on
// that pixel and that sphere, so tiles, ranks and draw chunks cannot change a single bit.
//
// The quad lies parallel to the image plane, between the near and far planes, so clipping never
// cuts it: a sphere cut by the near plane, or reaching behind the eye, still gets every pixel
// whose ray meets it beyond the near plane (the CPU raster's rule).
//
// Color comes out as a key, R * 65536 + G * 256 + B of the 8-bit shaded color (exact in a float),
// that the renderer blends with GL_MIN in a second pass over the fragments at the nearest depth:
// at equal depth the smaller color wins, whatever the drawing order - compositing's rule
// (core/composite/packed_pixel.h), so ties are settled alike within a rank and across ranks.
#pragma once

#include <cstdio>
#include <string>

#include "core/config/lighting.h"
#include "core/render/screen_door.h"
#include "core/render/shading.h"

namespace lantern::shaders {

inline constexpr const char *kSphereVertex = R"GLSL(#version 330 core
layout(location = 0) in vec4 a_sphere;  // centre relative to the scene origin (xyz), radius (w)
layout(location = 1) in vec4 a_color;   // RGBA8, normalised
uniform mat4 u_view;       // scene-relative world -> view (camera looks down -z)
uniform mat4 u_tile_proj;  // view -> clip of the current tile
uniform bool u_ortho;
uniform float u_near;      // near-plane distance (> 0)
uniform float u_far;       // far-plane distance (> near), to float rounding
uniform vec2 u_slack;      // 0.05 pixel in x and y: view length (ortho) or slope x/-z (perspective)
flat out vec3 v_center;    // view space
flat out float v_radius;
flat out vec4 v_color;

// The range of slopes a/(-z) over the part of a sphere at or beyond the near plane, along one
// view axis a (x or y), from its centre (ca, cz) in the (a, z) plane: the tangents from the eye,
// or, where a tangent point lies nearer than the near plane (or behind the eye), the end of the
// sphere's chord on the near plane on that side (Mara & McGuire 2013, "2D Polyhedral Bounds of a
// Clipped, Perspective-Projected 3D Sphere"). Returns (lowest, highest).
vec2 slope_range(float ca, float cz, float r) {
  float near_z = -u_near;
  vec2 c = vec2(ca, cz);
  float t2 = dot(c, c) - r * r;
  bool eye_inside = t2 <= 0.0;  // in this plane; the sphere then reaches the near plane
  // (cos, sin) of the angle between the centre and a tangent, scaled for the tangent point.
  vec2 v = eye_inside ? vec2(0.0) : vec2(sqrt(t2), r) / length(c);
  bool cut = cz + r >= near_z;
  float k = sqrt(max(r * r - (near_z - cz) * (near_z - cz), 0.0));
  // Rotating c by +angle gives the tangent of the larger slope, by -angle the smaller one.
  vec2 hi = vec2(c.x * v.x - c.y * v.y, c.x * v.y + c.y * v.x) * v.x;
  vec2 lo = vec2(c.x * v.x + c.y * v.y, -c.x * v.y + c.y * v.x) * v.x;
  if (cut && (eye_inside || hi.y > near_z)) hi = vec2(ca + k, near_z);
  if (cut && (eye_inside || lo.y > near_z)) lo = vec2(ca - k, near_z);
  return vec2(lo.x / -lo.y, hi.x / -hi.y);
}

void main() {
  vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
  vec3 c = (u_view * vec4(a_sphere.xyz, 1.0)).xyz;
  float r = a_sphere.w;
  v_center = c;
  v_radius = r;
  v_color = a_color;
  // Nothing to draw when the sphere lies wholly nearer than the near plane or beyond the far
  // plane (with margins: u_far is only known to float rounding, and the fragment shader's own
  // depth test decides at the planes), or, in perspective, holds the eye: every ray then meets
  // its surface behind the eye first, as the CPU raster's rays do.
  bool hidden = r - c.z < u_near * 0.999 || -c.z - r > u_far * 1.01 ||
                (!u_ortho && dot(c, c) <= r * r);
  if (hidden) {
    gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
    return;
  }
  // A quad parallel to the image plane, halfway between the near and far planes, so that no
  // clipping plane can cut it, over every pixel whose ray can meet the sphere beyond the near
  // plane (plus a twentieth of a pixel for the float rounding of this bound): the fragment
  // shader decides each pixel exactly.
  float s = 0.5 * (u_near + u_far);
  vec3 p;
  if (u_ortho) {
    p = vec3(c.xy + corner * (r + u_slack), -s);
  } else {
    vec2 x = slope_range(c.x, c.z, r) + vec2(-u_slack.x, u_slack.x);
    vec2 y = slope_range(c.y, c.z, r) + vec2(-u_slack.y, u_slack.y);
    vec2 slope = vec2(corner.x < 0.0 ? x.x : x.y, corner.y < 0.0 ? y.x : y.y);
    p = vec3(slope * s, -s);
  }
  gl_Position = u_tile_proj * vec4(p, 1.0);
}
)GLSL";

// The fragment shader without its #version line, lighting constants and dither matrix, which
// sphere_fragment_source() puts in front.
inline constexpr const char *kSphereFragmentBody = R"GLSL(
uniform mat4 u_proj;          // full-image view -> clip
uniform mat4 u_inv_proj;
uniform vec2 u_image_size;    // full image, pixels
uniform vec2 u_tile_origin;   // this tile's lower-left pixel in the full image
uniform bool u_ortho;
uniform bool u_depth_only;    // the first pass: depth alone, no color
flat in vec3 v_center;
flat in float v_radius;
flat in vec4 v_color;
out float o_key;              // the color key (see above)

void main() {
  // Screen-door transparency (screen_door.h): a see-through sphere keeps only the pixels whose
  // dither threshold is below its opacity; rows counted from the top, as the CPU raster does.
  if (v_color.a < 1.0) {
    ivec2 pixel = ivec2(gl_FragCoord.xy + u_tile_origin);
    int row = int(u_image_size.y) - 1 - pixel.y;
    int index = k_bayer[(row & 3) * 4 + (pixel.x & 3)];
    if (float(2 * index + 1) * 255.0 >= 32.0 * round(v_color.a * 255.0)) discard;
  }
  vec2 ndc = (gl_FragCoord.xy + u_tile_origin) / u_image_size * 2.0 - 1.0;
  vec4 on_near = u_inv_proj * vec4(ndc, -1.0, 1.0);
  vec3 origin = u_ortho ? on_near.xyz / on_near.w : vec3(0.0);
  vec3 dir = u_ortho ? vec3(0.0, 0.0, -1.0) : normalize(on_near.xyz / on_near.w);
  // Distance of the centre from the ray, squared, computed without cancellation: far from the
  // eye |oc|^2 - b^2 would lose every digit of r^2.
  vec3 oc = v_center - origin;
  float b = dot(oc, dir);
  vec3 q = oc - b * dir;
  float h2 = v_radius * v_radius - dot(q, q);
  if (h2 < 0.0) discard;
  vec3 hit = origin + (b - sqrt(h2)) * dir;
  vec4 clip = u_proj * vec4(hit, 1.0);
  float z = clip.z / clip.w;
  if (z < -1.0 || z > 1.0) discard;
  gl_FragDepth = z * 0.5 + 0.5;
  if (u_depth_only) return;
  // Headlight: light along the view ray, Lambert diffuse plus a Blinn-Phong highlight.
  vec3 n = (hit - v_center) / v_radius;
  float lambert = max(dot(n, -dir), 0.0);
  // k_ambient, k_diffuse, k_specular, k_shininess: shading.h's, put in front by
  // sphere_fragment_source().
  vec3 rgb = v_color.rgb * (k_ambient + k_diffuse * lambert) +
             vec3(k_specular) * pow(lambert, k_shininess);
  // To 8 bits as Mesa's llvmpipe stores a color to an RGBA8 buffer (round half to even), so that
  // images keep the bytes they had when this shader wrote RGBA8.
  vec3 level = roundEven(min(rgb, vec3(1.0)) * 255.0);
  o_key = (level.r * 256.0 + level.g) * 256.0 + level.b;
}
)GLSL";

// A GLSL float literal that reads back as exactly v: 9 significant digits round-trip every float
// (0.2f prints as 0.200000003), and a '.' is added where needed so GLSL reads a float, not an int.
inline std::string glsl_float(float v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", double(v));
  std::string literal = text;
  if (literal.find_first_of(".e") == std::string::npos) literal += ".0";
  return literal;
}

// core/render/screen_door.h's dither matrix as a GLSL constant array: one definition for both
// renderers.
inline std::string bayer_glsl() {
  std::string s = "const int k_bayer[16] = int[16](";
  for (int i = 0; i < 16; ++i) s += std::to_string(kBayer4[i]) + (i < 15 ? ", " : ");\n");
  return s;
}

// The lighting block of kSphereFragmentBody for a lighting other than the default
// (core/config/lighting.h; the steps of core/render/shading.h's LightModel): it replaces the
// headlight block in a variant program, so the default program's source stays exactly what it was.
inline constexpr const char *kCustomLightBlock = R"GLSL(  // Custom lighting: k_light (unit,
  // camera space, towards the light) or the view ray when k_along_view; Blinn-Phong highlight.
  vec3 n = normalize(hit - v_center);
  vec3 v = -dir;
  vec3 l = k_along_view ? v : k_light;
  float n_l = dot(n, l);
  vec3 h = l + v;
  float h_len2 = dot(h, h);
  float highlight = 0.0;
  if (n_l > 0.0 && h_len2 > 0.0) {
    float n_h = dot(n, h) / sqrt(h_len2);
    if (n_h > 0.0) highlight = k_specular * pow(n_h, k_shininess);
  }
  vec3 rgb = v_color.rgb * (k_ambient + k_diffuse * max(n_l, 0.0)) + vec3(highlight);
)GLSL";

// What goes in front of a fragment shader body: the #version line, the lighting's constants
// (the headlight constants of core/render/shading.h, or a custom lighting's values), and the
// dither matrix. Constants, not uniforms, as in the default program.
inline std::string fragment_prologue(const Lighting &lighting) {
  if (lighting.is_default())
    return std::string("#version 330 core\n") +
           "const float k_ambient = " + glsl_float(shading::kAmbient<float>) + ";\n" +
           "const float k_diffuse = " + glsl_float(shading::kDiffuse<float>) + ";\n" +
           "const float k_specular = " + glsl_float(shading::kSpecular<float>) + ";\n" +
           "const float k_shininess = " + glsl_float(float(shading::kShininess)) + ";\n" +
           bayer_glsl();
  const auto f = [](double v) { return glsl_float(float(v)); };
  return std::string("#version 330 core\n") + "const float k_ambient = " + f(lighting.ambient) +
         ";\n" + "const float k_diffuse = " + f(lighting.diffuse) + ";\n" +
         "const float k_specular = " + f(lighting.specular) + ";\n" +
         "const float k_shininess = " + f(lighting.shininess) + ";\n" +
         "const bool k_along_view = " + (lighting.headlight() ? "true" : "false") + ";\n" +
         "const vec3 k_light = vec3(" + f(lighting.direction[0]) + ", " + f(lighting.direction[1]) +
         ", " + f(lighting.direction[2]) + ");\n" + bayer_glsl();
}

// A fragment body whose headlight block (from "  // Headlight:" up to "  // To 8 bits") is
// replaced by kCustomLightBlock for a lighting other than the default; `normal_given` drops the
// block's own normal (a body that computed `n` itself).
inline std::string lit_body(const char *body_text, const Lighting &lighting, bool normal_given) {
  std::string body = body_text;
  if (lighting.is_default()) return body;
  std::string block = kCustomLightBlock;
  if (normal_given) {
    const std::string own_normal = "  vec3 n = normalize(hit - v_center);\n";
    block.erase(block.find(own_normal), own_normal.size());
  }
  const size_t begin = body.find("  // Headlight:"), end = body.find("  // To 8 bits");
  body.replace(begin, end - begin, block);
  return body;
}

// The impostor fragment shader, with the headlight constants of core/render/shading.h injected as
// GLSL constants: one change there changes the OpenGL and the CPU images alike. A lighting other
// than the default gets a variant: its own values as constants (constants, not uniforms, as in the
// default program) and kCustomLightBlock in place of the headlight block.
inline std::string sphere_fragment_source(const Lighting &lighting = Lighting()) {
  return fragment_prologue(lighting) + lit_body(kSphereFragmentBody, lighting, false);
}

}  // namespace lantern::shaders
