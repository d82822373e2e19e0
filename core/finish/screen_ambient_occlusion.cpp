#include "core/finish/screen_ambient_occlusion.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace lantern {

namespace {

constexpr float kGoldenAngle = 2.39996323f;  // radians: pi (3 - sqrt 5)
// Added before truncating a sample offset (|offset| <= kMaxAoPixels) to round it to nearest.
constexpr float kRoundShift = float(kMaxAoPixels + 1) + 0.5f;

glm::vec3 position(const ViewPositions &v, int x, int y, float z) {
  return {v.view_x(x, z), v.view_y(y, z), -z};
}

// The tangent along one axis at (x, y): towards the neighbour whose depth differs less, or a
// zero vector where both neighbours are background or outside the held rows.
glm::vec3 tangent(const ViewPositions &v, int x, int y, const glm::vec3 &p, int dx, int dy) {
  glm::vec3 best(0.0f);
  float best_step = ViewPositions::kBackground;
  for (const int s : {1, -1}) {
    const int nx = x + s * dx, ny = y + s * dy;
    if (nx < 0 || nx >= v.width() || ny < v.first_row() || ny >= v.last_row()) continue;
    const float z = v.z(nx, ny);
    if (z == ViewPositions::kBackground) continue;
    const float step = std::abs(z - (-p.z));
    if (step < best_step) {
      best_step = step;
      best = float(s) * (position(v, nx, ny, z) - p);
    }
  }
  return best;
}

// The surface normal at (x, y), facing the eye; the direction to the eye where it cannot be
// reconstructed.
glm::vec3 normal_at(const ViewPositions &v, int x, int y, const glm::vec3 &p) {
  const glm::vec3 to_eye = glm::normalize(-p);
  const glm::vec3 n = glm::cross(tangent(v, x, y, p, 1, 0), tangent(v, x, y, p, 0, 1));
  const float length = glm::length(n);
  if (!(length > 0.0f)) return to_eye;
  return glm::dot(n, to_eye) < 0.0f ? -n / length : n / length;
}

// The spiral's unit-disc offsets, turned for each of the 16 pixel positions mod 4.
std::vector<float> sample_kernel(int samples) {
  std::vector<float> kernel(size_t(16) * size_t(samples) * 2);
  for (int r = 0; r < 16; ++r) {
    const float turn = float(r) * (2.0f * 3.14159265f / 16.0f);
    for (int k = 0; k < samples; ++k) {
      const float a = float(k) * kGoldenAngle + turn;
      const float d = std::sqrt((float(k) + 0.5f) / float(samples));
      kernel[(size_t(r) * size_t(samples) + size_t(k)) * 2] = d * std::cos(a);
      kernel[(size_t(r) * size_t(samples) + size_t(k)) * 2 + 1] = d * std::sin(a);
    }
  }
  return kernel;
}

// A fixed shuffle of the 16 turns over a 4 x 4 block, so neighbouring pixels differ most.
constexpr int kTurnOf[16] = {0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5};

}  // namespace

void apply_screen_ambient_occlusion(const ViewPositions &v, const AmbientOcclusionStyle &style,
                                    BandFrame *band) {
  const int w = v.width(), h = v.height(), n = style.samples;
  const std::vector<float> kernel = sample_kernel(n);
  const float r2 = style.radius * style.radius;
  const float gain = 2.0f * style.strength / float(n);
  for (int y = band->owned.y0; y < band->owned.y1; ++y) {
    uint8_t *rgba = &band->frame.rgba[size_t(y - band->first) * size_t(w) * 4];
    for (int x = 0; x < w; ++x) {
      const float z = v.z(x, y);
      if (z == ViewPositions::kBackground) continue;
      const float pixels = std::min(float(kMaxAoPixels), style.radius * v.pixels_per_unit(z));
      if (pixels < 1.0f) continue;  // the whole kernel would read this pixel
      const glm::vec3 p = position(v, x, y, z);
      const glm::vec3 normal = normal_at(v, x, y, p);
      const float *k = &kernel[size_t(kTurnOf[(y & 3) * 4 + (x & 3)]) * size_t(n) * 2];
      float occlusion = 0.0f;
      for (int s = 0; s < n; ++s) {
        // Offsets rounded to nearest (half up) by truncating a positive value: no libm call.
        const int sx = x + int(pixels * k[2 * s] + kRoundShift) - kMaxAoPixels - 1;
        const int sy = y + int(pixels * k[2 * s + 1] + kRoundShift) - kMaxAoPixels - 1;
        if (sx < 0 || sx >= w || sy < 0 || sy >= h) continue;
        const float sz = v.z(sx, sy);
        if (sz == ViewPositions::kBackground) continue;
        const glm::vec3 d = position(v, sx, sy, sz) - p;
        const float d2 = glm::dot(d, d);
        if (!(d2 > 0.0f) || d2 >= r2) continue;
        const float cosine = glm::dot(normal, d) / std::sqrt(d2);
        occlusion += std::max(0.0f, cosine - kAoBias) * (1.0f - d2 / r2);
      }
      const float keep = 1.0f - std::min(style.strength, gain * occlusion);
      for (int c = 0; c < 3; ++c) rgba[4 * x + c] = uint8_t(float(rgba[4 * x + c]) * keep + 0.5f);
    }
  }
}

}  // namespace lantern
