// style: density on one rank: a single footprint integrates to its weight, level of detail keeps
// the total brightness, the transfer functions and the color blend.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/culling/brick_selection.h"
#include "core/finish/density_transfer.h"
#include "core/pipeline/scene_settings.h"
#include "core/render/density_pass.h"
#include "core/render/density_splat.h"
#include "core/view/view_geometry.h"
#include "tests/support/bricked_particles.h"

namespace lantern {
namespace {

// An orthographic camera framing [0, 10]^3 from +z, at 200 x 200 px (20 px per unit).
// xorshift32 numbers in [0, 1): the same test data on every machine.
struct Uniform {
  uint32_t h;
  double operator()() {
    h ^= h << 13, h ^= h >> 17, h ^= h << 5;
    return double(h) / 4294967296.0;
  }
};

ViewGeometry ortho_geometry(Camera *camera) {
  CameraConfig cc;
  cc.projection = Projection::kOrthographic;
  cc.position = std::array<double, 3>{5, 5, 50};
  cc.look_at = {5, 5, 5};
  cc.up = {0, 1, 0};
  EXPECT_TRUE(make_camera(cc, {0, 0, 0}, {10, 10, 10}, 0.5, 200, 200, camera).ok());
  return ViewGeometry::from_camera(*camera, 100.0);
}

double total_weight(const DensityImage &image) {
  double sum = 0.0;
  for (size_t p = 0; p < image.pixel_count(); ++p)
    sum += double(image.sum[p * size_t(image.channels)]);
  return sum / kDensityUnit;
}

TEST(DensitySplat, OneFootprintIntegratesToItsWeight) {
  Camera camera;
  const ViewGeometry g = ortho_geometry(&camera);
  // Sub-pixel, a few pixels, and ~25 px sigma (the analytic normalisation), off pixel centres.
  for (const double r : {0.005, 0.1, 0.37, 4.0})
    for (const double weight : {1.0, 7.25}) {
      DensityImage image;
      image.reset(g.width, g.height, 1);
      DensitySplatter splat(g, &image);
      ASSERT_TRUE(splat.splat(g.to_view({5.013, 4.971, 5.0}), r, weight, {0, 0, 0}));
      EXPECT_NEAR(total_weight(image), weight, 0.01 * weight) << "r " << r;  // within 1 %
      // Tighter: the kernel's own normalisation leaves only the fixed-point rounding (sigma < 8
      // px: the taps are summed) or the analytic integral's 0.1 % (r = 4: sigma ~ 27 px).
      EXPECT_NEAR(total_weight(image), weight, (r < 1.0 ? 1e-5 : 1e-3) * weight) << "r " << r;
      int64_t nonzero = 0;
      for (const int64_t v : image.sum) nonzero += v != 0;
      EXPECT_GT(nonzero, 1) << "r " << r;  // a footprint, not a point
    }
}

// W keeps 24 significant bits of any weight (F follows the weight's octave): weights far from 1
// integrate as exactly as 1 does, and nothing outside [kDensityMinWeight, kDensityMaxWeight).
TEST(DensitySplat, WeightsOfEveryOctaveIntegrateToThemselves) {
  Camera camera;
  const ViewGeometry g = ortho_geometry(&camera);
  for (const double weight : {1.0 / 3.0, 1.0, 1.37, 255.5, 65536.0 + 0.25, 3.1e9, 2.0e11})
    for (const int channels : {1, 4}) {
      DensityImage image;
      image.reset(g.width, g.height, channels);
      DensitySplatter splat(g, &image);
      ASSERT_TRUE(splat.splat(g.to_view({5.013, 4.971, 5.0}), 0.1, weight, {255, 255, 255}));
      EXPECT_NEAR(total_weight(image), weight, 2e-6 * weight) << weight << " ch " << channels;
    }
  DensityImage image;
  image.reset(g.width, g.height, 1);
  DensitySplatter splat(g, &image);
  EXPECT_FALSE(splat.splat(g.to_view({5, 5, 5}), 0.1, kDensityMaxWeight, {0, 0, 0}));
  EXPECT_FALSE(splat.splat(g.to_view({5, 5, 5}), 0.1, 0.0, {0, 0, 0}));
  EXPECT_FALSE(splat.splat(g.to_view({5, 5, 5}), 0.1, std::nan(""), {0, 0, 0}));
  EXPECT_EQ(total_weight(image), 0.0);
}

// The four-channel image's weight channel (the vector pixel loop) is the one-channel image (the
// scalar loop) bit for bit, and each colour channel is the weight times c / 256 up to rounding.
TEST(DensitySplat, FourChannelWeightIsTheOneChannelImage) {
  Camera camera;
  const ViewGeometry g = ortho_geometry(&camera);
  DensityImage one, four;
  one.reset(g.width, g.height, 1);
  four.reset(g.width, g.height, 4);
  DensitySplatter s1(g, &one), s4(g, &four);
  Uniform next{7u};
  for (int n = 0; n < 3000; ++n) {
    const glm::dvec3 c = g.to_view({10.4 * next() - 0.2, 10.4 * next() - 0.2, 5.0});
    const double r = 0.02 + 0.5 * next(), w = 1.0 + 20.0 * next();
    const Rgb8 color{uint8_t(n % 256), uint8_t(255 - n % 256), uint8_t(n % 7)};
    ASSERT_EQ(s1.splat(c, r, w, color), s4.splat(c, r, w, color));
  }
  int64_t worst = 0;
  for (size_t p = 0; p < one.pixel_count(); ++p) {
    ASSERT_EQ(one.sum[p], four.sum[4 * p]) << "pixel " << p;
    for (int k = 1; k < 4; ++k) {
      ASSERT_LE(four.sum[4 * p + size_t(k)], four.sum[4 * p]);
      ASSERT_GE(four.sum[4 * p + size_t(k)], 0);
    }
    worst = std::max(worst, four.sum[4 * p]);
  }
  EXPECT_GT(worst, int64_t(kDensityUnit));  // footprints overlap: sums of many particles
}

// The pixel loops of a four-channel image (AVX-512 and AVX2 where the processor has them, SSE2,
// scalar) give the same sums, bit for bit, on overlapping footprints of many widths and weights,
// at the image's edges too.
TEST(DensitySplat, EveryPixelLoopGivesTheSameSums) {
  Camera camera;
  const ViewGeometry g = ortho_geometry(&camera);
  std::vector<int64_t> sums[4];
  const DensityPixelLoop loops[4] = {DensityPixelLoop::kAuto, DensityPixelLoop::kAvx2,
                                     DensityPixelLoop::kSse2, DensityPixelLoop::kScalar};
  for (int l = 0; l < 4; ++l) {
    DensityImage image;
    image.reset(g.width, g.height, 4);
    DensitySplatter splat(g, &image);
    splat.set_pixel_loop(loops[l]);
    Uniform next{3u};
    for (int n = 0; n < 2000; ++n) {
      const glm::dvec3 c = g.to_view({10.4 * next() - 0.2, 10.4 * next() - 0.2, 5.0});
      const double r = n % 50 == 0 ? 3.0 * next() : 0.02 + 0.4 * next();  // some beyond the table
      const double w = n % 3 == 0 ? 1.0 : 1.0 + 300.0 * next();
      splat.splat(c, r, w, {uint8_t(n % 256), uint8_t(255 - n % 256), uint8_t(n % 7)});
    }
    sums[l].assign(image.sum.begin(), image.sum.end());
  }
  EXPECT_TRUE(sums[0] == sums[1]);
  EXPECT_TRUE(sums[0] == sums[2]);
  EXPECT_TRUE(sums[0] == sums[3]);
  int64_t nonzero = 0;
  for (const int64_t v : sums[0]) nonzero += v != 0;
  EXPECT_GT(nonzero, 10000);
}

// Splatting into rows padded apart (reset_padded, as the density pass does), then compact(),
// gives the sums of dense rows, bit for bit, with one and four channels, the automatic and the
// scalar pixel loop, for footprints across the right and bottom edges and beyond the table.
TEST(DensitySplat, PaddedRowsCompactToTheDenseSums) {
  CameraConfig cc;
  cc.projection = Projection::kOrthographic;
  cc.position = std::array<double, 3>{5, 5, 50};
  cc.look_at = {5, 5, 5};
  cc.up = {0, 1, 0};
  Camera camera;
  ASSERT_TRUE(make_camera(cc, {0, 0, 0}, {10, 10, 10}, 0.5, 256, 256, &camera).ok());
  const ViewGeometry g = ViewGeometry::from_camera(camera, 100.0);
  for (const int channels : {1, 4})
    for (const DensityPixelLoop loop : {DensityPixelLoop::kAuto, DensityPixelLoop::kScalar}) {
      DensityImage dense, padded;
      dense.reset(g.width, g.height, channels);
      padded.reset_padded(g.width, g.height, channels);
      ASSERT_GT(padded.pitch, g.width);  // 256 px rows of 8 or 32 bytes a pixel are padded
      DensitySplatter a(g, &dense), b(g, &padded);
      a.set_pixel_loop(loop), b.set_pixel_loop(loop);
      Uniform next{5u};
      for (int n = 0; n < 20000; ++n) {
        const glm::dvec3 c = g.to_view({20.0 * next() - 5.0, 20.0 * next() - 5.0, 5.0});
        const double r = n % 40 == 0 ? 2.0 * next() : 0.02 + 0.2 * next();
        const double w = n % 3 == 0 ? 1.0 : 1.0 + 100.0 * next();
        const Rgb8 color{uint8_t(n % 256), uint8_t(255 - n % 256), uint8_t(n % 7)};
        EXPECT_EQ(a.splat(c, r, w, color), b.splat(c, r, w, color));
      }
      padded.compact();
      EXPECT_EQ(padded.pitch, padded.width);
      EXPECT_TRUE(padded.sum == dense.sum) << channels;
      int64_t right_edge = 0;
      for (int y = 0; y < g.height; ++y)
        right_edge +=
            dense.sum[(size_t(y) * size_t(g.width) + size_t(g.width - 1)) * size_t(channels)] != 0;
      EXPECT_GT(right_edge, 20);
    }
}

// project_all (the vectorised projection of world positions) gives project(g.to_view(x)), bit for
// bit, in both projections, with per-particle and constant radii, for particles in front of,
// on and behind the near plane.
// A 300 x 200 (or width x height) view of the box [0, 10]^3 from z = 30 (false when the camera is
// refused).
bool box_view(Projection projection, ViewGeometry *g, int width = 300, int height = 200) {
  CameraConfig cc;
  cc.projection = projection;
  cc.position = std::array<double, 3>{5, 5, 30};
  cc.look_at = {5, 5, 5};
  cc.up = {0.1, 1, 0};
  Camera camera;
  if (!make_camera(cc, {0, 0, 0}, {10, 10, 10}, 0.5, width, height, &camera).ok()) return false;
  *g = ViewGeometry::from_camera(camera, 100.0);
  return true;
}

// box_view and an empty one-channel image of its size.
bool box_view_image(Projection projection, ViewGeometry *g, DensityImage *image) {
  if (!box_view(projection, g)) return false;
  image->reset(g->width, g->height, 1);
  return true;
}

TEST(DensitySplat, ProjectAllIsProjectParticleByParticle) {
  for (const Projection projection : {Projection::kPerspective, Projection::kOrthographic}) {
    ViewGeometry g;
    DensityImage image;
    ASSERT_TRUE(box_view_image(projection, &g, &image));
    const DensitySplatter splat(g, &image);
    std::vector<double> x, y, z, r;
    Uniform next{7u};
    for (int k = 0; k < 1003; ++k) {
      x.push_back(14.0 * next() - 2.0), y.push_back(14.0 * next() - 2.0);
      z.push_back(k % 100 == 0 ? 30.0 - g.near_plane : 40.0 * next() - 5.0);  // some not in front
      r.push_back(0.05 + next());
    }
    for (const bool per_particle : {true, false}) {
      DensityFootprints all;
      splat.project_all(x.data(), y.data(), z.data(), per_particle ? r.data() : nullptr, 0.37, 1.25,
                        int(x.size()), &all);
      int in_front = 0;
      for (size_t k = 0; k < x.size(); ++k) {
        DensityFootprint one;
        const bool front =
            splat.project(g.to_view({x[k], y[k], z[k]}), (per_particle ? r[k] : 0.37) * 1.25, &one);
        ASSERT_EQ(bool(all.in_front[k]), front) << k;
        if (!front) continue;
        ++in_front;
        ASSERT_EQ(all.px[k], one.px) << k;
        ASSERT_EQ(all.py[k], one.py) << k;
        ASSERT_EQ(all.sigma2[k], one.sigma2) << k;
      }
      EXPECT_GT(in_front, 300);
      EXPECT_LT(in_front, int(x.size()));
    }
  }
}

// project_xyz (the projection read straight from interleaved double positions) gives
// project_all's bits in both projections, for particles in front of, on and behind the near
// plane, at any alignment; it declines a count that is not a multiple of 8 and a batch with a
// coordinate that is not finite. Its AVX-512 path where the processor has it, else its AVX2 one.
TEST(DensitySplat, ProjectXyzIsProjectAll) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "project_xyz needs AVX2";
#else
  GTEST_SKIP() << "project_xyz needs AVX2";
#endif
  for (const Projection projection : {Projection::kPerspective, Projection::kOrthographic}) {
    ViewGeometry g;
    DensityImage image;
    ASSERT_TRUE(box_view_image(projection, &g, &image));
    const DensitySplatter splat(g, &image);
    std::vector<double> x, y, z;
    Uniform next{11u};
    constexpr int kCount = 1000;
    for (int k = 0; k < kCount; ++k) {
      x.push_back(14.0 * next() - 2.0), y.push_back(14.0 * next() - 2.0);
      z.push_back(k % 100 == 0 ? 30.0 - g.near_plane : 40.0 * next() - 5.0);
    }
    std::vector<unsigned char> bytes(kCount * 24 + 1);  // offset by one: unaligned
    for (int k = 0; k < kCount; ++k)
      for (int c = 0; c < 3; ++c) {
        const double v = (c == 0 ? x : c == 1 ? y : z)[size_t(k)];
        std::memcpy(bytes.data() + 1 + 24 * k + 8 * c, &v, 8);
      }
    DensityFootprints all, direct;
    splat.project_all(x.data(), y.data(), z.data(), nullptr, 0.37, 1.0, kCount, &all);
    ASSERT_TRUE(splat.project_xyz(bytes.data() + 1, 0.37, kCount, &direct));
    int in_front = 0;
    for (size_t k = 0; k < size_t(kCount); ++k) {
      ASSERT_EQ(direct.in_front[k], all.in_front[k]) << k;
      if (!all.in_front[k]) continue;
      ++in_front;
      ASSERT_EQ(direct.px[k], all.px[k]) << k;
      ASSERT_EQ(direct.py[k], all.py[k]) << k;
      ASSERT_EQ(direct.sigma2[k], all.sigma2[k]) << k;
    }
    EXPECT_GT(in_front, 300);
    EXPECT_LT(in_front, kCount);
    EXPECT_FALSE(splat.project_xyz(bytes.data() + 1, 0.37, kCount - 4, &direct));
    for (const double bad : {std::nan(""), HUGE_VAL, -HUGE_VAL})
      for (const int c : {0, 1, 2}) {
        std::vector<unsigned char> spoilt = bytes;
        std::memcpy(spoilt.data() + 1 + 24 * 997 + 8 * c, &bad, 8);
        EXPECT_FALSE(splat.project_xyz(spoilt.data() + 1, 0.37, kCount, &direct)) << c;
      }
  }
}

// bin_all (vectorised look-ups; a batch that follows itself on the image deposited at once,
// another filed in tile bins) then deposit_bins gives the sums of deposit() one by one: for a
// coherent order (along a line), a random one, and footprints beyond the table, behind the near
// plane or off the image; with the automatic pixel loops and the AVX2 ones (each has its own
// weight-1 loop for coherent batches).
TEST(DensitySplat, BinAllGivesTheSumsOfDepositOneByOne) {
  Uniform next{31u};
  // The second time into rows padded apart (256 px of 32 bytes: DensityImage::reset_padded), as
  // the density pass splats, compacted before comparing.
  for (const DensityPixelLoop loop : {DensityPixelLoop::kAuto, DensityPixelLoop::kAvx2})
    for (const bool padded : {false, true})
      for (const bool coherent : {true, false}) {
        ViewGeometry g;
        ASSERT_TRUE(box_view(Projection::kPerspective, &g, padded ? 256 : 300, 200));
        std::vector<double> x, y, z, r;
        std::vector<Rgb8> color;
        for (int k = 0; k < 3001; ++k) {
          const double t = double(k) / 3000.0;
          x.push_back(coherent ? -1.0 + 12.0 * t : 14.0 * next() - 2.0);
          y.push_back(coherent ? 5.0 + 3.0 * std::sin(20.0 * t) : 14.0 * next() - 2.0);
          z.push_back(k % 500 == 0 ? 30.0 - 0.5 * g.near_plane : 10.0 * next());
          r.push_back(k % 250 == 0 ? 6.0 : 0.02 + 0.3 * next());  // some beyond the table
          color.push_back({uint8_t(k), uint8_t(7 * k), uint8_t(255 - k % 256)});
        }
        DensityImage binned, one_by_one;
        if (padded) {
          binned.reset_padded(g.width, g.height, 4);
          ASSERT_GT(binned.pitch, binned.width);
        } else {
          binned.reset(g.width, g.height, 4);
        }
        one_by_one.reset(g.width, g.height, 4);
        DensitySplatter a(g, &binned), b(g, &one_by_one);
        a.set_pixel_loop(loop);
        DensityFootprints f;
        DensityBins bins;
        bins.reset(g.width, g.height);
        a.project_all(x.data(), y.data(), z.data(), r.data(), 0.0, 1.0, int(x.size()), &f);
        const int64_t touched = a.bin_all(f, color.data(), int(x.size()), &bins);
        a.deposit_bins(bins);
        binned.compact();
        int64_t expected = 0;
        for (size_t k = 0; k < x.size(); ++k)
          expected += f.in_front[k] && b.deposit({f.px[k], f.py[k], f.sigma2[k]}, 1.0, color[k]);
        EXPECT_EQ(touched, expected) << coherent;
        EXPECT_GT(expected, 2000) << coherent;
        EXPECT_LT(expected, 3001) << coherent;
        EXPECT_TRUE(binned.sum == one_by_one.sum) << coherent;
        EXPECT_EQ(a.pixels_written(), b.pixels_written()) << coherent;
      }
}

// Perspective: the footprint's centroid is the projected centre (within 0.05 px, see
// density_kernel_test) and it integrates to its weight; farther away, the same sphere is narrower.
TEST(DensitySplat, PerspectiveFootprintsSitAtTheProjectedCentre) {
  CameraConfig cc;
  cc.projection = Projection::kPerspective;
  cc.position = std::array<double, 3>{5, 5, 30};
  cc.look_at = {5, 5, 5};
  cc.up = {0, 1, 0};
  Camera camera;
  ASSERT_TRUE(make_camera(cc, {0, 0, 0}, {10, 10, 10}, 0.5, 300, 200, &camera).ok());
  const ViewGeometry g = ViewGeometry::from_camera(camera, 100.0);
  double widths[2] = {0, 0};
  int n = 0;
  for (const glm::dvec3 x : {glm::dvec3{3.3, 6.2, 8.0}, glm::dvec3{3.3, 6.2, 0.0}}) {
    DensityImage image;
    image.reset(g.width, g.height, 1);
    DensitySplatter splat(g, &image);
    const glm::dvec3 v = g.to_view(x);
    ASSERT_TRUE(splat.splat(v, 0.3, 1.0, {0, 0, 0}));
    EXPECT_NEAR(total_weight(image), 1.0, 1e-5);
    const double d = -v.z;
    const double px = 0.5 * (g.sx * v.x / d + 1.0) * g.width;
    const double py = 0.5 * (1.0 - g.sy * v.y / d) * g.height;
    double cx = 0, cy = 0, w = 0, xx = 0;
    for (int y = 0; y < g.height; ++y)
      for (int xi = 0; xi < g.width; ++xi) {
        const double s = double(image.sum[size_t(y) * size_t(g.width) + size_t(xi)]);
        cx += s * (xi + 0.5), cy += s * (y + 0.5), w += s;
      }
    cx /= w, cy /= w;
    for (int y = 0; y < g.height; ++y)
      for (int xi = 0; xi < g.width; ++xi)
        xx += double(image.sum[size_t(y) * size_t(g.width) + size_t(xi)]) * (xi + 0.5 - cx) *
              (xi + 0.5 - cx);
    EXPECT_NEAR(cx, px, 0.05);  // 1/64 px phase step, plus the cut-off's and sampling's bias
    EXPECT_NEAR(cy, py, 0.05);
    widths[n++] = std::sqrt(xx / w);
  }
  EXPECT_GT(widths[0], 1.2 * widths[1]);  // the nearer one (z = 8, depth 22 vs 30) is wider
}

TEST(DensitySplat, ColorChannelsHoldTheWeightTimesTheColor) {
  Camera camera;
  const ViewGeometry g = ortho_geometry(&camera);
  DensityImage image;
  image.reset(g.width, g.height, 4);
  DensitySplatter splat(g, &image);
  ASSERT_TRUE(splat.splat(g.to_view({3.3, 6.1, 5.0}), 0.3, 2.0, {255, 51, 0}));
  int64_t w = 0, r = 0, gr = 0, b = 0;
  for (size_t p = 0; p < image.pixel_count(); ++p)
    w += image.sum[4 * p], r += image.sum[4 * p + 1], gr += image.sum[4 * p + 2],
        b += image.sum[4 * p + 3];
  // Colour channels hold the weight times c / 256 (density_splat.h), each pixel rounded.
  EXPECT_NEAR(double(r) / double(w), 255.0 / 256.0, 1e-6);
  EXPECT_NEAR(double(gr) / double(w), 51.0 / 256.0, 1e-6);
  EXPECT_EQ(b, 0);
}

TEST(DensitySplat, ParticlesBehindTheNearPlaneOrOffTheImageDepositNothing) {
  Camera camera;
  const ViewGeometry g = ortho_geometry(&camera);
  DensityImage image;
  image.reset(g.width, g.height, 1);
  DensitySplatter splat(g, &image);
  EXPECT_FALSE(splat.splat({0.0, 0.0, 1.0}, 0.5, 1.0, {0, 0, 0}));        // behind the eye
  EXPECT_FALSE(splat.splat(g.to_view({30, 5, 5}), 0.5, 1.0, {0, 0, 0}));  // far to the right
  EXPECT_EQ(total_weight(image), 0.0);
}

// A cloud of 60,000 particles in [1, 9]^3 in bricks with the z-order level layout.
struct Cloud : testing::BrickedParticles {
  Cloud() {
    Uniform next{12345u};
    for (int i = 0; i < 60000; ++i) {
      // Half uniform, half in a dense blob: uneven brick sizes.
      const bool blob = i % 2 == 0;
      for (int k = 0; k < 3; ++k) xyz.push_back(blob ? 4.0 + 1.5 * next() : 1.0 + 8.0 * next());
      type.push_back(i % 3);
    }
    finish();
  }
};

double rendered_weight(const Cloud &cloud, const SceneConfig &scene, const Camera &camera,
                       int64_t *drawn) {
  BrickSelection sel;
  const RadiusRule radius = radius_rule(scene, cloud.arrays);
  select_density_bricks(cloud.bricks, camera, cull_settings(scene), radius, &sel, nullptr);
  Extent ext;
  ext.lo = {1, 1, 1}, ext.hi = {9, 9, 9};
  const InstanceRecipe recipe =
      make_recipe(cloud.arrays, shading_settings(scene), radius, camera, ext);
  DensityImage image;
  const CullStats st =
      render_density(cloud.arrays, cloud.bricks, cull_settings(scene), sel, recipe, &image);
  *drawn = st.drawn;
  EXPECT_EQ(st.drawn + st.lod_dropped, 60000);
  return total_weight(image);
}

TEST(DensityLevelOfDetail, WeightsKeepTheTotalIntensityAtTenPercent) {
  const Cloud cloud;
  Camera camera;
  ortho_geometry(&camera);
  SceneConfig scene;
  scene.style = SceneStyle::kDensity;
  scene.radius = 0.1;
  scene.color.by = ColorBy::kSolid;
  int64_t all_drawn = 0, some_drawn = 0;
  const double full = rendered_weight(cloud, scene, camera, &all_drawn);
  EXPECT_EQ(all_drawn, 60000);
  EXPECT_NEAR(full, 60000.0, 0.01 * 60000.0);
  scene.lod.fraction = 0.1;
  const double tenth = rendered_weight(cloud, scene, camera, &some_drawn);
  EXPECT_LE(some_drawn, 6000 + int64_t(cloud.bricks.bricks.size()));
  EXPECT_GE(some_drawn, 6000);
  EXPECT_NEAR(tenth, full, 0.01 * full);
}

// Colours by type read from a type array of either datatype (int32, int64), with types beyond
// the pass's table (negative, 64 and more, coloured by the palette's own lookup): the streamed
// pass gives the sums of splat() particle by particle with recipe.color(), bit for bit.
// The density pass over `arrays` (bricks built here, the bricks `camera` sees selected) with the
// selection and recipe it used: what the DensityPass tests compare with one splat per particle.
struct DensityPassResult {
  BrickSelection sel;
  InstanceRecipe recipe;
  DensityImage image;
  CullStats st;
};

DensityPassResult run_density_pass(const ParticleArrays &arrays, const SceneConfig &scene,
                                   const Camera &camera) {
  const BrickSet bricks = build_bricks(arrays, BrickOptions{});
  DensityPassResult r;
  const RadiusRule radius = radius_rule(scene, arrays);
  select_density_bricks(bricks, camera, cull_settings(scene), radius, &r.sel, nullptr);
  Extent ext;
  ext.lo = {1, 1, 1}, ext.hi = {9, 9, 9};
  r.recipe = make_recipe(arrays, shading_settings(scene), radius, camera, ext);
  r.st = render_density(arrays, bricks, cull_settings(scene), r.sel, r.recipe, &r.image);
  return r;
}

// splat() of every finite particle of `arrays` one by one, with the pass's view, footprint radius
// `radius` and recipe colours (none in a one-channel image), into *out: the sums the pass must
// give. Returns how many touched the image.
int64_t splat_one_by_one(const ParticleArrays &arrays, const DensityPassResult &pass, double radius,
                         int channels, DensityImage *out) {
  out->reset(pass.sel.g.width, pass.sel.g.height, channels);
  DensitySplatter splat(pass.sel.g, out);
  int64_t drawn = 0;
  for (int64_t i = 0; i < arrays.count(); ++i) {
    const glm::dvec3 x = arrays.position(i);
    if (!(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z))) continue;
    const Rgb8 color = channels == 1 ? Rgb8{0, 0, 0} : pass.recipe.color(i);
    drawn += splat.splat(pass.sel.g.to_view(x), radius, 1.0, color);
  }
  return drawn;
}

