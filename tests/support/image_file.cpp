#include "tests/support/image_file.h"

#include <OpenImageIO/imageio.h>

#include <fstream>
#include <iterator>

namespace lantern::testing {

ImagePixels read_image(const std::string &path) {
  ImagePixels img;
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    img.error = "cannot open " + path + ": " + OIIO::geterror();
    return img;
  }
  const OIIO::ImageSpec &spec = in->spec();
  img.width = spec.width;
  img.height = spec.height;
  img.channels = spec.nchannels;
  img.pixels.resize(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, img.pixels.data()))
    img.error = "cannot read " + path + ": " + in->geterror();
  return img;
}

std::vector<char> read_bytes(const std::string &path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

}  // namespace lantern::testing
