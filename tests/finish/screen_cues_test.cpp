// The screen-space cues (core/finish/screen_cues.h) on analytic frames: spheres seen by an
// orthographic camera, drawn here with exact window depth, then cued through the collective
// apply_screen_cues on every rank of MPI_COMM_WORLD (run at 1, 2, 3, 4 and 8 ranks).
#include <gtest/gtest.h>

#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "core/camera/camera.h"
#include "core/finish/depth_cue.h"
#include "core/finish/outline.h"
#include "core/finish/screen_ambient_occlusion.h"
#include "core/finish/screen_cues.h"
#include "core/finish/view_positions.h"
#include "tests/support/mpi_world.h"
#include "tests/support/orthographic_camera.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {
namespace {

constexpr int kWidth = 120, kHeight = 80;
constexpr uint8_t kBg[4] = {250, 240, 230, 255};

// Orthographic, looking down -z from (0, 0, 50), near 10, far 90: a sphere at world z = w is at
// distance 50 - w from the eye.
Camera test_camera() {
  return orthographic_down_z(6.0, 1.0, kWidth, kHeight);
}

// View-space x, y of a pixel centre (independent of core/finish/view_positions.cpp).
glm::dvec2 pixel_to_view(const Camera &camera, int x, int y) {
  const glm::dmat4 inverse = glm::inverse(camera.projection);
  const glm::dvec4 v = inverse * glm::dvec4(2.0 * (x + 0.5) / kWidth - 1.0,
                                            1.0 - 2.0 * (y + 0.5) / kHeight, 0.0, 1.0);
  return {v.x / v.w, v.y / v.w};
}

struct Ball {
  double x, y, distance, radius;
  uint8_t gray;
};

// Flat-coloured spheres with exact depth: per pixel the nearest hit.
Frame draw(const Camera &camera, const std::vector<Ball> &balls) {
  Frame f(kWidth, kHeight);
  f.clear(kBg);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const glm::dvec2 p = pixel_to_view(camera, x, y);
      for (const Ball &b : balls) {
        const double rho2 = (p.x - b.x) * (p.x - b.x) + (p.y - b.y) * (p.y - b.y);
        if (rho2 >= b.radius * b.radius) continue;
        const double z = b.distance - std::sqrt(b.radius * b.radius - rho2);
        const float d = float((z - camera.near_plane) / (camera.far_plane - camera.near_plane));
        const size_t i = f.index(x, y);
        if (d >= f.depth[i]) continue;
        f.depth[i] = d;
        std::fill(&f.rgba[4 * i], &f.rgba[4 * i + 3], b.gray);
      }
    }
  return f;
}

// The pixel nearest to view-space (vx, vy).
std::pair<int, int> pixel_at(const Camera &camera, double vx, double vy) {
  const glm::dvec4 c = camera.projection * glm::dvec4(vx, vy, -50.0, 1.0);
  return {int(std::floor((c.x / c.w + 1.0) * 0.5 * kWidth)),
          int(std::floor((1.0 - c.y / c.w) * 0.5 * kHeight))};
}

// Cues `frame` on every rank of the world (the frame matters on rank 0 only) and returns rank 0's.
Frame cued(const ScreenCueSettings &cues, const Camera &camera, double radius, Frame frame) {
  EXPECT_OK(apply_screen_cues(MPI_COMM_WORLD, 0, cues, kWidth, kHeight, camera, radius, &frame));
  return frame;
}

// A camera on the cube [-6, 6]^3 for a width x height image, and a band of that image: `rows`
// rows from image row `first`, owning `owned`, its pixels zero.
Camera cube_camera(const CameraConfig &c, int width, int height) {
  Camera camera;
  EXPECT_OK(make_camera(c, glm::dvec3(-6), glm::dvec3(6), 1.0, width, height, &camera));
  return camera;
}
BandFrame blank_band(int width, int rows, int first, RowBand owned) {
  BandFrame band;
  band.first = first;
  band.owned = owned;
  band.frame = Frame(width, rows);
  return band;
}

// No cue on, the frames' background.
ScreenCueSettings no_cues() {
  ScreenCueSettings s;
  s.background = {kBg[0] / 255.0, kBg[1] / 255.0, kBg[2] / 255.0};
  return s;
}

TEST(ViewPositions, DistancesFourAtATimeAreTheOneAtATimeDistances) {
  // Window depths across [0, 1] (and the background, alone and in runs, and the values next to
  // it, a NaN and odd widths that leave a tail): the distances of the vector build (AVX2 where the
  // processor has it) and of the one-at-a-time build, bit for bit, perspective and orthographic.
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const bool orthographic : {false, true}) {
    CameraConfig c;
    if (orthographic) c.projection = Projection::kOrthographic;
    for (const int width : {1, 3, 64, 333}) {
      const Camera camera = cube_camera(c, width, 50);
      BandFrame band = blank_band(width, 50, 7, {7, 57});
      for (size_t i = 0; i < band.frame.depth.size(); ++i) {
        float d = u(rng);
        if (i % 7 == 0) d = std::pow(d, 0.01f);  // near 1: the far plane
        if (i % 11 == 0) d = kBackgroundDepth;
        if (i % 13 == 0) d = std::nextafter(kBackgroundDepth, 0.0f);
        if (i % 17 == 0) d = 0.0f;
        if ((i / 40) % 5 == 2) d = kBackgroundDepth;  // runs of background (skipped four at once)
        if (i % 101 == 5) d = std::nanf("");          // some inside those runs
        band.frame.depth[i] = d;
      }
      ViewPositions vector, single;
      vector.build(band, camera, true);
      single.build(band, camera, false);
      for (int y = 7; y < 57; ++y)
        for (int x = 0; x < width; ++x) {
          const float a = vector.z(x, y), b = single.z(x, y);
          ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0)
              << "pixel " << x << ", " << y << " of width " << width << ": " << a << " against "
              << b << " (depth " << band.frame.depth[size_t(y - 7) * size_t(width) + size_t(x)]
              << ")";
        }
      // The nearest and (negated) farthest drawn distance of the rows, eight at a time and one
      // at a time: of all rows, of some, of one and of none.
      for (const RowBand rows : {RowBand{7, 57}, RowBand{20, 31}, RowBand{56, 57}, RowBand{9, 9}}) {
        const std::array<float, 2> a = vector.drawn_minima(rows, true),
                                   b = single.drawn_minima(rows, false);
        EXPECT_EQ(std::memcmp(a.data(), b.data(), sizeof a), 0)
            << "rows " << rows.y0 << "-" << rows.y1 << " of width " << width << ": " << a[0] << ", "
            << a[1] << " against " << b[0] << ", " << b[1];
        if (rows.rows() == 0) EXPECT_EQ(a[0], ViewPositions::kBackground);
      }
    }
  }
}

