// Object-space ambient occlusion (core/render/object_occlusion.h) on simple cubic lattices of
// spacing 1 with the scene defaults (sphere radius 0.5, so an occlusion radius of 2, strength
// 0.6): flat open faces, edges and corners keep their colour, buried particles darken by the
// strength, and what is enclosed darkens in between - the crease of an L-shaped block (a step
// between blocks), the wall of a spherical void, the bottom of a pit. A cut plane opens the cut
// face, and the factors do not depend on how the particles are split (run at 1, 2, 3 and 4
// ranks).
#include <gtest/gtest.h>

#include <mpi.h>

#include <cmath>
#include <functional>
#include <vector>

#include "core/particles/global_extent.h"
#include "core/render/object_occlusion.h"
#include "tests/support/mpi_world.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {
namespace {

constexpr double kRadius = 2.0;  // kDefaultAoRadiusInSphereRadii x 0.5
constexpr double kStrength = 0.6;
// "Does not darken": at most this share of the strength.
constexpr double kOpen = 0.1;

struct Site {
  int x, y, z;
};

struct Lattice {
  std::vector<double> xyz;
  std::vector<Site> sites;
  ParticleArrays arrays;
};

// The sites of the box [0, nx) x [0, ny) x [0, nz) for which inside(site) holds, as this rank's
// particles when mine(k) holds for their rank-independent index k.
Lattice lattice(
    int nx, int ny, int nz, const std::function<bool(const Site &)> &inside,
    const std::function<bool(int)> &mine = [](int) { return true; }) {
  Lattice l;
  int k = 0;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        const Site s{x, y, z};
        if (!inside(s)) continue;
        if (mine(k++)) {
          l.sites.push_back(s);
          l.xyz.insert(l.xyz.end(), {double(x), double(y), double(z)});
        }
      }
  ParticleDescription d;
  d.count = int64_t(l.sites.size());
  d.position = {l.xyz.data(), DataType::kFloat64, 0};
  EXPECT_OK(ParticleArrays::validate(d, &l.arrays));
  return l;
}

OcclusionVolume volume_of(MPI_Comm comm, const Lattice &l, const std::vector<CutPlane> &cuts = {}) {
  Extent local;
  for (const Site &s : l.sites) local.add_particle(s.x, s.y, s.z, 0.5);
  OcclusionVolume v;
  EXPECT_OK(v.build(comm, l.arrays, reduce_extent(comm, local), cuts, kRadius, kStrength));
  return v;
}

double darkening(const OcclusionVolume &v, int x, int y, int z) {
  return (1.0 - v.factor(glm::dvec3(x, y, z))) / kStrength;  // 0: none, 1: the full strength
}

TEST(ObjectOcclusion, AFlatSlabDarkensInsideAndNotOnItsFaces) {
  const Lattice slab = lattice(24, 24, 8, [](const Site &) { return true; });
  const OcclusionVolume v = volume_of(MPI_COMM_SELF, slab);
  EXPECT_NEAR(v.bulk_per_cell(), 1.0, 0.05);  // one particle per unit cube, cell 1
  EXPECT_GT(v.face_occupancy(), 0.5);
  EXPECT_LT(v.face_occupancy(), 0.9);
  EXPECT_NEAR(darkening(v, 12, 12, 4), 1.0, 1e-6) << "buried";
  for (const int x : {5, 12, 18}) {
    EXPECT_LE(darkening(v, x, 12, 7), kOpen) << "top face at x = " << x;
    EXPECT_LE(darkening(v, x, 12, 0), kOpen) << "bottom face at x = " << x;
    EXPECT_LE(darkening(v, 0, x, 4), kOpen) << "side face at y = " << x;
  }
  EXPECT_EQ(darkening(v, 0, 12, 7), 0.0) << "edge";
  EXPECT_EQ(darkening(v, 0, 0, 0), 0.0) << "corner";
}

// A block with a step: [0, 20) x [0, 20) x [0, 6), and on its left half a second block up to
// z = 14. Along the step's concave edge the particles darken; on the flat tops, the step's wall
// away from the edge and the step's convex top edge they do not.
TEST(ObjectOcclusion, TheCreaseOfAnLShapedBlockDarkens) {
  const Lattice l = lattice(20, 20, 14, [](const Site &s) { return s.z < 6 || s.x < 10; });
  const OcclusionVolume v = volume_of(MPI_COMM_SELF, l);
  for (const int y : {5, 10, 15}) {
    EXPECT_GE(darkening(v, 10, y, 5), 0.4) << "floor beside the wall, y = " << y;
    EXPECT_GE(darkening(v, 9, y, 6), 0.4) << "wall above the floor, y = " << y;
    EXPECT_LE(darkening(v, 16, y, 5), kOpen) << "floor away from the wall";
    EXPECT_LE(darkening(v, 5, y, 13), kOpen) << "top of the step";
    EXPECT_LE(darkening(v, 9, y, 11), kOpen) << "wall away from the floor";
    EXPECT_EQ(darkening(v, 9, y, 13), 0.0) << "convex edge of the step";
  }
}