// The density pass over `arrays` coloured by type with `color_keys` (radius 0.1, every particle in
// view) gives the count and sums of splat() particle by particle with recipe.color().
void expect_type_colors_of_one_splat_per_particle(const ParticleArrays &arrays,
                                                  const ColorConfig &color_keys, const char *what) {
  Camera camera;
  ortho_geometry(&camera);
  SceneConfig scene;
  scene.style = SceneStyle::kDensity;
  scene.radius = 0.1;
  scene.color = color_keys;
  scene.color.by = ColorBy::kType;
  const DensityPassResult pass = run_density_pass(arrays, scene, camera);
  DensityImage one_by_one;
  const int64_t drawn = splat_one_by_one(arrays, pass, 0.1, 4, &one_by_one);
  EXPECT_EQ(pass.st.drawn, drawn) << what;
  EXPECT_EQ(drawn, arrays.count()) << what;
  EXPECT_TRUE(pass.image.sum == one_by_one.sum) << what;
}

TEST(DensityPass, ColorsByTypeOfEveryDatatypeMatchOneSplatPerParticle) {
  constexpr int kCount = 20000;
  std::vector<double> xyz;
  std::vector<int32_t> t32;
  std::vector<int64_t> t64;
  Uniform next{99u};
  for (int i = 0; i < kCount; ++i) {
    for (int k = 0; k < 3; ++k) xyz.push_back(1.0 + 8.0 * next());
    const int type = i % 75 - 5;  // -5 .. 69
    t32.push_back(type), t64.push_back(type);
  }
  for (const DataType datatype : {DataType::kInt32, DataType::kInt64}) {
    ParticleDescription d{};
    d.count = kCount;
    d.position = {xyz.data(), DataType::kFloat64, 0};
    d.type = {datatype == DataType::kInt32 ? static_cast<const void *>(t32.data())
                                           : static_cast<const void *>(t64.data()),
              datatype, 0};
    ParticleArrays arrays;
    ASSERT_TRUE(ParticleArrays::validate(d, &arrays).ok());
    ColorConfig colors;
    // Five colours: types t and t mod 64 differ in colour, as do -5 and 59.
    colors.palette = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0.2, 0.4, 0.6}};
    expect_type_colors_of_one_splat_per_particle(arrays, colors,
                                                 datatype == DataType::kInt32 ? "int32" : "int64");
  }
}