// Readers may reach kBorder pixels beyond the columns and the held rows without testing bounds
// (the screen AO's samples): what they read there is the background, whatever the band holds,
// also from one object built again and again (its border kept while the size stays, written
// again when it changes).
TEST(ViewPositions, TheBorderAroundTheHeldRowsIsBackground) {
  ViewPositions v;
  float depth = 0.3f;  // up to 0.9 over the 12 builds
  for (const bool orthographic : {false, true}) {
    CameraConfig c;
    if (orthographic) c.projection = Projection::kOrthographic;
    for (const int width : {1, 5, 64}) {
      const Camera camera = cube_camera(c, width, 50);
      BandFrame band = blank_band(width, 50, 7, {7, 20});
      for (const bool vector : {true, false}) {
        depth += 0.05f;  // every pixel drawn, at another depth than in the last build
        std::fill(band.frame.depth.begin(), band.frame.depth.end(), depth);
        v.build(band, camera, vector);
        const int k = ViewPositions::kBorder, first = v.first_row(), last = v.last_row();
        int border = 0;
        for (int y = first - k; y < last + k; ++y)
          for (int x = -k; x < width + k; ++x) {
            const bool held = y >= first && y < last && x >= 0 && x < width;
            if (held) {
              ASSERT_EQ(v.z(x, y), float(camera.window_depth_to_distance(depth))) << x << ", " << y;
            } else {
              ASSERT_EQ(v.z(x, y), ViewPositions::kBackground) << x << ", " << y;
              ++border;
            }
          }
        EXPECT_EQ(border, (last - first + 2 * k) * (width + 2 * k) - (last - first) * width);
      }
    }
  }
}

TEST(ViewPositions, DrawnMinimaOfABackgroundAreTheBackground) {
  const Camera camera = test_camera();
  BandFrame band;
  band.owned = {0, camera.height};
  band.frame = Frame(camera.width, camera.height);
  std::fill(band.frame.depth.begin(), band.frame.depth.end(), kBackgroundDepth);
  ViewPositions positions;
  positions.build(band, camera);
  for (const bool vector : {true, false}) {
    const std::array<float, 2> m = positions.drawn_minima(band.owned, vector);
    EXPECT_EQ(m[0], ViewPositions::kBackground);
    EXPECT_EQ(m[1], ViewPositions::kBackground);
  }
  // One drawn pixel: both minima are its distance (negated for the farthest).
  band.frame.depth[size_t(camera.width) * 3 + 17] = 0.5f;
  positions.build(band, camera);
  for (const bool vector : {true, false}) {
    const std::array<float, 2> m = positions.drawn_minima(band.owned, vector);
    EXPECT_EQ(m[0], positions.z(17, 3));
    EXPECT_EQ(m[1], -positions.z(17, 3));
  }
}

TEST(ScreenCues, NoCueLeavesTheFrameAlone) {
  const Camera camera = test_camera();
  const Frame before = draw(camera, {{0, 0, 50, 3, 180}});
  const Frame after = cued(no_cues(), camera, 3, before);
  EXPECT_FALSE(wants_screen_cues(no_cues()));
  if (world_rank() == 0) EXPECT_EQ(after.rgba, before.rgba);
}

// Two touching spheres: the crease between them darkens, their outer halves do not change; at
// half and at full resolution.
class ScreenAoResolution : public ::testing::TestWithParam<AoResolution> {};

TEST_P(ScreenAoResolution, AmbientOcclusionDarkensTheCreaseAndNotTheFarSide) {
  const Camera camera = test_camera();
  const double r = 3.0;
  const Frame before = draw(camera, {{-r, 0, 50, r, 200}, {r, 0, 50, r, 200}});
  ScreenCueSettings scene = no_cues();
  scene.ambient_occlusion.enabled = true;
  scene.ambient_occlusion.radius = 2.0 * r;
  scene.ambient_occlusion.strength = 1.0;
  scene.ambient_occlusion.resolution = GetParam();
  const Frame after = cued(scene, camera, r, before);
  if (world_rank() != 0) return;
  // The crease: pixels within 0.2 r of the contact point, drawn in both images.
  double crease_before = 0, crease_after = 0;
  int crease = 0, far_side = 0, far_changed = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const size_t i = before.index(x, y);
      const glm::dvec2 p = pixel_to_view(camera, x, y);
      if (before.depth[i] == kBackgroundDepth) {
        EXPECT_EQ(after.rgba[4 * i], before.rgba[4 * i]) << "background " << x << "," << y;
        continue;
      }
      if (std::hypot(p.x, p.y) < 0.2 * r) {
        ++crease;
        crease_before += before.rgba[4 * i];
        crease_after += after.rgba[4 * i];
      }
      // Outer halves, away from the silhouette (whose depth-derived normals are poorest).
      for (const double cx : {-r, r}) {
        const double dx = p.x - cx, rho = std::hypot(dx, p.y);
        if (dx * cx > 0.3 * r * r && rho < 0.85 * r) {
          ++far_side;
          if (after.rgba[4 * i] != before.rgba[4 * i]) ++far_changed;
        }
      }
    }
  ASSERT_GT(crease, 4);
  ASSERT_GT(far_side, 50);
  EXPECT_LT(crease_after / crease, crease_before / crease - 20.0) << "the crease is not darker";
  EXPECT_EQ(far_changed, 0) << "of " << far_side << " pixels on the far sides";
}

