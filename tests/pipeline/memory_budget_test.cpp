// The per-rank memory estimate of a configuration's scenes and its check (memory_budget.h).
#include "core/pipeline/memory_budget.h"

#include <gtest/gtest.h>

#include <string>

namespace lantern {
namespace {

SceneConfig scene(const std::string &name, int w, int h, int samples) {
  SceneConfig s;
  s.name = name;
  s.width = w;
  s.height = h;
  s.samples = samples;
  return s;
}

TEST(MemoryBudget, TheEstimateFollowsTheDocumentedFormula) {
  Config config;
  config.scenes.push_back(scene("plain", 1000, 500, 1));
  config.scenes.push_back(scene("sampled", 1000, 500, 16));
  SceneConfig density = scene("density", 1000, 500, 1);
  density.style = SceneStyle::kDensity;
  density.color.by = ColorBy::kSolid;
  config.scenes.push_back(density);
  SceneConfig asynchronous = scene("async", 1000, 500, 1);
  asynchronous.output.asynchronous = true;
  config.scenes.push_back(asynchronous);
  const auto m = estimate_scene_memory(config);
  ASSERT_EQ(m.size(), 4u);
  const int64_t p = 500000;
  EXPECT_EQ(m[0].name, "plain");
  EXPECT_EQ(m[0].bytes, 2 * p * 8);
  EXPECT_EQ(m[1].bytes, 2 * p * 16 * 8 + 2 * p * 8);
  EXPECT_EQ(m[2].bytes, 2 * p * 1 * 8 + p * 8);
  EXPECT_EQ(m[3].bytes, 3 * p * 8);
}

TEST(MemoryBudget, TheSumIsCheckedAndTheMessageNamesTotalScenesAndShare) {
  Config config;
  for (int i = 0; i < 32; ++i)
    config.scenes.push_back(scene("s" + std::to_string(i), 2048, 2048, 64));
  const auto m = estimate_scene_memory(config);
  const MemoryShare share{int64_t(24) << 30, "24.0 GiB on this node shared by 1 rank"};
  const Status s = check_scene_memory(m, share);
  EXPECT_EQ(s.code, StatusCode::kOutOfMemory);
  EXPECT_NE(s.message.find("the 32 scenes need about 130.0 GiB per rank"), std::string::npos)
      << s.message;
  EXPECT_NE(s.message.find("'s0' 4.1 GiB, 's1' 4.1 GiB"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("and 24 more"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("24.0 GiB on this node shared by 1 rank allow (24.0 GiB per rank)"),
            std::string::npos)
      << s.message;
  // One such scene fits.
  config.scenes.resize(1);
  EXPECT_TRUE(check_scene_memory(estimate_scene_memory(config), share).ok());
}

TEST(MemoryBudget, ByteText) {
  EXPECT_EQ(byte_text(512), "512 bytes");
  EXPECT_EQ(byte_text(int64_t(3) << 29), "1.5 GiB");
  EXPECT_EQ(byte_text(int64_t(640) << 20), "640.0 MiB");
}

}  // namespace
}  // namespace lantern
