// One rendered image with per-pixel depth: what a rank renders, what compositing merges, and what
// the output stage writes.
//
// Layout: row-major, row 0 is the TOP of the image (as image files store it). color is RGBA8,
// 4 bytes per pixel; depth is the OpenGL window depth in [0, 1] (0 = near plane), with exactly
// 1.0f (kBackgroundDepth) where nothing was drawn. Window depth is monotonic in distance for both
// projections, so "nearer" is "smaller" everywhere. Ownership: a Frame owns its buffers.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

#include "core/common/page_allocator.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lantern {

inline constexpr float kBackgroundDepth = 1.0f;

// What a renderer that drew a frame right after clear() says of it: every pixel outside the
// rectangle [x0, x1) x [y0, y1) (y counted from the top row) still holds what that clear() wrote,
// `background` at kBackgroundDepth.
struct DrawnWithin {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  uint8_t background[4] = {0, 0, 0, 0};
};

struct Frame {
  int width = 0;
  int height = 0;
  PageVector<uint8_t> rgba;  // 4 * width * height
  PageVector<float> depth;   // width * height
  // Set by the CPU raster's pass (cpu_sphere_pass.h) once it has drawn; compositing's scan then
  // reads only that rectangle of the frame, and drops it (its merges write outside it). clear()
  // and reset() drop it, and so does whoever draws into the frame without widening it.
  std::optional<DrawnWithin> drawn_within;

  Frame() = default;
  Frame(int w, int h) : width(w), height(h), rgba(size_t(w) * h * 4), depth(size_t(w) * h) {}

  // Makes this what Frame(w, h) makes (zero colour and depth), reusing the buffers when they
  // already have the size: the buffers are mapped pages (page_allocator.h), so a frame made anew
  // every step would fault all of them in again.
  void reset(int w, int h) {
    const size_t pixels = size_t(w) * size_t(h);
    if (rgba.size() != 4 * pixels || depth.size() != pixels) {
      *this = Frame(w, h);
      return;
    }
    width = w, height = h;
    drawn_within.reset();
    std::fill(rgba.begin(), rgba.end(), uint8_t(0));
    std::fill(depth.begin(), depth.end(), 0.0f);
  }

  // The same as reset(w, h) then clear(background_rgba), without zeroing the buffers first.
  void reset(int w, int h, const uint8_t background_rgba[4]) {
    const size_t pixels = size_t(w) * size_t(h);
    if (rgba.size() != 4 * pixels || depth.size() != pixels)
      *this = Frame(w, h);
    else
      width = w, height = h;
    clear(background_rgba);
  }

  size_t pixel_count() const { return size_t(width) * size_t(height); }
  size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }

  // Fills every pixel with the background color (RGBA8) at background depth.
  void clear(const uint8_t background_rgba[4]) {
    drawn_within.reset();
    uint32_t packed;  // one 4-byte word per pixel: this runs for every frame
    std::memcpy(&packed, background_rgba, 4);
    uint32_t background_depth;
    std::memcpy(&background_depth, &kBackgroundDepth, 4);
    fill_words(rgba.data(), pixel_count(), packed);
    fill_words(depth.data(), pixel_count(), background_depth);
  }

 private:
  // Frames of this many pixels or more are filled with non-temporal stores, which write the
  // lines without reading them first. On the 1 M-atom LJ frame at 1024^2 (8 MB a rank, more than
  // the L2 cache) the CPU raster's stage took 0.6-1.4 ms less in 5 of 6 alternated rounds; at
  // 512^2 (2 MB) it made no difference (tests/bench/culling/results/frame_clear_streaming_ab.txt).
  // Smaller frames, which the raster may still find in cache, keep ordinary stores.
  static constexpr size_t kStreamedFillPixels = size_t(512) * 512;

  // Writes the 4-byte word v (its bytes as in memory) to the n words at p.
  static void fill_words(void *p, size_t n, uint32_t v) {
    auto *out = static_cast<unsigned char *>(p);
    size_t i = 0;
#if defined(__SSE2__)
    if (n >= kStreamedFillPixels) {
      for (; i < n && reinterpret_cast<uintptr_t>(out + 4 * i) % 16 != 0; ++i)
        std::memcpy(out + 4 * i, &v, 4);
      const __m128i four = _mm_set1_epi32(int(v));
      for (; i + 4 <= n; i += 4) _mm_stream_si128(reinterpret_cast<__m128i *>(out + 4 * i), four);
      _mm_sfence();  // ordered before whatever reads the frame next
    }
#endif
    for (; i < n; ++i) std::memcpy(out + 4 * i, &v, 4);
  }
};

}  // namespace lantern