INSTANTIATE_TEST_SUITE_P(HalfAndFull, ScreenAoResolution,
                         ::testing::Values(AoResolution::kHalf, AoResolution::kFull));

// A crowd of spheres of a few pixels to tens of pixels at different depths: silhouettes,
// creases and slivers of surface narrower than two pixels.
Frame crowd(const Camera &camera) {
  std::vector<Ball> balls;
  for (int k = 0; k < 90; ++k)
    balls.push_back({-15.0 + 0.33 * k, 7.0 * std::sin(0.9 * k), 45.0 + 4.0 * std::cos(1.3 * k),
                     0.3 + 0.2 * (k % 9), uint8_t(60 + 2 * k)});
  return draw(camera, balls);
}

// Touching spheres of 40 pixels in a grid: creases everywhere, whose occlusion comes from
// samples up to kMaxAoPixels away.
Frame creases(const Camera &camera) {
  std::vector<Ball> balls;
  for (int row = -2; row <= 2; ++row)
    for (int column = -3; column <= 3; ++column)
      balls.push_back({4.2 * column + 1.1 * row, 3.9 * row, 50.0 + 0.3 * column, 2.4,
                       uint8_t(255 - 5 * (row + 3 * column + 20))});
  return draw(camera, balls);
}

// The owned rows of `band` (rows [y0, y1) of `whole`, with `halo` rows each side) after ambient
// occlusion, as one band would get them.
// Rows [y0, y1) of `whole` with `halo` rows each side, as a band holds them.
BandFrame band_of(const Frame &whole, int y0, int y1, int halo) {
  const int first = std::max(0, y0 - halo), last = std::min(whole.height, y1 + halo);
  BandFrame band;
  band.first = first;
  band.owned = {y0, y1};
  band.frame = Frame(whole.width, last - first);
  const size_t offset = size_t(first) * size_t(whole.width);
  std::copy(whole.rgba.begin() + 4 * offset,
            whole.rgba.begin() + 4 * (offset + band.frame.pixel_count()), band.frame.rgba.begin());
  std::copy(whole.depth.begin() + offset, whole.depth.begin() + offset + band.frame.pixel_count(),
            band.frame.depth.begin());
  return band;
}

std::vector<uint8_t> occluded_band(const Frame &whole, const Camera &camera, int y0, int y1,
                                   int halo, const AmbientOcclusionStyle &style,
                                   AoVectorPath path = AoVectorPath::kAuto,
                                   AoScratch *scratch = nullptr, int threads = 1) {
  const int first = std::max(0, y0 - halo);
  BandFrame band = band_of(whole, y0, y1, halo);
  ViewPositions positions;
  positions.build(band, camera);
  apply_screen_ambient_occlusion(positions, style, &band, path, scratch, threads);
  const size_t row = size_t(whole.width) * 4;
  return {band.frame.rgba.begin() + ptrdiff_t(size_t(y0 - first) * row),
          band.frame.rgba.begin() + ptrdiff_t(size_t(y1 - first) * row)};
}

// Every band of rows, whatever its boundaries (odd or even, one row or many), gets from its halo
// of screen_ambient_occlusion_halo() rows exactly the bytes the whole image gives those rows.
TEST(ScreenAmbientOcclusion, EveryBandWithItsHaloGivesTheWholeImagesBytes) {
  if (world_rank() != 0) return;
  const Camera camera = test_camera();
  for (const Frame &frame : {crowd(camera), creases(camera)})
    for (const bool half : {true, false}) {
      AmbientOcclusionStyle style;
      style.radius = 10.0f;  // 33 pixels at this camera: samples reach kMaxAoPixels
      style.strength = 1.0f;
      style.half_resolution = half;
      const int halo = screen_ambient_occlusion_halo(style);
      const std::vector<uint8_t> whole = occluded_band(frame, camera, 0, kHeight, 0, style);
      ASSERT_NE(whole, std::vector<uint8_t>(frame.rgba.begin(), frame.rgba.end()));
      for (const auto &[y0, y1] : std::vector<std::pair<int, int>>{{0, 1},
                                                                   {0, 2},
                                                                   {1, 2},
                                                                   {1, 4},
                                                                   {2, 3},
                                                                   {7, 8},
                                                                   {7, 30},
                                                                   {8, 31},
                                                                   {30, 31},
                                                                   {31, 33},
                                                                   {39, 41},
                                                                   {40, 80},
                                                                   {41, 80},
                                                                   {50, 79},
                                                                   {79, 80},
                                                                   {0, 40},
                                                                   {0, 41}}) {
        const std::vector<uint8_t> band = occluded_band(frame, camera, y0, y1, halo, style);
        const size_t row = size_t(kWidth) * 4;
        EXPECT_TRUE(std::equal(band.begin(), band.end(), whole.begin() + ptrdiff_t(y0 * row)))
            << (half ? "half" : "full") << " resolution, rows " << y0 << ".." << y1;
      }
    }
}

