// Synthetic rendered frames for compositing tests and benchmarks: analytic spheres drawn on the
// CPU with exact depth, and an independent serial merge to compare against.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/view/frame.h"

namespace lantern::testing {

inline constexpr uint8_t kBackground[4] = {10, 20, 30, 255};

// A sphere seen along -z: centre in pixels, radius in pixels, centre depth and depth radius in
// window depth units. flat = true draws a disc of constant depth (to provoke depth ties).
struct Sphere {
  double cx = 0, cy = 0, radius = 0;
  float depth = 0.5f, depth_radius = 0.1f;
  uint8_t rgba[4] = {255, 255, 255, 255};
  bool flat = false;
};

// A background-cleared frame.
Frame blank_frame(int width, int height);

// Draws s into frame with a depth test (nearer wins, ties keep the smaller color), shading the
// color by the surface normal so neighbouring pixels differ.
void draw_sphere(const Sphere &s, Frame &frame);

// The sphere rank `rank` of a test case draws: deterministic in (rank, seed), overlapping its
// neighbours', inside a width x height image.
Sphere sphere_for_rank(int rank, int seed, int width, int height, bool flat);

// The expected composite: per pixel the smallest depth, ties by the lexicographically smallest
// RGBA. Written independently of core/composite (no packed keys).
Frame serial_merge(const std::vector<Frame> &frames);

// "" if a and b are bit-identical (color and depth bits), else how many pixels differ and where
// the first one is.
std::string describe_difference(const Frame &a, const Frame &b);

}  // namespace lantern::testing
