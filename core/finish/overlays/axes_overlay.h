// axes: a small triad in a corner showing how the world's x, y and z axes lie in the picture:
// each axis is the camera's rotation applied to its unit vector, drawn from the triad's centre
// (x red, y green, z blue, each named at its tip); nearer axes are drawn over farther ones.
#pragma once

#include "core/camera/camera.h"
#include "core/config/config.h"
#include "core/finish/overlays/font_face.h"
#include "core/finish/overlays/overlay_layout.h"
#include "core/view/frame.h"

namespace lantern {

void draw_axes(const AxesConfig &axes, const Camera &camera, FontFace &font, OverlayLayout &layout,
               Frame *image);

}  // namespace lantern
