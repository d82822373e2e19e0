// The camera of one scene and frame: where the eye is, what it sees, and the scene origin that
// float rendering is relative to.
//
// Every rank builds the same Camera from the same (globally reduced) bounds, so all ranks agree
// to the bit. Units: the simulation's length unit; angles in the config are degrees.
#pragma once

#include <string>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "core/camera/render_view.h"
#include "core/common/status.h"
#include "core/config/config.h"

namespace lantern {

struct Camera {
  glm::dvec3 origin{0.0};  // scene origin: positions are sent to GL as float(x - origin)
  glm::dvec3 eye{0.0}, target{0.0}, up{0.0, 0.0, 1.0};
  glm::dmat4 view{1.0};        // world -> view
  glm::dmat4 projection{1.0};  // view -> clip
  bool orthographic = false;
  double near_plane = 0.01, far_plane = 100.0;
  int width = 1, height = 1;
  // The automatic camera had (nearly) a point to frame and framed kMinFramedExtent around it.
  bool point_bounds = false;

  // The float, scene-relative view the renderer takes.
  RenderView render_view(const uint8_t background[4]) const;
  // View-space depth (distance along the view axis) of a window depth in [0, 1].
  double window_depth_to_distance(double window_depth) const;
};

// Where a scene's largest radius comes from: the configuration (`radius: 0.5`) or the published
// per-particle radii. Decides whom an unusable radius is blamed on.
enum class RadiusSource { kConfig, kParticles };

// Positions (and radii) larger than this in magnitude cannot be framed: fitting the camera squares
// lengths in double precision, which overflows near 1e154. Lengths in the simulation's unit.
constexpr double kMaxFramedLength = 1e150;
// The smallest half-extent the automatic camera frames, relative to the bounds' distance from the
// origin (and at least this, absolutely): bounds that are a point (every particle at one place,
// radius 0) put the eye 1e-12 from them and the particles before the near plane, a blank image.
// Such bounds are framed as a sphere of this radius, and Camera::point_bounds says so.
constexpr double kMinFramedExtent = 1e-9;

// Builds the camera for `config` and the global particle bounds [lo, hi] (centres), whose
// spheres reach at most `max_radius` beyond them. Empty bounds (lo > hi) frame the unit cube;
// bounds smaller than kMinFramedExtent x max(1, distance from the origin) are framed at that size.
// Returns OK, or an error naming the input at fault: kConfig for a camera key (e.g. position ==
// look_at, a zoom so large that the eye meets its target in double precision) or a configured
// radius above kMaxFramedLength; kInvalidArgument for particles (positions or per-particle radii
// above kMaxFramedLength, or a span too small for their coordinates in double precision).
Status make_camera(const CameraConfig &config, const glm::dvec3 &lo, const glm::dvec3 &hi,
                   double max_radius, int width, int height, Camera *out,
                   RadiusSource radius_source = RadiusSource::kConfig);

}  // namespace lantern
