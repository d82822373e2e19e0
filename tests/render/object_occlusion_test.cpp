// Object-space ambient occlusion (core/render/object_occlusion.h) on simple cubic lattices of
// spacing 1 with the scene defaults (sphere radius 0.5, so an occlusion radius of 2, strength
// 0.6): flat open faces, edges and corners keep their colour, buried particles darken by the
// strength, and what is enclosed darkens in between - the crease of an L-shaped block (a step
// between blocks), the wall of a spherical void, the bottom of a pit. A cut plane opens the cut
// face, and the factors do not depend on how the particles are split (run at 1, 2, 3 and 4
// ranks).
#include <gtest/gtest.h>

#include <mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/bricks/brick_set.h"
#include "core/culling/cut_planes.h"
#include "core/particles/global_extent.h"
#include "core/particles/particle_scan.h"
#include "core/particles/position_tap.h"
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

// Positions as x y z doubles one after the other.
ParticleArrays packed_arrays(std::vector<double> &xyz) {
  ParticleDescription d;
  d.count = int64_t(xyz.size() / 3);
  d.position = {xyz.data(), DataType::kFloat64, 0};
  ParticleArrays arrays;
  EXPECT_OK(ParticleArrays::validate(d, &arrays));
  return arrays;
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

namespace lantern::testing {
namespace {

// The extent (a 40 x 30 x 35 box) and the oblique cutting plane the volume tests share.
Extent cloud_extent() {
  Extent global;
  global.add_particle(0.0, 0.0, 0.0, 0.5);
  global.add_particle(40.0, 30.0, 35.0, 0.5);
  return global;
}

CutPlane oblique_cut() {
  CutPlane cut;
  cut.normal = {0.6, 0.0, 0.8};
  cut.offset = 30.0;
  return cut;
}

// The volume of the header comment computed one particle and one node at a time, in the
// simplest form (the library's deposit and filter are vectorised and reordered): its enclosure
// per node, given the grid the volume chose.
std::vector<float> reference_enclosure(const std::vector<double> &xyz,
                                       const std::vector<int32_t> &mask,
                                       const std::vector<CutPlane> &cuts,
                                       const OcclusionVolume &v) {
  constexpr int kSteps = 16;
  const std::array<int, 3> n = v.node_counts();
  const std::array<double, 3> origin = v.node_origin();
  const double inverse_cell = 1.0 / v.node_spacing();
  const size_t nodes = size_t(n[0]) * size_t(n[1]) * size_t(n[2]);
  const auto index = [&](int x, int y, int z) {
    return (size_t(z) * size_t(n[1]) + size_t(y)) * size_t(n[0]) + size_t(x);
  };
  std::vector<int64_t> deposit(nodes, 0);
  for (size_t p = 0; p < mask.size(); ++p) {
    const glm::dvec3 x(xyz[3 * p], xyz[3 * p + 1], xyz[3 * p + 2]);
    if (mask[p] == 0 || !std::isfinite(x.x) || !std::isfinite(x.y) || !std::isfinite(x.z)) continue;
    if (CutPlanes(cuts).drops(x)) continue;
    int at[3], w[3][2];
    for (int a = 0; a < 3; ++a) {
      // The nearest 1/kSteps step of the lattice of nodes, counted from the grid's first node.
      const double step = std::floor(x[a] * (kSteps * inverse_cell) + 0.5);
      const double u =
          std::clamp(step - kSteps * origin[size_t(a)], 0.0, double(kSteps * (n[a] - 1)));
      at[a] = std::min(int(u) / kSteps, n[a] - 2);
      w[a][1] = int(u) - kSteps * at[a];
      w[a][0] = kSteps - w[a][1];
    }
    for (int c = 0; c < 2; ++c)
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a)
          deposit[index(at[0] + a, at[1] + b, at[2] + c)] += w[0][a] * w[1][b] * w[2][c];
  }
  // The 1 4 6 4 1 filter along each axis, taps beyond the grid dropped.
  std::vector<int64_t> smooth = deposit;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<int64_t> next(nodes, 0);
    const int64_t taps[5] = {1, 4, 6, 4, 1};
    for (int z = 0; z < n[2]; ++z)
      for (int y = 0; y < n[1]; ++y)
        for (int x = 0; x < n[0]; ++x)
          for (int k = -2; k <= 2; ++k) {
            int at[3] = {x, y, z};
            at[axis] += k;
            if (at[axis] < 0 || at[axis] >= n[axis]) continue;
            next[index(x, y, z)] += taps[k + 2] * smooth[index(at[0], at[1], at[2])];
          }
    smooth.swap(next);
  }
  std::vector<float> value(nodes);
  float top = 0.0f;
  int64_t total = 0;
  for (size_t i = 0; i < nodes; ++i) {
    value[i] = float(double(smooth[i]) / double(4096 * 4096));
    top = std::max(top, value[i]);
    total += deposit[i];
  }
  if (total == 0) return {};
  std::vector<int64_t> histogram(4096, 0);
  for (size_t i = 0; i < nodes; ++i)
    if (deposit[i] > 0) histogram[size_t(std::min(4095, int(value[i] / top * 4096)))] += deposit[i];
  int64_t below = 0;
  int bin = 0;
  for (; bin < 4095; ++bin) {
    below += histogram[size_t(bin)];
    if (double(below) >= kOcclusionBulkQuantile * double(total)) break;
  }
  const double bulk = double(top) * (bin + 0.5) / 4096;
  EXPECT_EQ(bulk, v.bulk_per_cell());
  const double face = v.face_occupancy();  // a function of the bulk alone
  if (!(face < 0.999)) return {};
  std::vector<float> enclosure(nodes);
  for (size_t i = 0; i < nodes; ++i)
    enclosure[i] = float((double(value[i]) * (1.0 / bulk) - face) * (1.0 / (1.0 - face)));
  return enclosure;
}

// The vectorised volume against the reference, bit for bit: a scattered cloud in no spatial
// order with clusters, masked-out and non-finite particles, a cut plane and particles beyond
// the bounds (clamped to the grid's faces).
TEST(ObjectOcclusion, TheVolumeIsTheOneParticleAtATimeSum) {
  std::vector<double> xyz;
  std::vector<int32_t> mask;
  uint64_t state = 12345;
  const auto uniform = [&state] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) / double(uint64_t(1) << 53);
  };
  for (int i = 0; i < 60000; ++i) {
    const bool cluster = i % 3 == 0;
    for (int a = 0; a < 3; ++a)
      xyz.push_back(cluster ? 10.0 + 4.0 * uniform() : -1.0 + 42.0 * uniform());
    mask.push_back(i % 17 != 0);
  }
  xyz[3 * 5] = std::nan(""), xyz[3 * 7 + 2] = HUGE_VAL;
  ParticleDescription d;
  d.count = int64_t(mask.size());
  d.position = {xyz.data(), DataType::kFloat64, 0};
  d.mask = {mask.data(), DataType::kInt32, 0};
  d.mask_bits = 1;
  ParticleArrays arrays;
  ASSERT_OK(ParticleArrays::validate(d, &arrays));
  const Extent global = cloud_extent();
  const CutPlane cut = oblique_cut();
  for (const std::vector<CutPlane> &cuts : {std::vector<CutPlane>{}, std::vector<CutPlane>{cut}}) {
    OcclusionVolume v;
    ASSERT_OK(v.build(MPI_COMM_SELF, arrays, global, cuts, kRadius, kStrength));
    const std::vector<float> expected = reference_enclosure(xyz, mask, cuts, v);
    ASSERT_FALSE(expected.empty());
    const std::vector<float> enclosure = v.enclosure_nodes();
    ASSERT_EQ(enclosure.size(), expected.size());
    for (size_t i = 0; i < expected.size(); ++i)
      ASSERT_EQ(enclosure[i], expected[i]) << "node " << i << ", cuts " << cuts.size();
  }
}

