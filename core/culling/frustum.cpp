#include "core/culling/frustum.h"

#include <cmath>

namespace lantern {

Frustum::Frustum(const ViewGeometry &g) : eps_(g.eps) {
  // Side planes. Perspective: |sx x| <= d = -z, i.e. +-sx x + z <= 0. Orthographic: |sx x + tx|
  // <= 1.
  int k = 0;
  for (int axis = 0; axis < 2; ++axis) {
    const double s = axis == 0 ? g.sx : g.sy;
    const double t = axis == 0 ? g.tx : g.ty;
    for (int sign = -1; sign <= 1; sign += 2) {
      glm::dvec3 n(0.0);
      double off = 0.0;
      if (g.orthographic) {
        n[axis] = sign * s;  // sign * (s x + t) - 1 <= 0
        off = sign * t - 1.0;
      } else {
        n[axis] = sign * s;
        n.z = 1.0;
      }
      const double len = glm::length(n);
      n_[k] = n / len;
      offset_[k] = off / len;
      ++k;
    }
  }
  // Near: d >= near  <=>  z + near <= 0.  Far: d <= far  <=>  -z - far <= 0.
  n_[4] = {0, 0, 1};
  offset_[4] = g.near_plane;
  n_[5] = {0, 0, -1};
  offset_[5] = -g.far_plane;
}

Containment Frustum::classify_sphere(const glm::dvec3 &c, double r) const {
  bool inside = true;
  for (int k = 0; k < 6; ++k) {
    const double s = glm::dot(n_[k], c) + offset_[k];
    if (s > r + eps_) return Containment::kOutside;
    if (s > -r - eps_) inside = false;
  }
  return inside ? Containment::kInside : Containment::kStraddling;
}

Containment Frustum::classify_box(const glm::dvec3 corners[8], double r) const {
  bool inside = true;
  for (int k = 0; k < 6; ++k) {
    double lo = glm::dot(n_[k], corners[0]), hi = lo;
    for (int c = 1; c < 8; ++c) {
      const double s = glm::dot(n_[k], corners[c]);
      lo = std::min(lo, s), hi = std::max(hi, s);
    }
    if (lo + offset_[k] > r + eps_) return Containment::kOutside;
    if (hi + offset_[k] > -r - eps_) inside = false;
  }
  return inside ? Containment::kInside : Containment::kStraddling;
}

}  // namespace lantern
