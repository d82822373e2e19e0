// Movies through the C API (output.movie): the decoded frames are the images of the same steps
// (exactly at lossless settings, within the codec's loss at the default ones), a movie can
// replace the images, bad settings and paths fail at lantern_open, a movie that fails midway
// leaves the images going, the stats line reports the movie, and a live change may start a new
// movie but not alter the one being written. A build without movies says so.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/api/api_fixture.h"
#include "tests/support/file_size_limit.h"
#include "tests/support/image_file.h"
#if LANTERN_TEST_MOVIES
#include "tests/support/movie_file.h"
#endif

namespace lantern::testing {
namespace {

class MovieTest : public ApiTest {
 protected:
  // A scene of w x h drawing a lattice by type; `output` is the output mapping's inside.
  std::string config(const std::string &output, int w = 161, int h = 97,
                     const std::string &color = "{by: type}") const {
    return "stats: '" + (dir_ / "stats.jsonl").string() +
           "'\nscenes:\n  - name: m\n    width: " + std::to_string(w) +
           "\n    height: " + std::to_string(h) +
           "\n    camera: {azimuth: 30, elevation: 25}\n    color: " + color + "\n    output: {" +
           output + "}\n";
  }
  std::string path(const std::string &name) const { return (dir_ / name).string(); }
  std::string pattern() const { return "pattern: '" + path("m_{step:04d}.png") + "'"; }

  // Publishes a 6^3 lattice that drifts with the step (types 0..2) and executes `steps` steps.
  void run_steps(int steps, std::vector<lantern_status> *statuses = nullptr) {
    for (int step = 0; step < steps; ++step) {
      std::vector<double> x = lattice(6, 0.15 * step);
      std::vector<int32_t> type(x.size() / 3);
      for (size_t i = 0; i < type.size(); ++i) type[i] = int32_t(i % 3);
      lantern_particles p = interleaved(x);
      p.type = {type.data(), LANTERN_INT32, 0};
      ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK) << message();
      const lantern_status s = lantern_execute(ctx_, step, 0.1 * step);
      if (statuses)
        statuses->push_back(s);
      else
        ASSERT_EQ(s, LANTERN_OK) << message();
    }
  }

