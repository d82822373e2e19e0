#include "core/camera/camera.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

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

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string vec_text(const glm::dvec3 &v) {
  return "[" + number_text(v.x) + ", " + number_text(v.y) + ", " + number_text(v.z) + "]";
}

double largest_magnitude(const glm::dvec3 &lo, const glm::dvec3 &hi) {
  return std::max({std::abs(lo.x), std::abs(lo.y), std::abs(lo.z), std::abs(hi.x), std::abs(hi.y),
                   std::abs(hi.z)});
}

bool all_finite(const glm::dmat4 &m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

// The automatic camera's eye: in the direction of azimuth/elevation from `centre`, far enough
// for the bounding sphere (radius `extent`) to fill the view at zoom 1.
glm::dvec3 automatic_eye(const CameraConfig &config, const glm::dvec3 &centre, double extent,
                         double aspect, bool orthographic) {
  const double az = radians(config.azimuth), el = radians(config.elevation);
  const glm::dvec3 dir{std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
  double distance;
  if (orthographic) {
    distance = 2.0 * extent;
  } else {
    const double half_y = radians(config.fov_y) / 2.0;
    const double half_x = std::atan(std::tan(half_y) * aspect);
    distance = extent / std::sin(std::min(half_y, half_x)) / config.zoom;
  }
  return centre + dir * distance;
}

// The automatic camera's up: +z, or +y when looking straight down or up the z axis.
glm::dvec3 automatic_up(const CameraConfig &config) {
  return std::abs(std::sin(radians(config.elevation))) > 0.9999 ? glm::dvec3(0, 1, 0)
                                                                : glm::dvec3(0, 0, 1);
}

// The view from eye to target, if double precision can build it: their difference must have a
// non-zero, finite squared length (lookAt normalizes it), else the matrix comes out NaN.
bool usable_view(const glm::dvec3 &eye, const glm::dvec3 &target, const glm::dvec3 &up,
                 glm::dmat4 *view) {
  const glm::dvec3 forward = target - eye;
  const double squared = glm::dot(forward, forward);
  if (!(squared > 0.0) || !std::isfinite(squared)) return false;
  *view = glm::lookAt(eye, target, up);
  return all_finite(*view);
}

// Why the automatic camera cannot look from its eye at `centre`: the zoom or fov the user set
// (if the default zoom and fov would work), or else the particles themselves.
Status unusable_automatic_camera(const CameraConfig &config, const glm::dvec3 &centre,
                                 const glm::dvec3 &eye, double extent, double aspect,
                                 bool orthographic, const glm::dvec3 &lo, const glm::dvec3 &hi) {
  CameraConfig plain = config;
  plain.zoom = CameraConfig().zoom;
  plain.fov_y = CameraConfig().fov_y;
  const glm::dvec3 plain_eye = automatic_eye(plain, centre, extent, aspect, orthographic);
  glm::dmat4 ignored;
  const bool blame_config = (config.zoom != plain.zoom || config.fov_y != plain.fov_y) &&
                            usable_view(plain_eye, centre, automatic_up(config), &ignored);
  if (blame_config) {
    std::string keys;
    if (config.zoom != plain.zoom) keys = "camera.zoom: " + number_text(config.zoom);
    if (config.fov_y != plain.fov_y)
      keys +=
          (keys.empty() ? "" : " with ") + std::string("camera.fov: ") + number_text(config.fov_y);
    return {StatusCode::kConfig,
            keys + " puts the eye at " + vec_text(eye) + ", which double precision cannot tell " +
                "apart from (or place that far from) the centre of the particles " +
                vec_text(centre) + " (radius " + number_text(extent) +
                "); bring it closer to the default (zoom 1, fov 30)"};
  }
  return {StatusCode::kInvalidArgument,
          "particles: their bounds " + vec_text(lo) + " to " + vec_text(hi) +
              " are too small for coordinates this far from the origin: double precision "
              "cannot place the camera apart from their centre " +
              vec_text(centre)};
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
                   double max_radius, int width, int height, Camera *out,
                   RadiusSource radius_source) {
  Camera cam;
  cam.width = width;
  cam.height = height;
  cam.orthographic = config.projection == Projection::kOrthographic;
  glm::dvec3 lo = lo_in, hi = hi_in;
  const bool empty = !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z);
  if (empty) lo = glm::dvec3(0.0), hi = glm::dvec3(1.0);
  // Too large to frame: say which input, instead of a NaN camera failing the near/far check.
  if (const double reach = largest_magnitude(lo, hi); !empty && reach > kMaxFramedLength)
    return {StatusCode::kInvalidArgument,
            "particles: positions reach " + number_text(reach) + " (bounds " + vec_text(lo) +
                " to " + vec_text(hi) + "); the camera frames positions up to " +
                number_text(kMaxFramedLength) +
                " in magnitude (fitting it squares lengths in double precision)"};
  if (max_radius > kMaxFramedLength) {
    const std::string what = " is larger than the camera can frame (up to " +
                             number_text(kMaxFramedLength) +
                             "; fitting it squares lengths in double precision)";
    if (radius_source == RadiusSource::kConfig)
      return {StatusCode::kConfig, "radius: " + number_text(max_radius) + what};
    return {StatusCode::kInvalidArgument,
            "particles.radius: the largest radius, " + number_text(max_radius) + "," + what};
  }
  lo -= glm::dvec3(max_radius);
  hi += glm::dvec3(max_radius);
  const glm::dvec3 centre = 0.5 * (lo + hi);
  const double smallest = kMinFramedExtent * std::max(1.0, glm::length(centre));
  const double span = 0.5 * glm::length(hi - lo);
  const double extent = std::max(span, smallest);
  cam.point_bounds = !empty && !config.position && span < smallest;
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
    if (!usable_view(cam.eye, cam.target, cam.up, &cam.view))
      return {StatusCode::kConfig, "camera.position/look_at: " + vec_text(cam.eye) + " and " +
                                       vec_text(cam.target) +
                                       " are too far apart for double precision"};
  } else {
    cam.target = centre;
    cam.eye = automatic_eye(config, centre, extent, aspect, cam.orthographic);
    cam.up = automatic_up(config);
    if (!usable_view(cam.eye, cam.target, cam.up, &cam.view))
      return unusable_automatic_camera(config, centre, cam.eye, extent, aspect, cam.orthographic,
                                       lo_in, hi_in);
  }
  fit_depth_range(cam.view, lo, hi, &cam.near_plane, &cam.far_plane);
  const bool near_set = config.near_plane.has_value(), far_set = config.far_plane.has_value();
  if (near_set) cam.near_plane = *config.near_plane;
  if (far_set) cam.far_plane = *config.far_plane;
  if (!(cam.near_plane > 0.0 && cam.far_plane > cam.near_plane))
    return {StatusCode::kConfig, "camera.near/far: need 0 < near < far, got near " +
                                     number_text(cam.near_plane) +
                                     (near_set ? "" : " (automatic)") + " and far " +
                                     number_text(cam.far_plane) + (far_set ? "" : " (automatic)")};

  if (cam.orthographic) {
    // The bounding sphere fills the shorter image side at zoom 1.
    double half_h = extent / zoom;
    if (aspect < 1.0) half_h /= aspect;
    const double half_w = half_h * aspect;
    cam.projection = glm::ortho(-half_w, half_w, -half_h, half_h, cam.near_plane, cam.far_plane);
    // Only the zoom can shrink the view this far (extent >= kMinFramedExtent).
    if (!all_finite(cam.projection) || !(half_w > 0.0))
      return {StatusCode::kConfig, "camera.zoom: " + number_text(zoom) +
                                       " shrinks the orthographic view to a width of " +
                                       number_text(2.0 * half_w) +
                                       ", below what double precision can use"};
  } else {
    cam.projection = glm::perspective(radians(config.fov_y), aspect, cam.near_plane, cam.far_plane);
  }
  *out = cam;
  return {};
}

}  // namespace lantern
