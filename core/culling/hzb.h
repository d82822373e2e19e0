// Exact occlusion culling against a conservative hierarchical depth buffer (a max-depth pyramid)
// built on the CPU from the spheres already accepted for drawing.
//
// Level 0 holds, per pixel, an upper bound of the depth the GPU will store there once the
// accepted spheres are drawn, or +inf where no accepted sphere certainly covers the pixel centre.
// A sphere is rasterised into it only where its silhouette certainly contains the pixel centre
// (by the ViewGeometry tolerance), only if its impostor quad cannot be clipped by the near or far
// plane, and with the depth of its ray hit at that centre plus the tolerance. Level k holds the
// max of its 2x2 children, updated over each occluder's footprint as it is added. A query "is every
// pixel of this rectangle covered by something strictly nearer than depth z?" answered yes
// therefore implies that the GPU would reject every fragment of a sphere whose nearest depth is z:
// dropping it cannot change a bit of the image.
//
// Queries take view-space depths (ViewGeometry); the pyramid stores window depths, the GPU's own
// currency, with a margin of a few float ulps on each side.
// Thread-safety: none (one culling thread owns it).
#pragma once

#include <atomic>
#include <vector>

#include <glm/vec3.hpp>

#include "core/view/max_depth_pyramid.h"
#include "core/view/pixel_rays.h"
#include "core/view/view_geometry.h"

namespace lantern {

class Hzb {
 public:
  // Clears to "nothing covered" for an image of g.width x g.height.
  void reset(const ViewGeometry &g);

  // True if every pixel of `rect` holds something certainly nearer than view depth z (rect
  // already clamped to the image).
  bool covered(const PixelRect &rect, double z) const;

  // Rasterises the accepted sphere (view-space centre c, radius r) into level 0, over `rect`
  // (its sphere_rect). Returns false (and writes nothing) when the sphere is unusable as an
  // occluder (its impostor could be clipped, or the eye is inside it).
  bool add_occluder(const glm::dvec3 &c, double r, const PixelRect &rect);

  // Level 0, row by row (tests compare it).
  const std::vector<float> &depth() const { return depth_; }

  // Whether add_occluder may rasterise four columns at a time with AVX2 where the processor has
  // it (the same depths bit for bit; tests turn it off to compare). Process-wide.
  static std::atomic<bool> &vector_rows();

 private:
  bool usable(const glm::dvec3 &c, double r) const;

  ViewGeometry g_;
  std::vector<float> depth_;  // level 0: the conservative window depth per pixel
  MaxDepthPyramid pyramid_;   // levels 1.. over depth_
  PixelRays rays_;
};

}  // namespace lantern
