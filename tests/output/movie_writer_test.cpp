// Movies through FFmpeg's libraries (core/output/movie): frames decoded back equal the frames
// given at the lossless settings and come close at the default ones, odd sizes, the codec and
// container checks, the bounded queue, and a movie that fails midway (a file-size limit).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/output/movie/movie_encoder.h"
#include "core/output/movie/movie_writer.h"
#include "tests/output/scratch_dir.h"
#include "tests/support/file_size_limit.h"
#if LANTERN_TEST_MOVIES
#include "tests/support/movie_file.h"
#endif

namespace lantern {
namespace {

// A w x h RGBA frame: smooth gradients that move with `t`, plus hash noise of `noise` levels (a
// hard case for the codecs; 0 for smooth frames).
Frame test_frame(int w, int h, int t, int noise = 0) {
  Frame f(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint32_t n = uint32_t(x) * 73856093u ^ uint32_t(y) * 19349663u ^ uint32_t(t) * 83492791u;
      n = (n ^ (n >> 13)) * 0x5bd1e995u;
      const int jitter = noise ? int(n % uint32_t(noise)) : 0;
      uint8_t *p = f.rgba.data() + f.index(x, y) * 4;
      p[0] = uint8_t((x * 255 / std::max(1, w - 1) + jitter) & 255);
      p[1] = uint8_t((y * 255 / std::max(1, h - 1) + 7 * t) & 255);
      p[2] = uint8_t((128 + 40 * std::sin(0.2 * (x + y + 3 * t))) + jitter / 2);
      p[3] = 255;
    }
  return f;
}

MovieConfig movie(const std::string &codec, bool lossless = false) {
  MovieConfig m;
  m.enabled = true;
  m.codec = codec;
  m.lossless = lossless;
  return m;
}

TEST(MovieSupport, ThisBuildSaysWhetherItHasMovies) {
  const Status s = check_movie_config(movie("auto"), "out.mp4");
  if (movie_support_built()) {
    EXPECT_TRUE(s.ok()) << s.message;
    EXPECT_NE(movie_codecs_available().find("h264 (libx264)"), std::string::npos)
        << movie_codecs_available();
  } else {
    EXPECT_EQ(s.code, StatusCode::kConfig);
    EXPECT_NE(s.message.find("built without movie support"), std::string::npos) << s.message;
    std::unique_ptr<MovieWriter> writer;
    EXPECT_EQ(MovieWriter::open(movie("auto"), "out.mp4", 8, 8, &writer).code, StatusCode::kConfig);
    EXPECT_FALSE(writer);
  }
}

#if LANTERN_TEST_MOVIES

// Encodes `frames` through a MovieWriter (waiting, so none is dropped) and decodes the file.
testing::MovieFrames round_trip(const MovieConfig &m, const std::string &path,
                                const std::vector<Frame> &frames) {
  MovieConfig config = m;
  config.when_behind = MovieWhenBehind::kWait;
  std::unique_ptr<MovieWriter> writer;
  const Status opened = MovieWriter::open(config, path, frames[0].width, frames[0].height, &writer);
  EXPECT_TRUE(opened.ok()) << opened.message;
  if (!opened.ok()) return {};
  for (const Frame &f : frames) EXPECT_TRUE(writer->submit(f).ok());
  const Status finished = writer->finish();
  EXPECT_TRUE(finished.ok()) << finished.message;
  EXPECT_EQ(writer->progress().written, int64_t(frames.size()));
  return testing::read_movie(path);
}

// Every lossless setting gives back the very bytes, at an odd size (no padding without chroma
// subsampling), in the containers that hold it.
TEST(MovieEncoder, LosslessSettingsGiveBackTheExactFrames) {
  ScratchDir dir;
  std::vector<Frame> frames;
  for (int t = 0; t < 5; ++t) frames.push_back(test_frame(37, 23, t, 40));
  const std::vector<std::pair<MovieConfig, std::string>> cases = {{movie("h264", true), "h264.mp4"},
                                                                  {movie("hevc", true), "hevc.mkv"},
                                                                  {movie("vp9", true), "vp9.webm"},
                                                                  {movie("ffv1"), "ffv1.mkv"}};
  for (const auto &[m, name] : cases) {
    SCOPED_TRACE(name);
    const testing::MovieFrames got = round_trip(m, dir.file(name), frames);
    ASSERT_EQ(got.error, "");
    ASSERT_EQ(got.rgb.size(), frames.size());
    EXPECT_EQ(got.width, 37);
    EXPECT_EQ(got.height, 23);
    for (size_t k = 0; k < frames.size(); ++k) {
      EXPECT_EQ(got.index[k], int64_t(k));
      EXPECT_TRUE(
          std::isinf(testing::movie_psnr(got.rgb[k], got.width, frames[k].rgba.data(), 37, 23, 4)))
          << "frame " << k << " is not exact";
    }
  }
}

// A frame of soft gradients (what 4:2:0 chroma keeps well) around the colour `base`.
Frame soft_frame(int w, int h, int t, std::array<int, 3> base) {
  Frame f(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t *p = f.rgba.data() + f.index(x, y) * 4;
      p[0] = uint8_t(base[0] + x / 2);
      p[1] = uint8_t(base[1] + y / 2 + t);
      p[2] = uint8_t(base[2] + 20 * std::sin(0.1 * (x + y + 3 * t)));
      p[3] = 255;
    }
  return f;
}

// The default (yuv420p) settings: an odd size is padded by one column and row repeating the
// edge, the picture stays close to the frames, and colours come back as they were (the BT.709
// matrix and limited range written and tagged alike: a saturated colour would be off by several
// levels otherwise).
TEST(MovieEncoder, DefaultSettingsPadOddSizesAndStayClose) {
  ScratchDir dir;
  std::vector<Frame> frames;
  for (int t = 0; t < 6; ++t) frames.push_back(soft_frame(65, 33, t, {150, 40, 60}));
  for (const auto &[codec, name] :
       std::vector<std::pair<std::string, std::string>>{{"h264", "a.mp4"}, {"vp9", "b.webm"}}) {
    SCOPED_TRACE(codec);
    const testing::MovieFrames got = round_trip(movie(codec), dir.file(name), frames);
    ASSERT_EQ(got.error, "");
    ASSERT_EQ(got.rgb.size(), frames.size());
    EXPECT_EQ(got.pixel_format, "yuv420p");
    EXPECT_EQ(got.width, 66);
    EXPECT_EQ(got.height, 34);
    for (size_t k = 0; k < frames.size(); ++k)
      EXPECT_GT(testing::movie_psnr(got.rgb[k], got.width, frames[k].rgba.data(), 65, 33, 4), 35.0)
          << "frame " << k;
    // Mean colour error per channel: no drift from a matrix or range mismatch.
    for (int c = 0; c < 3; ++c) {
      double sum = 0.0;
      for (int y = 0; y < 33; ++y)
        for (int x = 0; x < 65; ++x)
          sum += double(got.rgb[0][(size_t(y) * 66 + x) * 3 + c]) -
                 double(frames[0].rgba[(size_t(y) * 65 + x) * 4 + c]);
      EXPECT_LT(std::abs(sum / (65 * 33)), 1.0) << "channel " << c;
    }
    // The padding repeats the last column: it looks like its neighbour.
    const auto &last = got.rgb.back();
    for (int y = 0; y < 33; ++y)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(int(last[(size_t(y) * 66 + 65) * 3 + c]),
                    int(last[(size_t(y) * 66 + 64) * 3 + c]), 12);
  }
}

TEST(MovieEncoder, UnknownCodecListsTheEncodersOfThisBuild) {
  const Status s = check_movie_config(movie("mpeg2"), "x.mp4");
  EXPECT_EQ(s.code, StatusCode::kConfig);
  EXPECT_NE(s.message.find("output.movie.codec: 'mpeg2' is not a codec"), std::string::npos)
      << s.message;
  EXPECT_NE(s.message.find("h264 (libx264)"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("ffv1 (ffv1)"), std::string::npos) << s.message;
}

TEST(MovieEncoder, ContainerAndQualityMismatchesAreConfigErrors) {
  Status s = check_movie_config(movie("ffv1"), "x.mp4");
  EXPECT_EQ(s.code, StatusCode::kConfig);
  EXPECT_NE(s.message.find("use .mkv"), std::string::npos) << s.message;
  MovieConfig q = movie("h264");
  q.quality = 60;
  s = check_movie_config(q, "x.mp4");
  EXPECT_EQ(s.code, StatusCode::kConfig);
  EXPECT_NE(s.message.find("output.movie.quality: 60 is beyond h264's range 0..51"),
            std::string::npos)
      << s.message;
  q.codec = "vp9";
  EXPECT_TRUE(check_movie_config(q, "x.webm").ok());
  s = check_movie_config(movie("av1", true), "x.mkv");
  EXPECT_EQ(s.code, StatusCode::kConfig);
  EXPECT_NE(s.message.find("output.movie.lossless"), std::string::npos) << s.message;
  MovieConfig f = movie("ffv1");
  f.quality = 3;
  EXPECT_EQ(check_movie_config(f, "x.mkv").code, StatusCode::kConfig);
}

TEST(MovieEncoder, UnwritablePathIsAnIoErrorAtOpen) {
  ScratchDir dir;
  std::fclose(std::fopen(dir.file("file").c_str(), "w"));
  std::unique_ptr<MovieEncoder> encoder;
  const std::string path = dir.file("file/movie.mp4");  // its parent is a file
  const Status s = MovieEncoder::open(movie("h264"), path, 16, 16, &encoder);
  EXPECT_EQ(s.code, StatusCode::kIo);
  EXPECT_NE(s.message.find(dir.file("file")), std::string::npos) << s.message;
  EXPECT_FALSE(encoder);
}

// The file is complete after every frame: readable before finish(), with every frame so far.
TEST(MovieEncoder, EveryFrameIsInTheFileBeforeFinish) {
  ScratchDir dir;
  for (const std::string name : {"live.mp4", "live.mkv"}) {
    SCOPED_TRACE(name);
    std::unique_ptr<MovieEncoder> encoder;
    ASSERT_TRUE(MovieEncoder::open(movie("h264"), dir.file(name), 48, 32, &encoder).ok());
    for (int t = 0; t < 4; ++t) {
      const Frame f = test_frame(48, 32, t);
      ASSERT_TRUE(encoder->encode(f.rgba.data(), t).ok());
      EXPECT_EQ(encoder->frames_written(), t + 1);
      const testing::MovieFrames now = testing::read_movie(dir.file(name));
      EXPECT_EQ(now.error, "");
      EXPECT_EQ(now.rgb.size(), size_t(t + 1)) << "after frame " << t;
    }
    EXPECT_TRUE(encoder->finish().ok());
  }
}

// A full queue: with `drop` the step never waits and every frame is either written or counted as
// dropped, dropped frames leaving gaps on the movie's clock; with `wait` none is lost.
TEST(MovieWriter, FullQueueDropsAndCountsOrWaits) {
  ScratchDir dir;
  std::vector<Frame> frames;
  for (int t = 0; t < 3; ++t) frames.push_back(test_frame(640, 360, t, 255));
  for (const MovieWhenBehind when : {MovieWhenBehind::kDrop, MovieWhenBehind::kWait}) {
    MovieConfig m = movie("h264");
    m.queue = 1;
    m.when_behind = when;
    const std::string path = dir.file(when == MovieWhenBehind::kDrop ? "drop.mp4" : "wait.mp4");
    std::unique_ptr<MovieWriter> writer;
    ASSERT_TRUE(MovieWriter::open(m, path, 640, 360, &writer).ok());
    constexpr int kFrames = 40;
    for (int k = 0; k < kFrames; ++k) ASSERT_TRUE(writer->submit(frames[k % 3]).ok());
    ASSERT_TRUE(writer->finish().ok());
    const MovieProgress p = writer->progress();
    EXPECT_EQ(p.submitted, kFrames);
    EXPECT_EQ(p.written + p.dropped, kFrames);
    if (when == MovieWhenBehind::kWait) EXPECT_EQ(p.dropped, 0);
    const testing::MovieFrames got = testing::read_movie(path);
    ASSERT_EQ(got.error, "");
    ASSERT_EQ(int64_t(got.rgb.size()), p.written);
    for (size_t k = 1; k < got.index.size(); ++k) EXPECT_GT(got.index[k], got.index[k - 1]);
    if (!got.index.empty()) EXPECT_LT(got.index.back(), kFrames);
  }
}

// A movie that fails midway (here a file-size limit, as a full disk would): submit() reports the
// error once, then takes frames without complaint; the file keeps the frames written before.
TEST(MovieWriter, AFailedMovieStopsReportsOnceAndKeepsItsFrames) {
  ScratchDir dir;
  const std::string path = dir.file("limited.mkv");
  MovieConfig m = movie("ffv1");
  m.when_behind = MovieWhenBehind::kWait;
  int64_t written = 0;
  {
    const testing::FileSizeLimit limit(200 * 1024);  // noisy 160 x 120 ffv1 frames: ~40 KiB each
    std::unique_ptr<MovieWriter> writer;
    ASSERT_TRUE(MovieWriter::open(m, path, 160, 120, &writer).ok());
    int errors = 0;
    std::string message;
    for (int t = 0; t < 30; ++t) {
      const Status s = writer->submit(test_frame(160, 120, t, 255));
      if (!s.ok()) {
        ++errors;
        message = s.message;
        EXPECT_EQ(s.code, StatusCode::kIo);
      }
    }
    const Status finished = writer->finish();
    EXPECT_EQ(finished.code, StatusCode::kIo);
    EXPECT_EQ(errors, 1) << "the failure is reported once";
    EXPECT_NE(message.find("limited.mkv"), std::string::npos) << message;
    EXPECT_NE(writer->progress().error, "");
    written = writer->progress().written;
    EXPECT_GT(written, 0);
    EXPECT_LT(written, 30);
  }
  const testing::MovieFrames got = testing::read_movie(path);
  EXPECT_GE(int64_t(got.rgb.size()), written - 1);  // the last cluster may be cut short
}

#endif  // LANTERN_TEST_MOVIES

}  // namespace
}  // namespace lantern