// Buffers kept from an earlier call hold that call's estimates; the next call must read none of
// them: here they are filled with estimates at the scene's depths (distances 41-59) before every
// band, and each band must still get the bytes of buffers of its own. The crowd stands before a
// wall that fills the image to its edges (where the grids' padding and the rows beyond the image
// meet drawn pixels).
TEST(ScreenAmbientOcclusion, KeptBuffersGiveTheBytesOfFreshOnes) {
  if (world_rank() != 0) return;
  const Camera camera = test_camera();
  std::vector<Ball> balls = {{0.0, 0.0, 150.0, 100.0, 180}};
  for (int k = 0; k < 90; ++k)
    balls.push_back({-15.0 + 0.33 * k, 7.0 * std::sin(0.9 * k), 45.0 + 4.0 * std::cos(1.3 * k),
                     0.3 + 0.2 * (k % 9), uint8_t(60 + 2 * k)});
  const Frame frame = draw(camera, balls);
  ASSERT_EQ(std::count(frame.depth.begin(), frame.depth.end(), 1.0f), 0);  // drawn everywhere
  AmbientOcclusionStyle style;
  style.radius = 10.0f;
  style.strength = 1.0f;
  const int halo = screen_ambient_occlusion_halo(style);
  AoScratch kept;
  int compared = 0;
  for (const auto &[y0, y1] :
       std::vector<std::pair<int, int>>{{0, 80}, {0, 1}, {1, 4}, {7, 30}, {40, 80}, {79, 80}}) {
    for (std::vector<float> *v : {&kept.raw_value, &kept.across_value, &kept.blurred_value})
      v->assign(size_t(4) * kWidth * kHeight, 1000.0f);
    for (std::vector<float> *z : {&kept.raw_z, &kept.across_z, &kept.blurred_z}) {
      z->resize(size_t(4) * kWidth * kHeight);
      for (size_t i = 0; i < z->size(); ++i) (*z)[i] = 41.0f + float(i % 19);
    }
    const std::vector<uint8_t> fresh = occluded_band(frame, camera, y0, y1, halo, style);
    for (const AoVectorPath path : {AoVectorPath::kAuto, AoVectorPath::kAvx512,
                                    AoVectorPath::kAvx2Gather, AoVectorPath::kPortable})
      EXPECT_EQ(occluded_band(frame, camera, y0, y1, halo, style, path, &kept), fresh)
          << "rows " << y0 << ".." << y1;
    ++compared;
  }
  EXPECT_EQ(compared, 6);
}

// Full strength, with a radius that reaches kMaxAoPixels at half resolution (a third of it at
// full resolution, which costs more a pixel); and the bands those tests cut the image into: whole,
// odd and even boundaries, one row.
AmbientOcclusionStyle full_strength(bool half) {
  AmbientOcclusionStyle style;
  style.radius = half ? 10.0f : 3.0f;
  style.strength = 1.0f;
  style.half_resolution = half;
  return style;
}
const std::vector<std::pair<int, int>> kCutBands = {{0, kHeight}, {7, 61}, {1, 80}, {40, 41}};

// `threads:` cuts a band's rows into parts that run at once: every count gives the one-thread
// bytes, at both resolutions, on every instruction set, for whole images and for bands (whose
// estimate rows start at odd and even rows), with kept buffers too.
TEST(ScreenAmbientOcclusion, EveryThreadCountGivesTheOneThreadBytes) {
  if (world_rank() != 0) return;
  const Camera camera = test_camera();
  int compared = 0;
  for (const Frame &frame : {crowd(camera), creases(camera)})
    for (const bool half : {true, false}) {
      const AmbientOcclusionStyle style = full_strength(half);
      const int halo = screen_ambient_occlusion_halo(style);
      for (const auto &[y0, y1] : kCutBands) {
        const std::vector<uint8_t> one = occluded_band(frame, camera, y0, y1, halo, style);
        ASSERT_NE(one, std::vector<uint8_t>(frame.rgba.begin() + 4 * y0 * kWidth,
                                            frame.rgba.begin() + 4 * y1 * kWidth));
        for (const AoVectorPath path : {AoVectorPath::kAuto, AoVectorPath::kPortable}) {
          AoScratch kept;
          for (const int threads : {2, 3, 4, 7, 64}) {
            EXPECT_EQ(occluded_band(frame, camera, y0, y1, halo, style, path, &kept, threads), one)
                << (half ? "half" : "full") << " resolution, rows " << y0 << ".." << y1 << ", path "
                << int(path) << ", " << threads << " threads";
            ++compared;
          }
        }
      }
    }
  EXPECT_EQ(compared, 2 * 2 * 4 * 2 * 5);
}

// Rows wider than 2^15 - 64 pixels: the estimates' row offsets no longer fit the 16-bit multiply
// the vector paths use, and they multiply in 32 bits as the baseline does; the same bytes. A
// 33000 x 48 band of bumps (ridges of spheres seen from above, with gaps of background).
TEST(ScreenAmbientOcclusion, RowsWiderThanSixteenBitsGiveTheBaselineBytes) {
  if (world_rank() != 0) return;
  constexpr int kWide = 33000, kRows = 48;
  const Camera camera = orthographic_down_z(2.0, 0.1, kWide, kRows);  // about 20 pixels a unit
  Frame frame(kWide, kRows);
  frame.clear(kBg);
  for (int y = 0; y < kRows; ++y)
    for (int x = 0; x < kWide; ++x) {
      const double u = std::fmod(x, 23.0) - 11.0, v = std::fmod(y, 17.0) - 8.0;
      const double rho2 = (u * u + v * v) / 121.0;
      if (rho2 >= 1.0) continue;
      const size_t i = frame.index(x, y);
      frame.depth[i] = float(0.5 - 0.05 * std::sqrt(1.0 - rho2) + 1e-6 * (x % 7));
      std::fill(&frame.rgba[4 * i], &frame.rgba[4 * i + 3], uint8_t(200));
    }
  AmbientOcclusionStyle style;
  style.radius = 0.5f;
  style.strength = 1.0f;
  BandFrame portable = band_of(frame, 0, kRows, 0);
  ViewPositions positions;
  positions.build(portable, camera);
  ASSERT_GE(positions.stride(), size_t(1) << 15);
  apply_screen_ambient_occlusion(positions, style, &portable, AoVectorPath::kPortable);
  ASSERT_NE(portable.frame.rgba, frame.rgba);  // something darkened
  for (const AoVectorPath path : {AoVectorPath::kAuto, AoVectorPath::kAvx512,
                                  AoVectorPath::kAvx2Gather, AoVectorPath::kAvx2}) {
    BandFrame band = band_of(frame, 0, kRows, 0);
    apply_screen_ambient_occlusion(positions, style, &band, path);
    EXPECT_EQ(band.frame.rgba, portable.frame.rgba) << "path " << int(path);
  }
}

