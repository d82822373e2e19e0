// GoogleTest comparison of two Extents, field by field (exact: extents are mins and maxes).
#pragma once

#include <gtest/gtest.h>

#include "core/particles/global_extent.h"

namespace lantern {

inline void expect_same_extent(const Extent &a, const Extent &b) {
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a.lo[k], b.lo[k]) << k;
    EXPECT_EQ(a.hi[k], b.hi[k]) << k;
  }
  EXPECT_EQ(a.max_radius, b.max_radius);
  EXPECT_EQ(a.scalar_min, b.scalar_min);
  EXPECT_EQ(a.scalar_max, b.scalar_max);
  EXPECT_EQ(a.finite_count, b.finite_count);
  EXPECT_EQ(a.nonfinite_count, b.nonfinite_count);
}

}  // namespace lantern
