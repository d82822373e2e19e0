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

ImagePixels read_image(const std::string &path);
std::vector<char> read_bytes(const std::string &path);

}  // namespace lantern::testing
