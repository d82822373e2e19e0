// The nine-spheres rule of seed 000 §3.2 on its auxiliary grid.
#include <gtest/gtest.h>

#include "core/culling/nine_spheres.h"

namespace lantern {
namespace {

TEST(NineSpheres, CullsASphereBehindAFullBlockOfNearerEqualSpheres) {
  NineSpheresGrid grid;
  grid.reset(16, 16);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) EXPECT_FALSE(grid.test_and_record(8 + dx, 8 + dy, 1.0f, 0.5f));
  EXPECT_TRUE(grid.test_and_record(8, 8, 2.0f, 0.5f));   // behind, same radius: hidden
  EXPECT_TRUE(grid.test_and_record(8, 8, 1.0f, 0.5f));   // equal depth counts as nearer (D <= d)
  EXPECT_FALSE(grid.test_and_record(8, 8, 2.0f, 0.6f));  // larger than the occluders: drawn
}

TEST(NineSpheres, KeepsTheSphereWhenOneNeighbourIsMissing) {
  for (int missing = 0; missing < 9; ++missing) {
    if (missing == 4) continue;  // the centre pixel itself: it then is unoccupied, drawn anyway
    NineSpheresGrid grid;
    grid.reset(16, 16);
    int k = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx, ++k)
        if (k != missing) grid.test_and_record(8 + dx, 8 + dy, 1.0f, 0.5f);
    EXPECT_FALSE(grid.test_and_record(8, 8, 2.0f, 0.5f)) << "missing neighbour " << missing;
  }
}

TEST(NineSpheres, KeepsTheSphereWhenANeighbourIsFarther) {
  NineSpheresGrid grid;
  grid.reset(16, 16);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      grid.test_and_record(8 + dx, 8 + dy, dx == 1 && dy == 1 ? 3.0f : 1.0f, 0.5f);
  EXPECT_FALSE(grid.test_and_record(8, 8, 2.0f, 0.5f));
}

TEST(NineSpheres, ImageBorderPixelsAreNeverHidden) {
  NineSpheresGrid grid;
  grid.reset(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) grid.test_and_record(x, y, 1.0f, 1.0f);
  EXPECT_FALSE(grid.test_and_record(0, 2, 5.0f, 0.1f));  // only 5 neighbours exist
  EXPECT_TRUE(grid.test_and_record(1, 2, 5.0f, 0.1f));
}

}  // namespace
}  // namespace lantern
