// The nine-spheres occluding rule (the nine-spheres paper, §3.2), an APPROXIMATE occlusion test.
//
// An auxiliary grid over the image holds, per pixel, an occupancy tag T (some drawn sphere's
// centre projects into it), the least depth D of those spheres, the smallest radius R among them
// and the count N of occupied pixels among its 8 neighbours. Processing spheres front to back, a
// sphere whose reference pixel (the pixel containing its projected centre) is occupied, has
// N = 8, and whose 3x3 block holds only nearer (D <= d) spheres that are not smaller (R >= r) is
// skipped; otherwise it is drawn and recorded.
//
// The paper's covering theorem counts a pixel as covered when a circle overlaps any of its area,
// while the GPU samples pixel centres, so the rule can drop a sphere that would have shown at a
// few pixels; lantern-bench measures that error. (R is our addition: the paper's rule says "not
// smaller" but stores no radius.) Thread-safety: none (one culling thread owns it).
//
// Which radius R and r are is the caller's choice (culling.nine_spheres_radius): the drawn
// radius, or the equivalent radius of the nine-spheres paper's conference version
// (equivalent_radius below). With equal equivalent radii the spheres project to equal circles, the
// setting of the paper's nine-circles covering theorem.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/view/view_geometry.h"

namespace lantern {

// The equivalent radius (the nine-spheres paper's conference version) of a sphere of radius r at
// view depth d: the radius of the sphere moved along the line of sight onto the near plane and
// scaled so that its projected size stays the same, r * near / d under perspective (the projected
// radius in pixels divided by the near plane's pixels per unit); r under an orthographic
// projection, where depth does not scale. Units: the simulation's length unit.
inline double equivalent_radius(const ViewGeometry &g, double d, double r) {
  return g.orthographic ? r : r * g.near_plane / std::max(d, g.near_plane);
}

class NineSpheresGrid {
 public:
  void reset(int width, int height);

  // Pixel (x, y) is the reference pixel; d the sphere's depth (any monotonic depth), r its
  // radius. Returns true when the rule hides it; otherwise records it as drawn and returns false.
  // Reference pixels outside the image are always drawn (and not recorded).
  bool test_and_record(int x, int y, float d, float r);

 private:
  int w_ = 0, h_ = 0;
  std::vector<uint8_t> occupied_, neighbours_;
  std::vector<float> depth_, radius_;
};

}  // namespace lantern
