#include "synthetic_frames.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include "tests/support/hash_noise.h"

namespace lantern::testing {
namespace {

// Nearer first, then lexicographically smaller color: the documented compositing rule.
bool wins(float depth_a, const uint8_t *rgba_a, float depth_b, const uint8_t *rgba_b) {
  if (depth_a != depth_b) return depth_a < depth_b;
  return std::lexicographical_compare(rgba_a, rgba_a + 4, rgba_b, rgba_b + 4);
}

}  // namespace

Frame blank_frame(int width, int height) {
  Frame f(width, height);
  f.clear(kBackground);
  return f;
}

void draw_sphere(const Sphere &s, Frame &frame) {
  const int x0 = std::max(0, int(std::floor(s.cx - s.radius)));
  const int x1 = std::min(frame.width - 1, int(std::ceil(s.cx + s.radius)));
  const int y0 = std::max(0, int(std::floor(s.cy - s.radius)));
  const int y1 = std::min(frame.height - 1, int(std::ceil(s.cy + s.radius)));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const double dx = (x + 0.5 - s.cx) / s.radius, dy = (y + 0.5 - s.cy) / s.radius;
      const double r2 = dx * dx + dy * dy;
      if (r2 > 1.0) continue;
      const double nz = std::sqrt(1.0 - r2);
      const float depth = s.flat ? s.depth : float(s.depth - s.depth_radius * nz);
      const double shade = s.flat ? 1.0 : 0.25 + 0.75 * nz;
      uint8_t rgba[4];
      for (int c = 0; c < 3; ++c) rgba[c] = uint8_t(std::lround(s.rgba[c] * shade));
      rgba[3] = s.rgba[3];
      const size_t i = frame.index(x, y);
      if (wins(depth, rgba, frame.depth[i], &frame.rgba[4 * i])) {
        frame.depth[i] = depth;
        std::memcpy(&frame.rgba[4 * i], rgba, 4);
      }
    }
  }
}

Sphere sphere_for_rank(int rank, int seed, int width, int height, bool flat) {
  const uint32_t h = hash(uint32_t(rank) * 7919U + uint32_t(seed) * 104729U + 1U);
  Sphere s;
  const double m = std::min(width, height);
  s.radius = std::max(1.0, m * (0.2 + 0.15 * unit(hash(h + 1))));
  s.cx = width * (0.25 + 0.5 * unit(hash(h + 2)));
  s.cy = height * (0.25 + 0.5 * unit(hash(h + 3)));
  // Flat discs share one of two depths, so ties between ranks are common.
  s.depth = flat ? (hash(h + 4) & 1 ? 0.25f : 0.5f) : float(0.3 + 0.4 * unit(hash(h + 4)));
  s.depth_radius = 0.2f;
  for (int c = 0; c < 3; ++c) s.rgba[c] = uint8_t(hash(h + 5 + c) & 0xff);
  s.rgba[3] = 255;
  s.flat = flat;
  return s;
}

Frame serial_merge(const std::vector<Frame> &frames) {
  Frame out = frames.at(0);
  for (size_t f = 1; f < frames.size(); ++f) {
    const Frame &in = frames[f];
    for (size_t i = 0; i < out.pixel_count(); ++i) {
      if (wins(in.depth[i], &in.rgba[4 * i], out.depth[i], &out.rgba[4 * i])) {
        out.depth[i] = in.depth[i];
        std::memcpy(&out.rgba[4 * i], &in.rgba[4 * i], 4);
      }
    }
  }
  return out;
}

std::string describe_difference(const Frame &a, const Frame &b) {
  if (a.width != b.width || a.height != b.height) return "sizes differ";
  size_t differing = 0, first = 0;
  for (size_t i = 0; i < a.pixel_count(); ++i) {
    const bool same = std::memcmp(&a.rgba[4 * i], &b.rgba[4 * i], 4) == 0 &&
                      std::memcmp(&a.depth[i], &b.depth[i], sizeof(float)) == 0;
    if (!same && differing++ == 0) first = i;
  }
  if (differing == 0) return {};
  std::ostringstream out;
  out << differing << " of " << a.pixel_count() << " pixels differ; first at (x "
      << first % size_t(a.width) << ", y " << first / size_t(a.width) << "): depth "
      << a.depth[first] << " vs " << b.depth[first] << ", rgba " << int(a.rgba[4 * first]) << ","
      << int(a.rgba[4 * first + 1]) << "," << int(a.rgba[4 * first + 2]) << " vs "
      << int(b.rgba[4 * first]) << "," << int(b.rgba[4 * first + 1]) << ","
      << int(b.rgba[4 * first + 2]);
  return out.str();
}

}  // namespace lantern::testing