// Without a mask the deposit reads the positions in place where they are x y z doubles one
// after the other (chunks with a non-finite coordinate gathered instead) and gathers them
// without a branch otherwise: the one-particle-at-a-time volume for each layout, with non-finite
// particles in the first chunks and far into the cloud, with and without a cut plane.
TEST(ObjectOcclusion, TheVolumeIsTheOneParticleAtATimeSumForEveryLayout) {
  constexpr int kCount = 60000;
  std::vector<double> xyz;
  uint64_t state = 24680;
  const auto uniform = [&state] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) / double(uint64_t(1) << 53);
  };
  for (int i = 0; i < kCount; ++i)
    for (int a = 0; a < 3; ++a)
      xyz.push_back(i % 3 == 0 ? 10.0 + 4.0 * uniform() : -1.0 + 42.0 * uniform());
  xyz[3 * 5] = std::nan(""), xyz[3 * 7 + 2] = HUGE_VAL, xyz[3 * 40001 + 1] = -HUGE_VAL;
  const std::vector<int32_t> every(kCount, 1);  // the reference's mask: all kept
  // The same positions as three arrays, and interleaved with a fourth value between them.
  std::vector<double> x(kCount), y(kCount), z(kCount), padded(4 * size_t(kCount), -7.0);
  for (int i = 0; i < kCount; ++i) {
    x[size_t(i)] = xyz[3 * size_t(i)], y[size_t(i)] = xyz[3 * size_t(i) + 1];
    z[size_t(i)] = xyz[3 * size_t(i) + 2];
    std::copy_n(&xyz[3 * size_t(i)], 3, &padded[4 * size_t(i)]);
  }
  std::vector<ParticleDescription> layouts(3);
  layouts[0].position = {xyz.data(), DataType::kFloat64, 0};
  layouts[1].position_x = {x.data(), DataType::kFloat64, 0};
  layouts[1].position_y = {y.data(), DataType::kFloat64, 0};
  layouts[1].position_z = {z.data(), DataType::kFloat64, 0};
  layouts[2].position = {padded.data(), DataType::kFloat64, 4 * sizeof(double)};
  const Extent global = cloud_extent();
  const CutPlane cut = oblique_cut();
  for (size_t layout = 0; layout < layouts.size(); ++layout) {
    layouts[layout].count = kCount;
    ParticleArrays arrays;
    ASSERT_OK(ParticleArrays::validate(layouts[layout], &arrays));
    for (const std::vector<CutPlane> &cuts :
         {std::vector<CutPlane>{}, std::vector<CutPlane>{cut}}) {
      OcclusionVolume v;
      ASSERT_OK(v.build(MPI_COMM_SELF, arrays, global, cuts, kRadius, kStrength));
      const std::vector<float> expected = reference_enclosure(xyz, every, cuts, v);
      ASSERT_FALSE(expected.empty());
      ASSERT_EQ(v.enclosure_nodes(), expected) << "layout " << layout << ", cuts " << cuts.size();
    }
  }
  // Positions in place, four particles at a time where the processor has AVX2 and eight where it
  // has AVX-512: last chunks whose counts are not multiples of 8 or 4 (99, 13: the last steps
  // overlap the ones before), of fewer than 8 (5: the AVX2 steps) and of fewer than 4 (2), with a
  // non-finite coordinate in the last particle of a chunk.
  for (const int count : {256 * 234 + 99, 256 * 234 + 13, 256 * 234 + 5, 256 * 234 + 2}) {
    std::vector<double> some(xyz.begin(), xyz.begin() + 3 * ptrdiff_t(count));
    some[3 * (256 * 3 + 255) + 2] = std::nan("");
    ParticleDescription d;
    d.count = count;
    d.position = {some.data(), DataType::kFloat64, 0};
    ParticleArrays arrays;
    ASSERT_OK(ParticleArrays::validate(d, &arrays));
    OcclusionVolume v;
    ASSERT_OK(v.build(MPI_COMM_SELF, arrays, global, {}, kRadius, kStrength));
    const std::vector<float> expected =
        reference_enclosure(some, std::vector<int32_t>(size_t(count), 1), {}, v);
    ASSERT_FALSE(expected.empty());
    ASSERT_EQ(v.enclosure_nodes(), expected) << count << " particles";
  }
}

