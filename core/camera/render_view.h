// What a renderer needs of the camera, already in float and relative to the scene origin: the
// camera produces it (Camera::render_view), the renderers consume it.
// Units: the simulation's length unit, relative to Camera::origin.
#pragma once

#include <cstdint>

#include <glm/mat4x4.hpp>

#include "core/config/lighting.h"

namespace lantern {

// What the renderer needs of the camera, already in float and scene-relative.
struct RenderView {
  glm::mat4 view{1.0f};        // scene-relative world -> view; the camera looks down -z
  glm::mat4 projection{1.0f};  // view -> clip (OpenGL conventions, NDC z in [-1, 1])
  bool orthographic = false;
  float near_plane = 0.01f;
  int width = 1;
  int height = 1;
  uint8_t background[4] = {255, 255, 255, 255};
  Lighting lighting;  // the spheres' light (default: the headlight, the original shader)
};

}  // namespace lantern
