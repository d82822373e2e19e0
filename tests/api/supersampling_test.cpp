// Super-sampled anti-aliasing (`samples: N`) through the C API: bad values and oversized sample
// frames refused at lantern_open, samples 1 running no extra stage, exact hzb culling at sample
// level (bit-identical to brute force), and the CPU raster against OpenGL at 4 samples.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/api/api_fixture.h"
#include "tests/support/image_file.h"

namespace lantern::testing {
namespace {

class Supersampling : public ApiTest {
 protected:
  // A random scene: a dense lattice block (so hzb has occluders) plus a random cloud with mixed
  // radii in front of and around it, interleaved doubles.
  static std::vector<double> random_scene(unsigned seed) {
    std::vector<double> x = lattice(14, 3.0);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 20.0);
    for (int i = 0; i < 1500; ++i)
      for (int k = 0; k < 3; ++k) x.push_back(u(rng));
    return x;
  }

  void render(const std::string &config, const std::vector<double> &x, int step = 0) {
    ASSERT_EQ(open(config), LANTERN_OK) << message();
    const lantern_particles p = interleaved(x);
    ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
    ASSERT_EQ(lantern_execute(ctx_, step, 0.0), LANTERN_OK) << message();
    lantern_close(ctx_);
    ctx_ = nullptr;
  }

  // The scenes of the last stats line.
  nlohmann::json last_stats() const {
    std::ifstream in(dir_ / "stats.jsonl");
    std::string line, last;
    while (std::getline(in, line)) last = line;
    return nlohmann::json::parse(last)["scenes"];
  }