// Building the distances as the pass goes (row by row on one thread, all first on several) gives
// the bytes and the distances of building them all before the pass: orthographic and perspective,
// both resolutions, whole images and bands, every instruction set, with kept buffers and kept
// positions that hold another frame's distances (which a row read before it is built would show).
TEST(ScreenAmbientOcclusion, BuildingThePositionsAsItGoesGivesTheBytesOfBuildingThemFirst) {
  if (world_rank() != 0) return;
  CameraConfig perspective;
  perspective.azimuth = 20.0;
  int compared = 0;
  ViewPositions kept_positions;
  AoScratch kept;
  for (const Camera &camera : {test_camera(), cube_camera(perspective, kWidth, kHeight)})
    for (const Frame &frame : {crowd(test_camera()), creases(test_camera())})
      for (const bool half : {true, false}) {
        const AmbientOcclusionStyle style = full_strength(half);
        const int halo = screen_ambient_occlusion_halo(style);
        for (const auto &[y0, y1] : kCutBands) {
          BandFrame first = band_of(frame, y0, y1, halo);
          ViewPositions built;
          built.build(first, camera);
          apply_screen_ambient_occlusion(built, style, &first);
          for (const AoVectorPath path : {AoVectorPath::kAuto, AoVectorPath::kPortable})
            for (const int threads : {1, 2, 64}) {
              BandFrame going = band_of(frame, y0, y1, halo);
              build_positions_and_apply_screen_ambient_occlusion(&kept_positions, camera, style,
                                                                 &going, path, &kept, threads);
              const std::string where = std::string(half ? "half" : "full") + " resolution, rows " +
                                        std::to_string(y0) + ".." + std::to_string(y1) + ", path " +
                                        std::to_string(int(path)) + ", " + std::to_string(threads) +
                                        " threads";
              EXPECT_EQ(going.frame.rgba, first.frame.rgba) << where;
              ASSERT_EQ(kept_positions.first_row(), built.first_row());
              ASSERT_EQ(kept_positions.last_row(), built.last_row());
              // Every held row and the border around them (kBorder each side).
              for (int y = built.first_row() - ViewPositions::kBorder;
                   y < built.last_row() + ViewPositions::kBorder; ++y)
                ASSERT_TRUE(std::equal(built.row(y) - ViewPositions::kBorder,
                                       built.row(y) + kWidth + ViewPositions::kBorder,
                                       kept_positions.row(y) - ViewPositions::kBorder))
                    << where << ", distances of row " << y;
              ++compared;
            }
        }
      }
  EXPECT_EQ(compared, 2 * 2 * 2 * 4 * 2 * 3);
}

// The half-resolution pass gives the same bits on every instruction set.
// Many white crowds at full strength, so that a last-bit difference of an estimate (a fused
// multiply-add where the baseline rounds twice, say) shows in the 8-bit colour somewhere.
TEST(ScreenAmbientOcclusion, HalfResolutionGivesTheSameBitsOnEveryInstructionSet) {
  if (world_rank() != 0) return;
  const Camera camera = test_camera();
  AmbientOcclusionStyle style;
  style.strength = 1.0f;
  int compared = 0;
  for (int seed = 0; seed < 40; ++seed) {
    std::vector<Ball> balls;
    for (int k = 0; k < 120; ++k)
      balls.push_back({-16.0 + 0.27 * k + 0.1 * seed, 7.5 * std::sin(0.9 * k + seed),
                       45.0 + 4.0 * std::cos(1.3 * k + 0.7 * seed), 0.4 + 0.25 * ((k + seed) % 9),
                       255});
    const Frame frame = draw(camera, balls);
    style.radius = 1.5f + 0.1f * float(seed % 10);
    const std::vector<uint8_t> automatic = occluded_band(frame, camera, 0, kHeight, 0, style);
    for (const AoVectorPath path : {AoVectorPath::kAvx512, AoVectorPath::kAvx2Gather,
                                    AoVectorPath::kAvx2, AoVectorPath::kPortable})
      ASSERT_EQ(occluded_band(frame, camera, 0, kHeight, 0, style, path), automatic)
          << "seed " << seed << ", path " << int(path);
    ++compared;
  }
  EXPECT_EQ(compared, 40);
}

// Half resolution against full resolution on the crowd at full strength: at least 35 dB (PSNR
// over the drawn pixels), and closer to it than the image without the cue.
TEST(ScreenAmbientOcclusion, HalfResolutionIsCloseToFullResolution) {
  if (world_rank() != 0) return;
  const Camera camera = test_camera();
  const Frame frame = crowd(camera);
  AmbientOcclusionStyle style;
  style.radius = 2.5f;
  style.strength = 1.0f;
  const std::vector<uint8_t> half = occluded_band(frame, camera, 0, kHeight, 0, style);
  style.half_resolution = false;
  const std::vector<uint8_t> full = occluded_band(frame, camera, 0, kHeight, 0, style);
  double error = 0.0, effect = 0.0;
  int drawn = 0;
  for (size_t i = 0; i < frame.pixel_count(); ++i) {
    if (frame.depth[i] == kBackgroundDepth) continue;
    ++drawn;
    for (int c = 0; c < 3; ++c) {
      const double h = half[4 * i + c], f = full[4 * i + c], none = frame.rgba[4 * i + c];
      error += (h - f) * (h - f);
      effect += (none - f) * (none - f);
    }
  }
  ASSERT_GT(drawn, 1000);
  const auto psnr = [&](double squared) {
    return 10.0 * std::log10(255.0 * 255.0 * 3 * drawn / squared);
  };
  EXPECT_GE(psnr(error), 35.0);
  EXPECT_LT(psnr(effect), psnr(error)) << "the method moves the image more than the cue does";
}

