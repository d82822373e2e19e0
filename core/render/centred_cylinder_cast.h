// The CPU raster's float ray cast of a closed cylinder (a half-bond) wholly in front of the eye,
// relative to the ray through its first end - the bonds' counterpart of the spheres' centred
// float cast (cpu_sphere_raster.cpp). CylinderCast (cylinder_cast.h) stays the double cast for
// cylinders reaching behind the eye plane.
//
// Perspective: with d = -a.z the depth of the end a, D0 = a / d = (u0, v0, -1) the ray through
// it and D = D0 + delta, delta = (dx, dy, 0), a pixel's ray, the point at view depth t of the ray
// less a, divided by d, is X = delta + s D with s = t / d - 1: the ray from delta along D against
// the cylinder from the origin along the unit axis u, of radius rho = r / d and length
// lambda = length / d, all quantities of order one or smaller (no large view-space coordinate
// enters a float). Orthographic: delta = (rx - a.x, ry - a.y, 0), D = (0, 0, -1), s = t - d,
// rho = r, lambda = length. With c = D x u and g = delta x u (both across the axis, so Lagrange's
// identity turns the dot products of their parts across the axis into theirs):
//   curved side: qa s^2 + 2 qb s + (|g|^2 - rho^2) = 0, qa = |c|^2, qb = c . g, whose
//     discriminant is h2 = qa rho^2 - (c0 . delta)^2 with c0 = D0 x u (c0 . delta = c . delta:
//     the triple product, without cancellation); c = c0 + g in perspective, c0 in orthographic;
//   end slab: 0 <= delta . u + s D . u <= lambda;
// the ray enters the solid at the larger of the two entries, as in CylinderCast. Window depth:
// perspective wa + wb / t = (wa + wb / d) - (wb / d) s / (1 + s), the large part computed once
// in double; orthographic (wa - wb' d) + wb' s. Shading: the headlight's squared Lambert factor
// is h2 / (rho^2 |D|^2) on the curved side and (D . u)^2 / |D|^2 on an end disc.
//
// A pixel's offset from the reference ray is (integer columns from a reference column) x step +
// the reference's own offset, as for spheres, so a pixel's result depends only on the pixel and
// the cylinder: not on the row span or the group of 8 pixels it is cast in, nor on the vector
// width (cylinder_pixel is the one sequence of IEEE operations every path runs, never contracted
// into FMA). Thread-safety: immutable values.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/view/divide_pair.h"
#include "core/view/pixel_rays.h"
#include "core/view/reference_ray_grid.h"
#include "core/view/view_geometry.h"

namespace lantern {

struct CentredCylinder : ReferenceRayGrid {
  // Usable when the cylinder lies wholly in front of the eye (perspective), or always (ortho).
  static bool applies(const ViewGeometry &g, const glm::dvec3 &a, const glm::dvec3 &b, double r) {
    return g.orthographic || std::min(-a.z, -b.z) - r > 0.0;
  }

  // The cylinder from view-space point a along unit axis u, `length` long, radius r.
  CentredCylinder(const ViewGeometry &g, const PixelRays &rays, const glm::dvec3 &a,
                  const glm::dvec3 &u, double length, double r)
      : orthographic(g.orthographic) {
    const double d = -a.z;
    double cu = a.x, cv = a.y;
    glm::dvec3 d0(0.0, 0.0, -1.0);
    if (orthographic) {
      rho2 = float(r * r), lambda = float(length);
      wc = float(0.5 + 0.5 * g.p32 - 0.5 * g.p22 * d), wd = float(-0.5 * g.p22);
      lo = float(g.near_plane - d), hi = float(g.far_plane - d);
    } else {
      // The eight quotients by d, two to a division (each the quotient a division of its own
      // would give).
      double r_d, length_d, w_d, near_d, far_d, unused;
      divide_pair(a.x, a.y, d, d, &cu, &cv);
      divide_pair(r, length, d, d, &r_d, &length_d);
      divide_pair(0.5 * g.p32, g.near_plane, d, d, &w_d, &near_d);
      divide_pair(g.far_plane, 0.0, d, d, &far_d, &unused);
      d0 = glm::dvec3(cu, cv, -1.0);
      rho2 = float(r_d * r_d), lambda = float(length_d);
      wc = float(0.5 - 0.5 * g.p22 + w_d), wd = float(w_d);
      lo = float(near_d), hi = float(far_d);
      u0 = float(cu), v0 = float(cv), l0sq = float(1.0 + cu * cu + cv * cv);
    }
    const glm::dvec3 c = glm::cross(d0, u);
    // Products of parts below 1e-30 would be float denormals, which are slow: those parts count
    // as zero.
    const auto tiny0 = [](double v) { return std::abs(v) < 1e-30 ? 0.0f : float(v); };
    c0x = tiny0(c.x), c0y = tiny0(c.y), c0z = tiny0(c.z);
    ux = tiny0(u.x), uy = tiny0(u.y), uz = tiny0(u.z);
    du0 = tiny0(glm::dot(d0, u));
    // Reference column and row: those of the ray through a (any fixed pair would do).
    place(rays, cu, cv);
  }

