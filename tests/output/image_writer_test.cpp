#include "core/output/image_writer.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "core/output/background_image_writer.h"
#include "tests/output/scratch_dir.h"
#include "tests/support/file_size_limit.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

namespace fs = std::filesystem;

// A 37x23 frame (odd sizes catch stride bugs) with a color gradient, varying alpha and a
// background border where depth is exactly 1.
Frame test_frame() {
  Frame f(37, 23);
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const size_t i = f.index(x, y);
      f.rgba[4 * i + 0] = static_cast<uint8_t>(7 * x);
      f.rgba[4 * i + 1] = static_cast<uint8_t>(11 * y);
      f.rgba[4 * i + 2] = static_cast<uint8_t>(x * y);
      f.rgba[4 * i + 3] = static_cast<uint8_t>(255 - x);
      const bool background = x == 0 || y == 0 || x == f.width - 1 || y == f.height - 1;
      f.depth[i] = background ? kBackgroundDepth : 0.01f * float(x) + 0.02f * float(y);
    }
  }
  return f;
}

float to_distance(float depth) {
  return 10.0f + 100.0f * depth;
}

OutputConfig output_as(ImageFormat format) {
  OutputConfig out;
  out.format = format;
  return out;
}

struct ReadBack {
  OIIO::ImageSpec spec;
  std::vector<float> pixels;   // all channels as float
  std::vector<uint8_t> bytes;  // all channels as uint8 (8-bit formats)
};

ReadBack read_back(const std::string &path) {
  ReadBack r;
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // raw bytes, no premultiplication on read
  auto in = OIIO::ImageInput::open(path, &config);
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return r;
  r.spec = in->spec();
  const size_t n = size_t(r.spec.width) * r.spec.height * r.spec.nchannels;
  r.pixels.resize(n);
  EXPECT_TRUE(in->read_image(0, 0, 0, r.spec.nchannels, OIIO::TypeDesc::FLOAT, r.pixels.data()))
      << in->geterror();
  if (r.spec.format == OIIO::TypeDesc::UINT8) {
    r.bytes.resize(n);
    EXPECT_TRUE(in->read_image(0, 0, 0, r.spec.nchannels, OIIO::TypeDesc::UINT8, r.bytes.data()))
        << in->geterror();
  }
  return r;
}

