// View-frustum culling (the nine-spheres paper, §3.1, "patch filtering"): bricks wholly outside are
// dropped, bricks wholly inside skip per-particle work, and only straddling bricks test each
// particle.
//
// Tests run in view space in double with the ViewGeometry tolerance on the "keep" side, so a
// sphere the GPU could still rasterise (in float) is never dropped. "Inside" means the sphere
// cannot cross any of the six planes, near and far included.
// Thread-safety: immutable value type.
#pragma once

#include <glm/vec3.hpp>

#include "core/view/view_geometry.h"

namespace lantern {

enum class Containment { kOutside, kStraddling, kInside };

class Frustum {
 public:
  explicit Frustum(const ViewGeometry &g);

  // The sphere at view-space centre c with radius r.
  Containment classify_sphere(const glm::dvec3 &c, double r) const;
  // A set of spheres whose centres lie in the view-space box spanned by `corners` (8 points)
  // and whose radii are at most r.
  Containment classify_box(const glm::dvec3 corners[8], double r) const;

 private:
  // Plane k: n . p + offset <= 0 inside; n unit length.
  glm::dvec3 n_[6];
  double offset_[6];
  double eps_;
};

}  // namespace lantern
