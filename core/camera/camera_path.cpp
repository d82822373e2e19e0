#include "core/camera/camera_path.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

namespace lantern {
namespace {

constexpr double kPi = 3.14159265358979323846;
double radians(double degrees) {
  return degrees * kPi / 180.0;
}
double degrees(double radians) {
  return radians * 180.0 / kPi;
}

// A keyframe with every value set; the zoom is interpolated as its logarithm.
struct Key {
  double step, azimuth, elevation, zoom, log_zoom;
};

// The path's keyframes with the keys each leaves out carried from the one before (the first's
// from the static camera), as load_config fills them in.
std::vector<Key> keys_of(const CameraConfig &config) {
  std::vector<Key> keys;
  double azimuth = config.azimuth, elevation = config.elevation, zoom = config.zoom;
  for (const CameraKeyframe &k : config.path) {
    azimuth = k.azimuth.value_or(azimuth);
    elevation = k.elevation.value_or(elevation);
    zoom = k.zoom.value_or(zoom);
    keys.push_back({double(k.step), azimuth, elevation, zoom, std::log(zoom)});
  }
  return keys;
}

// The rotation by `angle` radians about the unit vector `axis`.
glm::dquat axis_angle(double angle, const glm::dvec3 &axis) {
  const double s = std::sin(0.5 * angle);
  return glm::dquat(std::cos(0.5 * angle), s * axis.x, s * axis.y, s * axis.z);
}

// The rotation whose rotation vector (axis times angle in radians) is `r`.
glm::dquat rotation_of(const glm::dvec3 &r) {
  const double angle = glm::length(r);
  if (angle == 0.0) return glm::dquat(1.0, 0.0, 0.0, 0.0);
  return axis_angle(angle, r / angle);
}

// The rotation vector of `q` as written: q and -q are the same rotation, but their half-angles
// differ by pi, so a quaternion built from the literal angles keeps turns of up to 360 degrees
// and their direction.
glm::dvec3 rotation_vector(const glm::dquat &q) {
  const glm::dvec3 v(q.x, q.y, q.z);
  const double s = glm::length(v);
  if (s == 0.0) return glm::dvec3(0.0);
  return v * (2.0 * std::atan2(s, q.w) / s);
}

// Of the rotation vectors of q's rotation (r + 2 pi n r / |r|), the one nearest `estimate`.
glm::dvec3 nearest_rotation_vector(const glm::dquat &q, const glm::dvec3 &estimate) {
  const glm::dvec3 r = rotation_vector(q);
  const double angle = glm::length(r);
  if (angle == 0.0) return r;
  glm::dvec3 best = r;
  for (const double turn : {-2.0 * kPi, 2.0 * kPi}) {
    const glm::dvec3 other = r * ((angle + turn) / angle);
    if (glm::length(other - estimate) < glm::length(best - estimate)) best = other;
  }
  return best;
}

const glm::dvec3 kX{1.0, 0.0, 0.0}, kY{0.0, 1.0, 0.0}, kZ{0.0, 0.0, 1.0};

// The automatic camera's orientation: turns +x into the view direction, horizon level.
glm::dquat orientation(double azimuth, double elevation) {
  return axis_angle(radians(azimuth), kZ) * axis_angle(-radians(elevation), kY);
}

// orientation(a)^-1 * orientation(b), from the azimuth difference as written (so that its sign
// and size survive: large azimuths do not cancel, 270 stays 270).
glm::dquat relative_rotation(const Key &a, const Key &b) {
  return axis_angle(radians(a.elevation), kY) * axis_angle(radians(b.azimuth - a.azimuth), kZ) *
         axis_angle(-radians(b.elevation), kY);
}

// The tangents at keyframe i (Catmull-Rom with the steps as the parameter: the slopes of the two
// segments weighted by the other's length, exact for quadratics), at rest at the ends: the
// angular velocity in the keyframe's own frame (radians per step), and d log(zoom) / d step.
struct Tangent {
  glm::dvec3 angular{0.0};
  double log_zoom = 0.0;
};

Tangent tangent_at(const std::vector<Key> &keys, size_t i) {
  if (i == 0 || i + 1 == keys.size()) return {};
  const Key &before = keys[i - 1], &at = keys[i], &after = keys[i + 1];
  const double h0 = at.step - before.step, h1 = after.step - at.step;
  // A segment's rotation turns about its own axis, so its rotation vector is the same in the
  // frames of both its keyframes.
  const glm::dvec3 w0 = rotation_vector(relative_rotation(before, at)) / h0;
  const glm::dvec3 w1 = rotation_vector(relative_rotation(at, after)) / h1;
  const double z0 = (at.log_zoom - before.log_zoom) / h0, z1 = (after.log_zoom - at.log_zoom) / h1;
  return {(h1 * w0 + h0 * w1) / (h0 + h1), (h1 * z0 + h0 * z1) / (h0 + h1)};
}

// The pose at `step` inside the segment from keys[k] to keys[k + 1]: the cubic Hermite quaternion
// curve of Kim, Kim and Shin, q(u) = q_a exp(w1 b1(u)) exp(w2 b2(u)) exp(w3 b3(u)) with the
// cumulative cubic Bernstein bases b1 = 1 - (1 - u)^3, b2 = 3u^2 - 2u^3, b3 = u^3; w1 and w3 are a
// third of the end angular velocities times the segment's length, w2 the rest of the rotation.
CameraPose segment_pose(const std::vector<Key> &keys, size_t k, double step) {
  const Key &a = keys[k], &b = keys[k + 1];
  const double h = b.step - a.step, u = (step - a.step) / h;
  const Tangent ta = tangent_at(keys, k), tb = tangent_at(keys, k + 1);
  const glm::dquat turn = relative_rotation(a, b);
  const glm::dvec3 w1 = ta.angular * (h / 3.0), w3 = tb.angular * (h / 3.0);
  const glm::dvec3 w2 = nearest_rotation_vector(
      glm::conjugate(rotation_of(w1)) * turn * glm::conjugate(rotation_of(w3)),
      rotation_vector(turn) - w1 - w3);
  const double v = 1.0 - u;
  const double b1 = 1.0 - v * v * v, b2 = u * u * (3.0 - 2.0 * u), b3 = u * u * u;
  const glm::dquat q = orientation(a.azimuth, a.elevation) * rotation_of(w1 * b1) *
                       rotation_of(w2 * b2) * rotation_of(w3 * b3);
  // Cubic Hermite in log(zoom).
  const double h00 = (1.0 + 2.0 * u) * v * v, h10 = u * v * v, h01 = u * u * (3.0 - 2.0 * u),
               h11 = -u * u * v;
  const double log_zoom =
      h00 * a.log_zoom + h10 * h * ta.log_zoom + h01 * b.log_zoom + h11 * h * tb.log_zoom;
  return {glm::normalize(q * kX), std::exp(log_zoom)};
}

// The keyframe whose values hold at `step` exactly: before the path, at a keyframe's step, after
// the path; nullptr between keyframes.
const Key *held_key(const std::vector<Key> &keys, double step) {
  if (step <= keys.front().step) return &keys.front();
  if (step >= keys.back().step) return &keys.back();
  const auto at = std::lower_bound(keys.begin(), keys.end(), step,
                                   [](const Key &k, double s) { return k.step < s; });
  return at->step == step ? &*at : nullptr;
}

}  // namespace

glm::dvec3 view_direction(double azimuth, double elevation) {
  const double az = radians(azimuth), el = radians(elevation);
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

CameraPose camera_pose(const CameraConfig &config, double step) {
  if (config.path.empty()) {
    const double turn = config.orbit.enabled ? config.orbit.degrees_per_step * step : 0.0;
    return {view_direction(config.azimuth + std::fmod(turn, 360.0), config.elevation), config.zoom};
  }
  const std::vector<Key> keys = keys_of(config);
  if (const Key *held = held_key(keys, step))
    return {view_direction(held->azimuth, held->elevation), held->zoom};
  const auto after = std::upper_bound(keys.begin(), keys.end(), step,
                                      [](double s, const Key &k) { return s < k.step; });
  return segment_pose(keys, size_t(after - keys.begin()) - 1, step);
}

CameraConfig camera_at_step(const CameraConfig &config, int64_t step) {
  if (!config.moves()) return config;
  CameraConfig still = config;
  still.path.clear();
  still.orbit = CameraOrbit();
  if (config.path.empty()) {
    // fmod is exact: the orbit's angle keeps its precision at any step.
    still.azimuth = config.azimuth + std::fmod(config.orbit.degrees_per_step * double(step), 360.0);
    return still;
  }
  const std::vector<Key> keys = keys_of(config);
  if (const Key *held = held_key(keys, double(step))) {
    still.azimuth = held->azimuth;
    still.elevation = held->elevation;
    still.zoom = held->zoom;
    return still;
  }
  const CameraPose pose = camera_pose(config, double(step));
  still.azimuth = degrees(std::atan2(pose.direction.y, pose.direction.x));
  still.elevation = degrees(std::asin(std::clamp(pose.direction.z, -1.0, 1.0)));
  still.zoom = pose.zoom;
  return still;
}

}  // namespace lantern
