// The pixel grid as seen from one reference pixel, in float: the float casts (spheres, cylinders)
// place the reference next to the ray through their own centre and take each pixel's offset from
// that ray as off + k * step, so that float keeps its precision anywhere in the image.
// Thread-safety: a plain value.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/view/divide_pair.h"
#include "core/view/pixel_rays.h"

namespace lantern {

struct ReferenceRayGrid {
  // The reference: the column and row of the ray (cu, cv) (perspective: its slopes; orthographic:
  // its origin), clamped far outside any image; off_* is the reference ray minus (cu, cv).
  void place(const PixelRays &rays, double cu, double cv) {
    const double *rx = rays.x_data(), *ry = rays.y_data();
    const double sx = rx[1] - rx[0], sy = ry[1] - ry[0];
    double qx, qy;  // both quotients in one packed division: the bits of two
    divide_pair(cu - rx[0], cv - ry[0], sx, sy, &qx, &qy);
    ref_x = int(std::clamp(std::floor(qx), -1e9, 1e9));
    ref_y = int(std::clamp(std::floor(qy), -1e9, 1e9));
    step_x = float(sx), step_y = float(sy);
    off_x = float(rx[0] + ref_x * sx - cu), off_y = float(ry[0] + ref_y * sy - cv);
  }

  int ref_x = 0, ref_y = 0;                            // reference column and row
  float step_x = 0, step_y = 0, off_x = 0, off_y = 0;  // ray steps; the reference's (dx, dy)
};

}  // namespace lantern