// A volume kept from frame to frame zeroes the planes of z its in-place deposits reach: a frame
// whose particles lie low in z (and high in y) after one that filled every plane.
TEST(ObjectOcclusion, InPlaceDepositsZeroThePlanesTheyReach) {
  uint64_t state = 97531;
  const auto uniform = [&state] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) / double(uint64_t(1) << 53);
  };
  std::vector<double> everywhere, low;
  for (int i = 0; i < 20000; ++i) {
    for (const double extent : {40.0, 30.0, 35.0}) everywhere.push_back(extent * uniform());
    low.push_back(40.0 * uniform());
    low.push_back(24.0 + 6.0 * uniform());
    low.push_back(4.0 * uniform());
  }
  const Extent global = cloud_extent();
  OcclusionVolume kept, fresh;
  ASSERT_OK(kept.build(MPI_COMM_SELF, packed_arrays(everywhere), global, {}, kRadius, kStrength));
  ASSERT_OK(kept.build(MPI_COMM_SELF, packed_arrays(low), global, {}, kRadius, kStrength));
  ASSERT_OK(fresh.build(MPI_COMM_SELF, packed_arrays(low), global, {}, kRadius, kStrength));
  ASSERT_FALSE(fresh.enclosure_nodes().empty());
  EXPECT_EQ(kept.bulk_per_cell(), fresh.bulk_per_cell());
  ASSERT_EQ(kept.enclosure_nodes(), fresh.enclosure_nodes());
}

// More particles on one node than a 32-bit sum of their deposits holds (2^20 x 4096, each on
// the node: the whole weight at one corner): the deposit's 32-bit sums are moved to 64-bit ones
// in time, and the smoothing is in 64 bits.
TEST(ObjectOcclusion, ALongRunOnOneNodeIsSummedExactly) {
  constexpr int kCount = (1 << 20) + 1000;
  std::vector<double> xyz;
  xyz.reserve(3 * (kCount + 2));
  for (int i = 0; i < kCount; ++i)
    xyz.insert(xyz.end(), {4.0, 4.0, 4.0});  // a node (cell 1 from 0)
  // Two particles elsewhere, so the bulk is not the pile.
  xyz.insert(xyz.end(), {1.0, 1.0, 1.0, 9.0, 9.0, 9.0});
  std::vector<int32_t> mask(kCount + 2, 1);
  ParticleDescription d;
  d.count = int64_t(mask.size());
  d.position = {xyz.data(), DataType::kFloat64, 0};
  ParticleArrays arrays;
  ASSERT_OK(ParticleArrays::validate(d, &arrays));
  Extent global;
  global.add_particle(0.0, 0.0, 0.0, 0.5);
  global.add_particle(10.0, 10.0, 10.0, 0.5);
  OcclusionVolume v;
  ASSERT_OK(v.build(MPI_COMM_SELF, arrays, global, {}, kRadius, kStrength));
  const std::vector<float> expected = reference_enclosure(xyz, mask, {}, v);
  ASSERT_EQ(v.enclosure_nodes(), expected);
  // Built again (a volume kept between frames): the first build's sums are not added again.
  ASSERT_OK(v.build(MPI_COMM_SELF, arrays, global, {}, kRadius, kStrength));
  ASSERT_EQ(v.enclosure_nodes(), expected) << "built again";
}

// A scattered cloud as in TheVolumeIsTheOneParticleAtATimeSum: clusters, masked-out and
// non-finite particles, some beyond the bounds; this rank's share when mine(k) holds.
struct Cloud {
  std::vector<double> xyz;
  std::vector<int32_t> mask;
  ParticleArrays arrays;
};

