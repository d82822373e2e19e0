// Absent keys take the defaults documented in config.h and config/README.md; present keys land
// in the right fields.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "core/config/config_loader.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

Config load_ok(const std::string &document) {
  Config c;
  EXPECT_OK(load_config(document, &c)) << document;
  return c;
}

TEST(ConfigDefaults, MinimalSceneGetsEveryDefault) {
  const Config c = load_ok("scenes:\n  - {}\n");
  EXPECT_EQ(c.schedule.every, 0);
  EXPECT_TRUE(c.schedule.steps.empty());
  EXPECT_EQ(c.stats_file, "");
  EXPECT_FALSE(c.verbose);
  EXPECT_FALSE(c.dump.enabled);
  ASSERT_EQ(c.scenes.size(), 1u);
  const SceneConfig &s = c.scenes[0];
  EXPECT_EQ(s.name, "scene");
  EXPECT_EQ(s.width, 1024);
  EXPECT_EQ(s.height, 1024);
  EXPECT_EQ(s.radius, 0.5);
  EXPECT_FALSE(s.per_particle_radius);
  EXPECT_EQ(s.camera.projection, Projection::kPerspective);
  EXPECT_EQ(s.camera.fov_y, 30.0);
  EXPECT_EQ(s.camera.zoom, 1.0);
  EXPECT_FALSE(s.camera.position);
  EXPECT_FALSE(s.camera.near_plane);
  EXPECT_EQ(s.color.by, ColorBy::kType);
  EXPECT_EQ(s.color.colormap, "viridis");
  EXPECT_FALSE(s.color.range);
  EXPECT_EQ(s.output.pattern, "lantern_{step:06d}.png");
  EXPECT_EQ(s.output.format, ImageFormat::kPng);
  EXPECT_EQ(s.output.jpeg_quality, 95);
  EXPECT_EQ(s.output.compression_level, 1);
  EXPECT_FALSE(s.output.asynchronous);
  EXPECT_TRUE(s.output.exr_half);
  EXPECT_TRUE(s.culling.frustum);
  EXPECT_EQ(s.culling.occlusion, OcclusionMode::kAuto);
  EXPECT_EQ(s.culling.nine_spheres_radius, NineSpheresRadius::kWorld);  // images unchanged
  EXPECT_EQ(s.lod.budget, 0);
  EXPECT_EQ(s.lod.fraction, 1.0);
  EXPECT_TRUE(s.cuts.empty());
}

TEST(ConfigDefaults, UnnamedScenesGetDistinctNames) {
  const Config c = load_ok(
      "scenes:\n  - {output: {pattern: 'a_{step}.png'}}\n  - {output: {pattern: "
      "'b_{step}.png'}}\n");
  ASSERT_EQ(c.scenes.size(), 2u);
  EXPECT_EQ(c.scenes[0].name, "scene");
  EXPECT_EQ(c.scenes[1].name, "scene1");
}

TEST(ConfigDefaults, EveryKeyIsRead) {
  const Config c = load_ok(R"(
schedule: {every: 10, start: 5, steps: [1, 2]}
stats: out/stats.jsonl
verbose: true
dump: {file: d.h5, schedule: {every: 100}, fields: [position, id], precision: float32}
scenes:
  - name: side
    width: 640
    height: 480
    background: [0, 0, 0.5]
    radius: per_particle
    camera:
      projection: orthographic
      fov: 45
      azimuth: 10
      elevation: -30
      zoom: 2.5
      position: [10, 0, 0]
      look_at: [0, 1, 0]
      up: [0, 1, 0]
      near: 0.1
      far: 100
    color:
      by: scalar
      solid: [1, 0, 0]
      palette: [[1, 0, 0], [0, 1, 0]]
      colormap: coolwarm
      range: [-1, 2]
    output: {pattern: "img/{scene}_{step:04d}.exr", jpeg_quality: 50, exr_color: float}
    culling: {frustum: false, occlusion: nine_spheres_sorted, nine_spheres_radius: equivalent,
              confidence: 0.9, probabilistic_budget: 3, probabilistic_patience: 5}
    lod: {budget: 1000, fraction: 0.25, min_pixels: 1.5, point_path: yes}
    cut_planes:
      - {normal: [1, 0, 0], offset: 2}
)");
  EXPECT_EQ(c.schedule.every, 10);
  EXPECT_EQ(c.schedule.start, 5);
  EXPECT_EQ(c.schedule.steps, (std::vector<int64_t>{1, 2}));
  EXPECT_EQ(c.stats_file, "out/stats.jsonl");
  EXPECT_TRUE(c.verbose);
  EXPECT_TRUE(c.dump.enabled);
  EXPECT_EQ(c.dump.file, "d.h5");
  EXPECT_EQ(c.dump.schedule.every, 100);
  EXPECT_EQ(c.dump.fields, (std::vector<std::string>{"position", "id"}));
  EXPECT_TRUE(c.dump.single_precision);
  ASSERT_EQ(c.scenes.size(), 1u);
  const SceneConfig &s = c.scenes[0];
  EXPECT_EQ(s.name, "side");
  EXPECT_EQ(s.width, 640);
  EXPECT_EQ(s.height, 480);
  EXPECT_EQ(s.background[2], 0.5);
  EXPECT_TRUE(s.per_particle_radius);
  EXPECT_EQ(s.camera.projection, Projection::kOrthographic);
  EXPECT_EQ(s.camera.fov_y, 45);
  EXPECT_EQ(s.camera.azimuth, 10);
  EXPECT_EQ(s.camera.elevation, -30);
  EXPECT_EQ(s.camera.zoom, 2.5);
  ASSERT_TRUE(s.camera.position);
  EXPECT_EQ((*s.camera.position)[0], 10);
  EXPECT_EQ(s.camera.look_at[1], 1);
  EXPECT_EQ(s.camera.up[1], 1);
  EXPECT_EQ(*s.camera.near_plane, 0.1);
  EXPECT_EQ(*s.camera.far_plane, 100);
  EXPECT_EQ(s.color.by, ColorBy::kScalar);
  EXPECT_EQ(s.color.solid[0], 1);
  EXPECT_EQ(s.color.palette.size(), 2u);
  EXPECT_EQ(s.color.colormap, "coolwarm");
  ASSERT_TRUE(s.color.range);
  EXPECT_EQ((*s.color.range)[0], -1);
  EXPECT_EQ((*s.color.range)[1], 2);
  EXPECT_EQ(s.output.pattern, "img/{scene}_{step:04d}.exr");
  EXPECT_EQ(s.output.format, ImageFormat::kExr);
  EXPECT_EQ(s.output.jpeg_quality, 50);
  EXPECT_FALSE(s.output.exr_half);
  EXPECT_FALSE(s.culling.frustum);
  EXPECT_EQ(s.culling.occlusion, OcclusionMode::kNineSpheresSorted);
  EXPECT_EQ(s.culling.nine_spheres_radius, NineSpheresRadius::kEquivalent);
  EXPECT_EQ(s.culling.probabilistic.confidence, 0.9);
  EXPECT_EQ(s.culling.probabilistic.budget, 3);
  EXPECT_EQ(s.culling.probabilistic.patience, 5);
  EXPECT_EQ(s.lod.budget, 1000);
  EXPECT_EQ(s.lod.fraction, 0.25);
  EXPECT_EQ(s.lod.min_pixels, 1.5);
  EXPECT_TRUE(s.lod.point_path);
  ASSERT_EQ(s.cuts.size(), 1u);
  EXPECT_EQ(s.cuts[0].normal[0], 1);
  EXPECT_EQ(s.cuts[0].offset, 2);
}

