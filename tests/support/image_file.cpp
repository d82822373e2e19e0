#include "tests/support/image_file.h"

#include <OpenImageIO/imageio.h>

#include <fstream>
#include <iterator>
#include <type_traits>

namespace lantern::testing {

namespace {

// Opens `path` and reads every channel as `type` into the image's pixels.
template <typename Image>
Image read_as(const std::string &path, bool as_stored, OIIO::TypeDesc type) {
  Image img;
  OIIO::ImageSpec config;
  if (as_stored) config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) {
    img.error = "cannot open " + path + ": " + OIIO::geterror();
    return img;
  }
  const OIIO::ImageSpec &spec = in->spec();
  img.width = spec.width;
  img.height = spec.height;
  img.channels = spec.nchannels;
  img.pixels.resize(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, type, img.pixels.data()))
    img.error = "cannot read " + path + ": " + in->geterror();
  if constexpr (std::is_same_v<Image, FloatImagePixels>) {
    img.alpha_channel = spec.alpha_channel;
    img.names = spec.channelnames;
  }
  return img;
}

}  // namespace

ImagePixels read_image(const std::string &path, bool as_stored) {
  return read_as<ImagePixels>(path, as_stored, OIIO::TypeDesc::UINT8);
}

FloatImagePixels read_float_image(const std::string &path, bool as_stored) {
  return read_as<FloatImagePixels>(path, as_stored, OIIO::TypeDesc::FLOAT);
}

std::vector<char> read_bytes(const std::string &path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

}  // namespace lantern::testing
