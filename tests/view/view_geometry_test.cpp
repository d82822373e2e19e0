// ViewGeometry's batched sphere rectangles against its one-at-a-time ones; PixelRays' row spans
// of extreme spheres.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/view/pixel_rays.h"
#include "core/view/view_geometry.h"

namespace lantern {
namespace {

ViewGeometry perspective(int width, int height, bool orthographic) {
  ViewGeometry g;
  g.width = width, g.height = height;
  g.orthographic = orthographic;
  g.near_plane = 0.05;
  g.sx = 1.7 * height / width, g.sy = 1.7;  // a 60-degree vertical field of view
  if (orthographic) g.sx = 0.1, g.sy = 0.1 * width / height, g.tx = 0.03, g.ty = -0.02;
  g.eps = 1e-5 * 40.0;
  return g;
}

// Spheres from well inside the view to far outside it, behind and across half the near plane,
// wider than their distance (a negative d^2 - r^2), sub-pixel and huge, and a few non-finite
// ones: x, y, z, r and a fifth double (a Candidate's index and scale), as the CPU raster lays
// them out.
std::vector<double> spheres(std::mt19937_64 *rng, int n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> s;
  for (int k = 0; k < n; ++k) {
    const double d = k % 17 == 0 ? 0.05 * u(*rng) : std::pow(10.0, 3.0 * u(*rng) - 1.0);
    const double spread = k % 5 == 0 ? 3.0 : 0.7;
    double x = (2.0 * u(*rng) - 1.0) * spread * d, y = (2.0 * u(*rng) - 1.0) * spread * d;
    double r = k % 11 == 0 ? 2.0 * d * u(*rng) : std::pow(10.0, 4.0 * u(*rng) - 4.0) * d;
    double z = -d;
    if (k % 97 == 3) x = std::numeric_limits<double>::quiet_NaN();
    if (k % 89 == 5) y = std::numeric_limits<double>::infinity();
    if (k % 83 == 7) r = 0.0;
    if (k % 79 == 9) z = 1.0;  // behind the eye
    s.insert(s.end(), {x, y, z, r, 12345.0});
  }
  return s;
}

TEST(ViewGeometry, BatchedTightRectanglesAreTheOneByOneRectangles) {
  std::mt19937_64 rng(7);
  int64_t compared = 0, nonempty = 0;
  for (const bool orthographic : {false, true})
    for (const int width : {1, 7, 640, 1024, 1921})
      for (const int n : {0, 1, 2, 3, 64, 1001}) {
        const ViewGeometry g = perspective(width, width * 3 / 4 + 1, orthographic);
        const std::vector<double> s = spheres(&rng, n);
        for (const size_t stride : {size_t(5), size_t(4)}) {
          std::vector<double> packed;
          for (int k = 0; k < n; ++k)
            packed.insert(packed.end(), s.begin() + 5 * k, s.begin() + 5 * k + long(stride));
          std::vector<PixelRect> batch(size_t(n) + 1, PixelRect{7, 7, 7, 7});
          for (const double slack : {0.05, 0.75}) {
            g.sphere_rects_tight(packed.data(), stride, n, slack, batch.data());
            for (int k = 0; k < n; ++k) {
              const double *p = &packed[size_t(k) * stride];
              const PixelRect one = g.sphere_rect_tight({p[0], p[1], p[2]}, p[3], slack);
              const PixelRect &b = batch[size_t(k)];
              ASSERT_TRUE(b.x0 == one.x0 && b.y0 == one.y0 && b.x1 == one.x1 && b.y1 == one.y1)
                  << "sphere " << k << " of " << n << " (" << p[0] << ", " << p[1] << ", " << p[2]
                  << ", r " << p[3] << "), width " << width << ", orthographic " << orthographic
                  << ": batched " << b.x0 << " " << b.y0 << " " << b.x1 << " " << b.y1
                  << ", one by one " << one.x0 << " " << one.y0 << " " << one.x1 << " " << one.y1;
              ++compared, nonempty += !one.empty() && one.area() < int64_t(g.width) * g.height;
            }
            const PixelRect &past = batch[size_t(n)];
            EXPECT_TRUE(past.x0 == 7 && past.y0 == 7 && past.x1 == 7 && past.y1 == 7);
          }
        }
      }
  EXPECT_GT(compared, 20000);
  EXPECT_GT(nonempty, 5000);  // rectangles that are neither empty nor the whole image
}

TEST(PixelRays, RowSpansOfExtremeSpheresStayWithinTheRow) {
  // Far beyond the image's side (a finite column far past int's range) and at 1e100 (the
  // perspective quadratic's squares overflow: inf - inf). Both converted NaN or out-of-range
  // doubles to int, which gave spans starting at INT_MIN (read as column indices by the
  // hierarchical z-buffer).
  for (const bool ortho : {false, true}) {
    const ViewGeometry g = perspective(64, 48, ortho);
    PixelRays rays;
    rays.reset(g);
    const struct {
      glm::dvec3 c;
      double r;
    } cases[] = {{glm::dvec3(1e15, 0.0, -10.0), 0.5},
                 {glm::dvec3(-1e15, 0.0, -10.0), 0.5},
                 {glm::dvec3(0.2e100, 0.1e100, -1e100), 0.01e100},
                 {glm::dvec3(0.0, 0.0, -1e100), 0.3e100}};
    for (const auto &k : cases)
      for (int row = 0; row < g.height; ++row) {
        int x0 = -7, x1 = -7;
        if (!rays.row_span(k.c, k.r * k.r, row, 3, 60, 2.0, &x0, &x1)) continue;
        SCOPED_TRACE(::testing::Message()
                     << "ortho " << ortho << " c.x " << k.c.x << " row " << row);
        EXPECT_GE(x0, 3);
        EXPECT_LE(x0, x1);
        EXPECT_LE(x1, 60);
      }
  }
}

}  // namespace
}  // namespace lantern
