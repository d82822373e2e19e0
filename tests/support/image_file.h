// Test support: read an image file's pixels (through OpenImageIO) and a file's bytes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lantern::testing {

struct ImagePixels {
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> pixels;  // 8-bit, row 0 = top
  std::string error;            // non-empty if the file could not be read
};

// OpenImageIO premultiplies a PNG with alpha while reading it (on the sRGB-encoded values);
// `as_stored` asks for the bytes the file holds (straight alpha) instead.
ImagePixels read_image(const std::string &path, bool as_stored = false);

// The same as floats (EXR channels as stored; 8-bit formats scaled to [0, 1]), with the channel
// names and the alpha channel's index (-1: none).
struct FloatImagePixels {
  int width = 0, height = 0, channels = 0, alpha_channel = -1;
  std::vector<std::string> names;
  std::vector<float> pixels;  // row 0 = top
  std::string error;          // non-empty if the file could not be read
  const float *at(int x, int y) const {
    return &pixels[(size_t(y) * size_t(width) + size_t(x)) * size_t(channels)];
  }
};
FloatImagePixels read_float_image(const std::string &path, bool as_stored = false);
std::vector<char> read_bytes(const std::string &path);

}  // namespace lantern::testing
