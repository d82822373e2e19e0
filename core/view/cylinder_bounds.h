// The axis-aligned bounds of a closed cylinder (a half-bond): in the frame the ends are given in,
// the cylinder from a to b of radius r reaches r * sqrt(1 - u_k^2) beyond its ends along axis k,
// u the unit axis (exactly: the extreme points lie on the end discs' rims). Used in view space by
// culling (screen rectangle, nearest depth) and by the CPU raster, whose rectangle must hold every
// pixel the cylinder covers.
// Thread-safety: pure functions. Units: those of the ends.
#pragma once

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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
  if (length2 > 0.0) {
#if defined(__SSE2__)
    // x and y side by side: the same IEEE operations (std::max(q, 0.0) is _mm_max_pd(0, q)).
    const __m128d xy = _mm_set_pd(u.y, u.x), one = _mm_set1_pd(1.0);
    const __m128d q = _mm_sub_pd(one, _mm_div_pd(_mm_mul_pd(xy, xy), _mm_set1_pd(length2)));
    const __m128d root = _mm_mul_pd(_mm_set1_pd(r), _mm_sqrt_pd(_mm_max_pd(_mm_setzero_pd(), q)));
    reach.x = _mm_cvtsd_f64(root), reach.y = _mm_cvtsd_f64(_mm_unpackhi_pd(root, root));
    reach.z = r * std::sqrt(std::max(1.0 - u.z * u.z / length2, 0.0));
#else
    for (int k = 0; k < 3; ++k)
      reach[k] = r * std::sqrt(std::max(1.0 - u[k] * u[k] / length2, 0.0));
#endif
  }
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
