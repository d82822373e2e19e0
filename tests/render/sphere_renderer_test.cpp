// The impostor renderer against analytic spheres: silhouettes, depths, intersections, tiling.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/camera/camera.h"
#include "core/render/gl/gl_session.h"
#include "core/view/view_geometry.h"
#include "tests/support/gl_test.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

constexpr uint8_t kWhite[4] = {255, 255, 255, 255};

class SphereRenderTest : public testing::GlTest {
 protected:
  // An explicit camera on the +z axis at distance `d`, looking at the origin.
  Camera camera(Projection projection, double d, int w, int h) {
    CameraConfig cfg;
    cfg.projection = projection;
    cfg.position = std::array<double, 3>{0, 0, d};
    cfg.look_at = {0, 0, 0};
    cfg.up = {0, 1, 0};
    cfg.fov_y = 40.0;
    Camera cam;
    EXPECT_OK(make_camera(cfg, {-2, -2, -2}, {2, 2, 2}, 0.0, w, h, &cam));
    return cam;
  }

  Frame render(const Camera &cam, const std::vector<SphereInstance> &spheres) {
    Frame f;
    RenderTimings t;
    EXPECT_OK(renderer_->render(cam.render_view(kWhite), spheres.data(), spheres.size(), &f, &t));
    return f;
  }
};

SphereInstance sphere(float x, float y, float z, float r, uint8_t red, uint8_t green) {
  return SphereInstance{x, y, z, r, {red, green, 0, 255}};
}

// Radius in pixels of the projected silhouette of a sphere of radius r centred on the view axis
// at distance d: the tangent cone's half-angle, through the projection.
double silhouette_pixels(const Camera &cam, double r, double d) {
  if (cam.orthographic) return r * cam.projection[1][1] * cam.height / 2.0;
  return r / std::sqrt(d * d - r * r) * cam.projection[1][1] * cam.height / 2.0;
}

void expect_circle(const Frame &f, double radius_px) {
  const double cx = f.width / 2.0, cy = f.height / 2.0;
  int inside_missing = 0, outside_drawn = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const double dist = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      const bool drawn = f.depth[f.index(x, y)] < 1.0f;
      if (dist < radius_px - 1.0 && !drawn) ++inside_missing;
      if (dist > radius_px + 1.0 && drawn) ++outside_drawn;
    }
  EXPECT_EQ(inside_missing, 0);
  EXPECT_EQ(outside_drawn, 0);
}

TEST_F(SphereRenderTest, PerspectiveSilhouetteAndDepthMatchAnalytic) {
  const double d = 10.0, r = 1.5;
  const Camera cam = camera(Projection::kPerspective, d, 256, 256);
  const Frame f = render(cam, {sphere(0, 0, 0, float(r), 255, 0)});
  expect_circle(f, silhouette_pixels(cam, r, d));
  // The pixel nearest the centre sees the sphere's front point, at distance d - r.
  const float depth = f.depth[f.index(128, 128)];
  EXPECT_NEAR(cam.window_depth_to_distance(depth), d - r, 1e-3);
}

TEST_F(SphereRenderTest, OrthographicSilhouetteAndDepthMatchAnalytic) {
  const double d = 10.0, r = 0.8;
  const Camera cam = camera(Projection::kOrthographic, d, 200, 200);
  const Frame f = render(cam, {sphere(0, 0, 0, float(r), 255, 0)});
  expect_circle(f, silhouette_pixels(cam, r, d));
  EXPECT_NEAR(cam.window_depth_to_distance(f.depth[f.index(100, 100)]), d - r, 1e-3);
}

// Two spheres that cut each other: each pixel shows whichever surface is nearer, so the color
// boundary is the analytic intersection curve.
TEST_F(SphereRenderTest, IntersectingSpheresShowTheAnalyticIntersectionCurve) {
  const double ra = 0.6, rb = 0.5;
  const glm::dvec3 a{-0.3, 0.0, 0.0}, b{0.25, 0.1, 0.2};
  const Camera cam = camera(Projection::kOrthographic, 10.0, 768, 768);
  const Frame f = render(cam, {sphere(float(a.x), float(a.y), float(a.z), float(ra), 255, 0),
                               sphere(float(b.x), float(b.y), float(b.z), float(rb), 0, 255)});
  const double px = 2.0 / (cam.projection[0][0] * f.width);  // world units per pixel
  int wrong = 0, checked = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const double wx = (x + 0.5 - f.width / 2.0) * px, wy = (f.height / 2.0 - y - 0.5) * px;
      const double ha = ra * ra - (wx - a.x) * (wx - a.x) - (wy - a.y) * (wy - a.y);
      const double hb = rb * rb - (wx - b.x) * (wx - b.x) - (wy - b.y) * (wy - b.y);
      if (ha < 0 || hb < 0) continue;  // only where both spheres cover the pixel
      const double za = a.z + std::sqrt(ha), zb = b.z + std::sqrt(hb);
      if (std::abs(za - zb) < 2 * px) continue;  // within a pixel of the curve
      ++checked;
      const uint8_t *c = &f.rgba[4 * f.index(x, y)];
      const bool shows_a = c[0] > c[1];
      if (shows_a != (za > zb)) ++wrong;
    }
  EXPECT_GT(checked, 1000);
  EXPECT_EQ(wrong, 0);
}

