// The moving camera (core/camera/camera_path.h) against analytic expectations: exact values at
// keyframes and outside the path, the half orbit's midpoint, a continuous first derivative across
// keyframes (measured numerically), motion on the sphere rather than per angle, the orbit form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>

#include "core/camera/camera_path.h"
#include "core/config/config.h"

namespace lantern {
namespace {

CameraKeyframe key(int64_t step, double azimuth, double elevation, double zoom) {
  CameraKeyframe k;
  k.step = step;
  k.azimuth = azimuth;
  k.elevation = elevation;
  k.zoom = zoom;
  return k;
}

CameraConfig path_of(std::vector<CameraKeyframe> keys) {
  CameraConfig c;
  c.path = std::move(keys);
  return c;
}

// Uneven spacing, elevation and zoom changing with the azimuth, a turn back.
CameraConfig winding_path() {
  return path_of({key(0, 0, 20, 1), key(100, 150, 45, 2), key(350, 60, -30, 0.5),
                  key(400, 200, 10, 1.5), key(1000, 250, 70, 3)});
}

double distance(const glm::dvec3 &a, const glm::dvec3 &b) {
  return glm::length(a - b);
}

TEST(CameraPath, KeyframesHoldTheirValuesExactly) {
  const CameraConfig c = winding_path();
  for (const CameraKeyframe &k : c.path) {
    const CameraConfig at = camera_at_step(c, k.step);
    EXPECT_EQ(at.azimuth, *k.azimuth) << "step " << k.step;
    EXPECT_EQ(at.elevation, *k.elevation) << "step " << k.step;
    EXPECT_EQ(at.zoom, *k.zoom) << "step " << k.step;
    EXPECT_TRUE(at.path.empty());
    EXPECT_FALSE(at.orbit.enabled);
    const CameraPose pose = camera_pose(c, double(k.step));
    EXPECT_EQ(pose.direction, view_direction(*k.azimuth, *k.elevation));
    EXPECT_EQ(pose.zoom, *k.zoom);
  }
}

TEST(CameraPath, StepsOutsideThePathHoldTheEndValues) {
  const CameraConfig c = path_of({key(100, 10, 5, 2), key(200, 100, 30, 4)});
  for (const int64_t step : {int64_t(0), int64_t(99), int64_t(100)}) {
    const CameraConfig at = camera_at_step(c, step);
    EXPECT_EQ(at.azimuth, 10);
    EXPECT_EQ(at.elevation, 5);
    EXPECT_EQ(at.zoom, 2);
  }
  for (const int64_t step : {int64_t(200), int64_t(201), int64_t(1) << 40}) {
    const CameraConfig at = camera_at_step(c, step);
    EXPECT_EQ(at.azimuth, 100);
    EXPECT_EQ(at.elevation, 30);
    EXPECT_EQ(at.zoom, 4);
  }
}

TEST(CameraPath, MidpointOfAHalfOrbitLooksFromAzimuth90) {
  // The straight line between the two views, and the great circle through them, would pass over
  // the pole; the orbit keeps the elevation.
  const CameraConfig c = path_of({key(0, 0, 20, 1), key(5000, 180, 20, 1)});
  const CameraConfig mid = camera_at_step(c, 2500);
  EXPECT_NEAR(mid.azimuth, 90.0, 1e-9);
  EXPECT_NEAR(mid.elevation, 20.0, 1e-9);
  EXPECT_NEAR(mid.zoom, 1.0, 1e-12);
  EXPECT_LT(distance(camera_pose(c, 2500).direction, view_direction(90, 20)), 1e-12);
  // The sign of the azimuth difference is the way round; its size the turn (270, not -90).
  EXPECT_NEAR(camera_at_step(path_of({key(0, 0, 20, 1), key(10, -180, 20, 1)}), 5).azimuth, -90,
              1e-9);
  EXPECT_NEAR(camera_at_step(path_of({key(0, 0, 20, 1), key(10, 270, 20, 1)}), 5).azimuth, 135,
              1e-9);
  // Azimuths many turns from zero move as their difference does.
  EXPECT_LT(distance(camera_pose(path_of({key(0, 3600, 20, 1), key(10, 3780, 20, 1)}), 5).direction,
                     view_direction(90, 20)),
            1e-9);
}

TEST(CameraPath, ZoomMovesGeometricallyBetweenTwoKeyframes) {
  const CameraConfig c = path_of({key(0, 0, 0, 1), key(100, 0, 0, 4)});
  EXPECT_NEAR(camera_pose(c, 50).zoom, 2.0, 1e-12);  // the geometric mean
  for (int step = 1; step < 100; ++step)
    EXPECT_GT(camera_pose(c, step).zoom, camera_pose(c, step - 1).zoom) << step;
}

// Between two keyframes the camera turns about one fixed axis: its view direction stays on one
// circle of the sphere (in one plane). Per-angle interpolation of azimuth and elevation leaves
// that plane when both change.
TEST(CameraPath, TwoKeyframesMoveAlongOneCircleOfTheSphere) {
  const CameraConfig c = path_of({key(0, 0, 0, 1), key(100, 90, 60, 1)});
  const glm::dvec3 a = camera_pose(c, 0).direction, b = camera_pose(c, 100).direction;
  const glm::dvec3 m = camera_pose(c, 50).direction;
  const glm::dvec3 normal = glm::normalize(glm::cross(m - a, b - a));
  for (int step = 5; step < 100; step += 10)
    EXPECT_NEAR(glm::dot(camera_pose(c, step).direction - a, normal), 0.0, 1e-12) << step;
  // The per-angle midpoint (azimuth 45, elevation 30) is off that circle.
  EXPECT_GT(std::abs(glm::dot(view_direction(45, 30) - a, normal)), 1e-2);
}

// One-sided difference quotients of the direction and zoom at each keyframe agree to within the
// quotient's own error (second derivative times h): no kink at inner keyframes, and at the ends
// the path starts and stops at rest, as the held values outside do.
TEST(CameraPath, FirstDerivativeIsContinuousAcrossKeyframes) {
  const CameraConfig c = winding_path();
  constexpr double h = 1e-4;
  for (size_t i = 0; i < c.path.size(); ++i) {
    const double s = double(c.path[i].step);
    const CameraPose before = camera_pose(c, s - h), at = camera_pose(c, s),
                     after = camera_pose(c, s + h);
    const glm::dvec3 left = (at.direction - before.direction) / h;
    const glm::dvec3 right = (after.direction - at.direction) / h;
    EXPECT_LT(distance(left, right), 1e-5) << "keyframe " << i;
    EXPECT_NEAR((at.zoom - before.zoom) / h, (after.zoom - at.zoom) / h, 1e-5) << "keyframe " << i;
    const bool end = i == 0 || i + 1 == c.path.size();
    if (end) {
      EXPECT_LT(glm::length(left) + glm::length(right), 1e-5) << "keyframe " << i;
    } else {
      EXPECT_GT(glm::length(right), 1e-3) << "keyframe " << i << " moves through";
    }
  }
}

// Inside segments the direction moves in small steps (no jumps, no flips through a wrong branch
// of a rotation), and stays a unit vector.
TEST(CameraPath, DirectionMovesContinuouslyAlongThePath) {
  const CameraConfig c = winding_path();
  glm::dvec3 previous = camera_pose(c, -1).direction;
  for (double s = 0; s <= 1001; s += 0.25) {
    const glm::dvec3 d = camera_pose(c, s).direction;
    EXPECT_NEAR(glm::length(d), 1.0, 1e-12);
    EXPECT_LT(distance(d, previous), 0.05) << "step " << s;
    previous = d;
  }
}

TEST(CameraPath, KeysLeftOutCarryThePreviousKeyframesOrTheCamerasValue) {
  CameraConfig c;
  c.azimuth = 40;
  c.elevation = 10;
  c.zoom = 3;
  CameraKeyframe first, second;
  first.step = 0;
  second.step = 100;
  second.azimuth = 130;
  c.path = {first, second};
  EXPECT_EQ(camera_at_step(c, 0).azimuth, 40);
  EXPECT_EQ(camera_at_step(c, 0).zoom, 3);
  const CameraConfig end = camera_at_step(c, 100);
  EXPECT_EQ(end.azimuth, 130);
  EXPECT_EQ(end.elevation, 10);
  EXPECT_EQ(end.zoom, 3);
  EXPECT_NEAR(camera_at_step(c, 50).azimuth, 85, 1e-9);
}

TEST(CameraPath, OrbitTurnsByItsRateEveryStep) {
  CameraConfig c;
  c.azimuth = 30;
  c.elevation = 15;
  c.orbit.enabled = true;
  c.orbit.degrees_per_step = 0.5;
  EXPECT_EQ(camera_at_step(c, 0).azimuth, 30);
  EXPECT_EQ(camera_at_step(c, 100).azimuth, 80);
  EXPECT_EQ(camera_at_step(c, 1000).azimuth, 30 + 140);  // 500 degrees: one turn and 140
  EXPECT_EQ(camera_at_step(c, 1000).elevation, 15);
  EXPECT_FALSE(camera_at_step(c, 1000).moves());
  EXPECT_LT(distance(camera_pose(c, 1000).direction, view_direction(530, 15)), 1e-12);
  // A step far into a long run keeps the angle exact (fmod is exact).
  EXPECT_EQ(camera_at_step(c, int64_t(1) << 40).azimuth,
            30 + std::fmod(0.5 * 1099511627776.0, 360));
}

TEST(CameraPath, StillCameraIsUnchanged) {
  CameraConfig c;
  c.azimuth = 12;
  const CameraConfig at = camera_at_step(c, 777);
  EXPECT_EQ(at.azimuth, 12);
  EXPECT_EQ(at.elevation, c.elevation);
  EXPECT_EQ(camera_pose(c, 5).direction, view_direction(12, c.elevation));
}

}  // namespace
}  // namespace lantern