// int32 types are coloured sixteen at a time where the processor allows (AVX-512), and a block
// holding a type beyond the pass's table one particle at a time: long stretches of types 0 .. 63
// with a stray type every 1000 particles, negative at every 3000th, and a count that is not a
// multiple of 16 give the sums of splat() particle by particle with recipe.color().
TEST(DensityPass, Int32TypesInBlocksAndStraysMatchOneSplatPerParticle) {
  constexpr int kCount = 20011;
  std::vector<double> xyz;
  std::vector<int32_t> type;
  Uniform next{7u};
  for (int i = 0; i < kCount; ++i) {
    for (int k = 0; k < 3; ++k) xyz.push_back(1.0 + 8.0 * next());
    type.push_back(i % 3000 == 1500 ? -2 : i % 1000 == 999 ? 64 + i % 7 : (i * 7) % 64);
  }
  ParticleDescription d{};
  d.count = kCount;
  d.position = {xyz.data(), DataType::kFloat64, 0};
  d.type = {type.data(), DataType::kInt32, 0};
  ParticleArrays arrays;
  ASSERT_TRUE(ParticleArrays::validate(d, &arrays).ok());
  ColorConfig colors;
  // Seven colours: types t and t + 32 differ (32 mod 7 = 4), as do t and t + 64.
  colors.palette = {{1, 0, 0}, {0, 1, 0},       {0, 0, 1},      {1, 1, 0},
                    {0, 1, 1}, {0.2, 0.4, 0.6}, {0.9, 0.1, 0.5}};
  expect_type_colors_of_one_splat_per_particle(arrays, colors, "int32 in blocks");
}

