// How a scene's particles look, as the renderers need it: colors (by type, scalar or solid), the
// per-type opacity, the light and the background. Resolved once per scene by the pipeline from
// the scene's configuration (core/pipeline/scene_settings.h), so rendering never reads the rest of
// it.
//
// Plain value type. Colors are linear [0, 1] triples, as configured.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/color/colormap.h"

#include "core/config/config.h"
#include "core/config/lighting.h"

namespace lantern {

struct ShadingSettings {
  // color: by, solid, palette, colormap (reverse), range. The pipeline resolves the automatic
  // ranges (color.range: {auto: first | running} remember earlier steps, core/color/color_range.h)
  // into `range`; absent: the step's global scalar range.
  ColorConfig color;
  std::vector<double> opacity;                      // opacity: per type (empty: all opaque)
  Lighting lighting;                                // lighting: the light model
  std::array<double, 3> background{1.0, 1.0, 1.0};  // background
  bool transparent_background = false;              // background: transparent
  BondsConfig bonds;                                // bonds: how bonds are colored (if drawn)
};

// The colour a frame is cleared to (RGBA8): the background, opaque; transparent black (0, 0, 0, 0)
// for background: transparent, so that a pixel nothing covers has alpha 0 and adds no colour to
// the alpha-weighted down-sampling (sample_downsampling.h).
inline std::array<uint8_t, 4> background_rgba8(const ShadingSettings &shading) {
  if (shading.transparent_background) return {0, 0, 0, 0};
  const Rgb8 bg = to_rgb8(shading.background);
  return {bg[0], bg[1], bg[2], 255};
}

}  // namespace lantern
