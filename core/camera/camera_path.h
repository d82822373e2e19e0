// A camera that moves with the simulation step: the automatic camera's azimuth, elevation and
// zoom at a step, from `camera.path` keyframes or the `camera.orbit` short form.
//
// The path is smooth: the camera's orientation (the rotation that turns the view from azimuth 0,
// elevation 0 to the keyframe's, horizon level) is interpolated as a unit-quaternion curve, the
// cubic Hermite quaternion curve of Kim, Kim and Shin ("A General Construction Scheme for Unit
// Quaternion Curves with Simple High Order Derivatives", SIGGRAPH 1995), with Catmull-Rom angular
// velocities weighted by the keyframes' step spacing. The view direction therefore moves on the
// sphere, not per Euler angle, and its first derivative is continuous across every keyframe. The
// camera starts and stops at rest at the first and last keyframe (so holding the end values
// outside the path has no kink either). An azimuth difference between keyframes is the turn
// taken, in its sign's direction (0 -> 270 turns 270 degrees, not -90). The zoom follows a cubic
// Hermite curve in log(zoom) with the same tangents, so it stays > 0 and dollies evenly.
//
// Everything is computed in double precision from the configuration and the step alone, so every
// rank resolves the same camera. Pure functions; thread-safe.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

#include "core/config/config.h"

namespace lantern {

// The automatic camera's view at one moment: the unit vector from the target towards the eye,
// and the zoom.
struct CameraPose {
  glm::dvec3 direction{1.0, 0.0, 0.0};
  double zoom = 1.0;
};

// The unit vector from the target towards the eye of the automatic camera at `azimuth` degrees
// about +z from +x, `elevation` degrees above the xy plane.
glm::dvec3 view_direction(double azimuth, double elevation);

// The pose of `config`'s camera at `step` (a real number: tests differentiate the path between
// steps). A camera without path or orbit has its static pose at every step. The path's keyframes
// must have all keys filled in and increasing steps, as load_config leaves them.
CameraPose camera_pose(const CameraConfig &config, double step);

// The static camera that `config` is at `step`: its azimuth, elevation and zoom resolved, path
// and orbit removed (make_camera then builds it). At a keyframe's step and outside the path the
// keyframe's own values exactly; a camera that does not move, unchanged.
CameraConfig camera_at_step(const CameraConfig &config, int64_t step);

}  // namespace lantern
