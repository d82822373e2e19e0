// Object-space ambient occlusion (core/render/object_occlusion.h) on a cubic lattice: buried
// particles darken by exactly `strength`, corners not at all, a cut plane opens the cut face, and
// the factors do not depend on how the particles are split (run at 1, 2, 3 and 4 ranks).
#include <gtest/gtest.h>

#include <mpi.h>

#include <vector>

#include "core/particles/global_extent.h"
#include "core/render/object_occlusion.h"
#include "tests/support/mpi_world.h"
#include "tests/support/status_expect.h"

namespace lantern::testing {
namespace {

constexpr int kSide = 10;  // a 10 x 10 x 10 lattice of spacing 1
constexpr double kStrength = 0.6;

struct Lattice {
  std::vector<double> xyz;
  std::vector<int> site;  // lattice index of each particle held
  ParticleArrays arrays;
};

// The sites i with keep(i), as this rank's particles.
template <typename Keep>
Lattice lattice(Keep keep) {
  Lattice l;
  for (int i = 0; i < kSide * kSide * kSide; ++i) {
    if (!keep(i)) continue;
    l.site.push_back(i);
    l.xyz.insert(l.xyz.end(), {double(i % kSide), double(i / kSide % kSide), double(i / 100)});
  }
  ParticleDescription d;
  d.count = int64_t(l.site.size());
  d.position = {l.xyz.data(), DataType::kFloat64, 0};
  EXPECT_OK(ParticleArrays::validate(d, &l.arrays));
  return l;
}

Extent extent_of(MPI_Comm comm, const Lattice &l) {
  Extent local;
  for (size_t i = 0; i < l.site.size(); ++i)
    local.add_particle(l.xyz[3 * i], l.xyz[3 * i + 1], l.xyz[3 * i + 2], 0.5);
  return reduce_extent(comm, local);
}

// Factors by lattice site of the particles this rank holds (1 elsewhere and where cut away).
std::vector<float> factors(MPI_Comm comm, const Lattice &l, const std::vector<CutPlane> &cuts) {
  OcclusionVolume volume;
  EXPECT_OK(volume.build(comm, l.arrays, extent_of(comm, l), cuts, 2.0, kStrength));
  std::vector<float> by_site(kSide * kSide * kSide, 1.0f);
  for (size_t i = 0; i < l.site.size(); ++i) {
    const glm::dvec3 x(l.xyz[3 * i], l.xyz[3 * i + 1], l.xyz[3 * i + 2]);
    bool cut = false;
    for (const CutPlane &c : cuts) cut = cut || x[2] * c.normal[2] > c.offset;
    if (!cut) by_site[size_t(l.site[i])] = volume.factor(x);
  }
  return by_site;
}

int site(int x, int y, int z) {
  return x + kSide * (y + kSide * z);
}

TEST(ObjectOcclusion, BuriedParticlesDarkenByTheStrengthAndCornersNotAtAll) {
  const Lattice all = lattice([](int) { return true; });
  const std::vector<float> f = factors(MPI_COMM_SELF, all, {});
  EXPECT_FLOAT_EQ(f[size_t(site(5, 5, 5))], float(1.0 - kStrength));
  EXPECT_FLOAT_EQ(f[size_t(site(0, 0, 0))], 1.0f);
  EXPECT_FLOAT_EQ(f[size_t(site(9, 9, 9))], 1.0f);
  // A face is half as crowded as the bulk: it keeps (most of) its colour.
  EXPECT_GT(f[size_t(site(5, 5, 0))], f[size_t(site(5, 5, 5))] + 0.3f);
}

TEST(ObjectOcclusion, ACutPlaneOpensTheCutFace) {
  const Lattice all = lattice([](int) { return true; });
  CutPlane cut;
  cut.normal = {0, 0, 1};
  cut.offset = 4.5;  // drops z > 4.5: z = 4 becomes the top face
  const std::vector<float> whole = factors(MPI_COMM_SELF, all, {});
  const std::vector<float> cut_open = factors(MPI_COMM_SELF, all, {cut});
  EXPECT_GT(cut_open[size_t(site(5, 5, 4))], whole[size_t(site(5, 5, 4))] + 0.3f);
  EXPECT_EQ(cut_open[size_t(site(5, 5, 8))], 1.0f);  // cut away: not drawn, factor 1
}

TEST(ObjectOcclusion, TheSameFactorsForEverySplit) {
  const Lattice all = lattice([](int) { return true; });
  const std::vector<float> alone = factors(MPI_COMM_SELF, all, {});
  const int rank = world_rank(), ranks = world_size();
  for (const int split : {0, 1, 2}) {
    const Lattice mine = lattice([&](int i) {
      switch (split) {
        case 0:
          return i % ranks == rank;  // round robin
        case 1:
          return i * ranks / 1000 == rank;  // slabs in z
        default:
          return rank == ranks - 1;  // all on the last rank
      }
    });
    const std::vector<float> f = factors(MPI_COMM_WORLD, mine, {});
    for (int i : mine.site) ASSERT_EQ(f[size_t(i)], alone[size_t(i)]) << "split " << split;
  }
}

}  // namespace
}  // namespace lantern::testing