// Without level of detail, mask or cutting plane, the pass reads positions in published order
// straight into the projection (interleaved doubles) or copies them without a branch (other
// layouts): batches holding a particle whose position is not finite take the path that drops
// it, and a count that is not a multiple of 8 ends in a short batch; the sums are those of
// splat() particle by particle, for interleaved and separate, double and float positions.
TEST(DensityPass, NonFinitePositionsAreDroppedInEveryLayout) {
  Camera camera;
  ortho_geometry(&camera);
  constexpr int kCount = 5003;  // 4 full batches and a short one
  std::vector<double> xyz, xs, ys, zs;
  std::vector<float> xyz32;
  Uniform next{5u};
  for (int i = 0; i < kCount; ++i)
    for (int k = 0; k < 3; ++k) {
      double v = 1.0 + 8.0 * next();
      if (i == 1500 + k || i == 4999) v = k == 1 ? std::nan("") : HUGE_VAL;
      if (i == 3100 && k == 2) v = -HUGE_VAL;
      xyz.push_back(v), xyz32.push_back(float(v));
      (k == 0 ? xs : k == 1 ? ys : zs).push_back(v);
    }
  for (int layout = 0; layout < 3; ++layout) {
    ParticleDescription d{};
    d.count = kCount;
    if (layout == 0) d.position = {xyz.data(), DataType::kFloat64, 0};
    if (layout == 1) d.position = {xyz32.data(), DataType::kFloat32, 0};
    if (layout == 2) {
      d.position_x = {xs.data(), DataType::kFloat64, 0};
      d.position_y = {ys.data(), DataType::kFloat64, 0};
      d.position_z = {zs.data(), DataType::kFloat64, 0};
    }
    ParticleArrays arrays;
    ASSERT_TRUE(ParticleArrays::validate(d, &arrays).ok()) << layout;
    SceneConfig scene;
    scene.style = SceneStyle::kDensity;
    scene.radius = 0.1;
    scene.color.by = ColorBy::kSolid;
    const DensityPassResult pass = run_density_pass(arrays, scene, camera);
    DensityImage one_by_one;
    const int64_t drawn = splat_one_by_one(arrays, pass, 0.1, 1, &one_by_one);
    EXPECT_EQ(pass.st.drawn, drawn) << layout;
    EXPECT_EQ(drawn, kCount - 5) << layout;
    // Dropped before projection, not projected and missed: no particle counts as off the image.
    EXPECT_EQ(pass.st.frustum_culled, 0) << layout;
    EXPECT_TRUE(pass.image.sum == one_by_one.sum) << layout;
  }
}

