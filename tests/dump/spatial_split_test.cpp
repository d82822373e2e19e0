// lantern-render's spatial split (adaptor/render_tool/spatial_split.h) at 1-4 ranks: every
// particle ends on exactly one rank with all its fields, each rank holds a contiguous run of the
// frame's z-order curve (ranks in curve order), in the file's row order, the counts balance, and
// particles off the curve (NaN, infinite) stay where they were read.
#include "spatial_split.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/bricks/morton.h"
#include "tests/support/mpi_world.h"

namespace lantern {
namespace {

using testing::world_rank;
using testing::world_size;

// Rows [begin, end) of a frame of n particles: a dense blob beside a sparse cloud, scrambled row
// order (as a file written by many ranks is), id = row, type and radius derived from the row.
ParticleFrame rows(int64_t n, int64_t begin, int64_t end) {
  ParticleFrame f;
  for (int64_t i = begin; i < end; ++i) {
    std::mt19937_64 rng(uint64_t(i) * 7919 + 1);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const bool blob = i % 3 != 0;
    const double s = blob ? 2.0 : 40.0;
    f.position.insert(f.position.end(), {s * u(rng), s * u(rng) + (blob ? 10.0 : 0.0), s * u(rng)});
    f.id.push_back(i);
    f.type.push_back(i % 5);
    f.radius.push_back(0.1 + 0.001 * double(i % 17));
  }
  if (begin <= 5 && 5 < end) f.position[size_t(3 * (5 - begin))] = std::nan("");
  f.global_count = n;
  return f;
}

TEST(SpatialSplit, EachRankHoldsARunOfTheCurveInFileOrder) {
  const int rank = world_rank(), ranks = world_size();
  constexpr int64_t kN = 20000;
  const auto [begin, end] = rank_share(kN, rank, ranks);
  ParticleFrame frame = rows(kN, begin, end);
  SplitStats stats;
  ASSERT_EQ(split_spatially(MPI_COMM_WORLD, &frame, &stats), "");
  const int64_t n = frame.count();
  ASSERT_EQ(int64_t(frame.id.size()), n);
  ASSERT_EQ(int64_t(frame.type.size()), n);
  ASSERT_EQ(int64_t(frame.radius.size()), n);
  // Fields travel together, and rows stay in file order.
  for (int64_t k = 0; k < n; ++k) {
    const ParticleFrame mine = rows(kN, frame.id[size_t(k)], frame.id[size_t(k)] + 1);
    for (int c = 0; c < 3; ++c) {
      const double want = mine.position[size_t(c)], got = frame.position[size_t(3 * k + c)];
      ASSERT_TRUE(want == got || (std::isnan(want) && std::isnan(got)));
    }
    ASSERT_EQ(frame.type[size_t(k)], mine.type[0]);
    ASSERT_EQ(frame.radius[size_t(k)], mine.radius[0]);
    if (k > 0) ASSERT_LT(frame.id[size_t(k - 1)], frame.id[size_t(k)]);
  }
  // Every particle on exactly one rank; the NaN one where it was read.
  int64_t total = 0;
  MPI_Allreduce(&n, &total, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(total, kN);
  const bool has_nan = std::find(frame.id.begin(), frame.id.end(), 5) != frame.id.end();
  EXPECT_EQ(has_nan, begin <= 5 && 5 < end);
  // Ranks hold disjoint, ordered runs of the curve over the frame's bounds.
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (int64_t k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c)
      if (!std::isnan(frame.position[size_t(3 * k)])) {
        lo[c] = std::min(lo[c], frame.position[size_t(3 * k + c)]);
        hi[c] = std::max(hi[c], frame.position[size_t(3 * k + c)]);
      }
  MPI_Allreduce(MPI_IN_PLACE, lo, 3, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, hi, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  const MortonQuantiser q =
      MortonQuantiser::for_bounds({lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]});
  uint64_t range[2] = {~uint64_t(0), 0};  // this rank's least and greatest key
  for (int64_t k = 0; k < n; ++k) {
    const double *p = frame.position.data() + 3 * k;
    if (std::isnan(p[0])) continue;
    const uint64_t key = q.key({p[0], p[1], p[2]});
    range[0] = std::min(range[0], key), range[1] = std::max(range[1], key);
  }
  std::vector<uint64_t> all(size_t(2 * ranks));
  MPI_Allgather(range, 2, MPI_UINT64_T, all.data(), 2, MPI_UINT64_T, MPI_COMM_WORLD);
  for (int r = 1; r < ranks; ++r) EXPECT_LT(all[size_t(2 * r - 1)], all[size_t(2 * r)]) << r;
  // Balanced to within the patches' size, and reported alike on every rank.
  EXPECT_EQ(stats.most, [&] {
    int64_t m = n;
    MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_INT64_T, MPI_MAX, MPI_COMM_WORLD);
    return m;
  }());
  EXPECT_LT(stats.imbalance(), 1.05);
}

TEST(SpatialSplit, RanksWithoutRowsAndFramesWithoutFiniteParticles) {
  const int rank = world_rank(), ranks = world_size();
  // Fewer rows than ranks: some ranks read nothing and lack the arrays the others have.
  ParticleFrame frame = rank == 0 ? rows(2, 0, 2) : ParticleFrame();
  SplitStats stats;
  ASSERT_EQ(split_spatially(MPI_COMM_WORLD, &frame, &stats), "");
  int64_t n = frame.count(), total = 0;
  MPI_Allreduce(&n, &total, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(total, 2);
  EXPECT_EQ(int64_t(frame.type.size()), n);
  // Nothing finite: nobody moves.
  ParticleFrame nan_only;
  nan_only.position = {std::nan(""), 0.0, 0.0};
  nan_only.id = {rank};
  ASSERT_EQ(split_spatially(MPI_COMM_WORLD, &nan_only, &stats), "");
  ASSERT_EQ(nan_only.id, std::vector<int64_t>{rank});
  (void)ranks;
}

}  // namespace
}  // namespace lantern
