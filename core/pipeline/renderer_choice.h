// Which renderer draws a sphere scene: decided once per scene and step, from the configuration,
// the camera and the occlusion mode the brick selection resolved - inputs every rank shares - so
// every rank decides the same (the CPU raster and OpenGL may differ in the last bit of a pixel).
#pragma once

#include "core/camera/camera.h"
#include "core/config/config.h"
#include "core/culling/brick_selection.h"

namespace lantern {

// True: the CPU sphere pass (core/render/cpu_sphere_pass.h) culls and draws; false: the culler
// then OpenGL's impostors. Where the chosen renderer cannot serve the selection's mode it is
// changed, and selection->stats.occlusion says why: without OpenGL (`have_opengl` false on every
// rank alike) the CPU raster culls exactly (hzb) where nine-spheres was asked for; with
// see-through types (`see_through`: some type's opacity below 1) OpenGL culls nothing and the
// probabilistic mode becomes hzb, as both assume opaque occluders. `max_radius`: the scene's
// largest drawn radius (its spheres' size on screen decides `renderer: auto`, measured in the
// final image's pixels: `image_height` rows, so `samples` never switches it).
bool draws_on_cpu(RendererChoice asked, int image_height, const Camera &camera, double max_radius,
                  bool have_opengl, bool see_through, BrickSelection *selection);

}  // namespace lantern