  lantern_status open_with_samples(const std::string &value, int w = 96, int h = 64) {
    return open(scene_config("s", w, h, "    samples: " + value + "\n"));
  }
};

TEST_F(Supersampling, SampleCountsOutsideTheAllowedSetAreConfigErrorsNamingKeyLineAndValues) {
  for (const char *bad : {"3", "0", "x", "2", "-4", "[4]"}) {
    EXPECT_EQ(open_with_samples(bad), LANTERN_ERR_CONFIG) << bad;
    const std::string m = message();
    EXPECT_NE(m.find("scenes[0].samples"), std::string::npos) << m;
    EXPECT_NE(m.find("line 7"), std::string::npos) << m;
    EXPECT_NE(m.find("1, 4, 16, 64"), std::string::npos) << m;
  }
  for (const char *good : {"1", "4", "16", "64"})
    EXPECT_EQ(open_with_samples(good), LANTERN_OK) << good << ": " << message();
}

// 16384^2 at 64 samples is a 2^34-pixel sample frame: 2^37 bytes, refused before any allocation.
TEST_F(Supersampling, SampleFramesBeyondTheLimitAreRefusedAtOpenWithTheBytesNeeded) {
  EXPECT_EQ(open_with_samples("64", 16384, 16384), LANTERN_ERR_CONFIG);
  std::string m = message();
  EXPECT_NE(m.find("137438953472 bytes"), std::string::npos) << m;
  EXPECT_NE(m.find("16384 x 16384 at 64 samples"), std::string::npos) << m;
  EXPECT_NE(m.find("scene 's'"), std::string::npos) << m;
  EXPECT_NE(m.find("scenes[0].samples"), std::string::npos) << m;
  EXPECT_EQ(open_with_samples("4", 16384, 16384), LANTERN_ERR_CONFIG);  // 8 GiB
  EXPECT_NE(message().find("8589934592 bytes"), std::string::npos) << message();
  // Exactly at the limit (2^28 sample pixels, 2 GiB) is accepted (not rendered here), as is the
  // largest image without super-sampling.
  EXPECT_EQ(open_with_samples("4", 8192, 8192), LANTERN_OK) << message();
  EXPECT_EQ(open_with_samples("64", 2048, 2048), LANTERN_OK) << message();
  EXPECT_EQ(open_with_samples("1", 16384, 16384), LANTERN_OK) << message();
}

// samples: 1 is today's path: the same bytes as no key at all, no down-sampling stage, the
// frame at the image's size. samples: 4 reports its sample frame.
TEST_F(Supersampling, OneSampleIsTodaysPathAndTheStatsSayTheSampleFrame) {
  const std::vector<double> x = random_scene(3);
  render(scene_config("plain"), x);
  EXPECT_EQ(last_stats()[0]["samples"], 1);
  EXPECT_EQ(last_stats()[0]["sample_frame"], nlohmann::json::array({96, 64}));
  EXPECT_EQ(last_stats()[0]["ms"]["downsample"], 0.0);
  render(scene_config("one", 96, 64, "    samples: 1\n"), x);
  EXPECT_EQ(last_stats()[0]["ms"]["downsample"], 0.0);
  EXPECT_EQ(read_bytes(png("plain", 0)), read_bytes(png("one", 0)));
  render(scene_config("four", 96, 64, "    samples: 4\n"), x);
  EXPECT_EQ(last_stats()[0]["samples"], 4);
  EXPECT_EQ(last_stats()[0]["sample_frame"], nlohmann::json::array({192, 128}));
  const ImagePixels four = read_image(png("four", 0)), plain = read_image(png("plain", 0));
  ASSERT_EQ(four.error, "");
  EXPECT_EQ(four.width, 96);
  EXPECT_EQ(four.height, 64);
  EXPECT_NE(four.pixels, plain.pixels);  // anti-aliased edges
}

// A live change of samples (4 -> 1 -> 16) renders each step as a fresh context would.
TEST_F(Supersampling, ReconfiguringSamplesGivesTheSameImagesAsAFreshContext) {
  const std::vector<double> x = random_scene(4);
  const auto config = [&](int samples) {
    return scene_config("live", 96, 64, "    samples: " + std::to_string(samples) + "\n");
  };
  for (const int samples : {4, 1, 16}) {
    render(config(samples), x, 10 + samples);  // fresh: live_00NN.png
  }
  ASSERT_EQ(open(config(4)), LANTERN_OK) << message();
  const lantern_particles p = interleaved(x);
  ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
  for (const int samples : {4, 1, 16}) {
    const std::vector<char> fresh = read_bytes(png("live", 10 + samples));
    ASSERT_EQ(lantern_reconfigure(ctx_, config(samples).c_str()), LANTERN_OK) << message();
    ASSERT_EQ(lantern_execute(ctx_, 20 + samples, 0.0), LANTERN_OK) << message();
    EXPECT_EQ(read_bytes(png("live", 20 + samples)), fresh) << samples << " samples";
  }
}

// hzb culls against the sample-resolution depth: bit-identical to drawing everything, on random
// scenes, 4 and 16 samples, both projections, CPU raster (and OpenGL where the build has it).
TEST_F(Supersampling, HzbAtSampleLevelIsBitIdenticalToBruteForce) {
  const bool have_gl = open(scene_config("probe", 8, 8, "    renderer: opengl\n")) == LANTERN_OK;
  for (const char *renderer : {"cpu", "opengl"}) {
    if (std::string(renderer) == "opengl" && !have_gl) continue;
    for (const int samples : {4, 16})
      for (const char *projection : {"perspective", "orthographic"})
        for (const unsigned seed : {1u, 2u}) {
          const std::vector<double> x = random_scene(seed);
          const std::string label = std::string(renderer) + "_" + std::to_string(samples) + "_" +
                                    projection + "_" + std::to_string(seed);
          const auto config = [&](const std::string &name, const std::string &occlusion) {
            return scene_config(
                name, 80, 60,
                "    radius: 0.45\n    samples: " + std::to_string(samples) +
                    "\n    renderer: " + renderer + "\n    camera: {projection: " + projection +
                    ", azimuth: " + std::to_string(20 + 13 * seed) +
                    ", elevation: 25, zoom: 1.4}\n    culling: {occlusion: " + occlusion + "}\n");
          };
          render(config("brute", "none"), x);
          render(config("hzb", "hzb"), x);
          EXPECT_GT(last_stats()[0]["particles"]["occlusion_culled"].get<int64_t>(), 500) << label;
          EXPECT_EQ(read_bytes(png("brute", 0)), read_bytes(png("hzb", 0))) << label;
        }
  }
}

double psnr(const ImagePixels &a, const ImagePixels &b) {
  double squared = 0.0;
  size_t values = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    if (a.channels == 4 && i % 4 == 3) continue;
    const double d = double(a.pixels[i]) - double(b.pixels[i]);
    squared += d * d;
    ++values;
  }
  return squared == 0.0 ? INFINITY : 10.0 * std::log10(255.0 * 255.0 * values / squared);
}

// The two renderers draw the same sample frame up to the rounding they already differ by (one
// color level, silhouettes within float rounding of a sample centre); down-sampling averages
// those differences out further.
TEST_F(Supersampling, CpuRasterAndOpenGlAgreeAtFourSamples) {
  if (open(scene_config("probe", 8, 8, "    renderer: opengl\n")) != LANTERN_OK)
    GTEST_SKIP() << "no OpenGL in this build or machine: " << message();
  const std::vector<double> x = random_scene(5);
  for (const char *renderer : {"cpu", "opengl"})
    render(scene_config(renderer, 160, 120,
                        "    radius: 0.45\n    samples: 4\n    renderer: " + std::string(renderer) +
                            "\n    culling: {occlusion: none}\n"),
           x);
  const ImagePixels cpu = read_image(png("cpu", 0)), gl = read_image(png("opengl", 0));
  ASSERT_EQ(cpu.error, "");
  ASSERT_EQ(gl.error, "");
  ASSERT_EQ(cpu.pixels.size(), gl.pixels.size());
  const double db = psnr(cpu, gl);
  EXPECT_GT(db, 45.0);
  std::printf("samples 4, cpu raster vs opengl: PSNR %.1f dB\n", db);
}

}  // namespace
}  // namespace lantern::testing