  std::vector<nlohmann::json> stats_lines() const {
    std::vector<nlohmann::json> lines;
    std::ifstream in(dir_ / "stats.jsonl");
    for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
    return lines;
  }
};

#if LANTERN_TEST_MOVIES

// Decodes the movie and compares every frame with the PNG of its step: the PSNR over the image.
std::vector<double> psnr_against_pngs(const MovieFrames &movie, int steps,
                                      const std::function<std::string(int)> &png) {
  std::vector<double> out;
  for (int step = 0; step < steps && step < int(movie.rgb.size()); ++step) {
    const ImagePixels image = read_image(png(step));
    EXPECT_EQ(image.error, "");
    if (!image.error.empty()) return out;
    out.push_back(movie_psnr(movie.rgb[size_t(step)], movie.width, image.pixels.data(), image.width,
                             image.height, image.channels));
  }
  return out;
}

TEST_F(MovieTest, LosslessMovieFramesAreThePngsOfTheSameSteps) {
  for (const std::string movie : {"{file: '" + path("m.mkv") + "', codec: ffv1}",
                                  "{file: '" + path("m.mp4") + "', codec: h264, lossless: true}"}) {
    SCOPED_TRACE(movie);
    ASSERT_EQ(open(config(pattern() + ", movie: " + movie)), LANTERN_OK) << message();
    run_steps(5);
    ASSERT_EQ(lantern_close(ctx_), LANTERN_OK);
    ctx_ = nullptr;
    const MovieFrames frames =
        read_movie(path(movie.find("mkv") != std::string::npos ? "m.mkv" : "m.mp4"));
    ASSERT_EQ(frames.error, "");
    ASSERT_EQ(frames.rgb.size(), 5u);
    EXPECT_EQ(frames.width, 161);  // RGB: the odd size as it is
    EXPECT_EQ(frames.height, 97);
    for (const double psnr : psnr_against_pngs(frames, 5, [&](int s) { return png("m", s); }))
      EXPECT_TRUE(std::isinf(psnr)) << psnr << " dB";
  }
}

// The default settings (h264, yuv420p, CRF 23) are within the codec's loss of the PNGs: close
// to what quality 0 keeps, which is only what 4:2:0 chroma keeps (on these small frames of sharp,
// saturated sphere edges about 30 dB; ffmpeg's own libx264 gives the same PSNR as Lantern's
// movie at the same settings). A lower quality value comes closer.
TEST_F(MovieTest, DefaultMovieFramesAreCloseToThePngsAndQualityImprovesThem) {
  std::vector<double> worst;
  for (const std::string quality : {"", ", quality: 10", ", quality: 0"}) {
    SCOPED_TRACE(quality);
    ASSERT_EQ(open(config(pattern() + ", movie: {file: '" + path("m.mp4") + "'" + quality + "}",
                          160, 96)),
              LANTERN_OK)
        << message();
    run_steps(4);
    ASSERT_EQ(lantern_close(ctx_), LANTERN_OK);
    ctx_ = nullptr;
    const MovieFrames frames = read_movie(path("m.mp4"));
    ASSERT_EQ(frames.error, "");
    EXPECT_EQ(frames.codec, "h264");
    EXPECT_EQ(frames.pixel_format, "yuv420p");
    ASSERT_EQ(frames.rgb.size(), 4u);
    worst.push_back(1e9);
    for (const double psnr : psnr_against_pngs(frames, 4, [&](int s) { return png("m", s); }))
      worst.back() = std::min(worst.back(), psnr);
  }
  EXPECT_GT(worst[2], 28.0);            // 4:2:0's own loss on these frames
  EXPECT_GT(worst[0], worst[2] - 2.0);  // CRF 23 within 2 dB of it (measured 1.0)
  EXPECT_GT(worst[1], worst[0] + 0.5);  // CRF 10 closer (measured 0.9 dB better)
}

TEST_F(MovieTest, AMovieWithoutAPatternReplacesTheImages) {
  ASSERT_EQ(open(config("movie: {file: '" + path("{scene}.mkv") + "', codec: ffv1}")), LANTERN_OK)
      << message();
  run_steps(3);
  ASSERT_EQ(lantern_close(ctx_), LANTERN_OK);
  ctx_ = nullptr;
  EXPECT_EQ(read_movie(path("m.mkv")).rgb.size(), 3u);
  for (const auto &entry : std::filesystem::directory_iterator(dir_))
    EXPECT_NE(entry.path().extension(), ".png") << entry.path();
  // The stats line reports the movie and no image file.
  const std::vector<nlohmann::json> lines = stats_lines();
  ASSERT_EQ(lines.size(), 3u);
  const nlohmann::json &scene = lines.back()["scenes"][0];
  EXPECT_EQ(scene["file"], "");
  EXPECT_EQ(scene["movie"]["file"], path("m.mkv"));
  EXPECT_EQ(scene["movie"]["encoder"], "ffv1");
  EXPECT_EQ(scene["movie"]["dropped"], 0);
  EXPECT_LE(scene["movie"]["frames"].get<int>(), 3);
}

TEST_F(MovieTest, UnwritableMoviePathIsAnIoErrorAtOpen) {
  std::ofstream(dir_ / "file") << "x";
  EXPECT_EQ(open(config(pattern() + ", movie: {file: '" + path("file/m.mp4") + "'}")),
            LANTERN_ERR_IO);
  EXPECT_NE(message().find(path("file")), std::string::npos) << message();
  EXPECT_NE(message().find("scenes 'm'"), std::string::npos) << message();
}

TEST_F(MovieTest, UnknownCodecIsAConfigErrorListingThisBuildsEncoders) {
  EXPECT_EQ(open(config("movie: {file: '" + path("m.mp4") + "', codec: theora}")),
            LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("output.movie.codec: 'theora'"), std::string::npos) << message();
  EXPECT_NE(message().find("h264 (libx264)"), std::string::npos) << message();
  EXPECT_FALSE(std::filesystem::exists(dir_ / "m.mp4"));
}

// The movie outgrows a file-size limit (as on a full disk) while every PNG stays below it: one
// step reports the movie's failure, and every step still writes its image.
TEST_F(MovieTest, AMovieThatFailsMidwayLeavesTheImagesGoing) {
  constexpr int kSteps = 24;
  std::vector<lantern_status> statuses;
  {
    const FileSizeLimit limit(96 * 1024);
    ASSERT_EQ(open(config(pattern() + ", movie: {file: '" + path("m.mkv") +
                              "', codec: ffv1, when_behind: wait}",
                          240, 180)),
              LANTERN_OK)
        << message();
    run_steps(kSteps, &statuses);
    lantern_close(ctx_);
    ctx_ = nullptr;
  }
  int failed = 0;
  for (const lantern_status s : statuses) {
    EXPECT_TRUE(s == LANTERN_OK || s == LANTERN_ERR_IO) << s;
    failed += s == LANTERN_ERR_IO;
  }
  EXPECT_EQ(failed, 1) << "the movie's failure is reported once";
  for (int step = 0; step < kSteps; ++step)
    EXPECT_TRUE(std::filesystem::exists(png("m", step))) << step;
  const std::vector<nlohmann::json> lines = stats_lines();
  ASSERT_EQ(lines.size(), size_t(kSteps));
  EXPECT_TRUE(lines.back()["scenes"][0]["movie"].contains("error")) << lines.back().dump();
  EXPECT_GT(read_movie(path("m.mkv")).rgb.size(), 0u);
}

// A live change may start a new movie (the old one is completed) but not change the codec or
// frame size of the file being written.
TEST_F(MovieTest, ALiveChangeStartsANewMovieButKeepsTheOneBeingWritten) {
  const std::string first = "movie: {file: '" + path("a.mkv") + "', codec: ffv1}";
  ASSERT_EQ(open(config(first)), LANTERN_OK) << message();
  run_steps(2);
  EXPECT_EQ(lantern_reconfigure(ctx_, config(first, 161, 99).c_str()), LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("output.movie"), std::string::npos) << message();
  ASSERT_EQ(
      lantern_reconfigure(
          ctx_, config("movie: {file: '" + path("b.mkv") + "', codec: ffv1}", 161, 99).c_str()),
      LANTERN_OK)
      << message();
  run_steps(3);
  ASSERT_EQ(lantern_close(ctx_), LANTERN_OK);
  ctx_ = nullptr;
  EXPECT_EQ(read_movie(path("a.mkv")).rgb.size(), 2u);
  const MovieFrames b = read_movie(path("b.mkv"));
  EXPECT_EQ(b.rgb.size(), 3u);
  EXPECT_EQ(b.height, 99);
}

#else  // a build without movies

TEST_F(MovieTest, ABuildWithoutMoviesSaysSoAtOpen) {
  EXPECT_EQ(open(config(pattern() + ", movie: {file: '" + path("m.mp4") + "'}")),
            LANTERN_ERR_CONFIG);
  EXPECT_NE(message().find("built without movie support"), std::string::npos) << message();
  EXPECT_NE(message().find("scenes 'm': output.movie"), std::string::npos) << message();
}

#endif

// color.range {auto: first} keeps the first frame's range, {auto: running} widens it, auto
// follows each frame: the stats line says which range each frame used.
TEST_F(MovieTest, RememberedColorRangesFollowTheirMode) {
  for (const auto &[mode, expected] :
       std::vector<std::pair<std::string, std::vector<std::array<double, 2>>>>{
           {"auto", {{0, 1}, {-1, 3}, {0.5, 1}}},
           {"{auto: first}", {{0, 1}, {0, 1}, {0, 1}}},
           {"{auto: running}", {{0, 1}, {-1, 3}, {-1, 3}}}}) {
    SCOPED_TRACE(mode);
    std::filesystem::remove(dir_ / "stats.jsonl");
    ASSERT_EQ(open(config(pattern(), 64, 48, "{by: scalar, range: " + mode + "}")), LANTERN_OK)
        << message();
    const std::vector<std::array<double, 2>> ranges = {{0, 1}, {-1, 3}, {0.5, 1}};
    for (int step = 0; step < 3; ++step) {
      std::vector<double> x = lattice(3);
      std::vector<double> scalar(x.size() / 3);
      for (size_t i = 0; i < scalar.size(); ++i)
        scalar[i] = ranges[step][0] +
                    (ranges[step][1] - ranges[step][0]) * double(i) / double(scalar.size() - 1);
      lantern_particles p = interleaved(x);
      p.scalar = {scalar.data(), LANTERN_FLOAT64, 0};
      ASSERT_EQ(lantern_publish(ctx_, &p), LANTERN_OK);
      ASSERT_EQ(lantern_execute(ctx_, step, 0.0), LANTERN_OK) << message();
    }
    const std::vector<nlohmann::json> lines = stats_lines();
    ASSERT_EQ(lines.size(), 3u);
    for (int step = 0; step < 3; ++step) {
      const nlohmann::json &range = lines[size_t(step)]["scenes"][0]["color_range"];
      EXPECT_EQ(range[0].get<double>(), expected[size_t(step)][0]) << "step " << step;
      EXPECT_EQ(range[1].get<double>(), expected[size_t(step)][1]) << "step " << step;
    }
  }
}

}  // namespace
}  // namespace lantern::testing
