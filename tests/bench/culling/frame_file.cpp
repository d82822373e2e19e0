#include "frame_file.h"

#include "tests/support/image_file.h"

namespace lantern::bench {

Frame read_frame(const std::string &path) {
  const lantern::testing::ImagePixels img = lantern::testing::read_image(path);
  Frame f(img.width, img.height);
  for (size_t i = 0; i < f.pixel_count(); ++i)
    for (int c = 0; c < 4; ++c)
      f.rgba[4 * i + size_t(c)] =
          c < img.channels ? img.pixels[size_t(img.channels) * i + size_t(c)] : 255;
  return f;
}

}  // namespace lantern::bench
