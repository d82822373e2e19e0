// The transfer of a summed density image (core/composite/density_sum.h) to colors
// (`density: {transfer, range, colormap}`), run on the root after the sum, so every input is
// already independent of the ranks.
//
// W is a pixel's summed weight in particles (the int64 sum / 2^24). The range [lo, hi]:
//   - fixed: density.range;
//   - auto: hi = the largest W of the summed image; lo = 0 (linear, asinh) or hi / 10^4 (log:
//     four decades). Computed from the summed integers, so the same for any ranks and split.
// t = transfer(W) in [0, 1], clamped:
//   linear: (W - lo) / (hi - lo);
//   log:    ln(W / lo) / ln(hi / lo), 0 for W <= lo;
//   asinh:  asinh((W - lo) / s) / asinh((hi - lo) / s) with s = (hi - lo) / 100: linear in the
//           faint 1 % of the range, logarithmic above.
// Color: one channel (color.by: solid) - the pixel is density.colormap at t, and the background
// where no footprint reached (W exactly 0); four channels (by type or scalar) - the weighted mean
// color m of the particles at the pixel, blended over the background: background + t (m -
// background). A transparent background (`background` with alpha 0) is blended over later, by
// whoever composites the image: the pixel is m with alpha t (straight alpha); one channel keeps
// the colormap opaque (alpha 255) wherever a footprint reached.
// Depth: a density image has no surface, so every pixel keeps the background depth (1.0; the
// EXR Z channel, like every background pixel, is +infinity everywhere).
// Thread-safety: pure functions.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "core/color/colormap.h"
#include "core/config/config.h"
#include "core/render/density_splat.h"
#include "core/view/frame.h"

namespace lantern {

struct DensityRange {
  double lo = 0.0, hi = 0.0;  // summed particle weight per pixel
};

// The range the transfer uses for `image` (see above). hi <= lo means an empty image.
DensityRange density_range(const DensityImage &image, const DensityConfig &config);

// The transfer alone: t in [0, 1] of a summed weight w. Ranges whose width over- or underflows a
// double still give t in [0, 1] (never NaN; a NaN is 0): see density_range_problem.
double density_transfer(double w, DensityTransfer transfer, const DensityRange &range);

// What is wrong with a fixed density.range that the transfer can only clamp, for a warning: ""
// when fine (or auto), else e.g. "density.range [0, 5e-324] is narrower than the summed
// weight's resolution ...: every pixel a footprint reached maps to the top of the range" or
// "... is wider than a double can hold ...".
std::string density_range_problem(const DensityConfig &config);

// Maps `image` into `frame` (resized to the image): colors as above, alpha 255 (or as above for a
// transparent background), background depth.
void map_density(const DensityImage &image, const DensityConfig &config, const Colormap &colormap,
                 const uint8_t background[4], Frame *frame);

}  // namespace lantern
