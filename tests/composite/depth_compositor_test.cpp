// Sort-last compositing: every rank draws synthetic spheres with analytic depth, the frames are
// composited, and root compares pixel by pixel with an independent serial merge of all ranks'
// frames (which every rank can regenerate). Run under mpiexec with 1, 2, 3, 4 and 8 ranks.
//
// Collectives first, checks last: an early ASSERT return on one rank would strand the others.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <ostream>
#include <vector>

#include "core/common/injected_fault.h"
#include "core/composite/active_pixel_exchange.h"
#include "core/composite/composite_cost_model.h"
#include "core/composite/composite_methods.h"
#include "core/composite/compositing_schedule.h"
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
  // The last rank holds pixels beyond the background (depth 2, not a window depth), one in every
  // rank's share of the frame: then no background pixel is neutral any more, and active pixels
  // must still merge exactly.
  bool beyond_background = false;
  // Every rank also draws one sphere over the whole frame (at its own depth): no pixel is empty
  // anywhere, so every active-pixel message is as long as its bound allows.
  bool covered = false;
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
  if (c.covered) {
    Sphere all;
    all.cx = 0.5 * c.width;
    all.cy = 0.5 * c.height;
    all.radius = 2.0 * (c.width + c.height);
    all.depth = 0.7f + 0.01f * float(rank % 16);
    all.depth_radius = 0.05f;
    all.rgba[0] = uint8_t(40 + 50 * (rank % 4));
    all.rgba[1] = uint8_t(200 - 30 * (rank % 5));
    draw_sphere(all, f);
  }
  if (c.beyond_background && rank == ranks - 1)  // one such pixel in every rank's share
    for (int k = 0; k < ranks; ++k)
      f.depth[std::min(f.pixel_count() - 1, f.pixel_count() * size_t(k) / size_t(ranks) + 1)] =
          2.0f;
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

Outcome composite_case(const Case &c, const CompositeOptions &options, int root) {
  const int rank = world_rank(), ranks = world_size();
  Frame frame = frame_of_rank(c, rank, ranks);
  Outcome out;
  out.status = composite_frames(MPI_COMM_WORLD, frame, root, options, &out.stats);
  if (rank == root && out.status.ok())
    out.difference = describe_difference(frame, expected_image(c, ranks));
  return out;
}

Outcome composite_case(const Case &c, CompositeMethod method, int root, size_t chunk = 0) {
  CompositeOptions options;
  options.method = method;
  options.chunk_pixels = chunk;
  return composite_case(c, options, root);
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

TEST_P(CompositeMethods, APixelBeyondTheBackgroundStillMergesExactly) {
  Case c;
  c.beyond_background = true;
  expect_matches(composite_case(c, GetParam(), 0));
  expect_matches(composite_case(c, GetParam(), world_size() - 1));  // on the rank that holds them
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
                                           CompositeMethod::kDirectSend,
                                           CompositeMethod::kActivePixels),
                         [](const ::testing::TestParamInfo<CompositeMethod> &info) {
                           return std::string(to_string(info.param));
                         });

