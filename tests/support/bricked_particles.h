// Test support: particles a test owns (positions and types in vectors), validated into the
// ParticleArrays that borrow them and grouped into bricks, as the pipeline would. A test fills
// xyz and type, then calls finish(). Not copyable: the arrays point into the vectors.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/particles/particle_arrays.h"

namespace lantern::testing {

struct BrickedParticles {
  std::vector<double> xyz;    // x, y, z per particle
  std::vector<int32_t> type;  // one per particle
  ParticleArrays arrays;      // borrows xyz and type
  BrickSet bricks;

  BrickedParticles() = default;
  BrickedParticles(const BrickedParticles &) = delete;
  BrickedParticles &operator=(const BrickedParticles &) = delete;

  // Validates the arrays (a test failure if they are refused) and builds the bricks.
  void finish() {
    ParticleDescription d{};
    d.count = int64_t(type.size());
    d.position = {xyz.data(), DataType::kFloat64, 0};
    d.type = {type.data(), DataType::kInt32, 0};
    EXPECT_TRUE(ParticleArrays::validate(d, &arrays).ok());
    bricks = build_bricks(arrays, BrickOptions{});
  }
};

}  // namespace lantern::testing