// The density pass gives the sums of splat() called particle by particle, bit for bit, coloured
// by type, through a cutting plane: at LOD 100 % (the particles streamed in published order,
// binned by image tile) and at LOD 30 % (each brick's prefix gathered with prefetching,
// projected in one vectorised loop, deposited per brick).
TEST(DensityPass, GivesTheSumsOfOneSplatPerParticle) {
  const Cloud cloud;
  Camera camera;
  const ViewGeometry g = ortho_geometry(&camera);
  SceneConfig scene;
  scene.style = SceneStyle::kDensity;
  scene.radius = 0.12;
  scene.color.by = ColorBy::kType;
  CutPlane cut;
  cut.normal = {1, 0.3, 0};
  cut.offset = 6.0;
  scene.cuts.push_back(cut);
  BrickSelection sel;
  const RadiusRule radius = radius_rule(scene, cloud.arrays);
  select_density_bricks(cloud.bricks, camera, cull_settings(scene), radius, &sel, nullptr);
  Extent ext;
  ext.lo = {1, 1, 1}, ext.hi = {9, 9, 9};
  const InstanceRecipe recipe =
      make_recipe(cloud.arrays, shading_settings(scene), radius, camera, ext);
  DensityImage pass;
  const CullStats st =
      render_density(cloud.arrays, cloud.bricks, cull_settings(scene), sel, recipe, &pass);
  DensityImage one_by_one;
  one_by_one.reset(g.width, g.height, 4);
  DensitySplatter splat(sel.g, &one_by_one);
  int64_t drawn = 0, cut_away = 0;
  for (int64_t i = 0; i < cloud.arrays.count(); ++i) {
    const glm::dvec3 x = cloud.arrays.position(i);
    if (glm::dot(glm::dvec3(1, 0.3, 0), x) > 6.0) {
      ++cut_away;
      continue;
    }
    drawn += splat.splat(sel.g.to_view(x), 0.12, 1.0, recipe.color(i));
  }
  EXPECT_EQ(st.drawn, drawn);
  EXPECT_EQ(st.cut_culled, cut_away);
  EXPECT_GT(cut_away, 10000);
  EXPECT_TRUE(pass.sum == one_by_one.sum);

  // Level of detail: each brick's prefix, weighted and grown, brick by brick.
  scene.lod.fraction = 0.3;
  select_density_bricks(cloud.bricks, camera, cull_settings(scene), radius, &sel, nullptr);
  const CullStats lod =
      render_density(cloud.arrays, cloud.bricks, cull_settings(scene), sel, recipe, &pass);
  one_by_one.reset(g.width, g.height, 4);
  drawn = 0;
  for (const VisibleBrick &v : sel.visible) {
    const Brick &b = cloud.bricks.bricks[v.brick];
    for (uint32_t k = 0; k < v.keep; ++k) {
      const uint32_t i = cloud.bricks.order[b.first + k];
      const glm::dvec3 x = cloud.arrays.position(i);
      if (v.cut_each && glm::dot(glm::dvec3(1, 0.3, 0), x) > 6.0) continue;
      drawn += splat.splat(sel.g.to_view(x), 0.12 * v.radius_scale, double(b.count) / v.keep,
                           recipe.color(i));
    }
  }
  EXPECT_EQ(lod.drawn, drawn);
  EXPECT_GT(lod.lod_dropped, 20000);
  EXPECT_TRUE(pass.sum == one_by_one.sum);
}

