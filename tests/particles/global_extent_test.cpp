// reduce_extent: every rank gets the union of all ranks' extents, empty ranks are neutral, and an
// all-empty communicator stays recognisably empty.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <limits>

#include "core/particles/global_extent.h"
#include "tests/support/extent_expect.h"
#include "tests/support/mpi_world.h"

namespace lantern::testing {
namespace {

// Rank r owns r particles (rank 0 none) along a diagonal, one of them with a NaN coordinate when
// r is odd, and scalars only on ranks >= 2.
Extent local_extent_of(int rank) {
  Extent e;
  for (int i = 0; i < rank; ++i) {
    const double x = rank * 10.0 + i, nan = std::numeric_limits<double>::quiet_NaN();
    const bool broken = rank % 2 == 1 && i == 0;
    if (e.add_particle(broken ? nan : x, -x, 0.5 * x, 0.1 * rank) && rank >= 2)
      e.add_scalar(i == 1 ? std::numeric_limits<double>::infinity() : -x);
  }
  return e;
}

TEST(GlobalExtent, EveryRankGetsTheUnionAndEmptyRanksAreNeutral) {
  const Extent global = reduce_extent(MPI_COMM_WORLD, local_extent_of(world_rank()));
  Extent expected;
  for (int r = 0; r < world_size(); ++r) expected = merge_extents(expected, local_extent_of(r));
  expect_same_extent(global, expected);
  // Rank 0 owns nothing and rank 1 only a NaN particle: up to two ranks the union is empty.
  EXPECT_EQ(global.empty(), world_size() <= 2);
  EXPECT_EQ(global.nonfinite_count, world_size() >= 2 ? (world_size() / 2) : 0);
  if (world_size() >= 3) {
    EXPECT_EQ(global.lo[0], 20.0);
    EXPECT_EQ(global.max_radius, 0.1 * (world_size() - 1));
    EXPECT_TRUE(global.has_scalar_range());
  }
}

TEST(GlobalExtent, AllEmptyStaysEmpty) {
  const Extent global = reduce_extent(MPI_COMM_WORLD, Extent{});
  EXPECT_TRUE(global.empty());
  EXPECT_FALSE(global.has_scalar_range());
  EXPECT_EQ(global.nonfinite_count, 0);
  EXPECT_TRUE(std::isinf(global.lo[0]) && global.lo[0] > 0);
  EXPECT_TRUE(std::isinf(global.hi[2]) && global.hi[2] < 0);
}

TEST(GlobalExtent, NonFiniteParticlesAreCountedNotBounded) {
  Extent e;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(e.add_particle(nan, 0, 0, 1));
  EXPECT_FALSE(e.add_particle(0, std::numeric_limits<double>::infinity(), 0, 1));
  EXPECT_TRUE(e.add_particle(1, 2, 3, nan));
  e.add_scalar(nan);
  EXPECT_EQ(e.finite_count, 1);
  EXPECT_EQ(e.nonfinite_count, 2);
  EXPECT_EQ(e.lo[1], 2.0);
  EXPECT_EQ(e.hi[2], 3.0);
  EXPECT_FALSE(std::isfinite(e.max_radius));  // only a NaN radius was seen
  EXPECT_FALSE(e.has_scalar_range());
}

}  // namespace
}  // namespace lantern::testing
