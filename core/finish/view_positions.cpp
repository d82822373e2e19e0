#include "core/finish/view_positions.h"

namespace lantern {

void ViewPositions::build(const BandFrame &band, const Camera &camera) {
  width_ = band.frame.width;
  height_ = camera.height;
  first_ = band.first;
  rows_ = band.frame.height;
  orthographic_ = camera.orthographic;
  // A pixel centre's normalised device x is 2 (x + 0.5) / W - 1 (y flipped: row 0 is the top).
  // Perspective: x_view = (x_ndc + P[2][0]) * z / P[0][0]; orthographic: (x_ndc - P[3][0]) /
  // P[0][0]. glm's matrices are column-major: P[column][row].
  const glm::dmat4 &p = camera.projection;
  const double sx = 1.0 / p[0][0], sy = 1.0 / p[1][1];
  const double shift_x = orthographic_ ? -p[3][0] : p[2][0];
  const double shift_y = orthographic_ ? -p[3][1] : p[2][1];
  x_scale_ = float(2.0 / camera.width * sx);
  x_offset_ = float((shift_x - 1.0) * sx);
  y_scale_ = float(-2.0 / camera.height * sy);
  y_offset_ = float((shift_y + 1.0) * sy);
  ppu_ = float(0.5 * camera.height * p[1][1]);
  z_.resize(band.frame.pixel_count());
  for (size_t i = 0; i < z_.size(); ++i) {
    const float d = band.frame.depth[i];
    z_[i] = d >= kBackgroundDepth ? kBackground : float(camera.window_depth_to_distance(d));
  }
}

}  // namespace lantern
