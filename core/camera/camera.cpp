#include "core/camera/camera.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

namespace lantern {
namespace {

constexpr double kPi = 3.14159265358979323846;
double radians(double degrees) {
  return degrees * kPi / 180.0;
}

// Near and far planes that enclose the box [lo, hi] seen from `view`, with a small margin.
void fit_depth_range(const glm::dmat4 &view, const glm::dvec3 &lo, const glm::dvec3 &hi,
                     double *near_plane, double *far_plane) {
  double nearest = std::numeric_limits<double>::max(), farthest = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 p{corner & 1 ? hi.x : lo.x, corner & 2 ? hi.y : lo.y,
                       corner & 4 ? hi.z : lo.z};
    const double depth = -(view * glm::dvec4(p, 1.0)).z;
    nearest = std::min(nearest, depth);
    farthest = std::max(farthest, depth);
  }
  *far_plane = std::max(farthest * 1.01, 1e-6);
  // A box around or behind the eye: keep 1e-4 of the far distance (float depth stays usable).
  *near_plane = std::max(nearest * 0.99, *far_plane * 1e-4);
}

}  // namespace

RenderView Camera::render_view(const uint8_t background[4]) const {
  RenderView v;
  v.view = glm::mat4(view * glm::translate(glm::dmat4(1.0), origin));
  v.projection = glm::mat4(projection);
  v.orthographic = orthographic;
  v.near_plane = float(near_plane);
  v.width = width;
  v.height = height;
  for (int c = 0; c < 4; ++c) v.background[c] = background[c];
  return v;
}

double Camera::window_depth_to_distance(double d) const {
  const double n = near_plane, f = far_plane;
  if (orthographic) return n + d * (f - n);
  const double z_ndc = 2.0 * d - 1.0;
  return 2.0 * n * f / (f + n - z_ndc * (f - n));
}

Status make_camera(const CameraConfig &config, const glm::dvec3 &lo_in, const glm::dvec3 &hi_in,
                   double max_radius, int width, int height, Camera *out) {
  Camera cam;
  cam.width = width;
  cam.height = height;
  cam.orthographic = config.projection == Projection::kOrthographic;
  glm::dvec3 lo = lo_in, hi = hi_in;
  if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) lo = glm::dvec3(0.0), hi = glm::dvec3(1.0);
  lo -= glm::dvec3(max_radius);
  hi += glm::dvec3(max_radius);
  const glm::dvec3 centre = 0.5 * (lo + hi);
  const double extent = std::max(0.5 * glm::length(hi - lo), 1e-12);
  cam.origin = centre;
  const double aspect = double(width) / double(height);
  const double zoom = config.zoom;

  if (config.position) {
    cam.eye = {(*config.position)[0], (*config.position)[1], (*config.position)[2]};
    cam.target = {config.look_at[0], config.look_at[1], config.look_at[2]};
    cam.up = {config.up[0], config.up[1], config.up[2]};
    const glm::dvec3 forward = cam.target - cam.eye;
    if (glm::length(forward) == 0.0)
      return {StatusCode::kConfig, "camera.look_at: equals camera.position"};
    if (glm::length(glm::cross(forward, cam.up)) <=
        1e-12 * glm::length(forward) * glm::length(cam.up))
      return {StatusCode::kConfig, "camera.up: parallel to the viewing direction (or zero)"};
  } else {
    const double az = radians(config.azimuth), el = radians(config.elevation);
    const glm::dvec3 dir{std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
    double distance;
    if (cam.orthographic) {
      distance = 2.0 * extent;
    } else {
      const double half_y = radians(config.fov_y) / 2.0;
      const double half_x = std::atan(std::tan(half_y) * aspect);
      distance = extent / std::sin(std::min(half_y, half_x)) / zoom;
    }
    cam.target = centre;
    cam.eye = centre + dir * distance;
    // Looking straight down or up the z axis: +y serves as "up" instead.
    cam.up = std::abs(dir.z) > 0.9999 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1);
  }
  cam.view = glm::lookAt(cam.eye, cam.target, cam.up);
  fit_depth_range(cam.view, lo, hi, &cam.near_plane, &cam.far_plane);
  if (config.near_plane) cam.near_plane = *config.near_plane;
  if (config.far_plane) cam.far_plane = *config.far_plane;
  if (!(cam.near_plane > 0.0 && cam.far_plane > cam.near_plane))
    return {StatusCode::kConfig, "camera.near/far: need 0 < near < far"};

  if (cam.orthographic) {
    // The bounding sphere fills the shorter image side at zoom 1.
    double half_h = extent / zoom;
    if (aspect < 1.0) half_h /= aspect;
    const double half_w = half_h * aspect;
    cam.projection = glm::ortho(-half_w, half_w, -half_h, half_h, cam.near_plane, cam.far_plane);
  } else {
    cam.projection = glm::perspective(radians(config.fov_y), aspect, cam.near_plane, cam.far_plane);
  }
  *out = cam;
  return {};
}

}  // namespace lantern
