// Overlays through the C API: the box's edges are hidden by a sphere in front of them and drawn
// over a sphere behind them (depth-tested against the composited depth), and the overlay keys'
// errors arrive at lantern_open as configuration errors naming what is at fault.
#include <gtest/gtest.h>

#include <mpi.h>

#include <unistd.h>
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "lantern/lantern.h"
#include "tests/support/image_file.h"
#if LANTERN_TEST_MOVIES
#include "tests/support/movie_file.h"
#endif

namespace lantern::testing {
namespace {

std::string scratch_directory() {
  char path[] = "/tmp/lantern_overlays_XXXXXX";
  return mkdtemp(path) != nullptr ? path : "";
}

struct Opened {
  lantern_status status;
  std::string error;
};

Opened open_only(const std::string &config) {
  lantern_context *ctx = nullptr;
  const lantern_status status = lantern_open(config.c_str(), MPI_Comm_c2f(MPI_COMM_SELF), &ctx);
  Opened o{status, lantern_error_message(ctx)};
  lantern_close(ctx);
  return o;
}

// Two spheres on the line y = 0 seen from +z (orthographic, centred on the origin): a red one at
// z = 3, in front of the box's edges along x at y = 0, z = +-1, and a blue one at (2.5, 0, -3)
// behind them. Renders one step with (or without) the box and returns the image.
ImagePixels render(const std::string &dir, bool box) {
  const std::string file = dir + (box ? "/box.png" : "/plain.png");
  const std::string config =
      "scenes:\n"
      "  - width: 101\n    height: 101\n    background: [1, 1, 1]\n    radius: 1\n"
      "    renderer: cpu\n"
      "    camera: {projection: orthographic, position: [0, 0, 50], look_at: [0, 0, 0], "
      "up: [0, 1, 0], near: 10, far: 90}\n"
      "    color: {by: type, palette: [[1, 0, 0], [0, 0, 1]]}\n"
      "    output: {pattern: '" +
      file + "'}\n" + (box ? "    box: {color: [0, 0, 0], width: 2}\n" : "");
  lantern_context *ctx = nullptr;
  EXPECT_EQ(lantern_open(config.c_str(), MPI_Comm_c2f(MPI_COMM_SELF), &ctx), LANTERN_OK)
      << lantern_error_message(ctx);
  const double low[3] = {-4, 0, -1}, high[3] = {4, 3, 1};
  const int periodic[3] = {0, 0, 0};
  EXPECT_EQ(lantern_set_box(ctx, low, high, periodic), LANTERN_OK);
  std::vector<double> x{0, 2.5}, y{0, 0}, z{3, -3};
  std::vector<int32_t> type{0, 1};
  lantern_particles d{};
  d.count = 2;
  d.position_x = {x.data(), LANTERN_FLOAT64, 0};
  d.position_y = {y.data(), LANTERN_FLOAT64, 0};
  d.position_z = {z.data(), LANTERN_FLOAT64, 0};
  d.type = {type.data(), LANTERN_INT32, 0};
  EXPECT_EQ(lantern_publish(ctx, &d), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx, 0, 0.0), LANTERN_OK) << lantern_error_message(ctx);
  lantern_close(ctx);
  return read_image(file);
}

TEST(BoxOverlay, HiddenBehindASphereInFrontAndDrawnOverOneBehind) {
  const std::string dir = scratch_directory();
  ASSERT_FALSE(dir.empty());
  const ImagePixels plain = render(dir, false), box = render(dir, true);
  ASSERT_EQ(plain.error, "");
  ASSERT_EQ(box.error, "");
  ASSERT_EQ(box.width, 101);
  const int c = plain.channels, row = 50;  // world y = 0 is the centre of row 50
  const auto at = [&](const ImagePixels &img, int x) {
    return &img.pixels[size_t(row * 101 + x) * c];
  };
  // The spheres' spans along the row: red around the centre, blue to its right.
  int red_lo = 101, red_hi = -1, blue_lo = 101, blue_hi = -1;
  for (int x = 0; x < 101; ++x) {
    const uint8_t *p = at(plain, x);
    if (p[0] > 100 && p[2] < 50) red_lo = std::min(red_lo, x), red_hi = std::max(red_hi, x);
    if (p[2] > 100 && p[0] < 50) blue_lo = std::min(blue_lo, x), blue_hi = std::max(blue_hi, x);
  }
  ASSERT_LE(red_lo, 50);
  ASSERT_GE(red_hi, 50);
  ASSERT_GT(blue_lo, red_hi);
  int hidden_same = 0, over_blue_dark = 0, over_background_dark = 0;
  for (int x = red_lo + 1; x < red_hi; ++x)
    hidden_same += std::equal(at(plain, x), at(plain, x) + c, at(box, x));
  for (int x = blue_lo + 2; x < blue_hi - 1; ++x) over_blue_dark += at(box, x)[2] < 60;
  for (int x = 5; x < red_lo - 3; ++x) over_background_dark += at(box, x)[0] < 60;
  EXPECT_EQ(hidden_same, red_hi - red_lo - 1) << "the red sphere in front hides the edge";
  EXPECT_EQ(over_blue_dark, blue_hi - blue_lo - 3) << "the edge is drawn over the blue sphere";
  EXPECT_GT(over_background_dark, 10) << "the edge is drawn over the background";
  std::system(("rm -rf '" + dir + "'").c_str());
}

#if LANTERN_TEST_MOVIES && LANTERN_TEST_TEXT
// The movie encodes the finished image: its lossless frames are the PNGs, overlays included (a
// label whose step changes, and a legend whose running range grows).
TEST(Overlays, AppearInTheMovie) {
  const std::string dir = scratch_directory();
  ASSERT_FALSE(dir.empty());
  const std::string config =
      "scenes:\n  - name: m\n    width: 96\n    height: 80\n    radius: 0.6\n"
      "    color: {by: scalar, range: {auto: running}}\n"
      "    labels: [{text: 'step {step}', size: 12}]\n"
      "    legend: {font_size: 9, length: 40, width: 6}\n    box: {}\n"
      "    output: {pattern: '" +
      dir + "/m_{step}.png', movie: {file: '" + dir + "/m.mkv', codec: ffv1, when_behind: wait}}\n";
  lantern_context *ctx = nullptr;
  ASSERT_EQ(lantern_open(config.c_str(), MPI_Comm_c2f(MPI_COMM_SELF), &ctx), LANTERN_OK)
      << lantern_error_message(ctx);
  std::vector<double> x, y, z, scalar;
  for (int i = 0; i < 27; ++i) x.push_back(i % 3), y.push_back(i / 3 % 3), z.push_back(i / 9);
  for (int step = 0; step < 3; ++step) {
    scalar.clear();
    for (int i = 0; i < 27; ++i) scalar.push_back(i * (1.0 + step));
    lantern_particles d{};
    d.count = 27;
    d.position_x = {x.data(), LANTERN_FLOAT64, 0};
    d.position_y = {y.data(), LANTERN_FLOAT64, 0};
    d.position_z = {z.data(), LANTERN_FLOAT64, 0};
    d.scalar = {scalar.data(), LANTERN_FLOAT64, 0};
    ASSERT_EQ(lantern_publish(ctx, &d), LANTERN_OK);
    ASSERT_EQ(lantern_execute(ctx, step, 0.5 * step), LANTERN_OK) << lantern_error_message(ctx);
  }
  ASSERT_EQ(lantern_close(ctx), LANTERN_OK);
  const MovieFrames movie = read_movie(dir + "/m.mkv");
  ASSERT_EQ(movie.error, "");
  ASSERT_EQ(movie.rgb.size(), 3u);
  std::vector<uint8_t> previous;
  for (int step = 0; step < 3; ++step) {
    const ImagePixels png = read_image(dir + "/m_" + std::to_string(step) + ".png");
    ASSERT_EQ(png.error, "");
    std::vector<uint8_t> rgb;
    for (size_t i = 0; i < png.pixels.size(); i += size_t(png.channels))
      rgb.insert(rgb.end(), png.pixels.begin() + long(i), png.pixels.begin() + long(i) + 3);
    EXPECT_TRUE(movie.rgb[size_t(step)] == rgb) << "movie frame " << step << " is not the PNG";
    EXPECT_NE(rgb, previous) << "the label and legend change with the step";
    previous = rgb;
  }
  std::system(("rm -rf '" + dir + "'").c_str());
}
#endif

TEST(OverlayKeys, ErrorsAtOpenNameTheKeyOrTheFont) {
  const std::string head = "scenes:\n  - output: {pattern: '/tmp/lantern_overlays_unused.png'}\n";
  Opened o = open_only(head + "    labels: [{text: 'T = {temp}'}]\n");
  EXPECT_EQ(o.status, LANTERN_ERR_CONFIG);
  EXPECT_NE(o.error.find("{temp}"), std::string::npos) << o.error;
  o = open_only(head + "    color: {by: solid}\n    legend: {}\n");
  EXPECT_EQ(o.status, LANTERN_ERR_CONFIG);
  EXPECT_NE(o.error.find("legend"), std::string::npos) << o.error;
  o = open_only(head + "    color: {by: type}\n    legend: {}\n");
  EXPECT_EQ(o.status, LANTERN_ERR_CONFIG);
  EXPECT_NE(o.error.find("type_names"), std::string::npos) << o.error;
  o = open_only(head + "    labels: [{text: 'x'}]\n    font: /nonexistent/Lantern.ttf\n");
  EXPECT_EQ(o.status, LANTERN_ERR_CONFIG);
#if LANTERN_TEST_TEXT
  EXPECT_NE(o.error.find("/nonexistent/Lantern.ttf"), std::string::npos) << o.error;
  o = open_only(head + "    labels: [{text: 'x'}]\n    font: No Such Family Zzyzx\n");
  EXPECT_EQ(o.status, LANTERN_ERR_CONFIG);
  EXPECT_NE(o.error.find("No Such Family Zzyzx"), std::string::npos) << o.error;
  EXPECT_EQ(open_only(head + "    labels: [{text: 'step {step}'}]\n").status, LANTERN_OK);
#else
  // A build without text refuses every text overlay, saying why.
  EXPECT_NE(o.error.find("LANTERN_WITH_TEXT"), std::string::npos) << o.error;
  o = open_only(head + "    axes: {}\n");
  EXPECT_EQ(o.status, LANTERN_ERR_CONFIG);
  EXPECT_NE(o.error.find("LANTERN_WITH_TEXT"), std::string::npos) << o.error;
#endif
  // The box needs no text, in any build.
  EXPECT_EQ(open_only(head + "    box: {}\n").status, LANTERN_OK);
}

}  // namespace
}  // namespace lantern::testing