void make_cloud(int count, const std::function<bool(int, const double *)> &mine, Cloud *c) {
  uint64_t state = 987654321;
  const auto uniform = [&state] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) / double(uint64_t(1) << 53);
  };
  for (int i = 0; i < count; ++i) {
    double x[3];
    for (double &a : x) a = i % 3 == 0 ? 10.0 + 4.0 * uniform() : -1.0 + 42.0 * uniform();
    if (i == 5) x[0] = std::nan("");
    if (i == 7) x[2] = HUGE_VAL;
    if (!mine(i, x)) continue;
    c->xyz.insert(c->xyz.end(), x, x + 3);
    c->mask.push_back(i % 17 != 0);
  }
  ParticleDescription d;
  d.count = int64_t(c->mask.size());
  d.position = {c->xyz.data(), DataType::kFloat64, 0};
  d.mask = {c->mask.data(), DataType::kInt32, 0};
  d.mask_bits = 1;
  EXPECT_OK(ParticleArrays::validate(d, &c->arrays));
}

// Each rank sums and smooths only its slab of planes from the planes the others' particles
// reach: the volume on every rank is the one-rank volume bit for bit, whichever rank holds which
// particles (spread over every slab, in slabs of z that are not the ranks' own, all on one
// rank), with and without a cut plane.
TEST(ObjectOcclusion, EveryRankHasTheOneRankVolumeForEverySplit) {
  constexpr int kCount = 40000;
  Cloud all;
  make_cloud(
      kCount, [](int, const double *) { return true; }, &all);
  const Extent global = cloud_extent();
  const CutPlane cut = oblique_cut();
  const int rank = world_rank(), ranks = world_size();
  for (const std::vector<CutPlane> &cuts : {std::vector<CutPlane>{}, std::vector<CutPlane>{cut}}) {
    OcclusionVolume alone;
    ASSERT_OK(alone.build(MPI_COMM_SELF, all.arrays, global, cuts, kRadius, kStrength));
    ASSERT_FALSE(alone.enclosure_nodes().empty());
    for (const int split : {0, 1, 2}) {
      Cloud mine;
      make_cloud(
          kCount,
          [&](int k, const double *x) {
            switch (split) {
              case 0:
                return k % ranks == rank;  // round robin
              case 1: {  // slabs of z in reverse rank order, the non-finite ones on rank 0
                if (!std::isfinite(x[2])) return rank == 0;
                const int slab = std::clamp(int(x[2] / 35.0 * ranks), 0, ranks - 1);
                return ranks - 1 - slab == rank;
              }
              default:
                return rank == 0;  // all on the first rank
            }
          },
          &mine);
      OcclusionVolume v;
      ASSERT_OK(v.build(MPI_COMM_WORLD, mine.arrays, global, cuts, kRadius, kStrength));
      EXPECT_EQ(v.bulk_per_cell(), alone.bulk_per_cell()) << "split " << split;
      EXPECT_EQ(v.face_occupancy(), alone.face_occupancy()) << "split " << split;
      ASSERT_EQ(v.enclosure_nodes(), alone.enclosure_nodes())
          << "split " << split << ", cuts " << cuts.size();
    }
  }
}

// max_nodes: the spacing widens past radius / 2 in steps of kOcclusionCellWidening, as little as
// keeps the nodes within it; a cap the nominal grid fits leaves the volume as it is; and a
// widened volume is still the one-rank volume for every split.
TEST(ObjectOcclusion, MaxNodesWidensTheSpacingAsLittleAsItMust) {
  constexpr int kCount = 40000;
  Cloud all;
  make_cloud(
      kCount, [](int, const double *) { return true; }, &all);
  const Extent global = cloud_extent();
  const auto nodes = [](const OcclusionVolume &v) {
    const std::array<int, 3> n = v.node_counts();
    return int64_t(n[0]) * n[1] * n[2];
  };
  OcclusionVolume nominal, fits, coarse, coarser;
  ASSERT_OK(nominal.build(MPI_COMM_SELF, all.arrays, global, {}, kRadius, kStrength));
  EXPECT_EQ(nominal.node_spacing(), kRadius * kOcclusionCellPerRadius);
  ASSERT_OK(
      fits.build(MPI_COMM_SELF, all.arrays, global, {}, kRadius, kStrength, 1, nodes(nominal)));
  EXPECT_EQ(fits.node_spacing(), nominal.node_spacing());
  EXPECT_EQ(fits.enclosure_nodes(), nominal.enclosure_nodes());
  ASSERT_OK(coarse.build(MPI_COMM_SELF, all.arrays, global, {}, kRadius, kStrength, 1,
                         nodes(nominal) - 1));
  EXPECT_LT(nodes(coarse), nodes(nominal));
  EXPECT_NEAR(coarse.node_spacing(), nominal.node_spacing() * kOcclusionCellWidening, 1e-12);
  ASSERT_OK(coarser.build(MPI_COMM_SELF, all.arrays, global, {}, kRadius, kStrength, 1, 4096));
  EXPECT_LE(nodes(coarser), 4096);
  // A whole number of widening steps, at least one.
  const double steps =
      std::log(coarser.node_spacing() / nominal.node_spacing()) / std::log(kOcclusionCellWidening);
  EXPECT_NEAR(steps, std::round(steps), 1e-6);
  EXPECT_GT(steps, 1.0);
  ASSERT_FALSE(coarser.enclosure_nodes().empty());
  const int rank = world_rank(), ranks = world_size();
  for (const int split : {0, 1}) {
    Cloud mine;
    make_cloud(
        kCount,
        [&](int k, const double *x) {
          if (split == 0) return k % ranks == rank;
          if (!std::isfinite(x[2])) return rank == 0;
          return std::clamp(int(x[2] / 35.0 * ranks), 0, ranks - 1) == rank;
        },
        &mine);
    OcclusionVolume v;
    ASSERT_OK(v.build(MPI_COMM_WORLD, mine.arrays, global, {}, kRadius, kStrength, 1, 4096));
    EXPECT_EQ(v.node_counts(), coarser.node_counts()) << "split " << split;
    EXPECT_EQ(v.bulk_per_cell(), coarser.bulk_per_cell()) << "split " << split;
    ASSERT_EQ(v.enclosure_nodes(), coarser.enclosure_nodes()) << "split " << split;
  }
}