// Tiling (images larger than the tile limit) must not change a single pixel.
TEST_F(SphereRenderTest, TiledRenderingIsBitIdenticalToOneTile) {
  const Camera cam = camera(Projection::kPerspective, 6.0, 640, 360);
  std::vector<SphereInstance> s;
  for (int i = 0; i < 200; ++i)
    s.push_back(sphere(-2.0f + 0.02f * i, 0.007f * i - 0.7f, 0.005f * i, 0.2f, uint8_t(i), 80));
  const int limit = renderer_->max_tile_size();
  const Frame whole = render(cam, s);
  renderer_->set_max_tile_size(100);  // 7 x 4 tiles, with ragged edges
  const Frame tiled = render(cam, s);
  renderer_->set_max_tile_size(limit);
  int drawn = 0;
  for (size_t i = 0; i < whole.pixel_count(); ++i) drawn += whole.depth[i] < 1.0f;
  EXPECT_GT(drawn, 10000);
  EXPECT_EQ(whole.rgba, tiled.rgba);
  EXPECT_EQ(whole.depth, tiled.depth);
}

TEST_F(SphereRenderTest, RepeatedRendersAreBitIdentical) {
  const Camera cam = camera(Projection::kPerspective, 5.0, 300, 200);
  std::vector<SphereInstance> s;
  for (int i = 0; i < 1000; ++i)
    s.push_back(sphere(std::sin(i * 1.3f), std::cos(i * 0.7f), std::sin(i * 0.31f), 0.1f,
                       uint8_t(i), uint8_t(3 * i)));
  const Frame a = render(cam, s), b = render(cam, s);
  EXPECT_EQ(a.rgba, b.rgba);
  EXPECT_EQ(a.depth, b.depth);
}

// Two coincident spheres, red and blue, tie at every pixel they cover: the smaller color (blue, R
// = 0) must win in either drawing order, in both projections, with many copies of each in between
// (several draw chunks are not needed: a tie is decided per fragment).
TEST_F(SphereRenderTest, DepthTiesGoToTheSmallerColorInEitherDrawingOrder) {
  for (const Projection projection : {Projection::kPerspective, Projection::kOrthographic}) {
    const Camera cam = camera(projection, 6.0, 160, 120);
    const SphereInstance red = sphere(0.3f, -0.2f, 0.1f, 1.0f, 255, 0);
    SphereInstance blue = red;
    blue.rgba[0] = 0, blue.rgba[2] = 255;
    const Frame red_first = render(cam, {red, blue, red}), blue_first = render(cam, {blue, red});
    const Frame blue_alone = render(cam, {blue});
    int drawn = 0;
    for (size_t i = 0; i < blue_alone.pixel_count(); ++i) drawn += blue_alone.depth[i] < 1.0f;
    EXPECT_GT(drawn, 500);
    EXPECT_EQ(red_first.rgba, blue_alone.rgba);
    EXPECT_EQ(blue_first.rgba, blue_alone.rgba);
    EXPECT_EQ(red_first.depth, blue_alone.depth);
    EXPECT_EQ(blue_first.depth, blue_alone.depth);
  }
}

// A sphere cut by the near plane keeps the pixels whose ray meets it beyond the plane (the CPU
// raster's crescent), in both projections, wherever it lies across the image: the quad the
// vertex shader builds must not be clipped away with the cut.
TEST_F(SphereRenderTest, SpheresCutByTheNearPlaneKeepTheirFarSide) {
  for (const Projection projection : {Projection::kPerspective, Projection::kOrthographic}) {
    CameraConfig cfg;
    cfg.projection = projection;
    cfg.position = std::array<double, 3>{0, -10, 0};
    cfg.look_at = {0, 0, 0};
    cfg.fov_y = 60.0;
    cfg.near_plane = 9.4;
    cfg.far_plane = 100.0;
    Camera cam;
    ASSERT_OK(make_camera(cfg, {-5, -5, -5}, {5, 5, 5}, 1.0, 160, 120, &cam));
    for (const float x : {0.0f, 2.0f, 4.0f}) {
      const glm::dvec3 c(x, 0.0, 0.0);
      const Frame f = render(cam, {sphere(float(c.x - cam.origin.x), float(c.y - cam.origin.y),
                                          float(c.z - cam.origin.z), 1.0f, 255, 0)});
      // Every pixel whose ray meets the sphere beyond the near plane, by the same ray in double.
      const ViewGeometry g = ViewGeometry::from_camera(cam, 20.0);
      const glm::dvec3 v = g.to_view(c);
      int expected = 0, drawn = 0, disagree = 0;
      for (int y = 0; y < f.height; ++y)
        for (int px = 0; px < f.width; ++px) {
          glm::dvec3 origin(0.0), dir(0.0, 0.0, -1.0);
          if (g.orthographic)
            origin = {g.ray_x(px), g.ray_y(y), 0.0};
          else
            dir = glm::normalize(glm::dvec3(g.ray_x(px), g.ray_y(y), -1.0));
          const glm::dvec3 oc = v - origin;
          const double b = glm::dot(oc, dir), h2 = 1.0 - glm::dot(oc - b * dir, oc - b * dir);
          const double t = b - std::sqrt(std::max(h2, 0.0));
          const bool hit = h2 > 0.0 && -(origin + t * dir).z >= g.near_plane;
          const bool is_drawn = f.depth[f.index(px, y)] < 1.0f;
          expected += hit, drawn += is_drawn, disagree += hit != is_drawn;
        }
      EXPECT_GT(expected, 20) << "x = " << x;
      EXPECT_LE(disagree, 2) << "x = " << x << ": " << drawn << " drawn, " << expected
                             << " expected";
    }
  }
}

}  // namespace
}  // namespace lantern
