// box: the simulation box's twelve edges, projected through the scene's camera and depth-tested
// against the composited depth, so that particles in front of an edge hide it and an edge in
// front of particles shows. Edges are clipped at the near plane; beyond the far plane they stay
// behind every particle and over the background.
#pragma once

#include <array>

#include "core/camera/camera.h"
#include "core/config/config.h"
#include "core/finish/overlays/overlay_canvas.h"
#include "core/view/frame.h"

namespace lantern {

// The box [low, high], simulation units; a triclinic one with LAMMPS's tilt {xy, xz, yz} (edge
// vectors (lx, 0, 0), (xy, ly, 0), (xz, yz, lz) from low; see core/dump/box.h).
struct BoxCorners {
  std::array<double, 3> low{0, 0, 0}, high{0, 0, 0};
  std::array<double, 3> tilt{0, 0, 0};
};

// `point` in world units to image pixels and window depth through `camera`'s view and projection,
// for an image of image.width x image.height (the camera's frustum; its own pixel count may be
// the super-sampled one). false when the point is behind the near plane.
bool project_point(const Camera &camera, int width, int height, const std::array<double, 3> &point,
                   LinePoint *out);

// Draws the twelve edges of `box` (a parallelepiped where it is tilted) on `image` (whose depth is
// the composited depth).
void draw_box(const BoxOverlayConfig &config, const BoxCorners &box, const Camera &camera,
              Frame *image);

}  // namespace lantern
