// Density rendering (Rizzi et al. 2015, §3.4, `style: density`): every particle is a screen-aligned
// Gaussian footprint, summed into a fixed-point image. The sum over ranks is then an integer sum
// (core/composite/density_sum.h), so the image does not depend on the order of the particles,
// on the ranks or on the split, bit for bit.
//
// The footprint of a particle of world radius r at view depth d:
//   - sigma_px = sqrt((r / 3 * pixels_per_unit(d))^2 + 0.5^2): the Gaussian of standard deviation
//     r / 3 (so its 3-sigma cut-off is the sphere's own outline) blurred by a Gaussian pixel
//     filter of 0.5 px (so a sub-pixel particle still spreads over a few pixels instead of
//     aliasing onto the pixel grid);
//   - separable: the share of pixel (x, y) is weight * tx(x) * ty(y) with tx, ty the integer
//     taps of core/render/density_kernel.h (each axis 2^16 in all: a Gaussian of that sigma cut
//     off at 3 sigma, quantised to 2.2 % steps of sigma and 1/32 px of position up to
//     sigma 7.9 px, computed beyond). A particle wholly inside the image therefore deposits its
//     weight, up to the rounding of each pixel's share; pixels off the image are lost;
//   - only a particle whose centre lies in front of the near plane contributes.
//
// Fixed point: a pixel's weight share is q = round(W tx ty / 2^(F + 8)) in units of 2^-24 of a
// particle's unit weight (kDensityFractionBits), with W = round(weight 2^F) and
// F = 23 - floor(log2 weight), so W in [2^23, 2^24) (clamped to 2^24 - 1) holds 24 significant
// bits of any weight, and W 256 and W c (c an 8-bit colour) fit 32 bits: a 32 x 32 -> 64-bit
// vector multiply per channel and pixel. Colour channels hold round(W c tx ty / 2^(F + 16)), the
// weight share times c / 256 (the mapping multiplies the mean back by 256), so every channel's
// contribution is at most the weight channel's. A weight of 1 is exact up to the final rounding.
// Weights outside [2^-24, 2^38) deposit nothing. Per particle and pixel q <= weight (2^24 + 2)
// for weight >= 1 (W <= weight 2^F (1 + 2^-24), p < 2^32, plus q's rounding), and the density
// pass's weights are >= 1 and sum to at most the particle count N (level of detail's n / m sum
// to the brick's n), so one pixel holds at most N (2^24 + 2) < 2^63
// while N <= 2^38 (2.7e11 particles): the pipeline refuses a density scene with more (a clear
// error, never a wrapped sum). Resolution 2^-24 = 6e-8 of one particle per pixel; the taps' 2^-16
// per axis keep a footprint's 3-sigma tail above zero up to about sigma_px = 100 px.
//
// Ownership: DensityImage owns its sums; DensitySplatter borrows the image and the geometry for
// its lifetime. Thread-safety: none (one splatter per thread and image). Units: pixels, and
// world lengths for the radius.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

#include <glm/vec3.hpp>

#include "core/color/colormap.h"
#include "core/render/density_kernel.h"
#include "core/view/view_geometry.h"

namespace lantern {

inline constexpr int kDensityFractionBits = 24;
inline constexpr double kDensityUnit = double(int64_t(1) << kDensityFractionBits);
// The most particles (over all ranks) a density scene accepts: see the header comment.
inline constexpr int64_t kDensityMaxParticles = int64_t(1) << 38;
// The weights a particle may carry (see the header comment).
inline constexpr double kDensityMinWeight = 1.0 / double(1 << 24);
inline constexpr double kDensityMaxWeight = double(kDensityMaxParticles);

// Storage on 64-byte (cache-line) boundaries: the pixel loops add two pixels' four channels
// (64 bytes) per vector, and an access that straddles two cache lines costs two.
template <typename T>
struct CacheLineAllocator {
  using value_type = T;
  CacheLineAllocator() = default;
  template <typename U>
  CacheLineAllocator(const CacheLineAllocator<U> &) {}  // NOLINT: conversions are implicit
  T *allocate(size_t n) {
    return static_cast<T *>(::operator new(n * sizeof(T), std::align_val_t(64)));
  }
  void deallocate(T *p, size_t) { ::operator delete(p, std::align_val_t(64)); }
  template <typename U>
  bool operator==(const CacheLineAllocator<U> &) const {
    return true;
  }
  template <typename U>
  bool operator!=(const CacheLineAllocator<U> &) const {
    return false;
  }
};

// The summed footprints of one frame. channels 1: the weight; 4: the weight, then weight times
// red, green and blue (each / 256, see above). Row-major, row 0 at the TOP, channels interleaved
// per pixel, rows `pitch` pixels apart: `pitch` is `width` (dense rows, what every reader of the
// sums sees) except while a pass splats into a padded image (reset_padded() ... compact()).
struct DensityImage {
  int width = 0;
  int height = 0;
  int channels = 1;
  int pitch = 0;
  std::vector<int64_t, CacheLineAllocator<int64_t>> sum;

