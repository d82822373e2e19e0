// Test fixture for the C API: a scratch directory, a lattice of particles and helpers to open
// contexts with inline YAML.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "lantern/lantern.h"

namespace lantern::testing {

class ApiTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto *info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("lantern_api_") + info->test_suite_name() + "_" + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    lantern_close(ctx_);
    std::filesystem::remove_all(dir_);
  }

  // One scene of w x h writing <dir>/<name>_{step:04d}.png, plus extra YAML lines for the scene.
  // `output_extra` goes inside the output mapping, e.g. ", asynchronous: true".
  std::string scene_config(const std::string &name, int w = 96, int h = 64,
                           const std::string &extra = "",
                           const std::string &output_extra = "") const {
    return "stats: '" + (dir_ / "stats.jsonl").string() +
           "'\n"
           "scenes:\n"
           "  - name: " +
           name + "\n    width: " + std::to_string(w) + "\n    height: " + std::to_string(h) +
           "\n    output: {pattern: '" + (dir_ / (name + "_{step:04d}.png")).string() + "'" +
           output_extra + "}\n" + extra;
  }
  std::string png(const std::string &name, int step) const {
    char buf[16];
    std::snprintf(buf, sizeof buf, "_%04d.png", step);
    return (dir_ / (name + buf)).string();
  }

  lantern_status open(const std::string &config) {
    lantern_close(ctx_);
    ctx_ = nullptr;
    return lantern_open(config.c_str(), LANTERN_COMM_WORLD, &ctx_);
  }
  std::string message() const { return lantern_error_message(ctx_); }

  // n^3 particles on a cubic lattice of spacing 1, shifted by `offset`, as interleaved doubles.
  static std::vector<double> lattice(int n, double offset = 0.0) {
    std::vector<double> x;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          x.push_back(i + offset);
          x.push_back(j + offset);
          x.push_back(k + offset);
        }
    return x;
  }
  static lantern_particles interleaved(const std::vector<double> &x) {
    lantern_particles p{};
    p.count = int64_t(x.size() / 3);
    p.position = {x.data(), LANTERN_FLOAT64, 0};
    return p;
  }

  std::filesystem::path dir_;
  lantern_context *ctx_ = nullptr;
};

}  // namespace lantern::testing
