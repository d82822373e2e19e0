// The rays through the pixel centres of one camera, as the sphere shader casts them, tabulated
// per column and row, and the span of a row whose rays can hit a sphere. Shared by the hzb
// pyramid (which needs a superset of the pixels a sphere certainly covers) and the CPU raster
// (which ray-casts exactly the pixels the span names).
//
// Ray through pixel (x, y): perspective D = (ray_x(x), ray_y(y), -1) from the eye;
// orthographic: origin (ray_x(x), ray_y(y)) on the near plane, direction -z (ViewGeometry).
// Thread-safety: immutable after reset(); concurrent readers are fine.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "core/view/view_geometry.h"

namespace lantern {

class PixelRays {
 public:
  // x_data() / y_data() hold kPadding columns / rows past the image (same affine formula), so
  // blocked loops may read a few entries beyond the last one they use.
  static constexpr int kPadding = 8;

  void reset(const ViewGeometry &g);

  double x(int column) const { return x_[size_t(column)]; }
  double y(int row) const { return y_[size_t(row)]; }
  const double *x_data() const { return x_.data(); }
  const double *y_data() const { return y_.data(); }

  // Columns [*x0, *x1] of `row`, within [lo, hi], whose rays may pass closer than sqrt(r2) to
  // the view-space point c: the analytic interval widened by `widen` pixels on each side.
  // False when no column qualifies, and when the quadratic's squares overflow (lengths beyond
  // about 1e77): a caller may only lose by a span left out (the hierarchical z-buffer's
  // occluders). (A whole-row answer when the quadratic degenerates.)
  bool row_span(const glm::dvec3 &c, double r2, int row, int lo, int hi, double widen, int *x0,
                int *x1) const;

 private:
  bool orthographic_ = false;
  int width_ = 0;
  std::vector<double> x_, y_;  // width_ + kPadding, height + kPadding entries
};

}  // namespace lantern
