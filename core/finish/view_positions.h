// View-space positions of a composited band's pixels, reconstructed from window depth through the
// camera: what the screen-space cues (screen_cues.h) measure distances and normals with.
//
// Only the composited frame and the camera go in, so the positions, and every cue computed from
// them, are the same whichever rank holds the row and however the particles were split.
// Units: the simulation's length unit, view space (eye at the origin looking down -z); `z` is
// the positive distance along the view axis, +infinity where nothing was drawn.
// Ownership: a value; build() reads the band and keeps nothing of it. Kept from frame to frame,
// it writes its border again only when the band's size changes.
#pragma once

#include <array>
#include <limits>
#include <vector>

#include "core/camera/camera.h"
#include "core/common/uninitialized_buffer.h"
#include "core/composite/row_bands.h"

namespace lantern {

class ViewPositions {
 public:
  static constexpr float kBackground = std::numeric_limits<float>::infinity();
  // Pixels of background around the held rows: kBorder on each side of every row, and kBorder
  // rows above and below. A reader that reaches at most kBorder pixels beyond the image's
  // columns or the held rows reads the background there instead of testing bounds (the screen
  // AO's samples).
  static constexpr int kBorder = 32;

  // Distances of every pixel of the band's held rows (BandFrame::held_rows(): owned rows and
  // halo); `image_width/height` are the whole image's. `vector`: with AVX2 where the processor has
  // it, four pixels at a time in either projection (the same distances bit for bit; false keeps to
  // one at a time, for tests to compare). `threads`: how many threads (this one included) may share
  // the rows; the same distances at any count.
  void build(const BandFrame &band, const Camera &camera, bool vector = true, int threads = 1);
  // build() in steps, for a reader that computes each row's distances just before it reads them
  // (screen_ambient_occlusion.h): begin() sizes the positions for the band and camera and frames
  // them with their border; build_rows() computes held image rows [y0, y1) (clipped to the held
  // rows; on up to `threads` threads), in any order, each row once before it is read. Every row
  // built gives build()'s distances.
  void begin(const BandFrame &band, const Camera &camera);
  void build_rows(const BandFrame &band, const Camera &camera, int y0, int y1, bool vector = true,
                  int threads = 1);

  // Over the drawn pixels of image rows `rows` (held by the band): the nearest distance and the
  // farthest one negated, kBackground for none; min, not max, as std::min(m, v) meets them.
  // `vector`: with AVX2 where the processor has it (the same two floats).
  std::array<float, 2> drawn_minima(const RowBand &rows, bool vector = true) const;

  // Distance along the view axis at image pixel (x, y), y an image row held by the band (or x, y
  // up to kBorder beyond the columns and the held rows: the background).
  float z(int x, int y) const { return row(y)[x]; }
  // The distances of held row y, `width()` of them, kBorder of background before and after
  // them; rows stride() apart (for vectorised readers).
  const float *row(int y) const {
    return &z_[size_t(y - first_ + kBorder) * stride() + size_t(kBorder)];
  }
  size_t stride() const { return size_t(width_) + 2 * size_t(kBorder); }
  // View-space x and y of image pixel (x, y)'s centre at distance z.
  float view_x(int x, float z) const { return (x_scale_ * (float(x) + 0.5f) + x_offset_) * at(z); }
  float view_y(int y, float z) const { return (y_scale_ * (float(y) + 0.5f) + y_offset_) * at(z); }
  // Pixels per simulation unit at distance z (the same horizontally and vertically).
  float pixels_per_unit(float z) const { return orthographic_ ? ppu_ : ppu_ / z; }

  // The terms of view_x, view_y and pixels_per_unit, for vectorised readers that must compute
  // exactly what those do: view_x = (x_scale (x + 0.5) + x_offset) at(z), at(z) = z in
  // perspective and 1 in orthographic projection.
  struct Terms {
    float x_scale, x_offset, y_scale, y_offset, ppu;
    bool orthographic;
  };
  Terms terms() const { return {x_scale_, x_offset_, y_scale_, y_offset_, ppu_, orthographic_}; }

  int width() const { return width_; }
  int height() const { return height_; }
  int first_row() const { return first_; }
  int last_row() const { return first_ + rows_; }  // one past the last held row

 private:
  // The factor by which a pixel's normalised offset grows with distance: z in perspective.
  float at(float z) const { return orthographic_ ? 1.0f : z; }

  UninitializedBuffer<float> z_;              // every entry written by build(): no zero-fill first
  int border_rows_ = -1, border_width_ = -1;  // the size whose border z_ holds
  int width_ = 0, height_ = 0, first_ = 0, rows_ = 0;
  bool orthographic_ = false;
  float x_scale_ = 0, x_offset_ = 0, y_scale_ = 0, y_offset_ = 0, ppu_ = 0;
};

}  // namespace lantern