  bool orthographic;
  float c0x = 0, c0y = 0, c0z = 0;  // D0 x u
  float ux = 0, uy = 0, uz = 0;     // the unit axis
  float du0 = 0;                    // D0 . u
  float rho2 = 0, lambda = 0;       // radius squared and length, in the cast's units
  float u0 = 0, v0 = 0, l0sq = 1;   // perspective: the reference ray and |D0|^2
  float wc = 0, wd = 0;             // window depth: wc - wd s / (1 + s), or wc + wd s
  float lo = 0, hi = 0;             // clip: 1 + s (perspective) or s (ortho) within [lo, hi]
};

// Window depth of a ray that misses or is clipped: loses every depth test (depths are <= 1).
inline constexpr float kCylinderMiss = 2.0f;

// Where the ray of the pixel kx columns and jy rows from the reference pixel enters the cylinder.
struct CylinderEntry {
  float dx, dy;  // the ray's delta
  float s;       // the entry (perspective: view depth / d - 1; orthographic: view depth - d)
  float du;      // D . u
  float h2;      // the curved side's discriminant
  float l2;      // |D|^2
  bool disc;     // entered through an end disc
  bool hit;      // entered, within the near and far planes
};

#define LANTERN_ALWAYS_INLINE inline __attribute__((always_inline))

LANTERN_ALWAYS_INLINE CylinderEntry cylinder_entry(const CentredCylinder &p, int kx, int jy) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  CylinderEntry e;
  const float dx = p.off_x + float(kx) * p.step_x, dy = p.off_y + float(jy) * p.step_y;
  const float gx = dy * p.uz, gy = -(dx * p.uz), gz = dx * p.uy - dy * p.ux;  // delta x u
  float cx = p.c0x, cy = p.c0y, cz = p.c0z, du = p.du0, l2 = 1.0f;
  const float delta_u = dx * p.ux + dy * p.uy;
  if (!p.orthographic) {
    cx = cx + gx, cy = cy + gy, cz = cz + gz, du = du + delta_u;
    l2 = p.l0sq + 2.0f * (p.u0 * dx + p.v0 * dy) + (dx * dx + dy * dy);
  }
  const float qa = cx * cx + cy * cy + cz * cz, qb = cx * gx + cy * gy + cz * gz;
  const float cross = dx * p.c0x + dy * p.c0y;
  const float h2 = qa * p.rho2 - cross * cross;
  // Curved side: along the axis (qa = 0) the ray is inside it or never meets it.
  const bool along = !(qa > 0.0f);
  const bool side_in = (along & (gx * gx + gy * gy + gz * gz < p.rho2)) | ((!along) & (h2 > 0.0f));
  const float root = std::sqrt(h2 > 0.0f ? h2 : 0.0f);
  const float inv_qa = 1.0f / (along ? 1.0f : qa);
  const float side0 = along ? -kInf : (-qb - root) * inv_qa;
  const float side1 = along ? kInf : (-qb + root) * inv_qa;
  // End slab: parallel to the discs (du = 0), the ray is between them or never.
  const bool flat = du == 0.0f;
  const bool slab_in = (!flat) | ((delta_u >= 0.0f) & (delta_u <= p.lambda));
  const float inv_du = 1.0f / (flat ? 1.0f : du);
  const float t_a = -delta_u * inv_du, t_b = (p.lambda - delta_u) * inv_du;
  const float slab0 = flat ? -kInf : (t_a < t_b ? t_a : t_b);
  const float slab1 = flat ? kInf : (t_a < t_b ? t_b : t_a);
  e.disc = slab0 > side0;
  e.s = e.disc ? slab0 : side0;
  const float exit = side1 < slab1 ? side1 : slab1;
  // The shader's clip-z discard: view depth outside [near, far].
  const float clip = p.orthographic ? e.s : 1.0f + e.s;
  e.hit = side_in & slab_in & (e.s <= exit) & (clip >= p.lo) & (clip <= p.hi);
  e.dx = dx, e.dy = dy, e.du = du, e.h2 = h2, e.l2 = l2;
  return e;
}

// The window depth of the pixel's hit (kCylinderMiss for a miss, or a hit outside the near and
// far planes) and the squared Lambert factor of the headlight there. Every path casts a pixel
// through here.
LANTERN_ALWAYS_INLINE void cylinder_pixel(const CentredCylinder &p, int kx, int jy, float *wz_out,
                                          float *lambert2_out) {
  const CylinderEntry e = cylinder_entry(p, kx, jy);
  const float wz = p.orthographic ? p.wc + p.wd * e.s : p.wc - p.wd * (e.s / (1.0f + e.s));
  *wz_out = e.hit ? wz : kCylinderMiss;
  *lambert2_out = (e.disc ? e.du * e.du * p.rho2 : e.h2) / (p.rho2 * e.l2);
}

// The unit normal and the unit vector towards the eye at the pixel's hit (custom lighting; for a
// pixel cylinder_pixel hit).
inline void cylinder_surface(const CentredCylinder &p, int kx, int jy, float n[3], float v[3]) {
  const CylinderEntry e = cylinder_entry(p, kx, jy);
  float d[3] = {0.0f, 0.0f, -1.0f};
  if (!p.orthographic) d[0] = p.u0 + e.dx, d[1] = p.v0 + e.dy;
  const float inv_l = 1.0f / std::sqrt(e.l2);
  v[0] = -d[0] * inv_l, v[1] = -d[1] * inv_l, v[2] = -d[2] * inv_l;
  if (e.disc) {  // the disc facing the ray
    const float sign = e.du > 0.0f ? -1.0f : 1.0f;
    n[0] = sign * p.ux, n[1] = sign * p.uy, n[2] = sign * p.uz;
    return;
  }
  // On the curved side: X = delta + s D, its part across the axis, normalised.
  const float x[3] = {e.dx + e.s * d[0], e.dy + e.s * d[1], e.s * d[2]};
  const float xu = x[0] * p.ux + x[1] * p.uy + x[2] * p.uz;
  const float m[3] = {x[0] - xu * p.ux, x[1] - xu * p.uy, x[2] - xu * p.uz};
  const float length = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  const float inv = length > 0.0f ? 1.0f / length : 0.0f;
  n[0] = m[0] * inv, n[1] = m[1] * inv, n[2] = m[2] * inv;
}

#undef LANTERN_ALWAYS_INLINE

}  // namespace lantern
