// GLSL of the ray-cast bond impostor: each half-bond is a closed cylinder (curved side and two end
// discs), drawn as one instanced quad over every pixel its view-space bounds can project to; the
// fragment shader casts the pixel-centre ray against the cylinder exactly, discards misses and
// writes the true per-pixel depth, so bonds and spheres cut each other correctly.
//
// Everything else follows the sphere impostor (sphere_shaders.h) and shares its parts: the ray
// from gl_FragCoord and the full image's inverse projection (so tiles, ranks and draw chunks
// change no bit), the quad between the near and far planes, the nearest hit only (clipped by the
// planes as a sphere's), screen-door opacity, the lighting block and the color key that the
// renderer's second pass settles ties with. The CPU raster casts the same cylinder, in float
// relative to the ray through its first end (or in double where it reaches behind the eye plane:
// CpuSphereRaster::draw_bond).
#pragma once

#include <string>

#include "core/config/lighting.h"
#include "core/render/gl/sphere_shaders.h"

namespace lantern::shaders {

inline constexpr const char *kBondVertex = R"GLSL(#version 330 core
layout(location = 0) in vec3 a_start;  // the atom's centre, relative to the scene origin
layout(location = 1) in vec4 a_end;    // the midpoint end (xyz) and the radius (w)
layout(location = 2) in vec4 a_color;  // RGBA8, normalised
uniform mat4 u_view;
uniform mat4 u_tile_proj;
uniform bool u_ortho;
uniform float u_near;
uniform float u_far;
uniform vec2 u_slack;      // 0.05 pixel in x and y: view length (ortho) or slope (perspective)
flat out vec3 v_start;     // view space
flat out vec3 v_axis;      // unit, from start to end
flat out float v_length;
flat out float v_radius;
flat out vec4 v_color;

void main() {
  vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
  vec3 a = (u_view * vec4(a_start, 1.0)).xyz;
  vec3 b = (u_view * vec4(a_end.xyz, 1.0)).xyz;
  float r = a_end.w;
  float len = length(b - a);
  vec3 u = len > 0.0 ? (b - a) / len : vec3(0.0, 0.0, 1.0);
  v_start = a;
  v_axis = u;
  v_length = len;
  v_radius = r;
  v_color = a_color;
  // The cylinder's view-space bounds: r sqrt(1 - u_k^2) beyond its ends along each axis, grown
  // by a little for the float rounding of this bound (the fragment shader decides each pixel).
  vec3 reach = r * 1.0001 * sqrt(max(vec3(1.0) - u * u, vec3(0.0))) + 1e-6 * (length(a) + r);
  vec3 lo = min(a, b) - reach, hi = max(a, b) + reach;
  // Nothing to draw for an empty cylinder, or one wholly nearer than the near plane or beyond
  // the far plane.
  bool hidden = !(len > 0.0) || !(r > 0.0) || -lo.z < u_near * 0.999 || -hi.z > u_far * 1.01;
  if (hidden) {
    gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
    return;
  }
  float s = 0.5 * (u_near + u_far);
  vec3 p;
  if (u_ortho) {
    vec2 x = vec2(lo.x, hi.x) + vec2(-u_slack.x, u_slack.x);
    vec2 y = vec2(lo.y, hi.y) + vec2(-u_slack.y, u_slack.y);
    p = vec3(corner.x < 0.0 ? x.x : x.y, corner.y < 0.0 ? y.x : y.y, -s);
  } else {
    // Slopes x / d over the part of the bounds at or beyond the near plane: extreme at its
    // corners, d from max(near, nearest) to the farthest.
    float d0 = max(-hi.z, u_near), d1 = -lo.z;
    vec4 sx = vec4(lo.x / d0, lo.x / d1, hi.x / d0, hi.x / d1);
    vec4 sy = vec4(lo.y / d0, lo.y / d1, hi.y / d0, hi.y / d1);
    vec2 x = vec2(min(min(sx.x, sx.y), min(sx.z, sx.w)) - u_slack.x,
                  max(max(sx.x, sx.y), max(sx.z, sx.w)) + u_slack.x);
    vec2 y = vec2(min(min(sy.x, sy.y), min(sy.z, sy.w)) - u_slack.y,
                  max(max(sy.x, sy.y), max(sy.z, sy.w)) + u_slack.y);
    vec2 slope = vec2(corner.x < 0.0 ? x.x : x.y, corner.y < 0.0 ? y.x : y.y);
    p = vec3(slope * s, -s);
  }
  gl_Position = u_tile_proj * vec4(p, 1.0);
}
)GLSL";

