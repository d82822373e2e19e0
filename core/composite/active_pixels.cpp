#include "core/composite/active_pixels.h"

#include <algorithm>
#include <cstring>
#include <optional>
#include <utility>

#include "core/composite/packed_pixel.h"

namespace lantern {
namespace {

// The frame's words read in place: GCC's may_alias lets a float array be read as its bits.
using AliasedWord = uint32_t __attribute__((may_alias));

constexpr uint32_t kOneBits = 0x3f800000u;  // 1.0f: NaN's canonical depth (background)

// canonical_depth on the bits, branch-free (masks, so that loops over it vectorise): positive
// finite or +inf stay, NaN becomes 1, the rest (+-0, negative) 0. Positive non-NaN floats are
// exactly the bit patterns in [1, 0x7f800000].
inline uint32_t canonical_bits(uint32_t d) {
  const uint32_t nan = 0u - uint32_t((d & 0x7fffffffu) > 0x7f800000u);
  const uint32_t positive = 0u - uint32_t(d - 1u < 0x7f800000u);
  return (kOneBits & nan) | (d & positive & ~nan);
}

// What one row holds against the running maximum M (depth bits md, colour word mc in memory
// order): how many pixels differ from M, the first and last of them, and whether any pixel is not
// canonical or may be above M (a greater depth, or M's depth with another colour: then the row is
// looked at pixel by pixel). Branch-free reductions over the row, so the compiler vectorises it;
// AVX2 gets the wider version.
struct RowTally {
  int count = 0, first = 0, last = 0;  // first > last when nothing differs
  bool unusual = false;
};

__attribute__((target_clones("avx2", "default"))) RowTally tally_row(
    const AliasedWord *__restrict depth, const AliasedWord *__restrict rgba, int n, uint32_t md,
    uint32_t mc) {
  uint32_t unusual = 0, count = 0, first = uint32_t(n), last_plus_one = 0;
  for (uint32_t x = 0; x < uint32_t(n); ++x) {
    const uint32_t raw = depth[x], c = rgba[x];
    const uint32_t d = canonical_bits(raw);
    const uint32_t depth_differs = uint32_t(d != md), colour_differs = uint32_t(c != mc);
    const uint32_t differs = depth_differs | colour_differs, mask = 0u - differs;
    count += differs;
    first = std::min(first, (x & mask) | (uint32_t(n) & ~mask));
    last_plus_one = std::max(last_plus_one, (x + 1) & mask);
    unusual |= (raw ^ d) | uint32_t(d > md) | (colour_differs & (depth_differs ^ 1u));
  }
  return {int(count), int(first), int(last_plus_one) - 1, unusual != 0};
}

uint64_t canonical_key(float *depth, const uint8_t *rgba, size_t i) {
  const float canonical = canonical_depth(depth[i]);
  depth[i] = canonical;
  return pack_pixel(canonical, rgba + 4 * i);
}

}  // namespace

EmptyPixel empty_pixel(uint64_t key) {
  EmptyPixel e;
  e.key = key;
  e.depth_bits = uint32_t(key >> 32);
  uint8_t rgba[4];
  store_color_word(uint32_t(key), rgba);
  std::memcpy(&e.rgba_word, rgba, sizeof e.rgba_word);
  return e;
}

namespace {

// scan_active_pixels over rows first_row, first_row + step, ... only; `active` counts the pixels
// of those rows.
ActiveScan scan_rows(Frame &frame, int first_row, int step) {
  ActiveScan scan;
  const size_t pixels = frame.pixel_count();
  if (pixels == 0 || first_row >= frame.height) return scan;
  float *depth = frame.depth.data();
  const uint8_t *rgba = frame.rgba.data();
  const int width = frame.width;
  uint64_t max_key = canonical_key(depth, rgba, size_t(first_row) * size_t(width));
  size_t active = 0, scanned = 0;  // scanned: pixels of the rows before this one
  for (int y = first_row; y < frame.height; y += step, scanned += size_t(width)) {
    const size_t row = size_t(y) * size_t(width);
    const EmptyPixel m = empty_pixel(max_key);
    const RowTally t = tally_row(reinterpret_cast<const AliasedWord *>(depth + row),
                                 reinterpret_cast<const AliasedWord *>(rgba + 4 * row), width,
                                 m.depth_bits, m.rgba_word);
    if (!t.unusual) {  // the common row
      active += size_t(t.count);
      scan.rect.add(t.first, y, t.last + 1, y + 1);
      continue;
    }
    // A row that may hold a new maximum or a depth to rewrite: pixel by pixel.
    int row_x0 = width, row_x1 = 0;  // active columns [row_x0, row_x1) of this row
    for (int x = 0; x < width; ++x) {
      const uint64_t key = canonical_key(depth, rgba, row + size_t(x));
      if (key < max_key) {
        ++active;
        row_x0 = std::min(row_x0, x);
        row_x1 = x + 1;
      } else if (key > max_key) {
        // A new maximum: every pixel scanned before this one is below it, so active.
        active = scanned + size_t(x);
        if (y > first_row) scan.rect.add(0, first_row, width, y);
        if (x > 0) row_x0 = 0, row_x1 = std::max(row_x1, x);
        max_key = key;
      }
    }
    scan.rect.add(row_x0, y, row_x1, y + 1);
  }
  scan.max_key = max_key;
  scan.active = active;
  return scan;
}

// scan_active_pixels of a frame whose pixels outside `w` (at least one) all hold the key b, reading
// only the window: the same result as the whole frame's scan wherever no pixel inside is above b
// (the frame's largest key is then b); nullopt otherwise.
std::optional<ActiveScan> scan_window(Frame &frame, const DrawnWithin &w, uint64_t b) {
  ActiveScan scan;
  float *depth = frame.depth.data();
  uint8_t *rgba = frame.rgba.data();
  const EmptyPixel m = empty_pixel(b);
  const int n = w.x1 - w.x0;
  size_t active = 0;
  for (int y = w.y0; y < w.y1; ++y) {
    const size_t row = size_t(y) * size_t(frame.width) + size_t(w.x0);
    const RowTally t = tally_row(reinterpret_cast<const AliasedWord *>(depth + row),
                                 reinterpret_cast<const AliasedWord *>(rgba + 4 * row), n,
                                 m.depth_bits, m.rgba_word);
    if (!t.unusual) {
      active += size_t(t.count);
      scan.rect.add(w.x0 + t.first, y, w.x0 + t.last + 1, y + 1);  // none when count is 0
      continue;
    }
    int row_x0 = frame.width, row_x1 = 0;
    for (int x = 0; x < n; ++x) {
      const uint64_t key = canonical_key(depth, rgba, row + size_t(x));
      if (key > b) return std::nullopt;
      if (key < b) {
        ++active;
        row_x0 = std::min(row_x0, w.x0 + x);
        row_x1 = w.x0 + x + 1;
      }
    }
    scan.rect.add(row_x0, y, row_x1, y + 1);
  }
  scan.max_key = b;
  scan.active = active;
  return scan;
}

}  // namespace

ActiveScan scan_active_pixels(Frame &frame) {
  // Used once: compositing's merges, which follow, write outside the rectangle.
  const std::optional<DrawnWithin> within = std::exchange(frame.drawn_within, std::nullopt);
  if (within && frame.pixel_count() > 0) {
    DrawnWithin w = *within;
    w.x0 = std::clamp(w.x0, 0, frame.width), w.x1 = std::clamp(w.x1, w.x0, frame.width);
    w.y0 = std::clamp(w.y0, 0, frame.height), w.y1 = std::clamp(w.y1, w.y0, frame.height);
    // Some pixel lies outside (else this is the whole frame's scan), holding the background's key.
    const bool all = w.x0 == 0 && w.y0 == 0 && w.x1 == frame.width && w.y1 == frame.height;
    if (!all) {
      if (std::optional<ActiveScan> scan =
              scan_window(frame, w, pack_pixel(kBackgroundDepth, w.background)))
        return *scan;
    }
  }
  return scan_rows(frame, 0, 1);
}

ActiveScan sample_active_pixels(Frame &frame, int row_step) {
  row_step = std::max(row_step, 1);
  ActiveScan sample = scan_rows(frame, row_step / 2, row_step);
  const size_t rows = frame.height > row_step / 2
                          ? size_t(frame.height - row_step / 2 + row_step - 1) / size_t(row_step)
                          : 0;
  if (rows > 0) sample.active = size_t(double(sample.active) * double(frame.height) / double(rows));
  return sample;
}

}  // namespace lantern