// A radius far below the particles' span: 4095 widening steps (a factor of 1e77) do not bring
// the nodes within max_nodes. The grid was left at up to max_nodes nodes per axis (its plane
// size an int overflow, its quads 2^58 bytes); it now fits, and the build completes.
TEST(ObjectOcclusion, ARadiusFarBelowTheSpanStillFitsTheNodes) {
  Cloud all;
  make_cloud(
      2000, [](int, const double *) { return true; }, &all);
  for (const double radius : {1e-80, 1e-200}) {
    OcclusionVolume v;
    ASSERT_OK(v.build(MPI_COMM_SELF, all.arrays, cloud_extent(), {}, radius, kStrength, 1, 4096));
    const std::array<int, 3> n = v.node_counts();
    EXPECT_LE(int64_t(n[0]) * n[1] * n[2], 4096) << radius;
    EXPECT_GE(std::min({n[0], n[1], n[2]}), 2) << radius;
    EXPECT_TRUE(std::isfinite(v.node_spacing()) && v.node_spacing() > 0.0) << radius;
  }
}

// `threads`: each part deposits on quads of its own, added up after: every count gives the
// one-thread volume bit for bit - a scattered cloud (300 k particles: parts of at least 64 Ki)
// with a mask, non-finite particles and a cut, and in place (no mask), in one volume kept over
// counts that go up and down; and a pile on one node whose parts' 32-bit sums together would
// pass 32 bits (they are added in 64).
TEST(ObjectOcclusion, EveryThreadCountGivesTheOneThreadVolume) {
  if (world_rank() != 0) return;
  Cloud cloud;
  make_cloud(
      300000, [](int, const double *) { return true; }, &cloud);
  std::vector<double> finite;
  for (size_t i = 0; i < cloud.xyz.size(); i += 3)
    if (std::isfinite(cloud.xyz[i]) && std::isfinite(cloud.xyz[i + 1]) &&
        std::isfinite(cloud.xyz[i + 2]))
      finite.insert(finite.end(), &cloud.xyz[i], &cloud.xyz[i] + 3);
  const ParticleArrays in_place = packed_arrays(finite);
  const Extent global = cloud_extent();
  const CutPlane cut = oblique_cut();
  int compared = 0;
  for (const ParticleArrays *arrays :
       {static_cast<const ParticleArrays *>(&cloud.arrays), &in_place})
    for (const std::vector<CutPlane> &cuts :
         {std::vector<CutPlane>{}, std::vector<CutPlane>{cut}}) {
      OcclusionVolume one, kept;
      ASSERT_OK(one.build(MPI_COMM_SELF, *arrays, global, cuts, kRadius, kStrength, 1));
      const std::vector<float> expected = one.enclosure_nodes();
      ASSERT_FALSE(expected.empty());
      for (const int threads : {2, 4, 3, 7, 1, 2}) {
        ASSERT_OK(kept.build(MPI_COMM_SELF, *arrays, global, cuts, kRadius, kStrength, threads));
        EXPECT_EQ(kept.bulk_per_cell(), one.bulk_per_cell());
        ASSERT_EQ(kept.enclosure_nodes(), expected)
            << threads << " threads, " << cuts.size() << " cuts, "
            << (arrays == &in_place ? "in place" : "masked");
        ++compared;
      }
    }
  EXPECT_EQ(compared, 2 * 2 * 6);

  constexpr int kPile = (1 << 20) + 1000;
  std::vector<double> pile;
  pile.reserve(3 * (kPile + 2));
  for (int i = 0; i < kPile; ++i) pile.insert(pile.end(), {4.0, 4.0, 4.0});
  pile.insert(pile.end(), {1.0, 1.0, 1.0, 9.0, 9.0, 9.0});
  Extent box;
  box.add_particle(0.0, 0.0, 0.0, 0.5);
  box.add_particle(10.0, 10.0, 10.0, 0.5);
  const ParticleArrays piled = packed_arrays(pile);
  const std::vector<int32_t> all(size_t(kPile) + 2, 1);
  for (const int threads : {2, 3, 4}) {
    OcclusionVolume v;
    ASSERT_OK(v.build(MPI_COMM_SELF, piled, box, {}, kRadius, kStrength, threads));
    ASSERT_EQ(v.enclosure_nodes(), reference_enclosure(pile, all, {}, v)) << threads << " threads";
  }
}

