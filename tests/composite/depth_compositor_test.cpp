// Sort-last compositing: every rank draws synthetic spheres with analytic depth, the frames are
// composited, and root compares pixel by pixel with an independent serial merge of all ranks'
// frames (which every rank can regenerate). Run under mpiexec with 1, 2, 3, 4 and 8 ranks.
//
// Collectives first, checks last: an early ASSERT return on one rank would strand the others.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <limits>
#include <ostream>
#include <vector>

#include "core/composite/depth_compositor.h"
#include "core/composite/packed_pixel.h"
#include "synthetic_frames.h"
#include "tests/support/mpi_world.h"
#include "tests/support/status_expect.h"

namespace lantern {
// Readable parameter names in gtest output (found by ADL).
void PrintTo(CompositeMethod m, std::ostream *os) {
  *os << to_string(m);
}
}  // namespace lantern

namespace lantern::testing {
namespace {

enum class Empty { kNone, kEvenRanks, kAllButLast, kAll };

struct Case {
  int width = 321;  // odd sizes: halves, blocks and chunks never divide evenly
  int height = 199;
  int seed = 1;
  bool flat = false;
  Empty empty = Empty::kNone;
  int spheres_per_rank = 3;
};

bool rank_is_empty(const Case &c, int rank, int ranks) {
  switch (c.empty) {
    case Empty::kNone:
      return false;
    case Empty::kEvenRanks:
      return rank % 2 == 0;
    case Empty::kAllButLast:
      return rank != ranks - 1;
    case Empty::kAll:
      return true;
  }
  return false;
}

Frame frame_of_rank(const Case &c, int rank, int ranks) {
  Frame f = blank_frame(c.width, c.height);
  if (rank_is_empty(c, rank, ranks)) return f;
  for (int k = 0; k < c.spheres_per_rank; ++k)
    draw_sphere(sphere_for_rank(rank, c.seed * 16 + k, c.width, c.height, c.flat), f);
  return f;
}

Frame expected_image(const Case &c, int ranks) {
  std::vector<Frame> frames;
  for (int r = 0; r < ranks; ++r) frames.push_back(frame_of_rank(c, r, ranks));
  return serial_merge(frames);
}

struct Outcome {
  Status status;
  CompositeStats stats;
  std::string difference;  // root only: "" if the composite equals the serial merge
};

Outcome composite_case(const Case &c, CompositeMethod method, int root, size_t chunk = 0) {
  const int rank = world_rank(), ranks = world_size();
  Frame frame = frame_of_rank(c, rank, ranks);
  Outcome out;
  out.status = composite_frames(MPI_COMM_WORLD, frame, root, method, chunk, &out.stats);
  if (rank == root && out.status.ok())
    out.difference = describe_difference(frame, expected_image(c, ranks));
  return out;
}

void expect_matches(const Outcome &o) {
  EXPECT_OK(o.status);
  EXPECT_EQ(o.difference, "");
  EXPECT_NE(o.stats.method, "auto");
}

class CompositeMethods : public ::testing::TestWithParam<CompositeMethod> {};

TEST_P(CompositeMethods, SpheresPerRankMatchSerialMerge) {
  expect_matches(composite_case(Case{}, GetParam(), 0));
}

TEST_P(CompositeMethods, DepthTiesAreBrokenByColorNotByRank) {
  Case c;
  c.flat = true;
  c.seed = 2;
  expect_matches(composite_case(c, GetParam(), 0));
}

TEST_P(CompositeMethods, EmptyRanksAreNeutral) {
  Case c;
  c.empty = Empty::kEvenRanks;
  expect_matches(composite_case(c, GetParam(), 0));
  c.empty = Empty::kAllButLast;
  expect_matches(composite_case(c, GetParam(), 0));
}

TEST_P(CompositeMethods, AllRanksEmptyGiveTheBackground) {
  Case c;
  c.empty = Empty::kAll;
  const Outcome o = composite_case(c, GetParam(), 0);
  expect_matches(o);
}

TEST_P(CompositeMethods, AnyRankCanBeRoot) {
  const int ranks = world_size();
  for (const int root : {ranks - 1, ranks / 2})
    expect_matches(composite_case(Case{}, GetParam(), root));
}

TEST_P(CompositeMethods, SmallChunksAndSegmentsGiveTheSameImage) {
  Case c;
  c.seed = 3;
  expect_matches(composite_case(c, GetParam(), 0, 777));
  // One pixel per message: every loop bound is exercised, on an image small enough to stay fast.
  c.width = 37;
  c.height = 23;
  expect_matches(composite_case(c, GetParam(), 0, 1));
}

TEST_P(CompositeMethods, ImagesWithFewerPixelsThanRanks) {
  for (const auto size : {std::pair<int, int>{1, 1}, {3, 1}, {2, 2}, {0, 0}}) {
    Case c;
    c.width = size.first;
    c.height = size.second;
    c.seed = 4;
    expect_matches(composite_case(c, GetParam(), 0));
  }
}

INSTANTIATE_TEST_SUITE_P(, CompositeMethods,
                         ::testing::Values(CompositeMethod::kAuto, CompositeMethod::kReduce64,
                                           CompositeMethod::kReduceScatter,
                                           CompositeMethod::kBinarySwap,
                                           CompositeMethod::kDirectSend),
                         [](const ::testing::TestParamInfo<CompositeMethod> &info) {
                           return std::string(to_string(info.param));
                         });

TEST(Composite, AllMethodsAreBitIdentical) {
  Case c;
  c.seed = 5;
  c.width = 640;
  c.height = 480;
  std::vector<Frame> results;
  for (const CompositeMethod m : {CompositeMethod::kReduce64, CompositeMethod::kReduceScatter,
                                  CompositeMethod::kBinarySwap, CompositeMethod::kDirectSend}) {
    Frame frame = frame_of_rank(c, world_rank(), world_size());
    EXPECT_OK(composite_frames(MPI_COMM_WORLD, frame, 0, m));
    results.push_back(std::move(frame));
  }
  if (world_rank() == 0)
    for (size_t m = 1; m < results.size(); ++m)
      EXPECT_EQ(describe_difference(results[0], results[m]), "") << m;
}

TEST(Composite, OneRankIsANoOp) {
  if (world_size() != 1) GTEST_SKIP() << "one-rank case";
  const Case c;
  const Frame before = frame_of_rank(c, 0, 1);
  Frame frame = before;
  CompositeStats stats;
  EXPECT_OK(composite_frames(MPI_COMM_WORLD, frame, 0, CompositeMethod::kAuto, 0, &stats));
  EXPECT_EQ(stats.method, "none");
  EXPECT_EQ(describe_difference(frame, before), "");
}

TEST(Composite, MismatchedFrameSizesFailOnEveryRankWithoutDeadlock) {
  if (world_size() < 2) GTEST_SKIP() << "needs two ranks";
  const int rank = world_rank();
  Frame frame = blank_frame(rank == 1 ? 33 : 32, 16);
  for (const CompositeMethod m :
       {CompositeMethod::kAuto, CompositeMethod::kReduce64, CompositeMethod::kReduceScatter,
        CompositeMethod::kBinarySwap, CompositeMethod::kDirectSend}) {
    const Status status = composite_frames(MPI_COMM_WORLD, frame, 0, m);
    EXPECT_EQ(status.code, StatusCode::kMpi) << status.message;
    EXPECT_NE(status.message.find("sizes differ"), std::string::npos) << status.message;
  }
}

TEST(Composite, BadRootOrDisagreeingMethodFailsOnEveryRank) {
  if (world_size() < 2) GTEST_SKIP() << "needs two ranks";
  Frame frame = blank_frame(8, 8);
  EXPECT_EQ(composite_frames(MPI_COMM_WORLD, frame, world_size()).code, StatusCode::kMpi);
  const CompositeMethod m =
      world_rank() == 0 ? CompositeMethod::kBinarySwap : CompositeMethod::kReduce64;
  EXPECT_EQ(composite_frames(MPI_COMM_WORLD, frame, 0, m).code, StatusCode::kMpi);
  // And the communicator is still usable afterwards.
  EXPECT_OK(composite_frames(MPI_COMM_WORLD, frame, 0));
}

TEST(Composite, StatsNameTheMethodThatRan) {
  Frame frame = blank_frame(64, 64);
  CompositeStats stats;
  EXPECT_OK(composite_frames(MPI_COMM_WORLD, frame, 0, CompositeMethod::kReduceScatter, 0, &stats));
  EXPECT_EQ(stats.method, world_size() == 1 ? "none" : "reduce_scatter");
  EXPECT_EQ(stats.ranks, world_size());
  EXPECT_EQ(stats.pixels, 64u * 64u);
  EXPECT_GE(stats.milliseconds, 0.0);
}

TEST(Composite, AutoPicksTheMeasuredMethodAndSaysWhich) {
  const bool alone = world_size() == 1;
  Frame small = blank_frame(64, 64), large = blank_frame(640, 480);
  CompositeStats s, l;
  EXPECT_OK(composite_frames(MPI_COMM_WORLD, small, 0, CompositeMethod::kAuto, 0, &s));
  EXPECT_OK(composite_frames(MPI_COMM_WORLD, large, 0, CompositeMethod::kAuto, 0, &l));
  EXPECT_EQ(s.method, alone ? "none" : "reduce64");  // latency-bound: one MPI_Reduce
  EXPECT_EQ(l.method, alone ? "none" : "binary_swap");
}

TEST(CompositeMethodNames, RoundTrip) {
  for (const CompositeMethod m :
       {CompositeMethod::kAuto, CompositeMethod::kReduce64, CompositeMethod::kReduceScatter,
        CompositeMethod::kBinarySwap, CompositeMethod::kDirectSend}) {
    CompositeMethod parsed = CompositeMethod::kAuto;
    EXPECT_TRUE(parse_composite_method(to_string(m), &parsed));
    EXPECT_EQ(parsed, m);
  }
  CompositeMethod untouched = CompositeMethod::kBinarySwap;
  EXPECT_FALSE(parse_composite_method("radix_k", &untouched));
  EXPECT_EQ(untouched, CompositeMethod::kBinarySwap);
}

TEST(PackedPixel, KeysOrderByDepthThenColorAndRoundTrip) {
  const uint8_t red[4] = {200, 0, 0, 255}, blue[4] = {0, 0, 200, 255};
  EXPECT_LT(pack_pixel(0.25f, red), pack_pixel(0.5f, blue));
  EXPECT_LT(pack_pixel(0.5f, blue), pack_pixel(0.5f, red));
  EXPECT_LT(pack_pixel(0.999f, red), pack_pixel(kBackgroundDepth, blue));
  EXPECT_EQ(pack_pixel(-0.0f, red), pack_pixel(0.0f, red));
  EXPECT_EQ(pack_pixel(-3.0f, red), pack_pixel(0.0f, red));
  EXPECT_EQ(pack_pixel(std::numeric_limits<float>::quiet_NaN(), red),
            pack_pixel(kBackgroundDepth, red));
  float depth = 0;
  uint8_t rgba[4] = {};
  unpack_pixel(pack_pixel(0.375f, red), &depth, rgba);
  EXPECT_EQ(depth, 0.375f);
  EXPECT_EQ(std::vector<uint8_t>(rgba, rgba + 4), std::vector<uint8_t>(red, red + 4));
}

// 6144 x 3072 (the tiled-display size of seed 001); run at 2 ranks.
TEST(LargeImage, TiledDisplaySizeMatchesSerialMerge) {
  Case c;
  c.width = 6144;
  c.height = 3072;
  c.seed = 6;
  c.spheres_per_rank = 1;
  const int rank = world_rank(), ranks = world_size();
  const Frame expected = rank == 0 ? expected_image(c, ranks) : Frame{};
  // One chunked MPI reduction and one point-to-point method (what kAuto runs): the other methods
  // share their loops, which the small-chunk tests cover.
  for (const CompositeMethod m : {CompositeMethod::kReduce64, CompositeMethod::kBinarySwap}) {
    Frame frame = frame_of_rank(c, rank, ranks);
    EXPECT_OK(composite_frames(MPI_COMM_WORLD, frame, 0, m));
    if (rank == 0) EXPECT_EQ(describe_difference(frame, expected), "") << to_string(m);
  }
}

}  // namespace
}  // namespace lantern::testing
