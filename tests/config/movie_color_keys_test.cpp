// The movie keys (output.movie) and the colour keys that keep colours comparable across frames
// (color.range {auto: ...}, colormap names, lists and files, reverse): defaults, given values,
// and bad values rejected naming key, line and what is allowed.
#include <gtest/gtest.h>

#include <unistd.h>

#include <fstream>
#include <string>

#include "core/config/config_loader.h"
#include "tests/support/config_error_expect.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::expect_config_error;

TEST(MovieKeys, OffByDefaultAndImagesOn) {
  Config c;
  ASSERT_OK(load_config("scenes:\n  - name: a\n", &c));
  EXPECT_FALSE(c.scenes[0].output.movie.enabled);
  EXPECT_TRUE(c.scenes[0].output.images);
}

TEST(MovieKeys, AMovieBesideOrInsteadOfThePattern) {
  Config c;
  ASSERT_OK(load_config("scenes:\n  - output: {movie: {file: 'out/{scene}.mp4'}}\n", &c));
  const MovieConfig &m = c.scenes[0].output.movie;
  EXPECT_TRUE(m.enabled);
  EXPECT_FALSE(c.scenes[0].output.images);  // no pattern: the movie replaces the images
  EXPECT_EQ(m.file, "out/{scene}.mp4");
  EXPECT_EQ(m.fps, 24.0);
  EXPECT_EQ(m.codec, "auto");
  EXPECT_FALSE(m.quality);
  EXPECT_FALSE(m.lossless);
  EXPECT_EQ(m.queue, 8);
  EXPECT_EQ(m.when_behind, MovieWhenBehind::kDrop);
  EXPECT_EQ(m.threads, 1);
  ASSERT_OK(load_config(
      "scenes:\n  - output:\n      pattern: 'a_{step}.png'\n      movie: {file: a.webm, fps: 30, "
      "codec: vp9, quality: 40, queue: 3, when_behind: wait, threads: 2}\n",
      &c));
  const MovieConfig &n = c.scenes[0].output.movie;
  EXPECT_TRUE(c.scenes[0].output.images);
  EXPECT_EQ(n.fps, 30.0);
  EXPECT_EQ(n.codec, "vp9");
  EXPECT_EQ(n.quality, 40);
  EXPECT_EQ(n.queue, 3);
  EXPECT_EQ(n.when_behind, MovieWhenBehind::kWait);
  EXPECT_EQ(n.threads, 2);
}

TEST(MovieKeys, BadValuesNameKeyAndLine) {
  expect_config_error("scenes:\n  - output: {movie: {fps: 24}}\n",
                      {"scenes[0].output.movie", "needs 'file'"});
  expect_config_error("scenes:\n  - output: {movie: {file: 'm_{step}.mp4'}}\n",
                      {"scenes[0].output.movie.file", "line 2", "{step} has no place"});
  expect_config_error("scenes:\n  - output: {movie: {file: m.avi}}\n",
                      {"scenes[0].output.movie.file", ".mp4, .mov", ".mkv", ".webm"});
  expect_config_error("scenes:\n  - output: {movie: {file: m.mp4, fps: 0}}\n",
                      {"scenes[0].output.movie.fps"});
  expect_config_error("scenes:\n  - output: {movie: {file: m.mp4, queue: 0}}\n",
                      {"scenes[0].output.movie.queue"});
  expect_config_error("scenes:\n  - output: {movie: {file: m.mp4, when_behind: block}}\n",
                      {"scenes[0].output.movie.when_behind", "drop, wait"});
  expect_config_error("scenes:\n  - output: {movie: {file: m.mp4, lossless: true, quality: 3}}\n",
                      {"scenes[0].output.movie.quality", "lossless"});
  expect_config_error("scenes:\n  - output: {movie: {file: m.mp4, fsp: 3}}\n",
                      {"scenes[0].output.movie.fsp", "did you mean 'fps'?"});
  expect_config_error("scenes:\n  - output: {movie: m.mp4}\n",
                      {"scenes[0].output.movie", "must be a mapping"});
}

