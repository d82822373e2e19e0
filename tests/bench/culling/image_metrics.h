// Error of an image against the brute-force reference: differing pixels, PSNR (OpenImageIO's
// ImageBufAlgo::compare) and SSIM (a small function of our own, on luma).
#pragma once

#include <cstddef>  // frame.h uses size_t
#include <cstdint>

#include "core/view/frame.h"

namespace lantern::bench {

struct ImageError {
  int64_t differing_pixels = 0;  // color differs in any channel
  int64_t differing_depth = 0;   // window depth differs
  double psnr = 0.0;             // dB over RGB in [0, 1]; +inf when identical
  double ssim = 1.0;             // mean SSIM of 8x8 luma windows (stride 4)
};

ImageError compare_frames(const Frame &reference, const Frame &test);

// The 8x8 box-filtered (mean) image, for the coarse-scale PSNR (structure at a coarser scale).
Frame box_filtered8(const Frame &f);

}  // namespace lantern::bench