// A volume kept from frame to frame and built again reuses its buffers without zeroing them:
// each build is a fresh volume's bit for bit, whatever the builds before it reached - other
// particles, other planes of z, another grid, a cut plane, particles on other ranks.
TEST(ObjectOcclusion, AVolumeBuiltAgainIsAFreshVolume) {
  constexpr int kCount = 40000;
  const int rank = world_rank(), ranks = world_size();
  Extent wide = cloud_extent();
  wide.add_particle(-20.0, -10.0, -30.0, 0.5);  // a larger box: another grid
  struct Frame {
    Extent global;
    std::function<bool(int, const double *)> mine;
    std::vector<CutPlane> cuts;
  };
  const std::vector<Frame> frames = {
      {cloud_extent(), [&](int k, const double *) { return k % ranks == rank; }, {}},
      // Only the lowest planes, in reverse rank order, cut: fewer planes reached.
      {cloud_extent(),
       [&](int k, const double *x) {
         return std::isfinite(x[2]) && x[2] < 12.0 && (k / 7) % ranks == ranks - 1 - rank;
       },
       {oblique_cut()}},
      {wide, [&](int, const double *) { return rank == 0; }, {}},
      {cloud_extent(), [&](int k, const double *) { return k % ranks == rank; }, {}},
  };
  OcclusionVolume kept;
  for (size_t f = 0; f < frames.size(); ++f) {
    Cloud mine;
    make_cloud(kCount, frames[f].mine, &mine);
    OcclusionVolume fresh;
    ASSERT_OK(fresh.build(MPI_COMM_WORLD, mine.arrays, frames[f].global, frames[f].cuts, kRadius,
                          kStrength));
    ASSERT_OK(kept.build(MPI_COMM_WORLD, mine.arrays, frames[f].global, frames[f].cuts, kRadius,
                         kStrength));
    ASSERT_FALSE(fresh.enclosure_nodes().empty()) << "frame " << f;
    EXPECT_EQ(kept.bulk_per_cell(), fresh.bulk_per_cell()) << "frame " << f;
    EXPECT_EQ(kept.face_occupancy(), fresh.face_occupancy()) << "frame " << f;
    ASSERT_EQ(kept.enclosure_nodes(), fresh.enclosure_nodes()) << "frame " << f;
  }
}

// Grids of fewer planes of z than the smoothing reaches across ranks' slabs (four planes: at 4
// ranks one each, the filter reading two slabs away), and of fewer planes than ranks (two: some
// slabs empty), with the particles round robin: the one-rank volume.
TEST(ObjectOcclusion, ThinGridsAreTheOneRankVolumeOnEveryRank) {
  for (const int layers : {3, 1}) {
    const auto all = [](int) { return true; };
    const auto inside = [](const Site &s) { return s.x < 4 || s.y < 4 || s.z == 0; };
    const Lattice whole = lattice(24, 24, layers, inside, all);
    const int rank = world_rank(), ranks = world_size();
    const Lattice mine = lattice(24, 24, layers, inside, [&](int k) { return k % ranks == rank; });
    // The bounds of the whole lattice on every rank.
    Extent global;
    for (const Site &s : whole.sites) global.add_particle(s.x, s.y, s.z, 0.5);
    OcclusionVolume alone, v;
    ASSERT_OK(alone.build(MPI_COMM_SELF, whole.arrays, global, {}, kRadius, kStrength));
    ASSERT_OK(v.build(MPI_COMM_WORLD, mine.arrays, global, {}, kRadius, kStrength));
    ASSERT_EQ(v.node_counts()[2], layers == 3 ? 4 : 2);
    EXPECT_EQ(v.bulk_per_cell(), alone.bulk_per_cell()) << layers << " layers";
    EXPECT_EQ(v.face_occupancy(), alone.face_occupancy()) << layers << " layers";
    if (layers == 3) ASSERT_FALSE(alone.enclosure_nodes().empty());
    ASSERT_EQ(v.enclosure_nodes(), alone.enclosure_nodes()) << layers << " layers";
  }
}

}  // namespace
}  // namespace lantern::testing

namespace lantern::testing {
namespace {

// Hands the bricks' refit's stream of positions to one volume, as the runtime does.
class VolumeTap : public PositionTap {
 public:
  explicit VolumeTap(OcclusionVolume *volume) : volume_(volume) {}
  void begin(int parts) override { volume_->begin_tapped_parts(parts); }
  void take(int part, const double *xyz, int64_t first, int64_t end) override {
    volume_->take_tapped(part, xyz, first, end);
  }