TEST(DensityTransfer, LinearLogAsinhAndAutoRange) {
  DensityImage image;
  image.reset(3, 1, 1);
  image.sum = {0, int64_t(2 * kDensityUnit), int64_t(8 * kDensityUnit)};
  DensityConfig linear;
  const DensityRange r = density_range(image, linear);
  EXPECT_EQ(r.lo, 0.0);
  EXPECT_EQ(r.hi, 8.0);
  EXPECT_DOUBLE_EQ(density_transfer(2.0, DensityTransfer::kLinear, r), 0.25);
  DensityConfig log;
  log.transfer = DensityTransfer::kLog;
  const DensityRange lr = density_range(image, log);
  EXPECT_DOUBLE_EQ(lr.lo, 8e-4);
  EXPECT_NEAR(density_transfer(0.08, DensityTransfer::kLog, lr), 0.5, 1e-12);
  EXPECT_EQ(density_transfer(1e-5, DensityTransfer::kLog, lr), 0.0);
  EXPECT_NEAR(density_transfer(8.0, DensityTransfer::kAsinh, r), 1.0, 1e-12);
  EXPECT_NEAR(density_transfer(0.04, DensityTransfer::kAsinh, r),
              std::asinh(0.5) / std::asinh(100.0), 1e-12);
  DensityConfig fixed;
  fixed.range = std::array<double, 2>{1.0, 3.0};
  EXPECT_EQ(density_range(image, fixed).hi, 3.0);
  EXPECT_EQ(density_transfer(5.0, DensityTransfer::kLinear, density_range(image, fixed)), 1.0);
}