  // Resizes to w x h x ch (dense rows) and zeroes every sum.
  void reset(int w, int h, int ch) {
    width = w, height = h, channels = ch, pitch = w;
    sum.assign(size_t(w) * size_t(h) * size_t(ch), 0);
  }
  // reset() with rows padded_pitch(w, ch) pixels apart, for splatting; compact() makes the rows
  // dense again, the same sums.
  void reset_padded(int w, int h, int ch) {
    width = w, height = h, channels = ch, pitch = padded_pitch(w, ch);
    sum.assign(size_t(pitch) * size_t(h) * size_t(ch), 0);
  }
  void compact();
  // A row length whose byte size is not a multiple of 1 KiB: rows of 2^k bytes (a 1024 px,
  // 4-channel image's 32 KiB) put the same column of successive rows in the same sets of the
  // L1 cache, so a footprint's rows evict each other. 128 bytes more spreads 32 successive rows
  // over distinct sets (the pixel loop alone on fcc 10 M at 1024^2: 153 -> 121 ms). Keeps rows on
  // 64-byte boundaries when they were.
  static int padded_pitch(int w, int ch) {
    const size_t bytes = size_t(w) * size_t(ch) * sizeof(int64_t);
    if (bytes % 1024 != 0) return w;
    return w + int((128 + ch * sizeof(int64_t) - 1) / (ch * sizeof(int64_t)));
  }
  size_t pixel_count() const { return size_t(width) * size_t(height); }
};

// A particle's footprint on the image: centre (pixel units, x from the left, y from the top) and
// sigma_eff^2 (px^2).
struct DensityFootprint {
  double px = 0.0, py = 0.0, sigma2 = 0.0;
};

// The pixel loop of a four-channel image. kAuto: AVX-512 where the processor has it (footprints
// of at most 4 pixels a row, two pixels per register; wider ones as AVX2), else AVX2, else SSE2
// on x86-64, else scalar; the others force one (falling back to the next where the processor
// lacks it), for tests. The AVX-512 and AVX2 loops each come with a loop for weight-1
// footprints of coherent batches (bin_all). All give the same bits: the arithmetic is integer.
enum class DensityPixelLoop { kAuto, kAvx2, kSse2, kScalar };

// Footprints of a batch of particles, one array per quantity (see DensitySplatter::project_all).
struct DensityFootprints {
  std::vector<double> px, py, sigma2;
  std::vector<uint8_t> in_front;  // project()'s result
  void resize(size_t n) { px.resize(n), py.resize(n), sigma2.resize(n), in_front.resize(n); }
};

// A footprint of weight 1 waiting in its image tile's bin (DensitySplatter::bin, bin_all): its
// taps on the image per axis (offsets into the kernel table's taps, first pixel, count) and its
// colour, so that depositing it looks nothing up again.
struct DensityRecord {
  uint32_t taps_x, taps_y;
  int16_t first_x, first_y;  // kMaxImageSize is 16384
  uint8_t count_x, count_y;  // table footprints span at most 49 pixels
  uint8_t color[3];
};

// Footprints binned by the image tile (kDensityTile pixels square) of their first pixel, to be
// deposited tile by tile: the image rows a tile's footprints touch stay in cache meanwhile.
inline constexpr int kDensityTile = 128;
struct DensityBins {
  int across = 0, down = 0;
  std::vector<std::vector<DensityRecord>> tiles;  // row by row
  void reset(int width, int height) {
    across = (width + kDensityTile - 1) / kDensityTile;
    down = (height + kDensityTile - 1) / kDensityTile;
    tiles.resize(size_t(across) * size_t(down));
    for (std::vector<DensityRecord> &t : tiles) t.clear();
  }
};

// Up to two byte ranges a caller will read next (the next batch of particles): bin_all()'s
// weight-1 loop prefetches them a cache line per footprint, between its pixel work.
struct DensityStreamAhead {
  const char *at[2] = {nullptr, nullptr};
  size_t bytes[2] = {0, 0};
};

class DensitySplatter {
 public:
  // Splats into `image` (already reset to the geometry's size) as seen through `g`.
  DensitySplatter(const ViewGeometry &g, DensityImage *image);

  // One particle: view-space centre `c`, world radius `r`, `weight` (1, or n / m under level of
  // detail; one outside [kDensityMinWeight, kDensityMaxWeight) deposits nothing), color used when
  // the image has 4 channels.
  // Returns whether it touched any pixel.
  bool splat(const glm::dvec3 &c, double r, double weight, const Rgb8 &color);

