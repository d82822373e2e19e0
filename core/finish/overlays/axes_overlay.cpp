#include "core/finish/overlays/axes_overlay.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "core/finish/overlays/overlay_canvas.h"

namespace lantern {

void draw_axes(const AxesConfig &axes, const Camera &camera, FontFace &font, OverlayLayout &layout,
               Frame *image) {
  const std::array<int, 2> at = layout.place(axes.position, axes.size, axes.size);
  const double cx = at[0] + 0.5 * axes.size, cy = at[1] + 0.5 * axes.size;
  const double length = 0.32 * axes.size, width = std::max(1.5, axes.size / 40.0);
  const glm::dmat3 rotation(camera.view);  // world -> view, the camera looking down -z
  static constexpr std::array<std::array<double, 3>, 3> kColors = {
      {{0.85, 0.10, 0.10}, {0.10, 0.60, 0.10}, {0.15, 0.30, 0.90}}};
  static constexpr const char *kNames[3] = {"x", "y", "z"};
  std::array<glm::dvec3, 3> directions;
  std::array<int, 3> order{0, 1, 2};
  for (int i = 0; i < 3; ++i) {
    glm::dvec3 unit(0.0);
    unit[i] = 1.0;
    directions[size_t(i)] = rotation * unit;
  }
  // Farthest first (smallest view z), so that the nearer axes cover it where they cross.
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return directions[size_t(a)].z < directions[size_t(b)].z; });
  for (const int i : order) {
    const glm::dvec3 &d = directions[size_t(i)];
    const Rgb8 color = to_rgb8(kColors[size_t(i)]);
    const LinePoint tip{cx + length * d.x, cy - length * d.y, 0};
    draw_line(image, {cx, cy, 0}, tip, width, color, false);
    const TextMask name = font.render(kNames[i], axes.font_size);
    const double reach = length + 0.6 * axes.font_size;
    draw_mask(image, name, int(std::lround(cx + reach * d.x - 0.5 * name.width)),
              int(std::lround(cy - reach * d.y - 0.5 * name.height)), color);
  }
}

}  // namespace lantern
