// Images written off the caller's thread: all of them land, whole; a bad directory fails the
// step that asked; a failure during the write surfaces at the next call.
#include <gtest/gtest.h>

#include <algorithm>

#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <fstream>

#include "core/output/background_image_writer.h"
#include "tests/output/scratch_dir.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

Frame gradient(int w, int h, uint8_t seed) {
  Frame f(w, h);
  for (size_t i = 0; i < f.pixel_count(); ++i) {
    for (int c = 0; c < 3; ++c) f.rgba[4 * i + c] = uint8_t(i * (c + 1) + seed);
    f.rgba[4 * i + 3] = 255;
    f.depth[i] = 0.5f;
  }
  return f;
}

std::vector<uint8_t> rgba_of(const Frame &f) {
  return std::vector<uint8_t>(f.rgba.begin(), f.rgba.end());
}

// RGBA bytes of an image file; opaque frames are stored as RGB, so alpha then reads as 255.
std::vector<uint8_t> read_rgba(const std::string &path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return {};
  const int channels = in->spec().nchannels;
  const size_t pixels = size_t(in->spec().width) * in->spec().height;
  std::vector<uint8_t> stored(pixels * size_t(channels)), px(pixels * 4, 255);
  in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, stored.data());
  for (size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < std::min(channels, 4); ++c) px[4 * i + c] = stored[i * channels + c];
  return px;
}

TEST(BackgroundImageWriter, EveryImageLandsWholeAfterWait) {
  ScratchDir dir;
  BackgroundImageWriter writer;
  const OutputConfig png;
  for (int i = 0; i < 4; ++i)
    ASSERT_OK(writer.submit(gradient(64, 48, uint8_t(i)), png, dir.file(std::to_string(i) + ".png"),
                            nullptr));
  ASSERT_OK(writer.wait());
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(read_rgba(dir.file(std::to_string(i) + ".png")),
              rgba_of(gradient(64, 48, uint8_t(i))));
  EXPECT_EQ(dir.entry_count(), 4u);  // no temporary left behind
}

TEST(BackgroundImageWriter, UnwritableDirectoryFailsTheStepThatAsked) {
  ScratchDir dir;
  std::ofstream(dir.file("blocker")) << "a file, not a directory";
  BackgroundImageWriter writer;
  const Status status =
      writer.submit(gradient(8, 8, 0), OutputConfig{}, dir.file("blocker/a.png"), nullptr);
  const std::string &error = status.message;
  EXPECT_EQ(status.code, StatusCode::kIo) << error;
  EXPECT_NE(error.find("blocker"), std::string::npos) << error;
  EXPECT_OK(writer.wait());  // nothing was in flight
}

TEST(BackgroundImageWriter, AFailedWriteSurfacesAtTheNextCall) {
  ScratchDir dir;
  std::filesystem::create_directories(dir.file("taken.png"));  // rename onto a directory fails
  BackgroundImageWriter writer;
  ASSERT_OK(writer.submit(gradient(8, 8, 0), OutputConfig{}, dir.file("taken.png"), nullptr));
  const Status status =
      writer.submit(gradient(8, 8, 1), OutputConfig{}, dir.file("next.png"), nullptr);
  const std::string &error = status.message;
  EXPECT_EQ(status.code, StatusCode::kIo) << error;
  EXPECT_NE(error.find("taken.png"), std::string::npos) << error;
  EXPECT_OK(writer.wait());
  EXPECT_TRUE(std::filesystem::is_regular_file(dir.file("next.png")));
}

TEST(BackgroundImageWriter, HandsBackTheWrittenFrameForTheNextImage) {
  // The previous image's buffers come back (the same storage, its pixels as written), so a
  // caller rendering every step reuses them instead of allocating a frame per step.
  ScratchDir dir;
  BackgroundImageWriter writer;
  const OutputConfig png;
  Frame spare(1, 1);
  Frame first = gradient(32, 16, 1);
  const uint8_t *first_pixels = first.rgba.data();
  ASSERT_OK(writer.submit(std::move(first), png, dir.file("a.png"), nullptr, &spare));
  EXPECT_EQ(spare.width, 0);  // no image before the first
  EXPECT_TRUE(spare.rgba.empty());
  ASSERT_OK(writer.submit(gradient(32, 16, 2), png, dir.file("b.png"), nullptr, &spare));
  EXPECT_EQ(spare.width, 32);
  EXPECT_EQ(spare.height, 16);
  EXPECT_EQ(spare.rgba.data(), first_pixels);
  EXPECT_EQ(rgba_of(spare), rgba_of(gradient(32, 16, 1)));
  ASSERT_OK(writer.wait());
  EXPECT_EQ(read_rgba(dir.file("b.png")), rgba_of(gradient(32, 16, 2)));
}

}  // namespace
}  // namespace lantern