// An isolated sphere gets a closed ring: exactly the drawn pixels with a background pixel within
// `width` pixels (a square), every boundary pixel included, and nothing else changes.
TEST(ScreenCues, OutlinesEightAtATimeAreTheOneAtATimeOutlines) {
  // Distances with jumps of every size, the background and NaN, bands with halos and images whose
  // widths leave tails and edges narrower than the reach: the vector outlines (AVX2 where the
  // processor has it) and the one-at-a-time outlines, byte for byte, alpha kept.
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const int width : {1, 5, 17, 64, 333})
    for (const int reach : {1, 2, 3}) {
      const Camera camera = cube_camera(CameraConfig(), width, 40);
      BandFrame band = blank_band(width, 32, 4, {4 + reach, 36 - reach});
      for (size_t i = 0; i < band.frame.depth.size(); ++i) {
        float d = 0.2f + 0.6f * u(rng);
        if (i % 9 < 3) d = 0.5f;  // flat patches
        if (i % 23 == 0) d = kBackgroundDepth;
        if (i % 101 == 7) d = std::nanf("");
        band.frame.depth[i] = d;
        for (int c = 0; c < 4; ++c) band.frame.rgba[4 * i + size_t(c)] = uint8_t(i * 7 + size_t(c));
      }
      ViewPositions positions;
      positions.build(band, camera);
      OutlineStyle style;
      style.width = reach;
      style.jump = 0.3f;
      style.color[0] = 9, style.color[1] = 200, style.color[2] = 77;
      BandFrame vector = band, single = band;
      draw_outlines(positions, style, &vector, true);
      draw_outlines(positions, style, &single, false);
      EXPECT_NE(single.frame.rgba, band.frame.rgba) << "no outline at all";
      ASSERT_EQ(vector.frame.rgba, single.frame.rgba) << "width " << width << ", reach " << reach;
    }
}

TEST(ScreenCues, DepthCueEightAtATimeIsTheOneAtATimeDepthCue) {
  // Distances across the ramp and beyond it, the background and NaN, odd widths (tails): the
  // vector fade (AVX2 where the processor has it) and the one-at-a-time fade, byte for byte, for
  // a ramp and a step (end <= start), towards a colour and towards transparency.
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const int width : {3, 8, 29, 333})
    for (const bool ramp : {true, false})
      for (const bool fade_alpha : {false, true}) {
        const Camera camera = cube_camera(CameraConfig(), width, 30);
        BandFrame band = blank_band(width, 30, 0, {2, 28});
        for (size_t i = 0; i < band.frame.depth.size(); ++i) {
          float d = u(rng);
          if (i % 19 == 0) d = kBackgroundDepth;
          if (i % 97 == 3) d = std::nanf("");
          band.frame.depth[i] = d;
          for (int c = 0; c < 4; ++c) band.frame.rgba[4 * i + size_t(c)] = uint8_t(rng());
        }
        ViewPositions positions;
        positions.build(band, camera);
        const std::array<float, 2> range = positions.drawn_minima(band.owned);
        DepthCueStyle style;
        style.start = range[0] + 0.3f * (-range[1] - range[0]);
        style.end = ramp ? range[0] + 0.8f * (-range[1] - range[0]) : style.start;
        // A pixel exactly at the start: the step fades what lies beyond it, not at it.
        if (!ramp) style.start = style.end = positions.z(width / 2, 5);
        style.color[0] = 250, style.color[1] = 3, style.color[2] = 128;
        style.fade_alpha = fade_alpha;
        BandFrame vector = band, single = band;
        apply_depth_cue(positions, style, &vector, true);
        apply_depth_cue(positions, style, &single, false);
        EXPECT_NE(single.frame.rgba, band.frame.rgba);
        ASSERT_EQ(vector.frame.rgba, single.frame.rgba)
            << "width " << width << ", ramp " << ramp << ", fade_alpha " << fade_alpha;
      }
}

// `threads:` cuts the distances', the outlines' and the depth cue's rows into parts (of at least
// 64 rows): every count gives the one-thread bytes, on a band tall enough for several parts.
// A band of random depths (flat runs, background and NaN among them) and colours.
BandFrame random_band(int width, int rows, int first, RowBand owned) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  BandFrame band = blank_band(width, rows, first, owned);
  for (size_t i = 0; i < band.frame.depth.size(); ++i) {
    float d = 0.2f + 0.6f * u(rng);
    if (i % 9 < 3) d = 0.5f;
    if (i % 23 == 0) d = kBackgroundDepth;
    if (i % 101 == 7) d = std::nanf("");
    band.frame.depth[i] = d;
    for (int c = 0; c < 4; ++c) band.frame.rgba[4 * i + size_t(c)] = uint8_t(rng());
  }
  return band;
}

