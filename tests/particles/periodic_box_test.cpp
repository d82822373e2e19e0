// PeriodicBox::minimum_image: its shortcut for separations within half the box gives the bits of
// the general formula, d - length * nearbyint(d / length), for every separation and length -
// signed zeros, exact halves, the neighbours of the half, many box lengths away, non-finite; and a
// triclinic box's images come back along its edge vectors.
#include "core/particles/periodic_box.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace lantern {
namespace {

double general(double d, double length) {
  return d - length * std::nearbyint(d / length);
}

uint64_t bits(double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// Compares every axis of minimum_image with the general formula, as bits - except that a NaN
// only needs to be a NaN: which sign a NaN gets depends on whether the compiler folded the
// operation or the processor ran it (x86 makes negative NaNs, folding positive ones), so a
// sanitizer build and a release build disagreed on the formula's own NaNs.
void expect_general(double d, double length) {
  PeriodicBox box;
  box.length = {length, length, length};
  box.periodic = {true, true, true};
  const glm::dvec3 got = box.minimum_image(glm::dvec3(d, -d, d));
  const double want[3] = {general(d, length), general(-d, length), general(d, length)};
  for (int a = 0; a < 3; ++a) {
    if (std::isnan(want[a])) {
      EXPECT_TRUE(std::isnan(got[a])) << "d " << d << " length " << length << " axis " << a;
      continue;
    }
    EXPECT_EQ(bits(got[a]), bits(want[a])) << "d " << d << " length " << length << " axis " << a;
  }
}

TEST(PeriodicBox, MinimumImageIsTheGeneralFormulaBitForBit) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double lengths[] = {
      1.0, 3.0, 80.0, 0.1, 1e-300, 5e-324, 1e300, std::numeric_limits<double>::max(), kInf};
  for (const double length : lengths) {
    const double half = 0.5 * length;
    const double special[] = {0.0,
                              -0.0,
                              half,
                              std::nextafter(half, 0.0),
                              std::nextafter(half, kInf),
                              length,
                              1.5 * length,
                              3.0 * length + 0.25,
                              1e-310,
                              std::numeric_limits<double>::max(),
                              kInf,
                              std::nan("")};
    for (const double d : special) expect_general(d, length), expect_general(-d, length);
  }
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-4.0, 4.0);
  for (int i = 0; i < 100000; ++i) {
    const double length = std::ldexp(1.0 + std::abs(unit(rng)), int(unit(rng) * 8));
    expect_general(unit(rng) * length, length);
  }
}

// Axes that are not periodic, or of zero length, keep the separation as given (-0 included).
TEST(PeriodicBox, OtherAxesKeepTheSeparation) {
  PeriodicBox box;
  box.length = {10.0, 0.0, 10.0};
  box.periodic = {true, true, false};
  const glm::dvec3 got = box.minimum_image(glm::dvec3(-0.0, -0.0, 7.0));
  EXPECT_EQ(bits(got.x), bits(0.0));
  EXPECT_EQ(bits(got.y), bits(-0.0));
  EXPECT_EQ(got.z, 7.0);
}

// A triclinic box (LAMMPS's restricted form): a separation moved by any whole number of edge
// vectors a = (10, 0, 0), b = (2, 8, 0), c = (1.5, -1, 6) comes back to itself - the closest
// image for a short bond - whichever images it crossed, as LAMMPS's minimum_image gives it.
TEST(PeriodicBox, TriclinicImagesComeBackAlongTheEdgeVectors) {
  PeriodicBox box;
  box.length = {10.0, 8.0, 6.0};
  box.periodic = {true, true, true};
  box.tilt = {2.0, 1.5, -1.0};  // xy, xz, yz
  const glm::dvec3 a(10, 0, 0), b(2, 8, 0), c(1.5, -1, 6);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> small(-1.5, 1.5);
  std::uniform_int_distribution<int> image(-3, 3);
  for (int trial = 0; trial < 2000; ++trial) {
    const glm::dvec3 s(small(rng), small(rng), small(rng));
    const glm::dvec3 d =
        s + double(image(rng)) * a + double(image(rng)) * b + double(image(rng)) * c;
    const glm::dvec3 got = box.minimum_image(d);
    for (int axis = 0; axis < 3; ++axis)
      ASSERT_NEAR(got[axis], s[axis], 1e-12) << "trial " << trial << " axis " << axis;
  }
  // Within half the box on every axis nothing moves: d + 0.0, the orthogonal shortcut's bits.
  const glm::dvec3 near = box.minimum_image(glm::dvec3(-0.0, 3.9, -2.9));
  EXPECT_EQ(bits(near.x), bits(0.0));
  EXPECT_EQ(near.y, 3.9);
  EXPECT_EQ(near.z, -2.9);
  // c not periodic: a separation along it stays, and so do the tilts it would have carried.
  box.periodic = {true, true, false};
  const glm::dvec3 up = box.minimum_image(glm::dvec3(0.5, 0.25, 5.0));
  EXPECT_EQ(up, glm::dvec3(0.5, 0.25, 5.0));
  // Zero tilt is the orthogonal box, bit for bit.
  box.tilt = {0, 0, 0};
  box.periodic = {true, true, true};
  const glm::dvec3 wrapped = box.minimum_image(glm::dvec3(9.25, -7.5, 4.0));
  EXPECT_EQ(bits(wrapped.x), bits(general(9.25, 10.0)));
  EXPECT_EQ(bits(wrapped.y), bits(general(-7.5, 8.0)));
  EXPECT_EQ(bits(wrapped.z), bits(general(4.0, 6.0)));
}

}  // namespace
}  // namespace lantern