// A keyframe's left-out keys carry the previous keyframe's values, the first's the camera's.
TEST(ConfigDefaults, CameraPathKeyframesCarryLeftOutKeys) {
  const Config c = load_ok(R"(
scenes:
  - camera:
      azimuth: 15
      zoom: 2
      path:
        - {step: 0, elevation: 30}
        - {step: 500, azimuth: 180}
        - {step: 800, zoom: 4, elevation: -10}
)");
  const CameraConfig &cam = c.scenes[0].camera;
  ASSERT_EQ(cam.path.size(), 3u);
  EXPECT_TRUE(cam.moves());
  const double expected[3][4] = {{0, 15, 30, 2}, {500, 180, 30, 2}, {800, 180, -10, 4}};
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(cam.path[i].step, expected[i][0]) << i;
    EXPECT_EQ(cam.path[i].azimuth, expected[i][1]) << i;
    EXPECT_EQ(cam.path[i].elevation, expected[i][2]) << i;
    EXPECT_EQ(cam.path[i].zoom, expected[i][3]) << i;
  }
  const Config orbit = load_ok("scenes:\n  - camera: {orbit: {degrees_per_step: -0.25}}\n");
  EXPECT_TRUE(orbit.scenes[0].camera.orbit.enabled);
  EXPECT_EQ(orbit.scenes[0].camera.orbit.degrees_per_step, -0.25);
  EXPECT_FALSE(load_ok("scenes: [{}]\n").scenes[0].camera.moves());
}

TEST(ConfigDefaults, FormatFollowsPatternExtension) {
  const std::vector<std::pair<std::string, ImageFormat>> cases = {
      {"a.png", ImageFormat::kPng},  {"a.jpg", ImageFormat::kJpeg},  {"a.JPEG", ImageFormat::kJpeg},
      {"a.tif", ImageFormat::kTiff}, {"a.tiff", ImageFormat::kTiff}, {"a.exr", ImageFormat::kExr}};
  for (const auto &[pattern, format] : cases) {
    const Config c = load_ok("scenes: [{output: {pattern: '" + pattern + "'}}]\n");
    ASSERT_EQ(c.scenes.size(), 1u);
    EXPECT_EQ(c.scenes[0].output.format, format) << pattern;
  }
  // An explicit format is needed (and used) when the pattern has no image extension.
  const Config c = load_ok("scenes: [{output: {pattern: 'frame_{step}', format: tiff}}]\n");
  EXPECT_EQ(c.scenes[0].output.format, ImageFormat::kTiff);
}

TEST(ConfigDefaults, RangeAutoAndRadiusNumber) {
  const Config c = load_ok("scenes: [{radius: 0.25, color: {range: auto}}]\n");
  EXPECT_EQ(c.scenes[0].radius, 0.25);
  EXPECT_FALSE(c.scenes[0].color.range);
}

TEST(ConfigDefaults, DumpAloneIsEnough) {
  const Config c = load_ok("dump: {file: particles.h5}\n");
  EXPECT_TRUE(c.dump.enabled);
  EXPECT_TRUE(c.scenes.empty());
}

TEST(ConfigDefaults, InlineFlowDocument) {
  const Config c = load_ok("{scenes: [{width: 64, height: 32}]}");
  EXPECT_EQ(c.scenes[0].width, 64);
  EXPECT_EQ(c.scenes[0].height, 32);
}

TEST(ConfigDefaults, LoadsFromFile) {
  const std::string path = ::testing::TempDir() + "lantern_config_test.yaml";
  std::ofstream(path) << "scenes:\n  - width: 8\n";
  Config c;
  EXPECT_OK(load_config(path, &c));
  EXPECT_EQ(c.scenes[0].width, 8);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace lantern