TEST(DensityTransfer, ColorsBlendTheMeanColorOverTheBackground) {
  DensityImage image;
  image.reset(2, 1, 4);
  const int64_t u = int64_t(kDensityUnit);
  // Pixel 1: weight 4, colour channels weight x c / 256: mean color (255, 127.5, 0).
  image.sum = {0, 0, 0, 0, 4 * u, 4 * u * 255 / 256, 2 * u * 255 / 256, 0};
  const uint8_t background[4] = {0, 0, 255, 255};
  Frame frame;
  map_density(image, DensityConfig{}, *Colormap::named("grayscale"), background, &frame);
  ASSERT_EQ(frame.width, 2);
  EXPECT_EQ(frame.rgba[0], 0);  // no footprint: background
  EXPECT_EQ(frame.rgba[2], 255);
  EXPECT_EQ(frame.rgba[4], 255);  // t = 1 (the auto range's top): the mean color itself
  EXPECT_EQ(frame.rgba[5], 128);
  EXPECT_EQ(frame.rgba[6], 0);
  EXPECT_EQ(frame.depth[1], kBackgroundDepth);
}

// Ranges whose width under- or overflows a double: every transfer stays in [0, 1] (a NaN gave
// uniform grey), clamped as documented, and the range is named for a warning.
TEST(DensityTransfer, RangesBeyondDoublePrecisionAreClampedNotNaN) {
  const DensityRange tiny{0.0, 5e-324}, huge{-1e308, 1e308};
  for (const DensityTransfer transfer : {DensityTransfer::kLinear, DensityTransfer::kAsinh}) {
    EXPECT_EQ(density_transfer(1.0 / kDensityUnit, transfer, tiny), 1.0);
    EXPECT_EQ(density_transfer(3.0, transfer, tiny), 1.0);
    const double mid = density_transfer(3.0, transfer, huge);
    EXPECT_TRUE(mid > 0.4 && mid < 0.9) << mid;
  }
  EXPECT_NEAR(density_transfer(3.0, DensityTransfer::kLinear, huge), 0.5, 1e-12);
  EXPECT_NEAR(density_transfer(3.0, DensityTransfer::kAsinh, huge),
              std::asinh(50.0) / std::asinh(100.0), 1e-12);
  EXPECT_EQ(density_transfer(std::nan(""), DensityTransfer::kLinear, DensityRange{0.0, 1.0}), 0.0);
  DensityConfig config;
  EXPECT_EQ(density_range_problem(config), "");  // auto
  config.range = std::array<double, 2>{0.0, 5e-324};
  EXPECT_NE(density_range_problem(config).find("narrower than the summed weight's resolution"),
            std::string::npos);
  config.range = std::array<double, 2>{-1e308, 1e308};
  EXPECT_NE(density_range_problem(config).find("wider than a double can hold"), std::string::npos);
  config.range = std::array<double, 2>{0.0, 1.0};
  EXPECT_EQ(density_range_problem(config), "");
}

