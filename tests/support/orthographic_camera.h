// Test support: the orthographic camera the finishing tests look through, looking down -z from
// (0, 0, 50) at the origin with near plane 10 and far plane 90, so that a point at world z = w is
// at distance 50 - w from the eye and window depth (40 - w) / 80.
#pragma once

#include <array>

#include <glm/vec3.hpp>

#include "core/camera/camera.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {

// Framing the cube [-half, half]^3 (with `radius`, the particles' largest, around it) in a
// width x height image.
inline Camera orthographic_down_z(double half, double radius, int width, int height) {
  CameraConfig c;
  c.projection = Projection::kOrthographic;
  c.position = std::array<double, 3>{0, 0, 50};
  c.look_at = {0, 0, 0};
  c.up = {0, 1, 0};
  c.near_plane = 10;
  c.far_plane = 90;
  Camera camera;
  EXPECT_OK(make_camera(c, glm::dvec3(-half), glm::dvec3(half), radius, width, height, &camera));
  return camera;
}

}  // namespace lantern::testing