TEST(ScreenCues, DistancesOutlinesAndDepthCueOnEveryThreadCountAreTheOneThreadBytes) {
  const int width = 333, rows = 420;
  const Camera camera = cube_camera(CameraConfig(), width, 500);
  const BandFrame band = random_band(width, rows, 40, {43, 457});
  ViewPositions one;
  one.build(band, camera);
  OutlineStyle outline;
  outline.width = 2;
  outline.jump = 0.3f;
  DepthCueStyle fade;
  const std::array<float, 2> range = one.drawn_minima(band.owned);
  fade.start = range[0];
  fade.end = -range[1];
  fade.color[0] = 250;
  BandFrame outlined = band, faded = band;
  draw_outlines(one, outline, &outlined);
  apply_depth_cue(one, fade, &faded);
  ASSERT_NE(outlined.frame.rgba, band.frame.rgba);
  ASSERT_NE(faded.frame.rgba, band.frame.rgba);
  for (const int threads : {2, 3, 5, 8}) {
    ViewPositions many;
    many.build(band, camera, true, threads);
    for (int y = many.first_row(); y < many.last_row(); ++y)
      ASSERT_EQ(std::memcmp(many.row(y), one.row(y), sizeof(float) * size_t(width)), 0)
          << "row " << y << ", " << threads << " threads";
    BandFrame o = band, f = band;
    draw_outlines(many, outline, &o, true, threads);
    apply_depth_cue(many, fade, &f, true, threads);
    EXPECT_EQ(o.frame.rgba, outlined.frame.rgba) << threads << " threads";
    EXPECT_EQ(f.frame.rgba, faded.frame.rgba) << threads << " threads";
  }
}

// The rows of a band held in place in a frame of the whole image (BandFrame::held, as a rank's
// merged frame holds them after compositing) get the band's bytes from every cue, and the frame's
// other rows are left alone.
TEST(ScreenCues, EveryCueOnRowsHeldInTheWholeImageGivesTheBandsBytes) {
  const int width = 333, height = 500;
  const Camera camera = cube_camera(CameraConfig(), width, height);
  const BandFrame band = random_band(width, 420, 40, {43, 457});
  BandFrame whole = random_band(width, height, 0, band.owned);  // other rows: other pixels
  whole.held = RowBand{40, 460};
  const size_t at = size_t(band.first) * size_t(width);
  std::copy(band.frame.depth.begin(), band.frame.depth.end(),
            whole.frame.depth.begin() + ptrdiff_t(at));
  std::copy(band.frame.rgba.begin(), band.frame.rgba.end(),
            whole.frame.rgba.begin() + ptrdiff_t(4 * at));
  const BandFrame before = whole;
  AmbientOcclusionStyle ao;
  ao.radius = 0.5f;
  ao.strength = 1.0f;
  OutlineStyle outline;
  outline.width = 2;
  outline.jump = 0.3f;
  ViewPositions of_band;
  of_band.build(band, camera);
  const std::array<float, 2> range = of_band.drawn_minima(band.owned);
  DepthCueStyle fade;
  fade.start = range[0];
  fade.end = -range[1];
  fade.color[0] = 250;
  for (const int cue : {0, 1, 2, 3}) {
    BandFrame b = band, w = whole;
    for (BandFrame *f : {&b, &w}) {
      ViewPositions v;
      v.build(*f, camera);
      ASSERT_EQ(v.first_row(), 40);
      ASSERT_EQ(v.last_row(), 460);
      ao.half_resolution = cue == 0;
      if (cue < 2) apply_screen_ambient_occlusion(v, ao, f);
      if (cue == 2) draw_outlines(v, outline, f);
      if (cue == 3) apply_depth_cue(v, fade, f);
    }
    const size_t row = size_t(width) * 4;
    const auto owned_rows = [&](const BandFrame &f) {
      const auto first = f.frame.rgba.begin() + ptrdiff_t(size_t(f.owned.y0 - f.first) * row);
      return std::vector<uint8_t>(first, first + ptrdiff_t(size_t(f.owned.rows()) * row));
    };
    EXPECT_NE(owned_rows(b), owned_rows(band)) << "cue " << cue;
    EXPECT_EQ(owned_rows(w), owned_rows(b)) << "cue " << cue;
    for (int y = 0; y < height; ++y) {
      if (y >= band.owned.y0 && y < band.owned.y1) continue;
      ASSERT_TRUE(std::equal(w.frame.rgba.begin() + ptrdiff_t(size_t(y) * row),
                             w.frame.rgba.begin() + ptrdiff_t(size_t(y + 1) * row),
                             before.frame.rgba.begin() + ptrdiff_t(size_t(y) * row)))
          << "cue " << cue << " wrote row " << y;
    }
  }
}

TEST(ScreenCues, IsolatedSphereGetsAClosedOutlineOfTheConfiguredWidth) {
  const Camera camera = test_camera();
  const Frame before = draw(camera, {{0.3, -0.2, 50, 4.2, 180}});
  ScreenCueSettings scene = no_cues();
  scene.outline.enabled = true;
  scene.outline.width = 2;
  scene.outline.color = {1.0, 0.0, 0.0};
  const Frame after = cued(scene, camera, 4.2, before);
  if (world_rank() != 0) return;
  int ring = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const size_t i = before.index(x, y);
      bool near_background = false;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx >= 0 && nx < kWidth && ny >= 0 && ny < kHeight &&
              before.depth[before.index(nx, ny)] == kBackgroundDepth)
            near_background = true;
        }
      const bool outlined = before.depth[i] != kBackgroundDepth && near_background;
      ring += outlined;
      const uint8_t expected[3] = {uint8_t(outlined ? 255 : before.rgba[4 * i]),
                                   uint8_t(outlined ? 0 : before.rgba[4 * i + 1]),
                                   uint8_t(outlined ? 0 : before.rgba[4 * i + 2])};
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(after.rgba[4 * i + c], expected[c]) << x << "," << y << " channel " << c;
    }
  EXPECT_GT(ring, 100);
}