// Every particle at one point with radius 0: the automatic camera framed a point 1e-12 away,
// behind its near plane, and the image was blank. It frames kMinFramedExtent around it instead,
// the particles in front of the near plane, at the centre of the image.
TEST(DensitySplat, ParticlesAtOnePointWithRadiusZeroAreFramed) {
  for (const glm::dvec3 point : {glm::dvec3(5, 5, 5), glm::dvec3(0, 0, 0), glm::dvec3(1e6, 0, 0)}) {
    Camera camera;
    ASSERT_TRUE(make_camera(CameraConfig{}, point, point, 0.0, 32, 32, &camera).ok());
    EXPECT_TRUE(camera.point_bounds);
    const glm::dvec4 v = camera.view * glm::dvec4(point, 1.0);
    EXPECT_GT(-v.z, camera.near_plane);
    EXPECT_LT(-v.z, camera.far_plane);
    const glm::dvec4 clip = camera.projection * v;
    EXPECT_NEAR(clip.x / clip.w, 0.0, 1e-6);
    EXPECT_NEAR(clip.y / clip.w, 0.0, 1e-6);
  }
  Camera spread;
  ASSERT_TRUE(make_camera(CameraConfig{}, {0, 0, 0}, {1, 1, 1}, 0.0, 32, 32, &spread).ok());
  EXPECT_FALSE(spread.point_bounds);
}

}  // namespace
}  // namespace lantern
