// What the C API renders: identical files for identical input, the same image far from the
// origin, background for no particles, and NaN particles skipped and counted.
#include <cmath>
#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>

#include "tests/api/api_fixture.h"
#include "tests/support/image_file.h"

namespace lantern::testing {
namespace {

using ImageOutcome = ApiTest;

TEST_F(ImageOutcome, RepeatedRendersGiveBitIdenticalFiles) {
  ASSERT_EQ(open(scene_config("r", 200, 150, "    color: {by: scalar, colormap: plasma}\n")),
            LANTERN_OK)
      << message();
  std::vector<double> x = lattice(12);
  std::vector<float> scalar(x.size() / 3);
  for (size_t i = 0; i < scalar.size(); ++i) scalar[i] = float(std::sin(0.01 * double(i)));
  lantern_particles p = interleaved(x);
  p.scalar = {scalar.data(), LANTERN_FLOAT32, 0};
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 1, 0.0), LANTERN_OK) << message();
  ASSERT_EQ(lantern_execute(ctx_, 2, 0.0), LANTERN_OK) << message();
  const auto a = read_bytes(png("r", 1)), b = read_bytes(png("r", 2));
  ASSERT_GT(a.size(), 1000u);
  EXPECT_EQ(a, b);
}

TEST_F(ImageOutcome, SceneFarFromTheOriginMatchesTheSameSceneAtTheOrigin) {
  for (const char *projection : {"perspective", "orthographic"}) {
    const std::string cam = std::string("    camera: {projection: ") + projection + "}\n";
    ASSERT_EQ(open(scene_config("near", 160, 120, cam)), LANTERN_OK) << message();
    std::vector<double> at_origin = lattice(10, 0.0);
    lantern_particles p = interleaved(at_origin);
    ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
    ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();

    ASSERT_EQ(open(scene_config("far", 160, 120, cam)), LANTERN_OK) << message();
    std::vector<double> far = lattice(10, 1.0e6);
    p = interleaved(far);
    ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
    ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();

    const ImagePixels a = read_image(png("near", 0)), b = read_image(png("far", 0));
    ASSERT_EQ(a.error, "");
    ASSERT_EQ(b.error, "");
    EXPECT_EQ(a.pixels, b.pixels) << projection;
  }
}

TEST_F(ImageOutcome, AsynchronousWritingGivesTheSameFiles) {
  std::vector<double> x = lattice(8);
  const lantern_particles p = interleaved(x);
  ASSERT_EQ(open(scene_config("sync", 120, 90)), LANTERN_OK) << message();
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  ASSERT_EQ(open(scene_config("async", 120, 90, "", ", asynchronous: true")), LANTERN_OK)
      << message();
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  for (int step = 0; step < 3; ++step)
    ASSERT_EQ(lantern_execute(ctx_, step, 0.0), LANTERN_OK) << message();
  ASSERT_EQ(lantern_close(ctx_), LANTERN_OK);  // waits for the image in flight
  ctx_ = nullptr;
  const auto reference = read_bytes(png("sync", 0));
  ASSERT_GT(reference.size(), 100u);
  for (int step = 0; step < 3; ++step) EXPECT_EQ(read_bytes(png("async", step)), reference);
}

TEST_F(ImageOutcome, ZeroParticlesRenderTheBackground) {
  ASSERT_EQ(open(scene_config("empty", 40, 30, "    background: [0.0, 0.5, 1.0]\n")), LANTERN_OK)
      << message();
  const lantern_particles none{};
  ASSERT_EQ(lantern_publish(ctx_, &none), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  const ImagePixels img = read_image(png("empty", 0));
  ASSERT_EQ(img.error, "");
  ASSERT_EQ(img.width, 40);
  for (int i = 0; i < img.width * img.height; ++i) {
    const uint8_t *px = &img.pixels[size_t(i) * img.channels];
    ASSERT_EQ(px[0], 0);
    ASSERT_EQ(px[1], 128);
    ASSERT_EQ(px[2], 255);
  }
}

TEST_F(ImageOutcome, NonFiniteParticlesAreSkippedAndCounted) {
  ASSERT_EQ(open(scene_config("nan", 64, 64)), LANTERN_OK) << message();
  std::vector<double> x = lattice(4);
  std::vector<double> clean = x;
  x[0] = std::numeric_limits<double>::quiet_NaN();
  x[5] = std::numeric_limits<double>::infinity();  // particle 1
  lantern_particles p = interleaved(x);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 0, 0.0), LANTERN_OK) << message();
  // The image equals that of the finite particles alone.
  std::vector<double> finite(clean.begin() + 6, clean.end());
  p = interleaved(finite);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx_, 1, 0.0), LANTERN_OK) << message();
  EXPECT_EQ(read_image(png("nan", 0)).pixels, read_image(png("nan", 1)).pixels);

  std::ifstream stats(dir_ / "stats.jsonl");
  std::string line;
  ASSERT_TRUE(std::getline(stats, line));
  const auto j = nlohmann::json::parse(line);
  EXPECT_EQ(j["step"], 0);
  EXPECT_EQ(j["particles"]["nonfinite"], 2);
  EXPECT_EQ(j["particles"]["finite"], 62);
  EXPECT_EQ(j["scenes"][0]["particles"]["drawn"], 62);
  EXPECT_GE(j["scenes"][0]["ms"]["total"].get<double>(), 0.0);
}

}  // namespace
}  // namespace lantern::testing