 private:
  OcclusionVolume *volume_;
};

// This rank's contiguous share of a 64 x 32 x 32 box of sites one unit apart in row order (x
// fastest, as an MD code's sorted arrays hold a crystal), each moved by `shift` and by a wobble
// under a tenth of the spacing that changes with `step`: packed x y z doubles.
void wobbled_share(int nx, int step, glm::dvec3 shift, std::vector<double> *xyz) {
  const int ny = 32, nz = 32, all = nx * ny * nz;
  const int rank = world_rank(), ranks = world_size();
  const int first = int(int64_t(all) * rank / ranks), end = int(int64_t(all) * (rank + 1) / ranks);
  xyz->resize(3 * size_t(end - first));
  for (int k = first; k < end; ++k) {
    const int site[3] = {k % nx, k / nx % ny, k / nx / ny};
    for (int a = 0; a < 3; ++a)
      (*xyz)[3 * size_t(k - first) + size_t(a)] =
          site[a] + shift[a] + 0.09 * std::sin(0.7 * k + 1.3 * a + 0.5 * step);
  }
}

Extent global_extent_of(const ParticleArrays &arrays) {
  return reduce_extent(MPI_COMM_WORLD, scan_particles(arrays, false, 0.0, 1));
}

// A deposit made from the refit's stream of the next step's positions (on last step's grid, a
// node wider) gives the volume a deposit of its own gives, at every rank count: after a wobble,
// after a shift past a node (the grid's origin moves, inside the wider grid), after a shift too
// far for it (the volume deposits on its own), and with a position that is not finite.
// The big box holds more particles than the 32-bit sums take (at one rank): they spill. The
// refit on one thread and on three (the big box in three parts, each depositing on its own).
TEST(ObjectOcclusion, ADepositTakenFromTheRefitIsTheVolumeOfItsOwn) {
  struct Case {
    const char *name;
    int nx;
    double shift_in_cells;  // along x, in node spacings (0.6: the bounds cross a node)
    bool nan;
    bool tapped;  // whether the refit's deposit is used
  };
  const Case cases[] = {{"wobble", 64, 0.0, false, true},
                        {"shift past a node", 64, 0.6, false, true},
                        {"shift too far", 64, 3.5, false, false},
                        {"not finite", 64, 0.0, true, false},
                        {"spilled sums", 1100, 0.6, false, true}};
  CutPlane through;  // through the lattice, oblique: the tap deposits what it leaves
  through.normal = {0.6, 0.0, 0.8};
  through.offset = 20.0;
  for (const Case &c : cases)
    for (const int threads : {1, 3})
      for (const std::vector<CutPlane> &cuts : {std::vector<CutPlane>{}, {through}}) {
        SCOPED_TRACE(std::string(c.name) + ", " + std::to_string(threads) + " threads, " +
                     std::to_string(cuts.size()) + " planes");
        std::vector<double> xyz;
        wobbled_share(c.nx, 0, glm::dvec3(0.0), &xyz);
        ParticleArrays arrays = packed_arrays(xyz);
        BrickSet bricks = build_bricks(arrays, BrickOptions());
        ASSERT_FALSE(bricks.runs.empty());  // the refit streams the positions
        OcclusionVolume kept;
        ASSERT_OK(
            kept.build(MPI_COMM_WORLD, arrays, global_extent_of(arrays), cuts, kRadius, kStrength));
        EXPECT_FALSE(kept.last_build_tapped());
        const std::array<double, 3> origin = kept.node_origin();
        // The next step: the host's array rewritten in place.
        std::vector<double> next;
        wobbled_share(c.nx, 1, glm::dvec3(c.shift_in_cells * kept.node_spacing(), 0.0, 0.0), &next);
        if (c.nan && !next.empty()) next[3 * (next.size() / 6) + 1] = std::nan("");
        std::copy(next.begin(), next.end(), xyz.begin());
        ASSERT_TRUE(kept.arm_tap());
        VolumeTap tap(&kept);
        BrickOptions options;
        options.tap = &tap;
        options.threads = threads;
        (void)refit_bricks(arrays, 1.25, &bricks, options);  // a rebuild asked for changes nothing
        const Extent global = global_extent_of(arrays);
        ASSERT_OK(kept.build(MPI_COMM_WORLD, arrays, global, cuts, kRadius, kStrength));
        EXPECT_EQ(kept.last_build_tapped(), c.tapped);
        if (c.shift_in_cells > 0.0) EXPECT_NE(kept.node_origin(), origin);  // the grid moved
        OcclusionVolume fresh;
        ASSERT_OK(fresh.build(MPI_COMM_WORLD, arrays, global, cuts, kRadius, kStrength));
        EXPECT_EQ(kept.node_counts(), fresh.node_counts());
        EXPECT_EQ(kept.node_origin(), fresh.node_origin());
        EXPECT_EQ(kept.bulk_per_cell(), fresh.bulk_per_cell());
        ASSERT_FALSE(fresh.enclosure_nodes().empty());
        EXPECT_TRUE(kept.enclosure_nodes() == fresh.enclosure_nodes());
      }
}

// A tap armed on one step and not used (a dump step, a scene that failed) is dropped by the next
// build: a volume armed and built without a refit deposits on its own. So is a deposit that
// missed particles or met a position that is not finite.
TEST(ObjectOcclusion, AnArmedTapThatGotNothingIsNotUsed) {
  std::vector<double> xyz;
  wobbled_share(64, 0, glm::dvec3(0.0), &xyz);
  const ParticleArrays arrays = packed_arrays(xyz);
  const Extent global = global_extent_of(arrays);
  OcclusionVolume v, fresh;
  ASSERT_OK(v.build(MPI_COMM_WORLD, arrays, global, {}, kRadius, kStrength));
  ASSERT_TRUE(v.arm_tap());
  ASSERT_OK(v.build(MPI_COMM_WORLD, arrays, global, {}, kRadius, kStrength));
  EXPECT_FALSE(v.last_build_tapped());
  ASSERT_OK(fresh.build(MPI_COMM_WORLD, arrays, global, {}, kRadius, kStrength));
  EXPECT_TRUE(v.enclosure_nodes() == fresh.enclosure_nodes());
  // Handed straight to the tap: whole and in order it is used; with a stripe missing, out of
  // order or holding a position that is not finite it is not. In parts: each part's stripes in
  // order and the parts one after the other, some parts with none, it is used; with the parts'
  // halves swapped, or a gap between two parts, it is not.
  const int64_t count = int64_t(xyz.size() / 3), half = count / 2;
  const std::string used[] = {"whole", "in two parts", "in parts, some empty"};
  for (const std::string how : {"whole", "missing", "out of order", "not finite", "in two parts",
                                "in parts, some empty", "parts swapped", "a gap between parts"}) {
    SCOPED_TRACE(how);
    std::vector<double> handed = xyz;
    if (how == "not finite") handed[3 * size_t(half) + 2] = HUGE_VAL;
    ASSERT_TRUE(v.arm_tap());
    if (how == "in two parts" || how == "parts swapped" || how == "a gap between parts") {
      v.begin_tapped_parts(2);
      const bool swapped = how == "parts swapped";
      const int64_t second = how == "a gap between parts" ? half + 1 : half;
      v.take_tapped(swapped ? 1 : 0, handed.data(), 0, half / 3);
      v.take_tapped(swapped ? 1 : 0, handed.data(), half / 3, half);
      v.take_tapped(swapped ? 0 : 1, handed.data(), second, count);
    } else if (how == "in parts, some empty") {
      v.begin_tapped_parts(5);  // parts 0, 2 and 4 get nothing
      v.take_tapped(1, handed.data(), 0, half);
      v.take_tapped(3, handed.data(), half, count);
    } else {
      if (how == "out of order") v.take_tapped(0, handed.data(), half, count);
      v.take_tapped(0, handed.data(), 0, half);
      if (how != "missing") v.take_tapped(0, handed.data(), half, count);
    }
    ASSERT_OK(v.build(MPI_COMM_WORLD, arrays, global, {}, kRadius, kStrength));
    EXPECT_EQ(v.last_build_tapped(),
              std::find(std::begin(used), std::end(used), how) != std::end(used));
    EXPECT_TRUE(v.enclosure_nodes() == fresh.enclosure_nodes());
  }
  // Behind a cutting plane the tap is armed and deposits what the plane leaves: used where the
  // next build has that plane, not where it has another or none.
  CutPlane moved = oblique_cut();
  moved.offset += 1.0;
  CutPlane off = oblique_cut();
  off.enabled = false;
  const std::vector<CutPlane> cut{oblique_cut()}, other{moved}, none{}, disabled{off};
  for (const std::vector<CutPlane> *next : {&cut, &other, &none, &disabled}) {
    ASSERT_OK(v.build(MPI_COMM_WORLD, arrays, global, cut, kRadius, kStrength));
    ASSERT_TRUE(v.arm_tap());
    v.take_tapped(0, xyz.data(), 0, count);
    ASSERT_OK(v.build(MPI_COMM_WORLD, arrays, global, *next, kRadius, kStrength));
    EXPECT_EQ(v.last_build_tapped(), next == &cut) << next->size() << " planes";
    OcclusionVolume own;
    ASSERT_OK(own.build(MPI_COMM_WORLD, arrays, global, *next, kRadius, kStrength));
    ASSERT_FALSE(own.enclosure_nodes().empty());
    EXPECT_TRUE(v.enclosure_nodes() == own.enclosure_nodes()) << next->size() << " planes";
  }
  // A disabled plane cuts nothing: armed behind it, the tap serves a build without planes.
  ASSERT_OK(v.build(MPI_COMM_WORLD, arrays, global, disabled, kRadius, kStrength));
  ASSERT_TRUE(v.arm_tap());
  v.take_tapped(0, xyz.data(), 0, count);
  ASSERT_OK(v.build(MPI_COMM_WORLD, arrays, global, none, kRadius, kStrength));
  EXPECT_TRUE(v.last_build_tapped());
  // A group: the next step is not armed (the deposit would need the mask).
  Cloud grouped;
  make_cloud(
      3000, [](int, const double *) { return true; }, &grouped);
  ASSERT_OK(v.build(MPI_COMM_WORLD, grouped.arrays, cloud_extent(), {}, kRadius, kStrength));
  EXPECT_FALSE(v.arm_tap());
}

// The nodes lie on a lattice fixed in space: moving one particle at the edge by less than a node
// moves neither the grid nor the factors of particles far from it.
TEST(ObjectOcclusion, TheGridStaysPutWhenTheBoundsMoveALittle) {
  std::vector<double> xyz;
  wobbled_share(64, 0, glm::dvec3(0.0), &xyz);
  const ParticleArrays arrays = packed_arrays(xyz);
  OcclusionVolume before, after;
  ASSERT_OK(before.build(MPI_COMM_WORLD, arrays, global_extent_of(arrays), {}, kRadius, kStrength));
  // The lowest particle in x moves a tenth of a node further out.
  const Extent global = global_extent_of(arrays);
  for (size_t i = 0; i < xyz.size(); i += 3)
    if (xyz[i] == global.lo[0]) xyz[i] -= 0.1 * before.node_spacing();
  ASSERT_OK(after.build(MPI_COMM_WORLD, arrays, global_extent_of(arrays), {}, kRadius, kStrength));
  if (before.node_origin() != after.node_origin()) GTEST_SKIP() << "the bound crossed a node";
  EXPECT_EQ(before.node_counts(), after.node_counts());
  for (const glm::dvec3 far : {glm::dvec3(40.0, 16.0, 16.0), glm::dvec3(60.0, 2.0, 30.0)})
    EXPECT_EQ(before.factor(far), after.factor(far));
}

}  // namespace
}  // namespace lantern::testing