// The fragment shader without its prologue (fragment_prologue, sphere_shaders.h).
inline constexpr const char *kBondFragmentBody = R"GLSL(
uniform mat4 u_proj;
uniform mat4 u_inv_proj;
uniform vec2 u_image_size;
uniform vec2 u_tile_origin;
uniform bool u_ortho;
uniform bool u_depth_only;
flat in vec3 v_start;
flat in vec3 v_axis;
flat in float v_length;
flat in float v_radius;
flat in vec4 v_color;
out float o_key;

void main() {
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
  // The curved side: |wp + t dp| = r across the axis, its discriminant qa r^2 - (u . (dir x w))^2
  // free of cancellation; then the slab between the end discs. The ray enters the solid at the
  // larger of the two entries (CpuSphereRaster::draw_bond does the same).
  vec3 w = origin - v_start;
  float d_u = dot(dir, v_axis), w_u = dot(w, v_axis);
  vec3 dp = dir - d_u * v_axis, wp = w - w_u * v_axis;
  float qa = dot(dp, dp);
  float side0 = -3.0e38, side1 = 3.0e38;
  if (qa > 0.0) {
    float cross_axis = dot(v_axis, cross(dir, w));
    float h2 = qa * v_radius * v_radius - cross_axis * cross_axis;
    if (!(h2 > 0.0)) discard;
    float qb = dot(dp, wp), root = sqrt(h2);
    side0 = (-qb - root) / qa;
    side1 = (-qb + root) / qa;
  } else if (!(dot(wp, wp) < v_radius * v_radius)) {
    discard;
  }
  float slab0 = -3.0e38, slab1 = 3.0e38;
  if (d_u != 0.0) {
    float t_a = -w_u / d_u, t_b = (v_length - w_u) / d_u;
    slab0 = min(t_a, t_b);
    slab1 = max(t_a, t_b);
  } else if (!(w_u >= 0.0 && w_u <= v_length)) {
    discard;
  }
  float t = max(side0, slab0);
  if (!(t <= min(side1, slab1))) discard;
  vec3 hit = origin + t * dir;
  vec4 clip = u_proj * vec4(hit, 1.0);
  float z = clip.z / clip.w;
  if (z < -1.0 || z > 1.0) discard;
  gl_FragDepth = z * 0.5 + 0.5;
  if (u_depth_only) return;
  vec3 n = slab0 > side0 ? (d_u > 0.0 ? -v_axis : v_axis) : normalize(wp + t * dp);
  // Headlight: light along the view ray, Lambert diffuse plus a Blinn-Phong highlight.
  float lambert = max(dot(n, -dir), 0.0);
  vec3 rgb = v_color.rgb * (k_ambient + k_diffuse * lambert) +
             vec3(k_specular) * pow(lambert, k_shininess);
  // To 8 bits as the sphere shader does.
  vec3 level = roundEven(min(rgb, vec3(1.0)) * 255.0);
  o_key = (level.r * 256.0 + level.g) * 256.0 + level.b;
}
)GLSL";

// The bond fragment shader for `lighting` (the custom block in place of the headlight's, as for
// spheres).
inline std::string bond_fragment_source(const Lighting &lighting = Lighting()) {
  return fragment_prologue(lighting) + lit_body(kBondFragmentBody, lighting, true);
}

}  // namespace lantern::shaders
