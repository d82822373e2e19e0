// Density rendering (seed 001 §3.4, `style: density`): every particle is a screen-aligned
// Gaussian footprint, summed into a fixed-point image. The sum over ranks is then an integer sum
// (core/composite/density_sum.h), so the image does not depend on the order of the particles,
// on the ranks or on the split, bit for bit.
//
// The footprint of a particle of world radius r at view depth d:
//   - sigma_px = sqrt((r / 3 * pixels_per_unit(d))^2 + 0.5^2): the Gaussian of standard deviation
//     r / 3 (so its 3-sigma cut-off is the sphere's own outline) blurred by a Gaussian pixel
//     filter of 0.5 px (so a sub-pixel particle still spreads over a few pixels instead of
//     aliasing onto the pixel grid);
//   - cut off at 3 sigma_px on each axis (a square of side 6 sigma_px around the projected
//     centre), separable: g(x, y) = gx(x) gy(y), each axis normalised so that its samples at the
//     pixel centres sum to 1 (for sigma_px >= 8 the analytic integral is used instead; they agree
//     to better than 0.1 %). A particle wholly inside the image therefore deposits exactly its
//     weight, up to the rounding of each pixel's share; pixels off the image are lost;
//   - only a particle whose centre lies in front of the near plane contributes.
//
// Fixed point: each pixel's share is rounded to a multiple of 2^-24 of a particle's unit weight
// (kDensityFractionBits) and summed in int64. Colour channels hold the share times the particle's
// colour / 255, rounded the same way, so every channel's contribution is at most the weight
// channel's. One pixel then holds at most N (2^24 + 1) for N particles of weight <= 1 each (level
// of detail's weights n/m sum to the brick's n), which fits in int64 (< 2^63) while
// N <= 2^38 (2.7e11 particles): the pipeline refuses a density scene with more (a clear error,
// never a wrapped sum). Resolution 2^-24 = 6e-8 of one particle per pixel: a footprint of up to
// about sigma_px = 100 px keeps its 3-sigma tail above it.
//
// Ownership: DensityImage owns its sums; DensitySplatter borrows the image and the geometry for
// its lifetime. Thread-safety: none (one splatter per thread and image). Units: pixels, and
// world lengths for the radius.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/color/colormap.h"
#include "core/view/view_geometry.h"

namespace lantern {

inline constexpr int kDensityFractionBits = 24;
inline constexpr double kDensityUnit = double(int64_t(1) << kDensityFractionBits);
// The most particles (over all ranks) a density scene accepts: see the header comment.
inline constexpr int64_t kDensityMaxParticles = int64_t(1) << 38;

// The summed footprints of one frame. channels 1: the weight; 4: the weight, then weight times
// red, green and blue (each / 255). Row-major, row 0 at the TOP, channels interleaved per pixel.
struct DensityImage {
  int width = 0;
  int height = 0;
  int channels = 1;
  std::vector<int64_t> sum;

  // Resizes to w x h x ch and zeroes every sum.
  void reset(int w, int h, int ch) {
    width = w, height = h, channels = ch;
    sum.assign(size_t(w) * size_t(h) * size_t(ch), 0);
  }
  size_t pixel_count() const { return size_t(width) * size_t(height); }
};

class DensitySplatter {
 public:
  // Splats into `image` (already reset to the geometry's size) as seen through `g`.
  DensitySplatter(const ViewGeometry &g, DensityImage *image);

  // One particle: view-space centre `c`, world radius `r`, `weight` (1, or n / m under level of
  // detail), color used when the image has 4 channels. Returns whether it touched any pixel.
  bool splat(const glm::dvec3 &c, double r, double weight, const Rgb8 &color);

  // Pixels written so far (for the benchmark's bytes per particle).
  int64_t pixels_written() const { return pixels_written_; }

 private:
  // The normalised 1D kernel of centre `centre` (pixel units) and `sigma` over pixel indices
  // [*first, *last] clipped to [0, size); false when nothing of it lies on the image.
  bool axis(double centre, double sigma, int size, std::vector<double> *taps, int *first,
            int *last) const;

  const ViewGeometry &g_;
  DensityImage *image_;
  std::vector<double> gx_, gy_;
  int64_t pixels_written_ = 0;
};

}  // namespace lantern