// Two spheres that intersect at the same depth read as one structure: no line where they meet;
// a sphere in front of a larger one gets a line where the depth jumps by more than the threshold.
TEST(ScreenCues, OutlinesFollowDepthJumpsNotIntersections) {
  const Camera camera = test_camera();
  const double r = 3.0;
  ScreenCueSettings scene = no_cues();
  scene.outline.enabled = true;
  const Frame joined = draw(camera, {{-0.6 * r, 0, 50, r, 200}, {0.6 * r, 0, 50, r, 200}});
  const Frame joined_after = cued(scene, camera, r, joined);
  const Frame stacked = draw(camera, {{0, 0, 30, r, 200}, {0, 0, 50, 3 * r, 100}});
  const Frame stacked_after = cued(scene, camera, r, stacked);
  if (world_rank() != 0) return;
  // Along the seam x = 0, inside the union: unchanged.
  const auto [seam_x, seam_y] = pixel_at(camera, 0.0, 0.0);
  for (int dy = -3; dy <= 3; ++dy) {
    const size_t i = joined.index(seam_x, seam_y + dy);
    EXPECT_EQ(joined_after.rgba[4 * i], joined.rgba[4 * i]) << "seam row " << seam_y + dy;
  }
  // Just inside the small front sphere's rim (0.95 r from its centre): a line; its centre: none.
  const auto [rim_x, rim_y] = pixel_at(camera, 0.95 * r, 0.0);
  EXPECT_EQ(stacked_after.rgba[4 * stacked.index(rim_x, rim_y)], 0);
  const auto [cx, cy] = pixel_at(camera, 0.0, 0.0);
  EXPECT_EQ(stacked_after.rgba[4 * stacked.index(cx, cy)], 200);
}

// Two identical spheres at distances 40 and 60, depth cue from the near one's front to 40 units
// beyond it: the far one's front pixel is exactly (60 - r - start) / 40 = 0.5 of the way to the
// background colour, the near one's front unchanged.
TEST(ScreenCues, DepthCueFadesTheFarSphereByTheConfiguredFraction) {
  const Camera camera = test_camera();
  const double r = 3.0;
  const uint8_t gray = 40;
  const Frame before = draw(camera, {{-6, 0, 40, r, gray}, {6, 0, 60, r, gray}});
  ScreenCueSettings scene = no_cues();
  scene.depth_cue.enabled = true;
  scene.depth_cue.start = 40 - r;
  scene.depth_cue.end = 40 - r + 40;
  const Frame after = cued(scene, camera, r, before);
  ScreenCueSettings to_black = scene;
  to_black.depth_cue.color = std::array<double, 3>{0, 0, 0};
  const Frame after_black = cued(to_black, camera, r, before);
  // Automatic range: from the near sphere's front to the far one's back rim.
  ScreenCueSettings automatic = no_cues();
  automatic.depth_cue.enabled = true;
  const Frame after_auto = cued(automatic, camera, r, before);
  if (world_rank() != 0) return;
  const auto [nx, ny] = pixel_at(camera, -6, 0);
  const auto [fx, fy] = pixel_at(camera, 6, 0);
  const size_t near_i = before.index(nx, ny), far_i = before.index(fx, fy);
  // The pixel centres miss the sphere centres slightly: the expected fraction from their depth.
  const double far_z = camera.window_depth_to_distance(before.depth[far_i]);
  const double f = (far_z - *scene.depth_cue.start) / 40.0;
  ASSERT_NEAR(f, 0.5, 0.01);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(after.rgba[4 * far_i + c], gray + f * (kBg[c] - gray), 1.0) << c;
    EXPECT_NEAR(after_black.rgba[4 * far_i + c], gray * (1 - f), 1.0) << c;
    EXPECT_NEAR(after.rgba[4 * near_i + c], gray, 1.0) << c;
  }
  // The near sphere's front is (almost) the nearest drawn depth: (almost) unchanged; the far
  // sphere's front, 20 of the range's 23 units beyond, is (z - nearest) / (farthest - nearest).
  float nearest = 1.0f, farthest = 0.0f;
  for (const float d : before.depth)
    if (d != kBackgroundDepth) nearest = std::min(nearest, d), farthest = std::max(farthest, d);
  const double z0 = camera.window_depth_to_distance(nearest);
  const double z1 = camera.window_depth_to_distance(farthest);
  const double f_auto = (far_z - z0) / (z1 - z0);
  EXPECT_NEAR(after_auto.rgba[4 * near_i], gray, 1.0);
  EXPECT_NEAR(after_auto.rgba[4 * far_i], gray + f_auto * (kBg[0] - gray), 1.0);
}

// Every cue at once gives the same bytes on every rank count as on one rank alone.
TEST(ScreenCues, AllCuesGiveTheSameBytesOnOneRankAndOnAll) {
  const Camera camera = test_camera();
  std::vector<Ball> balls;
  for (int k = 0; k < 40; ++k)
    balls.push_back({-14.0 + 0.7 * k, 6.0 * std::sin(0.9 * k), 45.0 + 3.0 * std::cos(1.3 * k),
                     1.0 + 0.05 * (k % 7), uint8_t(60 + 4 * k)});
  const Frame before = draw(camera, balls);
  ScreenCueSettings scene = no_cues();
  scene.ambient_occlusion.enabled = true;
  scene.outline.enabled = true;
  scene.outline.width = 2;
  scene.depth_cue.enabled = true;
  const Frame all = cued(scene, camera, 1.3, before);
  if (world_rank() != 0) return;
  Frame alone = before;
  ASSERT_OK(apply_screen_cues(MPI_COMM_SELF, 0, scene, kWidth, kHeight, camera, 1.3, &alone));
  EXPECT_EQ(all.rgba, alone.rgba);
  EXPECT_EQ(all.depth, before.depth);  // cues change colours only
  EXPECT_NE(all.rgba, before.rgba);
}

}  // namespace
}  // namespace lantern::testing
