#include "core/composite/run_length_pixels.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "core/composite/packed_pixel.h"

namespace lantern {
namespace {

constexpr uint64_t kLastFlag = uint64_t(1) << 63;
constexpr int kBlock = 16;  // pixels tested at once for a change of state

// The frame's pixels as raw words: depth bits and the colour word in memory order.
struct RawPixels {
  const float *depth;
  const uint8_t *rgba;
  uint32_t d(size_t i) const {
    uint32_t b;
    std::memcpy(&b, depth + i, sizeof b);
    return b;
  }
  uint32_t c(size_t i) const {
    uint32_t w;
    std::memcpy(&w, rgba + 4 * i, sizeof w);
    return w;
  }
};

// The first pixel in [i, end) that is (want_active) or is not (!want_active) empty, or end.
// Frames are canonical, so "empty" is "raw bits equal to E's".
size_t find_state(const RawPixels &px, const EmptyPixel &e, size_t i, size_t end,
                  bool want_active) {
  while (i + kBlock <= end) {
    // Branch-free over a block (the compiler vectorises it), then one test.
    uint32_t any = 0;
    for (int t = 0; t < kBlock; ++t) {
      const bool active =
          ((px.d(i + size_t(t)) ^ e.depth_bits) | (px.c(i + size_t(t)) ^ e.rgba_word)) != 0;
      any |= uint32_t(active == want_active);
    }
    if (any) break;
    i += kBlock;
  }
  for (; i < end; ++i) {
    const bool active = ((px.d(i) ^ e.depth_bits) | (px.c(i) ^ e.rgba_word)) != 0;
    if (active == want_active) return i;
  }
  return end;
}

// The first active pixel in [i, end), or end: rows and columns outside the active rectangle are
// jumped over.
size_t next_active(const ActiveFrame &f, const RawPixels &px, size_t i, size_t end) {
  const ActiveRect &r = f.rect;
  if (r.empty()) return end;
  const size_t width = size_t(f.frame->width);
  while (i < end) {
    const size_t y = i / width, x = i - y * width;
    if (y < size_t(r.y0)) {
      i = size_t(r.y0) * width + size_t(r.x0);
    } else if (y >= size_t(r.y1)) {
      return end;
    } else if (x < size_t(r.x0)) {
      i = y * width + size_t(r.x0);
    } else if (x >= size_t(r.x1)) {
      i = (y + 1) * width + size_t(r.x0);
    } else {
      const size_t row_end = std::min(end, y * width + size_t(r.x1));
      const size_t found = find_state(px, f.empty, i, row_end, true);
      if (found < row_end) return found;
      i = row_end;
    }
  }
  return end;
}

// The end of the active run starting at active pixel i (the first empty pixel after it, or
// end). A run leaves the rectangle only where the rectangle spans whole rows.
size_t run_end(const ActiveFrame &f, const RawPixels &px, size_t i, size_t end) {
  const ActiveRect &r = f.rect;
  const size_t width = size_t(f.frame->width);
  const bool whole_rows = r.x0 == 0 && size_t(r.x1) == width;
  while (i < end) {
    const size_t y = i / width;
    const size_t row_end = std::min(end, y * width + size_t(r.x1));
    const size_t found = find_state(px, f.empty, i, row_end, false);
    if (found < row_end || !whole_rows || y + 1 >= size_t(r.y1)) return found;
    i = row_end;
  }
  return end;
}

}  // namespace

size_t RunLengthEncoder::encode(const ActiveFrame &f, uint64_t *out, size_t capacity) {
  const RawPixels px{f.frame->depth.data(), f.frame->rgba.data()};
  const size_t start = next_;
  size_t cursor = next_, words = 1;
  bool last = false;
  for (;;) {
    const size_t active = next_active(f, px, cursor, range_.hi);
    if (active == range_.hi) {
      cursor = range_.hi;
      last = true;
      break;
    }
    if (words + 2 > capacity) {
      cursor = active;  // the gap before it is empty: this message covers it
      break;
    }
    const size_t end = run_end(f, px, active, range_.hi);
    const size_t count = std::min(end - active, capacity - words - 1);
    out[words++] = uint64_t(active - cursor) << 32 | uint64_t(count);
    for (size_t i = active; i < active + count; ++i)
      out[words++] = uint64_t(px.d(i)) << 32 | color_word(f.frame->rgba.data() + 4 * i);
    cursor = active + count;
    if (cursor < end) break;  // the message is full in the middle of a run
  }
  out[0] = uint64_t(cursor - start) | (last ? kLastFlag : 0);
  next_ = cursor;
  done_ = last;
  return words;
}

Status RunLengthDecoder::decode(const uint64_t *message, size_t words, ActiveFrame &f) {
  const auto corrupt = [&](const char *what) {
    return Status(StatusCode::kInternal,
                  std::string("compositing: malformed active-pixel message (") + what +
                      ") for pixels " + std::to_string(range_.lo) + ".." +
                      std::to_string(range_.hi));
  };
  if (words == 0 || done_) return corrupt("empty or after the last");
  const size_t covered = size_t(message[0] & ~kLastFlag);
  const bool last = (message[0] & kLastFlag) != 0;
  if (covered > range_.hi - next_ || (last && next_ + covered != range_.hi)) return corrupt("span");
  const size_t end = next_ + covered;
  Frame &frame = *f.frame;
  float *depth = frame.depth.data();
  uint8_t *rgba = frame.rgba.data();
  const size_t width = size_t(frame.width);
  size_t cursor = next_;
  for (size_t w = 1; w < words;) {
    const size_t skip = size_t(message[w] >> 32), count = size_t(message[w] & 0xffffffffu);
    ++w;
    if (count > words - w || skip > end - cursor || count > end - cursor - skip)
      return corrupt("run");
    cursor += skip;
    if (count > 0) {
      const uint64_t *keys = message + w;
      for (size_t t = 0; t < count; ++t) {
        const size_t i = cursor + t;
        uint32_t own_depth;
        std::memcpy(&own_depth, depth + i, sizeof own_depth);
        const uint64_t own = uint64_t(own_depth) << 32 | color_word(rgba + 4 * i);
        if (keys[t] < own) unpack_pixel(keys[t], depth + i, rgba + 4 * i);
      }
      // The merged pixels' rows and columns join the active rectangle.
      const size_t first = cursor, final = cursor + count - 1;
      const int y0 = int(first / width), y1 = int(final / width);
      if (y0 == y1) {
        f.rect.add(int(first - size_t(y0) * width), y0, int(final - size_t(y0) * width) + 1,
                   y0 + 1);
      } else {
        f.rect.add(0, y0, int(width), y1 + 1);
      }
    }
    cursor += count;
    w += count;
  }
  next_ = end;
  done_ = last;
  return {};
}

}  // namespace lantern
