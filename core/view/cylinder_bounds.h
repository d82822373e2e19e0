// The axis-aligned bounds of a closed cylinder (a half-bond): in the frame the ends are given in,
// the cylinder from a to b of radius r reaches r * sqrt(1 - u_k^2) beyond its ends along axis k,
// u the unit axis (exactly: the extreme points lie on the end discs' rims). Used in view space by
// culling (screen rectangle, nearest depth) and by the CPU raster, whose rectangle must hold every
// pixel the cylinder covers.
// Thread-safety: pure functions. Units: those of the ends.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/view/view_geometry.h"

namespace lantern {

struct CylinderBounds {
  glm::dvec3 lo, hi;
};

inline CylinderBounds cylinder_bounds(const glm::dvec3 &a, const glm::dvec3 &b, double r) {
  const glm::dvec3 u = b - a;
  const double length2 = glm::dot(u, u);
  glm::dvec3 reach(r);
  if (length2 > 0.0)
    for (int k = 0; k < 3; ++k)
      reach[k] = r * std::sqrt(std::max(1.0 - u[k] * u[k] / length2, 0.0));
  return {glm::min(a, b) - reach, glm::max(a, b) + reach};
}

// The 8 corners of a box, in the order ViewGeometry::box_rect and Frustum::classify_box take.
inline void box_corners(const glm::dvec3 &lo, const glm::dvec3 &hi, glm::dvec3 out[8]) {
  for (int k = 0; k < 8; ++k)
    out[k] = {k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z};
}

// Every pixel whose centre the cylinder (view-space ends a, b, radius r) could cover, clamped to
// the image, and the nearest view depth it reaches less the tolerance g.eps.
inline PixelRect cylinder_rect(const ViewGeometry &g, const glm::dvec3 &a, const glm::dvec3 &b,
                               double r, double *near_depth) {
  const CylinderBounds box = cylinder_bounds(a, b, r + g.eps);
  *near_depth = -box.hi.z - g.eps;
  return g.box_rect(box.lo, box.hi);
}

}  // namespace lantern
