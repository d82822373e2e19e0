// yaml-cpp 0.7 on text it mishandles (core/config/yaml_guard.h): a stray ',' made YAML::LoadAll
// loop forever with growing memory (found by fuzz_config, tests/fuzz); nesting beyond its
// recursion limit said "bad file", a 1 MB key "end of map flow not found". Each is a prompt
// LANTERN_ERR_CONFIG naming the cause.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <future>
#include <string>

#include "core/config/config_loader.h"

namespace lantern {
namespace {

// load_config_text, given a few seconds: a loader that does not return fails the test and ends
// the process (its thread cannot be stopped, and it would take the machine's memory with it).
Status load_within_seconds(const std::string &text) {
  auto loading = std::async(std::launch::async, [text] {
    Config config;
    return load_config_text(text, "inline config", &config);
  });
  if (loading.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    ADD_FAILURE() << "load_config_text did not return within 10 s on: " << text.substr(0, 60);
    std::_Exit(1);
  }
  return loading.get();
}

TEST(YamlGuard, AStrayCommaIsAnErrorNotAnEndlessLoop) {
  for (const char *text : {",", "[1],", ", x", "scenes: [{}]\n---\n,\n"}) {
    const Status s = load_within_seconds(text);
    EXPECT_EQ(s.code, StatusCode::kConfig) << text;
    EXPECT_NE(s.message.find("no flow collection"), std::string::npos) << s.message;
  }
  // The minimised input the fuzzer found.
  const Status s = load_within_seconds(
      ", height: 8,(camera: {position: [0, 0, 9], look_at: [0, 0, 0]}}\n M\xff\xff"
      "0], x: 1}]\n");  // split: "\xff0" would be one escape, out of range
  EXPECT_EQ(s.code, StatusCode::kConfig);
  // Commas inside scalars and flow collections are fine.
  const Status fine =
      load_within_seconds("scenes: [{name: a, output: {pattern: 'a,{step}.png'}}, {name: c}]\n");
  EXPECT_TRUE(fine.ok()) << fine.message;
}

TEST(YamlGuard, DeepNestingSaysSo) {
  const Status s = load_within_seconds(std::string(100000, '[') + std::string(100000, ']') + "\n");
  EXPECT_EQ(s.code, StatusCode::kConfig);
  EXPECT_NE(s.message.find("nested too deeply"), std::string::npos) << s.message.substr(0, 300);
  EXPECT_EQ(s.message.find("bad file"), std::string::npos);
}

TEST(YamlGuard, AnOverlongKeySaysSo) {
  const Status s = load_within_seconds("{" + std::string(1000000, 'k') + ": 1}\n");
  EXPECT_EQ(s.code, StatusCode::kConfig);
  EXPECT_NE(s.message.find("a key of 1000000 characters at line 1"), std::string::npos)
      << s.message.substr(0, 300);
  EXPECT_NE(s.message.find("at most 1024"), std::string::npos);
  const Status block = load_within_seconds(std::string(2000, 'k') + ": 1\n");
  EXPECT_NE(block.message.find("a key of 2000 characters"), std::string::npos)
      << block.message.substr(0, 300);
}

}  // namespace
}  // namespace lantern
