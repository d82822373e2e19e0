// Compositing into row bands (core/composite/band_compositing.h): every rank's band of the merged
// frame is bit-identical to the same rows of an independent serial merge (and so of
// composite_frames), for any rank count, every schedule (folding included) and dense direct send,
// with depth ties, and bands on a super-sampling multiple; mismatched sizes fail on every rank
// without deadlock.
#include <gtest/gtest.h>

#include <mpi.h>

#include <cstring>
#include <string>
#include <vector>

#include "core/composite/band_compositing.h"
#include "core/composite/compositing_schedule.h"
#include "tests/composite/synthetic_frames.h"
#include "tests/support/mpi_world.h"

namespace lantern::testing {
namespace {

// The options every band test runs with: the default (active pixels, the model's schedule), every
// candidate schedule with small messages, and dense direct send.
std::vector<CompositeOptions> band_options() {
  std::vector<CompositeOptions> all(1);
  CompositeOptions dense;
  dense.method = CompositeMethod::kDirectSend;
  all.push_back(dense);
  if (world_size() > 1)
    for (const CompositingSchedule &s : candidate_schedules(world_size(), false)) {
      CompositeOptions o;
      o.method = CompositeMethod::kActivePixels;
      o.schedule = s;
      o.chunk_pixels = 61;
      all.push_back(o);
    }
  return all;
}

TEST(BandCompositing, EveryRanksBandIsTheSerialMergesRows) {
  const int ranks = world_size(), rank = world_rank();
  for (const CompositeOptions &options : band_options())
    for (const bool flat : {false, true})  // flat discs: depth ties settled by the smaller color
      for (const int multiple : {1, 4}) {
        const int width = 41, height = 13 * multiple;
        std::vector<Frame> all;
        for (int k = 0; k < ranks; ++k) {
          all.push_back(blank_frame(width, height));
          draw_sphere(sphere_for_rank(k, 7, width, height, flat), all.back());
          draw_sphere(sphere_for_rank(k + ranks, 7, width, height, flat), all.back());
        }
        const Frame expected = serial_merge(all);
        Frame mine = all[size_t(rank)];
        RowBand owned;
        CompositeStats stats;
        ASSERT_TRUE(
            composite_to_row_bands(MPI_COMM_WORLD, mine, multiple, &owned, options, &stats).ok());
        const RowBand want = row_band(height, ranks, rank, multiple);
        EXPECT_EQ(owned.y0, want.y0);
        EXPECT_EQ(owned.y1, want.y1);
        const bool dense = options.method == CompositeMethod::kDirectSend;
        EXPECT_EQ(stats.method, ranks == 1 ? "none"
                                : dense    ? "direct_send_bands"
                                           : "active_pixels_bands");
        if (options.schedule) EXPECT_EQ(stats.schedule, options.schedule->name());
        int64_t differing = 0;
        for (int y = owned.y0; y < owned.y1; ++y)
          for (int x = 0; x < width; ++x) {
            const size_t i = mine.index(x, y);
            differing += mine.depth[i] != expected.depth[i] ||
                         std::memcmp(&mine.rgba[4 * i], &expected.rgba[4 * i], 4) != 0;
          }
        EXPECT_EQ(differing, 0) << "rank " << rank << ", flat " << flat << ", multiple " << multiple
                                << ", " << stats.method << " " << stats.schedule;
      }
}

TEST(BandCompositing, MethodsThatCannotEndInBandsAreRefusedOnEveryRank) {
  Frame frame = blank_frame(20, 8);
  RowBand owned;
  CompositeOptions o;
  o.method = CompositeMethod::kReduce64;
  Status s = composite_to_row_bands(MPI_COMM_WORLD, frame, 2, &owned, o);
  EXPECT_EQ(s.code, StatusCode::kInvalidArgument);
  EXPECT_NE(s.message.find("reduce64"), std::string::npos) << s.message;
  if (world_size() == 1) return;
  o.method = CompositeMethod::kActivePixels;
  o.schedule = CompositingSchedule{world_size(), {}, true};
  s = composite_to_row_bands(MPI_COMM_WORLD, frame, 2, &owned, o);
  EXPECT_EQ(s.code, StatusCode::kMpi);
  EXPECT_NE(s.message.find("cannot end in row bands"), std::string::npos) << s.message;
}

TEST(BandCompositing, FramesOfDifferentSizesFailOnEveryRankWithoutDeadlock) {
  if (world_size() == 1) GTEST_SKIP() << "needs two ranks";
  Frame frame = blank_frame(20, world_rank() == 0 ? 8 : 12);
  RowBand owned;
  const Status s = composite_to_row_bands(MPI_COMM_WORLD, frame, 2, &owned);
  EXPECT_EQ(s.code, StatusCode::kMpi);
  EXPECT_NE(s.message.find("sizes differ"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace lantern::testing