TEST(Composite, AllMethodsAreBitIdentical) {
  Case c;
  c.seed = 5;
  c.width = 640;
  c.height = 480;
  std::vector<Frame> results;
  for (const CompositeMethod m :
       {CompositeMethod::kReduce64, CompositeMethod::kReduceScatter, CompositeMethod::kBinarySwap,
        CompositeMethod::kDirectSend, CompositeMethod::kActivePixels}) {
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
  for (const CompositeMethod m : {CompositeMethod::kAuto, CompositeMethod::kReduce64,
                                  CompositeMethod::kReduceScatter, CompositeMethod::kBinarySwap,
                                  CompositeMethod::kDirectSend, CompositeMethod::kActivePixels}) {
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

// A message the root cannot decode (only an encoder defect could make one: an injected fault
// here) fails the call on every rank, not on the root alone, whose peers would otherwise go on
// to the collective steps after compositing (the image's write) without it.
TEST(Composite, AMessageOneRankCannotDecodeFailsOnEveryRank) {
  if (world_size() < 2) GTEST_SKIP() << "needs two ranks";
  Case c;
  c.seed = 7;
  c.width = 160;
  c.height = 120;
  Frame frame = frame_of_rank(c, world_rank(), world_size());
  if (world_rank() == 0) inject_fault("active pixels: decode");
  const Status status = composite_frames(MPI_COMM_WORLD, frame, 0, CompositeMethod::kActivePixels);
  inject_fault("");
  EXPECT_EQ(status.code, StatusCode::kInternal) << status.message;
  EXPECT_NE(status.message.find("active pixels: decode (injected fault)"), std::string::npos)
      << status.message;
  // Nothing is left in flight: the next call composites the same frames exactly.
  expect_matches(composite_case(c, CompositeMethod::kActivePixels, 0));
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

// kAuto runs what the default model says is cheapest for the frame it sees: active pixels along
// the model's schedule, or the cheaper dense method (one MPI_Reduce or the dense binary swap)
// where no schedule is cheaper. On frames where nothing is drawn only messages and the scan cost,
// and the tree reduce's log2(p) messages beat MPI_Reduce's (which moves the whole frame); where
// every rank but the last covers every pixel the active schedules move whole frames too, and
// scanning and encoding them costs more than a dense merge.
TEST(Composite, AutoPicksTheModelsCheapestAndSaysWhich) {
  const int ranks = world_size(), rank = world_rank();
  const bool alone = ranks == 1;
  // Covered: rank r draws every pixel at depth 0.5 + r / 64 (the last rank's pixels are the
  // frames' largest key, so every other rank's are all active).
  const auto covered = [&](int width, int height) {
    Frame f = blank_frame(width, height);
    std::fill(f.depth.begin(), f.depth.end(), 0.5f + float(rank) / 64.0f);
    std::fill(f.rgba.begin(), f.rgba.end(), uint8_t(40 + rank));
    return f;
  };
  struct Expect {
    const char *what;
    Frame frame;
    size_t most_active;  // the busiest rank's active pixels
  };
  std::vector<Expect> cases;
  cases.push_back({"tiny blank", blank_frame(4, 4), 0});
  cases.push_back({"large blank", blank_frame(640, 480), 0});
  cases.push_back({"tiny covered", covered(4, 4), alone ? 0u : 16u});
  cases.push_back({"large covered", covered(640, 480), alone ? 0u : 640u * 480u});
  std::vector<CompositeStats> stats(cases.size());
  for (size_t i = 0; i < cases.size(); ++i)
    EXPECT_OK(
        composite_frames(MPI_COMM_WORLD, cases[i].frame, 0, CompositeMethod::kAuto, 0, &stats[i]));
  for (size_t i = 0; i < cases.size(); ++i) {
    const CompositeStats &st = stats[i];
    if (alone) {
      EXPECT_EQ(st.method, "none") << cases[i].what;
      continue;
    }
    const size_t n = cases[i].frame.pixel_count();
    CostEstimate best;
    const CompositingSchedule s =
        cheapest_schedule(ranks, n, cases[i].most_active, true, default_cost_model(), &best);
    const CostEstimate reduce = estimate_reduce64(ranks, n, default_cost_model());
    const CostEstimate swap = estimate_dense_binary_swap(ranks, n, default_cost_model());
    const CostEstimate dense = swap.seconds < reduce.seconds ? swap : reduce;
    const char *dense_name = swap.seconds < reduce.seconds ? "binary_swap" : "reduce64";
    const bool dense_wins = dense.seconds <= best.seconds;
    EXPECT_EQ(st.method, dense_wins ? dense_name : "active_pixels") << cases[i].what;
    EXPECT_EQ(st.schedule, dense_wins ? std::string("dense ") + dense_name : s.name())
        << cases[i].what;
    EXPECT_DOUBLE_EQ(st.model_ms, (dense_wins ? dense : best).seconds * 1e3) << cases[i].what;
  }
  if (alone) return;
  EXPECT_EQ(stats[0].schedule, "tree_reduce");
  EXPECT_EQ(stats[1].method, "active_pixels");
  EXPECT_EQ(stats[2].method, "reduce64");
  EXPECT_NE(stats[3].method, "active_pixels");
}

// The model prices the CPU work of active pixels (scan, encode, merge) against the dense merge:
// where half of every rank's frame is drawn and that work costs more than the bytes it saves,
// kAuto keeps the dense binary swap (deciding on a sample of the rows, without scanning the whole
// frame); with the CPU work free it sends active pixels. The image is the same either way.
TEST(Composite, AutoPricesTheCpuWorkOfActivePixels) {
  if (world_size() == 1) GTEST_SKIP() << "needs two ranks";
  const int rank = world_rank();
  const auto half_drawn = [&] {
    Frame f = blank_frame(512, 256);
    for (int y = 0; y < f.height; ++y)
      for (int x = 0; x < f.width; ++x)
        if (((x / 32 + y / 32 + rank) % 2) == 0) {
          const size_t i = f.index(x, y);
          f.depth[i] = 0.25f + float((x + y + 5 * rank) % 97) / 256.0f;
          for (int c = 0; c < 4; ++c) f.rgba[4 * i + size_t(c)] = uint8_t(30 * rank + c + 1);
        }
    return f;
  };
  CompositeCostModel priced;
  priced.latency_s = 1e-6, priced.bytes_per_s = 1e10;
  priced.scan_s = 1e-9, priced.encode_s = 3e-9, priced.merge_s = 2e-9, priced.dense_merge_s = 2e-9;
  CompositeCostModel free_cpu = priced;
  free_cpu.scan_s = free_cpu.encode_s = free_cpu.merge_s = free_cpu.dense_merge_s = 0.0;
  Frame dense_frame = half_drawn(), active_frame = half_drawn();
  CompositeOptions o;
  CompositeStats dense_stats, active_stats;
  o.model = &priced;
  EXPECT_OK(composite_frames(MPI_COMM_WORLD, dense_frame, 0, o, &dense_stats));
  o.model = &free_cpu;
  EXPECT_OK(composite_frames(MPI_COMM_WORLD, active_frame, 0, o, &active_stats));
  EXPECT_EQ(dense_stats.method, "binary_swap");
  EXPECT_EQ(dense_stats.schedule, "dense binary_swap");
  EXPECT_EQ(dense_stats.active_pixels, 0u);  // decided on the sample: no full scan
  EXPECT_EQ(active_stats.method, "active_pixels");
  EXPECT_GT(active_stats.active_pixels, 0u);
  // Over every rank, active pixels move fewer bytes.
  unsigned long long moved[2] = {active_stats.traffic.bytes_sent, dense_stats.traffic.bytes_sent},
                     total[2];
  MPI_Allreduce(moved, total, 2, MPI_UNSIGNED_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_LT(total[0], total[1]);
  if (rank == 0) {
    EXPECT_EQ(dense_frame.depth, active_frame.depth);
    EXPECT_EQ(dense_frame.rgba, active_frame.rgba);
  }
}

// Every schedule the model could choose for this rank count, with messages small enough that
// every stream is cut into many: bit-identical to the serial merge, for every root.
TEST(ActivePixels, EveryCandidateScheduleMatchesSerialMerge) {
  if (world_size() == 1) GTEST_SKIP() << "needs two ranks";
  for (const CompositingSchedule &s : candidate_schedules(world_size(), true)) {
    CompositeOptions o;
    o.method = CompositeMethod::kActivePixels;
    o.schedule = s;
    o.chunk_pixels = 97;
    Case c;
    c.seed = 8;
    const Outcome out = composite_case(c, o, world_size() - 1);
    expect_matches(out);
    EXPECT_EQ(out.stats.schedule, s.name());
    Case ties;
    ties.flat = true;
    ties.empty = Empty::kEvenRanks;
    expect_matches(composite_case(ties, o, 0));
  }
}

// Frames drawn everywhere, so that every stream's messages fill their bound. When the root takes
// the blocks of several ranks at once, each sender sends to it alone: the senders must still cut
// their messages to the root's share of its receive pool (a sender filling its whole pool once
// overflowed the root's buffer, MPI_ERR_TRUNCATE, at three ranks and more). Every schedule, both
// ends of the rank range as root, a pool of a few dozen pixels so that every stream is cut into
// many messages; and the default chunk, where a stream is one large message.
TEST(ActivePixels, FullyDrawnFramesMatchSerialMergeForEveryScheduleAndRoot) {
  if (world_size() == 1) GTEST_SKIP() << "needs two ranks";
  Case c;
  c.width = 97;
  c.height = 61;
  c.covered = true;
  for (const size_t chunk : {size_t(61), size_t(0)}) {
    for (const CompositingSchedule &s : candidate_schedules(world_size(), true)) {
      for (const int root : {0, world_size() - 1}) {
        CompositeOptions o;
        o.method = CompositeMethod::kActivePixels;
        o.schedule = s;
        o.chunk_pixels = chunk;
        const Outcome out = composite_case(c, o, root);
        expect_matches(out);
        EXPECT_EQ(out.stats.schedule, s.name());
      }
    }
  }
}

// Scratch is kept between calls and only grows, so ranks that composited with a larger chunk
// before (here ranks 0 and 1 among themselves) hold larger buffers than the others. Message
// bounds must follow this call's agreed chunk, not the buffers: otherwise ranks 0 and 1 send
// messages the others cannot receive.
TEST(ActivePixels, ScratchGrownByEarlierCallsOnSomeRanksLeavesMessageBoundsAgreed) {
  if (world_size() < 3) GTEST_SKIP() << "needs three ranks";
  Case c;
  c.width = 97;
  c.height = 61;
  c.covered = true;
  MPI_Comm pair = MPI_COMM_NULL;
  MPI_Comm_split(MPI_COMM_WORLD, world_rank() < 2 ? 0 : 1, world_rank(), &pair);
  int pair_rank = 0, pair_size = 1;
  MPI_Comm_rank(pair, &pair_rank);
  MPI_Comm_size(pair, &pair_size);
  CompositeOptions large;
  large.method = CompositeMethod::kActivePixels;
  large.chunk_pixels = 8192;
  Frame first = frame_of_rank(c, pair_rank, pair_size);
  const Status first_status = composite_frames(pair, first, 0, large, nullptr);
  MPI_Comm_free(&pair);
  EXPECT_OK(first_status);
  for (const CompositingSchedule &s : candidate_schedules(world_size(), true)) {
    CompositeOptions o;
    o.method = CompositeMethod::kActivePixels;
    o.schedule = s;
    o.chunk_pixels = 61;
    const Outcome out = composite_case(c, o, world_size() - 1);
    expect_matches(out);
  }
}

// A rank sends what it drew: with one small sphere per rank, active pixels move a fraction of
// what dense binary swap moves, and the stats count both sides of every message.
TEST(ActivePixels, BytesFollowWhatWasDrawnAndAreCounted) {
  if (world_size() == 1) GTEST_SKIP() << "needs two ranks";
  Case c;
  c.width = 400;
  c.height = 300;
  c.spheres_per_rank = 1;
  c.seed = 9;
  const int rank = world_rank();
  Frame dense_frame = frame_of_rank(c, rank, world_size()), sparse_frame = dense_frame;
  CompositeStats dense, sparse;
  EXPECT_OK(
      composite_frames(MPI_COMM_WORLD, dense_frame, 0, CompositeMethod::kBinarySwap, 0, &dense));
  EXPECT_OK(composite_frames(MPI_COMM_WORLD, sparse_frame, 0, CompositeMethod::kActivePixels, 0,
                             &sparse));
  if (rank == 0) EXPECT_EQ(describe_difference(dense_frame, sparse_frame), "");
  EXPECT_GT(sparse.active_pixels, 0u);
  EXPECT_LT(sparse.active_pixels, c.width * c.height / 2u);
  // Totals over the ranks: every byte sent was received.
  uint64_t mine[4] = {sparse.traffic.bytes_sent, sparse.traffic.bytes_received,
                      dense.traffic.bytes_sent, dense.traffic.bytes_received};
  uint64_t total[4];
  MPI_Allreduce(mine, total, 4, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(total[0], total[1]);
  EXPECT_EQ(total[2], total[3]);
  EXPECT_GT(total[0], 0u);
  // Dense binary swap sends (1 - 1/p) of the frame per rank plus the gather: 8 bytes a pixel.
  EXPECT_LT(total[0] * 2, total[2]);
  EXPECT_GT(sparse.traffic.messages_sent + sparse.traffic.messages_received, 0u);
}

TEST(ActivePixels, DifferentCostModelsOrSchedulesFailOnEveryRankWithoutDeadlock) {
  if (world_size() == 1) GTEST_SKIP() << "needs two ranks";
  Frame frame = blank_frame(32, 16);
  CompositeCostModel model = default_cost_model();
  if (world_rank() == 1) model.latency_s *= 2;
  CompositeOptions o;
  o.model = &model;
  Status s = composite_frames(MPI_COMM_WORLD, frame, 0, o);
  EXPECT_EQ(s.code, StatusCode::kMpi);
  EXPECT_NE(s.message.find("cost models"), std::string::npos) << s.message;
  CompositeOptions bad;
  bad.method = CompositeMethod::kActivePixels;
  bad.schedule = CompositingSchedule{world_size(), {world_size() + 1}, false};
  s = composite_frames(MPI_COMM_WORLD, frame, 0, bad);
  EXPECT_EQ(s.code, StatusCode::kMpi);
  EXPECT_NE(s.message.find("does not fit"), std::string::npos) << s.message;
  EXPECT_OK(composite_frames(MPI_COMM_WORLD, frame, 0));
}

TEST(CompositeCostModel, MeasuredModelIsTheSameOnEveryRank) {
  CompositeCostModel model;
  EXPECT_OK(measure_cost_model(MPI_COMM_WORLD, &model));
  EXPECT_GT(model.latency_s, 0.0);
  EXPECT_GT(model.bytes_per_s, 0.0);
  EXPECT_EQ(model.measured, world_size() > 1);
  // The CPU figures per pixel: positive and below a microsecond (a pass over a frame of 8-byte
  // pixels, not a system call per pixel).
  for (const double s : {model.scan_s, model.encode_s, model.merge_s, model.dense_merge_s}) {
    EXPECT_GT(s, 0.0);
    EXPECT_LT(s, 1e-6);
  }
  double figures[6] = {model.latency_s, model.bytes_per_s, model.scan_s,
                       model.encode_s,  model.merge_s,     model.dense_merge_s};
  double low[6], high[6];
  MPI_Allreduce(figures, low, 6, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(figures, high, 6, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(low[i], high[i]) << i;
}

TEST(CompositeMethodNames, RoundTrip) {
  for (const CompositeMethod m : {CompositeMethod::kAuto, CompositeMethod::kReduce64,
                                  CompositeMethod::kReduceScatter, CompositeMethod::kBinarySwap,
                                  CompositeMethod::kDirectSend, CompositeMethod::kActivePixels}) {
    CompositeMethod parsed = CompositeMethod::kAuto;
    EXPECT_TRUE(parse_composite_method(to_string(m), &parsed));
    EXPECT_EQ(parsed, m);
  }
  CompositeMethod untouched = CompositeMethod::kBinarySwap;
  EXPECT_FALSE(parse_composite_method("radix_k", &untouched));
  EXPECT_TRUE(parse_composite_method("active_pixels", &untouched));
  EXPECT_EQ(untouched, CompositeMethod::kActivePixels);
  untouched = CompositeMethod::kBinarySwap;
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

// The scratch compositing keeps between frames stays bounded whatever the frame: binary swap and
// direct send receive a partner's pixels a segment at a time, active pixels stream messages
// carved from a pool of at most kActivePoolWords.
TEST(CompositeScratch, StaysBoundedWhateverTheFrame) {
  for (const CompositeMethod m : {CompositeMethod::kBinarySwap, CompositeMethod::kDirectSend}) {
    MethodScratch s;
    prepare_scratch(m, size_t(1024) * 1024, 2, size_t(1024) * 1024, s);
    EXPECT_EQ(s.depth.size(), kExchangeSegmentPixels);
    EXPECT_EQ(s.rgba.size(), 4 * kExchangeSegmentPixels);
    MethodScratch small;
    prepare_scratch(m, 1000, 2, size_t(1024) * 1024, small);
    EXPECT_EQ(small.depth.size(), 500u);  // half a small frame
  }
  ActivePixelScratch a;
  a.prepare(size_t(1024) * 1024, 2);
  EXPECT_EQ(a.pool_words, kActivePoolWords);
  EXPECT_EQ(a.send.size(), kActivePoolWords);
  EXPECT_EQ(a.receive.size(), kActivePoolWords);
  ActivePixelScratch small;
  small.prepare(100, 2);
  EXPECT_EQ(small.pool_words, 102u);  // a whole small chunk and its header
  ActivePixelScratch many;
  many.prepare(size_t(1024) * 1024, 1 << 17);  // still a minimal message for every stream
  EXPECT_EQ(many.pool_words, size_t(1 << 17) * kMinMessageWords);
}

// 6144 x 3072 (the tiled-display size of Rizzi et al. 2015); run at 2 ranks.
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
  for (const CompositeMethod m :
       {CompositeMethod::kReduce64, CompositeMethod::kBinarySwap, CompositeMethod::kActivePixels}) {
    Frame frame = frame_of_rank(c, rank, ranks);
    EXPECT_OK(composite_frames(MPI_COMM_WORLD, frame, 0, m));
    if (rank == 0) EXPECT_EQ(describe_difference(frame, expected), "") << to_string(m);
  }
}

}  // namespace
}  // namespace lantern::testing
