// Test support: decode a movie file's frames through FFmpeg's libraries (built with movies only),
// to compare them with the images of the same steps.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lantern::testing {

struct MovieFrames {
  int width = 0, height = 0;              // the coded frame size
  std::string codec, pixel_format;        // e.g. "h264", "yuv420p"
  std::vector<std::vector<uint8_t>> rgb;  // each frame as RGB8, row 0 = top
  std::vector<int64_t> index;             // each frame's time in frames (pts * fps)
  std::string error;                      // non-empty if the file could not be decoded
};

// Decodes every frame; YUV frames are converted with BT.709 limited-range coefficients (what
// Lantern writes), RGB frames are copied exactly.
MovieFrames read_movie(const std::string &path);

// PSNR (dB) of `movie` against `image` (RGB8 or RGBA8, `channels` per pixel) over the image's
// width x height (a movie padded to even sizes has one more column or row); +inf if equal.
double movie_psnr(const std::vector<uint8_t> &movie, int movie_width, const uint8_t *image,
                  int width, int height, int channels);

}  // namespace lantern::testing
