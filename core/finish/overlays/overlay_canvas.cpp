#include "core/finish/overlays/overlay_canvas.h"

#include <algorithm>
#include <cmath>

namespace lantern {
namespace {

uint8_t mix(uint8_t over, uint8_t under, unsigned a) {
  return uint8_t((over * a + under * (255u - a) + 127u) / 255u);
}

// Straight-alpha "over" (Porter and Duff, Compositing Digital Images, SIGGRAPH 1984) of `over`
// at coverage a onto `under` at alpha u < 255: the colours weighted by their share of the
// result, a 255 + u (255 - a) in units of 1 / 255^2, rounded to nearest. At u = 255 it is mix().
uint8_t mix_straight(uint8_t over, uint8_t under, unsigned a, unsigned u) {
  const unsigned weight = a * 255u + u * (255u - a);  // > 0: a > 0
  return uint8_t((over * a * 255u + under * u * (255u - a) + weight / 2) / weight);
}

}  // namespace

void blend_pixel(Frame *image, int x, int y, const Rgb8 &color, uint8_t coverage) {
  if (x < 0 || y < 0 || x >= image->width || y >= image->height || coverage == 0) return;
  uint8_t *p = image->rgba.data() + 4 * image->index(x, y);
  // An opaque pixel takes the plain blend; a transparent background's pixels hold straight
  // colour, whose share in the result is its alpha (where nothing was drawn, none at all).
  if (p[3] == 255)
    for (int c = 0; c < 3; ++c) p[c] = mix(color[c], p[c], coverage);
  else
    for (int c = 0; c < 3; ++c) p[c] = mix_straight(color[c], p[c], coverage, p[3]);
  p[3] = uint8_t(p[3] + (coverage * (255u - p[3]) + 127u) / 255u);
}

void draw_mask(Frame *image, const TextMask &mask, int x, int y, const Rgb8 &color) {
  const int y0 = std::max(0, -y), y1 = std::min(mask.height, image->height - y);
  const int x0 = std::max(0, -x), x1 = std::min(mask.width, image->width - x);
  for (int j = y0; j < y1; ++j)
    for (int i = x0; i < x1; ++i)
      blend_pixel(image, x + i, y + j, color, mask.coverage[size_t(j) * mask.width + i]);
}

void fill_rect(Frame *image, int x, int y, int w, int h, const Rgb8 &color) {
  const int x0 = std::max(0, x), x1 = std::min(image->width, x + w);
  const int y0 = std::max(0, y), y1 = std::min(image->height, y + h);
  for (int j = y0; j < y1; ++j)
    for (int i = x0; i < x1; ++i) blend_pixel(image, i, j, color, 255);
}

void draw_line(Frame *image, const LinePoint &a, const LinePoint &b, double width,
               const Rgb8 &color, bool depth_test) {
  const double dx = b.x - a.x, dy = b.y - a.y, length2 = dx * dx + dy * dy;
  if (!std::isfinite(length2)) return;
  const double half = 0.5 * width;
  // Step along the major axis; across it, cover every pixel the line's width may reach (the
  // width across a major-axis column is at most sqrt(2) times the line's).
  const bool steep = std::abs(dy) > std::abs(dx);
  const double reach = half * 1.5 + 1.0;
  const double m0 = steep ? std::min(a.y, b.y) : std::min(a.x, b.x);
  const double m1 = steep ? std::max(a.y, b.y) : std::max(a.x, b.x);
  const int major_size = steep ? image->height : image->width;
  const int minor_size = steep ? image->width : image->height;
  // Clamped to the image (and one past it) before any conversion to int: an edge of a box far
  // larger than the view, clipped at the near plane, may project billions of pixels away, where
  // the conversion was undefined (on x86 INT_MIN: a loop of 2^31 columns).
  const auto clamped_int = [](double v, int lo, int hi) {
    return v > double(lo) ? (v < double(hi) ? int(v) : hi) : lo;
  };
  const int first = clamped_int(std::floor(m0 - reach), 0, major_size);
  const int last = clamped_int(std::ceil(m1 + reach), -1, major_size - 1);
  const double slope = steep ? (dy != 0 ? dx / dy : 0) : (dx != 0 ? dy / dx : 0);
  for (int m = first; m <= last; ++m) {
    const double along = m + 0.5;
    const double clamped = std::clamp(along, m0, m1);
    const double across = steep ? a.x + (clamped - a.y) * slope : a.y + (clamped - a.x) * slope;
    const int n0 = clamped_int(std::floor(across - reach), 0, minor_size),
              n1 = clamped_int(std::ceil(across + reach), -1, minor_size - 1);
    for (int n = n0; n <= n1; ++n) {
      const int x = steep ? n : m, y = steep ? m : n;
      if (x < 0 || y < 0 || x >= image->width || y >= image->height) continue;
      const double px = x + 0.5 - a.x, py = y + 0.5 - a.y;
      const double t = length2 > 0 ? std::clamp((px * dx + py * dy) / length2, 0.0, 1.0) : 0.0;
      const double ex = px - t * dx, ey = py - t * dy;
      const double coverage = std::clamp(half + 0.5 - std::sqrt(ex * ex + ey * ey), 0.0, 1.0);
      if (coverage <= 0) continue;
      if (depth_test) {
        const double depth = std::min(a.depth + t * (b.depth - a.depth), 1.0 - 1e-7);
        if (double(image->depth[image->index(x, y)]) < depth) continue;
      }
      blend_pixel(image, x, y, color, uint8_t(std::lround(coverage * 255.0)));
    }
  }
}

}  // namespace lantern
