// Super-sampled anti-aliasing (scene key `samples: N`): from a frame rendered at s times the
// image's width and height (s = sqrt(N)) to the image.
//
// The sample pattern is an s x s ordered (regular) grid in every pixel: image pixel (x, y) owns
// the sample-frame pixels (s*x + i, s*y + j), i, j in [0, s), whose centres lie at
// ((i + 0.5) / s, (j + 0.5) / s) inside the image pixel, measured from its top-left corner.
// Rendering the scene at (s*W) x (s*H) with the same camera frustum therefore IS sampling every
// pixel at that pattern: identical for every pixel, frame, rank and rerun. An ordered grid
// anti-aliases edges well at most angles; edges close to horizontal or vertical get only s
// distinct coverage levels instead of N.
//
// Colour is averaged in linear light: the RGB bytes are taken as sRGB-encoded, decoded through a
// 256-entry fixed-point table, summed as integers (so the result depends on the samples only,
// never on an order or a floating-point mode), and the mean is encoded back to the sRGB byte
// nearest to it in the encoded domain (a table of thresholds, looked up by the mean's bucket). N
// equal samples give back exactly their byte. Alpha is averaged as is (round to nearest). With
// SampleAlpha::kStraight (background: transparent) colour is instead the alpha-weighted mean
// (straight, unassociated alpha, what PNG stores): background samples (alpha 0) add no colour, so
// an antialiased edge keeps its surface's colour and carries the covered share as alpha; fully
// covered pixels get the same bytes either way. Depth:
// the output pixel holds the NEAREST sample's window depth (the minimum), so an EXR `Z` channel
// holds the distance of the nearest surface any sample of the pixel saw (background depth only
// where every sample saw background).
#pragma once

#include <cstdint>

#include "core/view/frame.h"

namespace lantern {

// The offset of sample (i, j) of a pixel, i along x and j down the rows, in pixel units from the
// pixel's top-left corner: ((i + 0.5) / s, (j + 0.5) / s) for s = samples_per_axis.
struct SampleOffset {
  double x = 0.5, y = 0.5;
};
SampleOffset sample_offset(int samples_per_axis, int i, int j);

// The fixed-point linear-light value of an sRGB-encoded byte (scale kLinearOne).
inline constexpr uint32_t kLinearOne = uint32_t(1) << 24;
uint32_t srgb_to_linear(uint8_t encoded);
// The sRGB byte nearest (in the encoded domain) to the mean of `count` linear values summing to
// `linear_sum` (each in [0, kLinearOne]); count a power of two in [1, 64].
uint8_t linear_sum_to_srgb(uint32_t linear_sum, uint32_t count);

// How samples' alpha enters the colour: kOpaque - plain mean of every sample's colour (opaque
// frames); kStraight - alpha-weighted mean (frames with a transparent background).
enum class SampleAlpha { kOpaque, kStraight };

// Down-samples `samples` (width and height multiples of s; s = samples_per_axis, one of 1, 2, 4,
// 8) by s along each axis into *image
// (resized to width / s x height / s). Thread-compatible: constant tables only.
void downsample_frame(const Frame &samples, int samples_per_axis, Frame *image,
                      SampleAlpha mode = SampleAlpha::kOpaque);

// The same for image rows [first_row, first_row + rows) only, into *band (resized to
// width / s x rows): what one rank does with its row band. `samples` must hold sample rows
// [s * first_row, s * (first_row + rows)); its other rows are not read.
void downsample_band(const Frame &samples, int samples_per_axis, int first_row, int rows,
                     Frame *band, SampleAlpha mode = SampleAlpha::kOpaque);

}  // namespace lantern
