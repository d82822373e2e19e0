#include "image_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

namespace lantern::bench {
namespace {

// Wraps the RGB channels of a frame (a copy: OIIO wants contiguous pixels of its own layout).
OIIO::ImageBuf rgb_image(const Frame &f) {
  OIIO::ImageBuf buf(OIIO::ImageSpec(f.width, f.height, 3, OIIO::TypeDesc::UINT8));
  std::vector<uint8_t> rgb(f.pixel_count() * 3);
  for (size_t i = 0; i < f.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c) rgb[3 * i + c] = f.rgba[4 * i + c];
  buf.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::UINT8, rgb.data());
  return buf;
}

std::vector<double> luma(const Frame &f) {
  std::vector<double> y(f.pixel_count());
  for (size_t i = 0; i < y.size(); ++i)
    y[i] = 0.299 * f.rgba[4 * i] + 0.587 * f.rgba[4 * i + 1] + 0.114 * f.rgba[4 * i + 2];
  return y;
}

// Wang et al. 2004, with 8x8 box windows every 4 pixels instead of an 11x11 Gaussian.
double ssim(const Frame &a, const Frame &b) {
  constexpr int kWin = 8, kStride = 4;
  constexpr double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
  const std::vector<double> x = luma(a), y = luma(b);
  double sum = 0.0;
  int64_t windows = 0;
  for (int wy = 0; wy + kWin <= a.height; wy += kStride)
    for (int wx = 0; wx + kWin <= a.width; wx += kStride) {
      double mx = 0, my = 0, sxx = 0, syy = 0, sxy = 0;
      for (int j = 0; j < kWin; ++j)
        for (int i = 0; i < kWin; ++i) {
          const size_t k = a.index(wx + i, wy + j);
          mx += x[k], my += y[k];
          sxx += x[k] * x[k], syy += y[k] * y[k], sxy += x[k] * y[k];
        }
      const double n = kWin * kWin;
      mx /= n, my /= n;
      const double vx = sxx / n - mx * mx, vy = syy / n - my * my, cxy = sxy / n - mx * my;
      sum += ((2 * mx * my + c1) * (2 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
      ++windows;
    }
  return windows ? sum / double(windows) : 1.0;
}

}  // namespace

ImageError compare_frames(const Frame &reference, const Frame &test) {
  ImageError e;
  for (size_t i = 0; i < reference.pixel_count(); ++i) {
    e.differing_pixels += std::memcmp(&reference.rgba[4 * i], &test.rgba[4 * i], 4) != 0;
    e.differing_depth += reference.depth[i] != test.depth[i];
  }
  if (e.differing_pixels == 0) {
    e.psnr = std::numeric_limits<double>::infinity();
    e.ssim = 1.0;
    return e;
  }
  const OIIO::ImageBufAlgo::CompareResults r =
      OIIO::ImageBufAlgo::compare(rgb_image(reference), rgb_image(test), 0.0f, 0.0f);
  e.psnr = r.PSNR;
  e.ssim = ssim(reference, test);
  return e;
}

Frame box_filtered8(const Frame &f) {
  Frame out(std::max(1, f.width / 8), std::max(1, f.height / 8));
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      for (int c = 0; c < 4; ++c) {
        int sum = 0;
        for (int j = 0; j < 8; ++j)
          for (int i = 0; i < 8; ++i)
            sum += f.rgba[4 * f.index(std::min(f.width - 1, 8 * x + i),
                                      std::min(f.height - 1, 8 * y + j)) +
                          size_t(c)];
        out.rgba[4 * out.index(x, y) + size_t(c)] = uint8_t((sum + 32) / 64);
      }
  std::fill(out.depth.begin(), out.depth.end(), kBackgroundDepth);
  return out;
}

}  // namespace lantern::bench