std::string file_bytes(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(ImageWriter, PngIsLosslessRgba8) {
  const ScratchDir dir;
  const Frame frame = test_frame();
  const std::string path = dir.file("sub/frame.png");
  ASSERT_OK(write_image(frame, output_as(ImageFormat::kPng), path, to_distance));
  const ReadBack r = read_back(path);
  EXPECT_EQ(r.spec.width, frame.width);
  EXPECT_EQ(r.spec.height, frame.height);
  EXPECT_EQ(r.spec.nchannels, 4);
  EXPECT_EQ(r.bytes, std::vector<uint8_t>(frame.rgba.begin(), frame.rgba.end()));
}

TEST(ImageWriter, PngIsRgbExactlyWhenEveryPixelIsOpaque) {
  // An opaque frame of 1100 x 5 pixels (blocks of the opacity check and a partial one) is written
  // as RGB; one pixel of alpha 254 anywhere - first, at a block's end or start, last - makes it
  // RGBA. Both read back as the frame's bytes.
  const ScratchDir dir;
  Frame frame(1100, 5);
  for (size_t i = 0; i < frame.pixel_count(); ++i)
    for (int c = 0; c < 4; ++c) frame.rgba[4 * i + c] = c == 3 ? 255 : uint8_t(i * (c + 3));
  const std::string path = dir.file("opaque.png");
  ASSERT_OK(write_image(frame, output_as(ImageFormat::kPng), path, to_distance));
  const ReadBack opaque = read_back(path);
  ASSERT_EQ(opaque.spec.nchannels, 3);
  for (size_t i = 0; i < frame.pixel_count(); ++i)
    ASSERT_EQ(std::memcmp(&opaque.bytes[3 * i], &frame.rgba[4 * i], 3), 0) << i;
  for (const size_t at : {size_t(0), size_t(1023), size_t(1024), frame.pixel_count() - 1}) {
    Frame one = frame;
    one.rgba[4 * at + 3] = 254;
    const std::string p = dir.file("alpha_" + std::to_string(at) + ".png");
    ASSERT_OK(write_image(one, output_as(ImageFormat::kPng), p, to_distance));
    const ReadBack r = read_back(p);
    EXPECT_EQ(r.spec.nchannels, 4) << at;
    EXPECT_EQ(r.bytes, std::vector<uint8_t>(one.rgba.begin(), one.rgba.end())) << at;
  }
}

TEST(ImageWriter, TiffIsLosslessRgba8) {
  const ScratchDir dir;
  const Frame frame = test_frame();
  const std::string path = dir.file("frame.tif");
  ASSERT_OK(write_image(frame, output_as(ImageFormat::kTiff), path, to_distance));
  const ReadBack r = read_back(path);
  EXPECT_EQ(r.spec.nchannels, 4);
  EXPECT_EQ(r.bytes, std::vector<uint8_t>(frame.rgba.begin(), frame.rgba.end()));
}

TEST(ImageWriter, JpegIsRgbWithinTolerance) {
  const ScratchDir dir;
  Frame frame(32, 16);
  const uint8_t grey[4] = {128, 64, 200, 255};
  frame.clear(grey);
  OutputConfig out = output_as(ImageFormat::kJpeg);
  out.jpeg_quality = 100;
  const std::string path = dir.file("frame.jpg");
  ASSERT_OK(write_image(frame, out, path, to_distance));
  const ReadBack r = read_back(path);
  ASSERT_EQ(r.spec.nchannels, 3);
  ASSERT_EQ(r.bytes.size(), frame.pixel_count() * 3);
  for (size_t i = 0; i < frame.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.bytes[3 * i + c], grey[c], 3);
}

TEST(ImageWriter, ExrCarriesZAsCameraDistance) {
  for (const bool half : {true, false}) {
    const ScratchDir dir;
    const Frame frame = test_frame();
    OutputConfig out = output_as(ImageFormat::kExr);
    out.exr_half = half;
    const std::string path = dir.file("frame.exr");
    ASSERT_OK(write_image(frame, out, path, to_distance));
    const ReadBack r = read_back(path);
    ASSERT_EQ(r.spec.nchannels, 5);
    const std::vector<std::string> expected_names = {"R", "G", "B", "A", "Z"};
    EXPECT_EQ(r.spec.channelnames, expected_names);
    EXPECT_EQ(r.spec.channelformat(0), half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
    EXPECT_EQ(r.spec.channelformat(4), OIIO::TypeDesc::FLOAT);
    for (size_t i = 0; i < frame.pixel_count(); ++i) {
      const float z = r.pixels[5 * i + 4];
      if (frame.depth[i] == kBackgroundDepth) {
        EXPECT_TRUE(std::isinf(z) && z > 0) << i;
      } else {
        EXPECT_EQ(z, to_distance(frame.depth[i])) << i;  // float Z: exact
      }
      EXPECT_NEAR(r.pixels[5 * i + 3], frame.rgba[4 * i + 3] / 255.0f, 1e-3f);
    }
    // Color is linearised from sRGB (code 255 -> 1.0, code 0 -> 0.0, code 128 -> ~0.2158) and,
    // as OpenEXR specifies, premultiplied by alpha (the frame's alpha is straight).
    const size_t white_red = frame.index(36, 5);  // 7 * 36 = 252, alpha 255 - 36
    EXPECT_NEAR(r.pixels[5 * white_red],
                std::pow((252 / 255.0 + 0.055) / 1.055, 2.4) * (255 - 36) / 255.0, 1e-3);
    const size_t opaque = frame.index(0, 5);  // alpha 255: green 55 as it is
    EXPECT_NEAR(r.pixels[5 * opaque + 1], std::pow((55 / 255.0 + 0.055) / 1.055, 2.4), 1e-3);
  }
}

TEST(ImageWriter, ExrWithoutDistanceFunctionStoresWindowDepth) {
  const ScratchDir dir;
  const Frame frame = test_frame();
  const std::string path = dir.file("raw.exr");
  ASSERT_OK(write_image(frame, output_as(ImageFormat::kExr), path, nullptr));
  const ReadBack r = read_back(path);
  const size_t i = frame.index(5, 5);
  EXPECT_EQ(r.pixels[5 * i + 4], frame.depth[i]);
}

TEST(ImageWriter, IdenticalFramesGiveIdenticalFiles) {
  const ScratchDir dir;
  const Frame frame = test_frame();
  const std::vector<ImageFormat> formats = {ImageFormat::kPng, ImageFormat::kJpeg,
                                            ImageFormat::kTiff, ImageFormat::kExr};
  const auto write_all = [&](const std::string &prefix) {
    for (const ImageFormat format : formats) {
      const std::string path = dir.file(prefix + image_format_extension(format));
      ASSERT_OK(write_image(frame, output_as(format), path, to_distance));
    }
  };
  write_all("first");
  // Cross a second boundary so that any wall-clock timestamp in the metadata would differ.
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  write_all("second");
  for (const ImageFormat format : formats) {
    const std::string a =
        file_bytes(dir.file(std::string("first") + image_format_extension(format)));
    const std::string b =
        file_bytes(dir.file(std::string("second") + image_format_extension(format)));
    EXPECT_FALSE(a.empty());
    EXPECT_TRUE(a == b) << image_format_extension(format) << " differs between two writes";
  }
  EXPECT_EQ(dir.entry_count(), 2 * formats.size());  // no temporaries left
}

TEST(ImageWriter, FormatComesFromConfigNotFileName) {
  const ScratchDir dir;
  const std::string path = dir.file("frame.data");
  ASSERT_OK(write_image(test_frame(), output_as(ImageFormat::kPng), path, to_distance));
  const std::string bytes = file_bytes(path);
  ASSERT_GE(bytes.size(), 8u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
}

TEST(ImageWriter, UnwritableDirectoryNamesPathAndLeavesNoFile) {
  const std::string path = "/proc/lantern_x/a.png";
  const Status status = write_image(test_frame(), output_as(ImageFormat::kPng), path, nullptr);
  const std::string &error = status.message;
  EXPECT_EQ(status.code, StatusCode::kIo) << error;
  EXPECT_NE(error.find("/proc/lantern_x"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(path));
}

TEST(ImageWriter, PathUnderRegularFileNamesPathAndLeavesNoFile) {
  const ScratchDir dir;
  std::ofstream(dir.file("plain")) << "x";
  const std::string path = dir.file("plain/a.exr");
  const Status status = write_image(test_frame(), output_as(ImageFormat::kExr), path, nullptr);
  const std::string &error = status.message;
  EXPECT_EQ(status.code, StatusCode::kIo) << error;
  EXPECT_NE(error.find(dir.file("plain")), std::string::npos) << error;
  EXPECT_EQ(dir.entry_count(), 1u);
}

TEST(ImageWriter, MismatchedFrameIsAnErrorNotACrash) {
  const ScratchDir dir;
  Frame frame(4, 4);
  frame.depth.clear();
  const std::string path = dir.file("bad.png");
  EXPECT_FALSE(write_image(frame, output_as(ImageFormat::kPng), path, nullptr).ok());
  EXPECT_FALSE(fs::exists(path));
}

// A frame of noise: every format's file is tens of kilobytes, whatever its compression.
Frame noise_frame() {
  Frame f(160, 120);
  uint32_t x = 2463534242u;
  for (size_t i = 0; i < f.rgba.size(); ++i) {
    x ^= x << 13, x ^= x >> 17, x ^= x << 5;  // xorshift32
    f.rgba[i] = uint8_t(x >> 24);
  }
  for (float &d : f.depth) d = 0.5f;
  return f;
}

// A full disk while an image is written (the file may grow to 4 kB, as on a file system with 4 kB
// left): every format returns kIo naming the file, leaves no file at its name and no hidden
// temporary file, and the process goes on. libjpeg's default error handler calls exit() on a
// failed write, which would end the host simulation.
class FullDisk : public ::testing::TestWithParam<ImageFormat> {};

TEST_P(FullDisk, EveryImageFormatReturnsIoAndLeavesNoFile) {
  const ScratchDir dir;
  const Frame frame = noise_frame();
  const std::string path = dir.file(std::string("frame") + image_format_extension(GetParam()));
  Status written;
  {
    const testing::FileSizeLimit full(4096);
    written = write_image(frame, output_as(GetParam()), path, to_distance);
  }
  EXPECT_EQ(written.code, StatusCode::kIo) << written.message;
  EXPECT_NE(written.message.find(path), std::string::npos) << written.message;
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(dir.entry_count(), 0u) << "a temporary file was left behind";
  // With room again, the same call writes the file.
  EXPECT_OK(write_image(frame, output_as(GetParam()), path, to_distance));
  EXPECT_TRUE(fs::exists(path));
}

TEST_P(FullDisk, AsynchronousWriterReportsItAtTheNextWait) {
  const ScratchDir dir;
  const std::string path = dir.file(std::string("frame") + image_format_extension(GetParam()));
  BackgroundImageWriter writer;
  Status waited;
  {
    const testing::FileSizeLimit full(4096);
    EXPECT_OK(writer.submit(noise_frame(), output_as(GetParam()), path, to_distance));
    waited = writer.wait();
  }
  EXPECT_EQ(waited.code, StatusCode::kIo) << waited.message;
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(dir.entry_count(), 0u) << "a temporary file was left behind";
}

INSTANTIATE_TEST_SUITE_P(Formats, FullDisk,
                         ::testing::Values(ImageFormat::kPng, ImageFormat::kJpeg,
                                           ImageFormat::kTiff, ImageFormat::kExr),
                         [](const auto &info) {
                           return std::string(image_format_extension(info.param) + 1);
                         });

}  // namespace
}  // namespace lantern