  // splat() in two steps, for a caller that projects a batch of particles before depositing
  // them (independent projections overlap in the processor; same results bit for bit):
  // project() is false when the centre is not in front of the near plane.
  bool project(const glm::dvec3 &c, double r, DensityFootprint *out) const;
  bool deposit(const DensityFootprint &f, double weight, const Rgb8 &color);

  // project(g.to_view(x), r * scale, ...) of `count` particles at WORLD positions (x[k], y[k],
  // z[k]), radius r[k] (r null: `radius` for every one), into out[0, count): the same bits, the
  // independent projections vectorised (AVX2 where the processor has it).
  void project_all(const double *x, const double *y, const double *z, const double *r,
                   double radius, double scale, int count, DensityFootprints *out) const;

  // project_all(x, y, z, nullptr, radius, 1, count, out) of `count` particles whose world
  // positions are interleaved doubles (x, y, z: 24 bytes a particle, any alignment) at `xyz`,
  // without copying them into arrays first: the same bits, 8 particles per AVX-512 vector (4 per
  // AVX2 one where the processor has only that). False, `out` then unspecified, where the
  // processor lacks AVX2, `count` is not a multiple of 8, or a coordinate is not finite (the
  // caller gathers those particles and drops them).
  bool project_xyz(const unsigned char *xyz, double radius, int count,
                   DensityFootprints *out) const;

  // deposit(f, 1, color) in two steps, for a pass that visits the particles in an order that
  // wanders over the image: bin() files a table footprint under its image tile (a wider one,
  // beyond the table, is deposited at once) and returns whether it touches the image;
  // deposit_bins() then deposits every bin, tile by tile. The same sums as deposit().
  bool bin(const DensityFootprint &f, const Rgb8 &color, DensityBins *bins);
  void deposit_bins(const DensityBins &bins);
  // bin() of footprint k with color[k] for every k in [0, count) with in_front[k], the table
  // look-ups vectorised (DensityKernelTable::place_all); a batch whose footprints follow each
  // other on the image is deposited at once instead (the same sums): returns how many touch
  // the image.
  int64_t bin_all(const DensityFootprints &footprints, const Rgb8 *color, int count,
                  DensityBins *bins);

  // deposit(footprint k, weight, color[k]) for every k in [0, count) with in_front[k] and not
  // skip[k]: returns how many touched a pixel.
  int64_t deposit_all(const DensityFootprints &footprints, const uint8_t *skip, const Rgb8 *color,
                      int count, double weight);

  void set_pixel_loop(DensityPixelLoop loop);
  // What the next bin_all() prefetches (once; a hint only: the sums do not depend on it).
  void stream_ahead(const DensityStreamAhead &next) { ahead_ = next; }

  // Pixels written so far (for the benchmark's bytes per particle).
  int64_t pixels_written() const { return pixels_written_; }

 private:
  const ViewGeometry &g_;
  DensityImage *image_;
  const DensityKernelTable &table_;
  std::vector<uint16_t> scratch_x_, scratch_y_;  // taps of footprints beyond the kernel table
  DensityPlacements placements_;                 // bin_all()'s, kept for its capacity
  void file(const DensityRecord &r, DensityBins *bins) const {
    bins->tiles[size_t(r.first_y / kDensityTile) * size_t(bins->across) +
                size_t(r.first_x / kDensityTile)]
        .push_back(r);
  }
  // The pixel loop for four channels, chosen once (set_pixel_loop).
  void (*add4_)(int64_t *image, int width, const AxisTaps &ax, const AxisTaps &ay,
                const uint64_t m[4], int shift) = nullptr;
  // Whether weight-1 footprints of a four-channel image take the AVX-512 loop made for them
  // (the processor has it and the pixel loop is kAuto; the same sums as add4_).
  bool units_ = false;
  // Whether they take the AVX2 weight-1 loop instead (where AVX2 is the pixel loop: the
  // processor lacks AVX-512 or the loop is kAvx2; the same sums). Coherent batches only.
  bool units_avx2_ = false;
  // The previous particle's weight and colour, and the factors made of them (see the .cpp).
  // Adds the footprint of taps ax x ay with `weight` and `color` to the image.
  void add(const AxisTaps &ax, const AxisTaps &ay, double weight, const Rgb8 &color);
  // The factors of (weight, colour) into factors_m_ / factors_shift_, unless they are the last's.
  void set_factors(double weight, const Rgb8 &color);
  double last_weight_ = -1.0;
  uint32_t last_color_ = 0;  // packed r | g << 8 | b << 16
  uint64_t factors_m_[4] = {0, 0, 0, 0};
  int factors_shift_ = 1;
  int64_t pixels_written_ = 0;
  DensityStreamAhead ahead_;
};

}  // namespace lantern
