// Every configuration shipped in config/ must load: they are the documentation users copy.
#include <gtest/gtest.h>

#include <filesystem>

#include "core/config/config_loader.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

std::vector<std::string> example_files() {
  std::vector<std::string> files;
  for (const auto &entry : std::filesystem::directory_iterator(LANTERN_CONFIG_DIR)) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".yaml" || ext == ".yml") files.push_back(entry.path().string());
  }
  return files;
}

TEST(ExampleConfigs, EveryFileInConfigDirLoads) {
  const std::vector<std::string> files = example_files();
  ASSERT_GE(files.size(), 4u) << "expected the example configurations in " LANTERN_CONFIG_DIR;
  for (const std::string &file : files) {
    Config c;
    EXPECT_OK(load_config(file, &c)) << file;
    EXPECT_FALSE(c.scenes.empty() && !c.dump.enabled) << file;
  }
}

TEST(ExampleConfigs, TwoScenesHasBothProjectionsAndColorings) {
  Config c;
  ASSERT_OK(load_config(std::string(LANTERN_CONFIG_DIR) + "/two_scenes.yaml", &c));
  ASSERT_EQ(c.scenes.size(), 2u);
  EXPECT_EQ(c.scenes[0].camera.projection, Projection::kPerspective);
  EXPECT_EQ(c.scenes[1].camera.projection, Projection::kOrthographic);
  EXPECT_EQ(c.scenes[0].color.by, ColorBy::kType);
  EXPECT_EQ(c.scenes[1].color.by, ColorBy::kScalar);
}

TEST(ExampleConfigs, ExrDepthWritesExr) {
  Config c;
  ASSERT_OK(load_config(std::string(LANTERN_CONFIG_DIR) + "/exr_depth.yaml", &c));
  ASSERT_FALSE(c.scenes.empty());
  EXPECT_EQ(c.scenes[0].output.format, ImageFormat::kExr);
}

}  // namespace
}  // namespace lantern