// A cube with a spherical void of radius 3 (1.5 occlusion radii) at its centre: the particles
// lining the void (a neighbour site inside it) darken, all but the few on the small flat facets
// of its discretised wall; the outer faces do not.
TEST(ObjectOcclusion, TheWallOfASphericalVoidDarkens) {
  const double c = 11.5, r = 3.0;
  const auto distance = [c](const Site &s) {
    return std::sqrt((s.x - c) * (s.x - c) + (s.y - c) * (s.y - c) + (s.z - c) * (s.z - c));
  };
  const Lattice l = lattice(24, 24, 24, [&](const Site &s) { return distance(s) >= r; });
  const OcclusionVolume v = volume_of(MPI_COMM_SELF, l);
  double wall = 0.0;
  int lining = 0, dark = 0;
  const auto in_void = [&](int x, int y, int z) { return distance({x, y, z}) < r; };
  for (const Site &s : l.sites)
    if (in_void(s.x - 1, s.y, s.z) || in_void(s.x + 1, s.y, s.z) || in_void(s.x, s.y - 1, s.z) ||
        in_void(s.x, s.y + 1, s.z) || in_void(s.x, s.y, s.z - 1) || in_void(s.x, s.y, s.z + 1)) {
      ++lining;
      wall += darkening(v, s.x, s.y, s.z);
      dark += darkening(v, s.x, s.y, s.z) >= 0.2;
    }
  ASSERT_GT(lining, 100);
  EXPECT_GE(wall / lining, 0.4) << "mean darkening of the void's wall";
  EXPECT_GE(dark, 0.75 * lining) << "lining particles darkened by at least 0.2 of " << lining;
  EXPECT_LE(darkening(v, 12, 12, 23), kOpen) << "outer face";
}

// A pit: a 3 x 3 column of sites removed from the top of a slab, 4 layers deep. Its bottom and
// walls darken; the top face away from it does not.
TEST(ObjectOcclusion, ThePitInAFaceDarkens) {
  const auto pit = [](const Site &s) { return s.x >= 11 && s.x <= 13 && s.y >= 11 && s.y <= 13; };
  const Lattice l = lattice(24, 24, 10, [&](const Site &s) { return !(pit(s) && s.z >= 6); });
  const OcclusionVolume v = volume_of(MPI_COMM_SELF, l);
  EXPECT_GE(darkening(v, 12, 12, 5), 0.4) << "bottom of the pit";
  EXPECT_GE(darkening(v, 10, 12, 7), 0.3) << "wall of the pit";
  EXPECT_LE(darkening(v, 4, 4, 9), kOpen) << "top face away from the pit";
}

TEST(ObjectOcclusion, ACutPlaneOpensTheCutFace) {
  const Lattice block = lattice(16, 16, 16, [](const Site &) { return true; });
  CutPlane cut;
  cut.normal = {0, 0, 1};
  cut.offset = 7.5;  // drops z > 7.5: z = 7 becomes the top face
  const OcclusionVolume whole = volume_of(MPI_COMM_SELF, block);
  const OcclusionVolume open = volume_of(MPI_COMM_SELF, block, {cut});
  EXPECT_NEAR(darkening(whole, 8, 8, 7), 1.0, 0.05) << "buried before the cut";
  EXPECT_LE(darkening(open, 8, 8, 7), kOpen) << "the cut face";
}

TEST(ObjectOcclusion, TheSameFactorsForEverySplit) {
  const auto shape = [](const Site &s) { return s.z < 6 || s.x < 10; };
  const Lattice all = lattice(20, 20, 14, shape);
  const OcclusionVolume alone = volume_of(MPI_COMM_SELF, all);
  const int rank = world_rank(), ranks = world_size();
  for (const int split : {0, 1, 2}) {
    const Lattice mine = lattice(20, 20, 14, shape, [&](int k) {
      switch (split) {
        case 0:
          return k % ranks == rank;  // round robin
        case 1:
          return k * ranks / int(all.sites.size()) == rank;  // slabs in z
        default:
          return rank == ranks - 1;  // all on the last rank
      }
    });
    const OcclusionVolume v = volume_of(MPI_COMM_WORLD, mine);
    for (const Site &s : all.sites) {
      const glm::dvec3 x(s.x, s.y, s.z);
      ASSERT_EQ(v.factor(x), alone.factor(x)) << "split " << split;
    }
  }
}

}  // namespace
}  // namespace lantern::testing
