#include "core/finish/overlays/box_overlay.h"

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

namespace lantern {
namespace {

LinePoint to_window(const glm::dvec4 &clip, int width, int height) {
  const double x = clip.x / clip.w, y = clip.y / clip.w, z = clip.z / clip.w;
  return {(x * 0.5 + 0.5) * width, (0.5 - y * 0.5) * height, z * 0.5 + 0.5};
}

// The segment a-b (clip space) with the part in front of the near plane (z < -w) cut off.
bool clip_near(glm::dvec4 *a, glm::dvec4 *b) {
  const double da = a->z + a->w, db = b->z + b->w;  // >= 0 on the visible side
  if (da < 0 && db < 0) return false;
  if (da < 0) *a = *a + (*b - *a) * (da / (da - db));
  if (db < 0) *b = *b + (*a - *b) * (db / (db - da));
  return true;
}

}  // namespace

bool project_point(const Camera &camera, int width, int height, const std::array<double, 3> &point,
                   LinePoint *out) {
  const glm::dvec4 clip =
      camera.projection * camera.view * glm::dvec4(point[0], point[1], point[2], 1.0);
  if (clip.z + clip.w < 0 || !(clip.w > 0)) return false;
  *out = to_window(clip, width, height);
  return true;
}

void draw_box(const BoxOverlayConfig &config, const BoxCorners &box, const Camera &camera,
              Frame *image) {
  const glm::dmat4 to_clip = camera.projection * camera.view;
  glm::dvec4 corners[8];
  // A triclinic box's corners low + i a + j b + k c, with a = (lx, 0, 0), b = (xy, ly, 0),
  // c = (xz, yz, lz): the axis-aligned corner moved by the tilts of b and c (zero: the same bits).
  const double xy = box.tilt[0], xz = box.tilt[1], yz = box.tilt[2];
  for (int c = 0; c < 8; ++c) {
    const double j = (c & 2) ? 1.0 : 0.0, k = (c & 4) ? 1.0 : 0.0;
    glm::dvec4 corner((c & 1) ? box.high[0] : box.low[0], (c & 2) ? box.high[1] : box.low[1],
                      (c & 4) ? box.high[2] : box.low[2], 1.0);
    if (xy != 0.0 || xz != 0.0 || yz != 0.0) corner.x += j * xy + k * xz, corner.y += k * yz;
    corners[c] = to_clip * corner;
  }
  const bool depth_test = image->depth.size() == image->pixel_count();
  const Rgb8 color = to_rgb8(config.color);
  // The edges join corners that differ in one axis bit.
  for (int c = 0; c < 8; ++c)
    for (int axis = 1; axis < 8; axis <<= 1) {
      if (c & axis) continue;
      glm::dvec4 a = corners[c], b = corners[c | axis];
      if (!clip_near(&a, &b) || !(a.w > 0) || !(b.w > 0)) continue;
      draw_line(image, to_window(a, image->width, image->height),
                to_window(b, image->width, image->height), config.width, color, depth_test);
    }
}

}  // namespace lantern