TEST(MovieKeys, TwoScenesMayNotWriteOneMovie) {
  expect_config_error(
      "scenes:\n  - name: a\n    output: {movie: {file: m.mp4}}\n"
      "  - name: b\n    output: {movie: {file: m.mp4}}\n",
      {"scenes[1].output.movie.file", "also the movie of scenes[0]", "{scene}"});
  Config c;
  ASSERT_OK(
      load_config("scenes:\n  - name: a\n    output: {movie: {file: '{scene}.mp4'}}\n"
                  "  - name: b\n    output: {movie: {file: '{scene}.mp4'}}\n",
                  &c));
  // Two movie-only scenes share the default pattern without writing images: no clash.
  EXPECT_FALSE(c.scenes[1].output.images);
}

TEST(ColorKeys, RangeModes) {
  Config c;
  ASSERT_OK(load_config("scenes:\n  - color: {range: auto}\n", &c));
  EXPECT_EQ(c.scenes[0].color.auto_range, AutoRange::kFrame);
  ASSERT_OK(load_config("scenes:\n  - color: {range: {auto: first}}\n", &c));
  EXPECT_EQ(c.scenes[0].color.auto_range, AutoRange::kFirst);
  EXPECT_FALSE(c.scenes[0].color.range);
  ASSERT_OK(load_config("scenes:\n  - color: {range: {auto: running}}\n", &c));
  EXPECT_EQ(c.scenes[0].color.auto_range, AutoRange::kRunning);
  expect_config_error("scenes:\n  - color: {range: {auto: last}}\n",
                      {"scenes[0].color.range.auto", "frame, first, running"});
  expect_config_error("scenes:\n  - color: {range: {atuo: first}}\n",
                      {"scenes[0].color.range.atuo", "did you mean 'auto'?"});
}

TEST(ColorKeys, ColormapNamesListsFilesAndReverse) {
  Config c;
  ASSERT_OK(load_config("scenes:\n  - color: {colormap: RdBu, reverse: true}\n", &c));
  EXPECT_EQ(c.scenes[0].color.colormap, "RdBu");
  EXPECT_TRUE(c.scenes[0].color.reverse);
  EXPECT_TRUE(c.scenes[0].color.colormap_colors.empty());
  ASSERT_OK(load_config("scenes:\n  - color: {colormap: [[0, 0, 0], [1, 0.5, 0]]}\n", &c));
  EXPECT_EQ(c.scenes[0].color.colormap, "custom");
  ASSERT_EQ(c.scenes[0].color.colormap_colors.size(), 2u);
  EXPECT_EQ(c.scenes[0].color.colormap_colors[1], (std::array<double, 3>{1, 0.5, 0}));
  const std::string file = ::testing::TempDir() + "lantern_map_" + std::to_string(getpid());
  std::ofstream(file) << "0 0 0\n128 128 255\n255 255 255\n";
  ASSERT_OK(load_config("scenes:\n  - color: {colormap: {file: '" + file + "'}}\n", &c));
  ASSERT_EQ(c.scenes[0].color.colormap_colors.size(), 3u);
  EXPECT_EQ(c.scenes[0].color.colormap_colors[2], (std::array<double, 3>{1, 1, 1}));
  std::ofstream(file) << "0 0 0\n1 1\n";
  expect_config_error("scenes:\n  - color: {colormap: {file: '" + file + "'}}\n",
                      {"scenes[0].color.colormap.file", "line 2", "expected 3 numbers"});
  std::remove(file.c_str());
  expect_config_error("scenes:\n  - color: {colormap: [[0, 0, 0]]}\n",
                      {"scenes[0].color.colormap", "2 to 4096 colors"});
  expect_config_error("scenes:\n  - color: {colormap: [[0, 0, 0], [2, 0, 0]]}\n",
                      {"scenes[0].color.colormap[1][0]", "[0, 1]"});
  expect_config_error("scenes:\n  - color: {colormap: {path: x}}\n",
                      {"scenes[0].color.colormap.path", "did you mean 'file'?"});
  expect_config_error("scenes:\n  - color: {colormap: Rdbu}\n",
                      {"scenes[0].color.colormap", "did you mean 'RdBu'?"});
  expect_config_error("scenes:\n  - color: {reverse: maybe}\n", {"scenes[0].color.reverse"});
}

}  // namespace
}  // namespace lantern
