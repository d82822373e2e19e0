// The pieces of active-pixel compositing that need no communication: the radix-k schedules
// (every candidate, simulated serially, leaves every block merged over every rank exactly once),
// the scan (empty key, rectangle, count, canonical depths) and the run-length messages (round
// trips at every message size, the size bound, merging by the rule).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <vector>

#include "core/composite/active_pixels.h"
#include "core/composite/composite_cost_model.h"
#include "core/composite/compositing_schedule.h"
#include "core/composite/packed_pixel.h"
#include "core/composite/run_length_pixels.h"
#include "tests/composite/synthetic_frames.h"
#include "tests/support/hash_noise.h"
#include "tests/support/mpi_world.h"

namespace lantern::testing {
namespace {

// ---- schedules ---------------------------------------------------------------------------------

// Runs a schedule serially on "images" that record which ranks' pixels they hold: per rank and
// block, the set of contributing ranks. Returns "" if, at the end, every group's base rank holds
// its block with every rank exactly once and no data was read that the sender did not hold.
std::string simulate(const CompositingSchedule &s, const std::vector<PixelRange> &blocks) {
  const int p = s.ranks, q = s.base();
  using Held = std::vector<std::multiset<int>>;  // per block
  std::vector<Held> held(static_cast<size_t>(p), Held(size_t(q)));
  for (int r = 0; r < p; ++r)
    for (int b = 0; b < q; ++b) held[size_t(r)][size_t(b)].insert(r);
  const auto blocks_of = [&](PixelRange range) {
    std::vector<int> out;
    for (int b = 0; b < q; ++b)
      if (blocks[size_t(b)].lo >= range.lo && blocks[size_t(b)].hi <= range.hi) out.push_back(b);
    return out;
  };
  // Fold.
  for (int g = 0; g < q; ++g) {
    const int extra = s.extra_rank(g), base = s.base_rank(g);
    if (extra < 0) continue;
    if (s.group_of(extra) != g || s.group_of(base) != g || !s.is_extra(extra)) return "groups";
    for (int b = 0; b < q; ++b)
      for (const int r : held[size_t(extra)][size_t(b)]) held[size_t(base)][size_t(b)].insert(r);
  }
  // Rounds: everyone computes its plan from the state before the round.
  for (int round = 0; round < int(s.radices.size()); ++round) {
    std::vector<Held> next = held;
    for (int g = 0; g < q; ++g) {
      const RoundPlan plan = round_plan(s, g, round, blocks);
      if (int(plan.partners.size()) != s.radices[size_t(round)] - 1) return "partner count";
      for (size_t i = 0; i < plan.partners.size(); ++i) {
        const int to = plan.partners[i];
        const RoundPlan theirs = round_plan(s, s.group_of(to), round, blocks);
        // Their keep must be exactly our give.
        if (theirs.keep.lo != plan.give[i].lo || theirs.keep.hi != plan.give[i].hi)
          return "give/keep mismatch";
        for (const int b : blocks_of(plan.give[i]))
          for (const int r : held[size_t(s.base_rank(g))][size_t(b)])
            next[size_t(to)][size_t(b)].insert(r);
      }
    }
    held = std::move(next);
  }
  for (int g = 0; g < q; ++g) {
    std::multiset<int> all;
    for (int r = 0; r < p; ++r) all.insert(r);
    if (held[size_t(s.base_rank(g))][size_t(g)] != all)
      return "block " + std::to_string(g) + " of " + s.name();
  }
  return "";
}

TEST(CompositingSchedule, EveryCandidateMergesEveryRankIntoEveryBlockOnce) {
  if (world_size() > 1) GTEST_SKIP() << "serial: runs in the one-rank job";
  for (int p = 2; p <= 70; ++p) {
    const std::vector<CompositingSchedule> candidates = candidate_schedules(p, false);
    ASSERT_FALSE(candidates.empty()) << p;
    bool has_direct_send = false;
    for (const CompositingSchedule &s : candidates) {
      EXPECT_TRUE(s.valid()) << p << " " << s.name();
      has_direct_send = has_direct_send || (s.radices.size() == 1 && s.extras() == 0);
      // Blocks of one pixel each (none empty), so a misrouted block shows.
      const std::vector<PixelRange> blocks = equal_blocks(size_t(s.base()), s.base());
      EXPECT_EQ(simulate(s, blocks), "") << p << " ranks, " << s.name();
    }
    EXPECT_TRUE(has_direct_send) << p;
    const std::vector<CompositingSchedule> to_root = candidate_schedules(p, true);
    EXPECT_EQ(to_root.size(), candidates.size() + 1);
    EXPECT_TRUE(to_root.back().tree);
  }
}

TEST(CompositingSchedule, NamesSayWhatRuns) {
  EXPECT_EQ((CompositingSchedule{8, {2, 2, 2}}.name()), "binary_swap");
  EXPECT_EQ((CompositingSchedule{8, {8}}.name()), "direct_send");
  EXPECT_EQ((CompositingSchedule{8, {4, 2}}.name()), "radix_k 4x2");
  EXPECT_EQ((CompositingSchedule{7, {2, 2}}.name()), "binary_swap fold 3");
  EXPECT_EQ((CompositingSchedule{7, {}, true}.name()), "tree_reduce");
  EXPECT_TRUE((CompositingSchedule{7, {}, true}.valid()));
  EXPECT_EQ((CompositingSchedule{7, {2, 2}}.extras()), 3);
  EXPECT_FALSE((CompositingSchedule{9, {2, 2}}.valid()));  // 5 extras for 4 base ranks
  EXPECT_FALSE((CompositingSchedule{8, {3, 3}}.valid()));  // more than the ranks
  EXPECT_FALSE((CompositingSchedule{8, {1, 8}}.valid()));
}

TEST(CompositingSchedule, FoldedGroupsAreConsecutiveRanks) {
  const CompositingSchedule s{7, {2, 2}};  // groups {0,1} {2,3} {4,5} {6}
  EXPECT_EQ(s.group_of(0), 0);
  EXPECT_EQ(s.group_of(1), 0);
  EXPECT_EQ(s.group_of(5), 2);
  EXPECT_EQ(s.group_of(6), 3);
  EXPECT_EQ(s.base_rank(3), 6);
  EXPECT_EQ(s.extra_rank(2), 5);
  EXPECT_EQ(s.extra_rank(3), -1);
}

TEST(CompositeCostModel, ChoosesFewerMessagesWhenLatencyDominatesAndIsDeterministic) {
  CompositeCostModel slow_messages{1e-3, 1e12, true}, slow_bytes{1e-9, 1e6, true};
  // Nothing drawn: only messages cost. To a root the tree reduce needs log2(p) of them on the
  // root's path; into bands binary swap's log2(p) rounds are the fewest.
  CostEstimate e;
  const CompositingSchedule tree = cheapest_schedule(64, 1 << 20, 0, true, slow_messages, &e);
  EXPECT_EQ(tree.name(), "tree_reduce");
  EXPECT_NEAR(e.seconds, 6e-3, 1e-9);
  const CompositingSchedule a = cheapest_schedule(64, 1 << 20, 0, false, slow_messages, &e);
  EXPECT_EQ(a.name(), "binary_swap") << e.seconds;
  EXPECT_NEAR(e.seconds, 6e-3, 1e-9);
  const CompositingSchedule b = cheapest_schedule(64, 1 << 20, 0, false, slow_messages, nullptr);
  EXPECT_EQ(a.radices, b.radices);
  // Binary swap to a root: 6 rounds and the gather's 63 messages.
  EXPECT_NEAR(estimate_active_pixels(a, 1 << 20, 0, true, slow_messages).seconds, 69e-3, 1e-9);
  // Bytes: every radix-k moves the same (1 - 1/p) of a dense frame; active pixels move fewer.
  const CostEstimate dense = estimate_active_pixels(a, 1 << 20, 1 << 20, true, slow_bytes);
  const CostEstimate sparse = estimate_active_pixels(a, 1 << 20, (1 << 20) / 64, true, slow_bytes);
  EXPECT_LT(sparse.bytes_sent * 8, dense.bytes_sent);
  EXPECT_NEAR(dense.bytes_sent, 8.0 * (1 << 20) * (63.0 / 64 + 1.0 / 64), 1.0);
  // The tree on dense frames: the root takes 6 whole frames.
  EXPECT_NEAR(estimate_active_pixels(tree, 1 << 20, 1 << 20, true, slow_bytes).seconds,
              6 * (1e-9 + 8.0 * (1 << 20) / 1e6), 1e-6);
}

// ---- the scan ----------------------------------------------------------------------------------

TEST(ActivePixelScan, FindsTheEmptyKeyTheRectangleAndTheCount) {
  Frame f = blank_frame(100, 60);
  EXPECT_EQ(scan_active_pixels(f).active, 0u);
  EXPECT_TRUE(scan_active_pixels(f).rect.empty());
  EXPECT_EQ(scan_active_pixels(f).max_key, pack_pixel(kBackgroundDepth, kBackground));
  const uint8_t red[4] = {200, 0, 0, 255};
  for (const auto [x, y] : {std::pair{10, 5}, {37, 20}, {11, 40}}) {
    f.depth[f.index(x, y)] = 0.5f;
    std::memcpy(&f.rgba[4 * f.index(x, y)], red, 4);
  }
  const ActiveScan s = scan_active_pixels(f);
  EXPECT_EQ(s.active, 3u);
  EXPECT_EQ(s.rect.x0, 10);
  EXPECT_EQ(s.rect.x1, 38);
  EXPECT_EQ(s.rect.y0, 5);
  EXPECT_EQ(s.rect.y1, 41);
}

TEST(ActivePixelScan, ALargerKeyLateInTheFrameMakesEverythingBeforeItActive) {
  // The first pixels are drawn and the background only starts later; then one pixel beyond the
  // background (depth 2) becomes the maximum, and every other pixel is active.
  Frame f = blank_frame(40, 30);
  const uint8_t blue[4] = {0, 0, 200, 255};
  for (int x = 0; x < 40; ++x) f.depth[f.index(x, 0)] = 0.25f;
  f.depth[f.index(20, 17)] = 2.0f;
  std::memcpy(&f.rgba[4 * f.index(20, 17)], blue, 4);
  const ActiveScan s = scan_active_pixels(f);
  EXPECT_EQ(s.max_key, pack_pixel(2.0f, blue));
  EXPECT_EQ(s.active, f.pixel_count() - 1);
  EXPECT_EQ(s.rect.x0, 0);
  EXPECT_EQ(s.rect.x1, 40);
  EXPECT_EQ(s.rect.y0, 0);
  EXPECT_EQ(s.rect.y1, 30);
}

TEST(ActivePixelScan, WritesDepthsBackInCanonicalForm) {
  Frame f = blank_frame(20, 3);
  f.depth[3] = -0.0f;
  f.depth[4] = -2.0f;
  f.depth[5] = std::numeric_limits<float>::quiet_NaN();
  scan_active_pixels(f);
  uint32_t bits;
  std::memcpy(&bits, &f.depth[3], 4);
  EXPECT_EQ(bits, 0u);
  EXPECT_EQ(f.depth[4], 0.0f);
  EXPECT_EQ(f.depth[5], kBackgroundDepth);
}

// A frame the CPU raster says it drew within a rectangle (Frame::drawn_within): its scan reads only
// the rectangle and finds what the scan of the whole frame finds (the same key, count, rectangle
// and canonical depths), drops the statement, and scans the whole frame where a pixel inside lies
// above the background.
TEST(ActivePixelScan, AFrameDrawnWithinARectangleScansTheSameReadingOnlyThere) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float odd_depths[] = {0.5f, -0.0f, -2.0f, nan, kBackgroundDepth, 0.0f, 0.999f};
  int fell_back = 0;
  for (int it = 0; it < 300; ++it) {
    const uint32_t h = hash(uint32_t(it));
    const int width = 1 + int(h % 70), height = 1 + int((h >> 8) % 50);
    Frame honest = blank_frame(width, height);
    DrawnWithin w;
    w.x0 = int(hash(h + 1) % uint32_t(width + 1));
    w.x1 = w.x0 + int(hash(h + 2) % uint32_t(width + 1 - w.x0));
    w.y0 = int(hash(h + 3) % uint32_t(height + 1));
    w.y1 = w.y0 + int(hash(h + 4) % uint32_t(height + 1 - w.y0));
    std::memcpy(w.background, kBackground, 4);
    if (it % 17 == 0) {  // beyond the frame: clamped to all of it
      w.x0 = w.y0 = -5;
      w.x1 = width + 9, w.y1 = height + 9;
    }
    for (int y = std::max(w.y0, 0); y < std::min(w.y1, height); ++y)
      for (int x = std::max(w.x0, 0); x < std::min(w.x1, width); ++x) {
        const uint32_t k = hash(h + 100 + uint32_t(y * width + x));
        if (k % 3 == 0) continue;  // background
        const size_t i = honest.index(x, y);
        honest.depth[i] = k % 5 == 0 ? odd_depths[(k >> 4) % 7] : float(unit(hash(k)));
        honest.rgba[4 * i] = uint8_t(k >> 12);  // some above, some below the background's
      }
    if (it % 7 == 3 && w.x1 > w.x0 && w.y1 > w.y0) {  // a pixel inside beyond the background
      honest.depth[honest.index(std::max(w.x0, 0), std::max(w.y0, 0))] = 2.0f;
      ++fell_back;
    }
    Frame told = honest;
    told.drawn_within = w;
    const ActiveScan whole = scan_active_pixels(honest);
    const ActiveScan windowed = scan_active_pixels(told);
    EXPECT_FALSE(told.drawn_within.has_value()) << "the statement is used once";
    EXPECT_EQ(windowed.max_key, whole.max_key) << "case " << it;
    EXPECT_EQ(windowed.active, whole.active) << "case " << it;
    EXPECT_EQ(windowed.rect.empty(), whole.rect.empty()) << "case " << it;
    if (!whole.rect.empty()) {
      EXPECT_EQ(windowed.rect.x0, whole.rect.x0) << "case " << it;
      EXPECT_EQ(windowed.rect.x1, whole.rect.x1) << "case " << it;
      EXPECT_EQ(windowed.rect.y0, whole.rect.y0) << "case " << it;
      EXPECT_EQ(windowed.rect.y1, whole.rect.y1) << "case " << it;
    }
    EXPECT_EQ(std::memcmp(told.depth.data(), honest.depth.data(), 4 * honest.pixel_count()), 0)
        << "case " << it;
  }
  EXPECT_GT(fell_back, 10);
}

TEST(ActivePixelScan, AFrameDrawnWithinARectangleIsNotReadOutsideIt) {
  // Pixels outside the rectangle that are not the background (which a renderer's statement rules
  // out) are neither read nor canonicalised: the scan's result is that of the honest frame.
  Frame honest = blank_frame(30, 20);
  const uint8_t red[4] = {200, 0, 0, 255};
  for (int y = 5; y < 9; ++y)
    for (int x = 10; x < 14; ++x) {
      honest.depth[honest.index(x, y)] = 0.25f;
      std::memcpy(&honest.rgba[4 * honest.index(x, y)], red, 4);
    }
  Frame told = honest;
  told.depth[told.index(1, 1)] = -0.0f;
  told.depth[told.index(29, 19)] = 0.5f;
  told.drawn_within = DrawnWithin{10, 5, 14, 9, {}};
  std::memcpy(told.drawn_within->background, kBackground, 4);
  const ActiveScan s = scan_active_pixels(told);
  const ActiveScan expected = scan_active_pixels(honest);
  EXPECT_EQ(s.active, 16u);
  EXPECT_EQ(s.active, expected.active);
  EXPECT_EQ(s.max_key, expected.max_key);
  EXPECT_EQ(s.rect.x0, 10);
  EXPECT_EQ(s.rect.x1, 14);
  EXPECT_EQ(s.rect.y0, 5);
  EXPECT_EQ(s.rect.y1, 9);
  EXPECT_TRUE(std::signbit(told.depth[told.index(1, 1)]));  // not read, so not rewritten
}

// ---- run-length messages -----------------------------------------------------------------------

// A frame of spheres and scattered single pixels, plus its scan, as a rank holds it.
Frame drawn_frame(int width, int height, int seed) {
  Frame f = blank_frame(width, height);
  for (int k = 0; k < 3; ++k) draw_sphere(sphere_for_rank(seed, k, width, height, false), f);
  for (int k = 0; k < 40; ++k) {
    const uint32_t h = hash(uint32_t(seed * 1000 + k));
    const size_t i = h % f.pixel_count();
    f.depth[i] = float(unit(hash(h + 1)));
    f.rgba[4 * i] = uint8_t(h >> 8);
  }
  return f;
}

// Encodes `range` of `from` in messages of `capacity` words and merges them into `into`.
void stream(const ActiveFrame &from, PixelRange range, size_t capacity, ActiveFrame &into,
            size_t *total_words, size_t *messages) {
  RunLengthEncoder encoder(range);
  RunLengthDecoder decoder(range);
  std::vector<uint64_t> buffer(capacity);
  *total_words = 0;
  *messages = 0;
  while (!encoder.done()) {
    const size_t words = encoder.encode(from, buffer.data(), capacity);
    ASSERT_LE(words, capacity);
    *total_words += words;
    ++*messages;
    ASSERT_TRUE(decoder.decode(buffer.data(), words, into).ok());
    ASSERT_LT(*messages, 100000u);
  }
  EXPECT_TRUE(decoder.done());
}

// Merged into a frame of empty pixels, the messages rebuild the range exactly.
TEST(RunLengthPixels, RoundTripsEveryRangeAtEveryMessageSize) {
  Frame original = drawn_frame(97, 41, 3);
  const ActiveScan scan = scan_active_pixels(original);
  const ActiveFrame from{&original, empty_pixel(scan.max_key), scan.rect};
  const size_t n = original.pixel_count();
  for (const PixelRange range :
       {PixelRange{0, n}, PixelRange{5, 6}, PixelRange{100, 2000}, PixelRange{n - 333, n}}) {
    for (const size_t capacity : {size_t(3), size_t(4), size_t(17), size_t(1000), n + 2}) {
      Frame copy = blank_frame(97, 41);
      ActiveFrame into{&copy, from.empty, {}};
      size_t words = 0, messages = 0;
      stream(from, range, capacity, into, &words, &messages);
      for (size_t i = range.lo; i < range.hi; ++i) {
        ASSERT_EQ(copy.depth[i], original.depth[i]) << i << " capacity " << capacity;
        ASSERT_EQ(std::memcmp(&copy.rgba[4 * i], &original.rgba[4 * i], 4), 0) << i;
      }
      // Pixels outside the range are left alone.
      for (size_t i = 0; i < n; ++i)
        if (i < range.lo || i >= range.hi) ASSERT_EQ(copy.depth[i], kBackgroundDepth) << i;
      if (capacity >= range.size() + 2) {
        // One message, at most 8 bytes per pixel plus a header and one pair.
        EXPECT_EQ(messages, 1u);
        EXPECT_LE(words, range.size() + 2);
      }
    }
  }
}

TEST(RunLengthPixels, AFrameWithNothingDrawnTakesOneWordPerRangeAndChangesNothing) {
  Frame empty = blank_frame(300, 200);
  const ActiveScan scan = scan_active_pixels(empty);
  const ActiveFrame from{&empty, empty_pixel(scan.max_key), scan.rect};
  Frame copy = drawn_frame(300, 200, 1);
  const Frame before = copy;
  ActiveFrame into{&copy, from.empty, {}};
  size_t words = 0, messages = 0;
  stream(from, {0, empty.pixel_count()}, 1000, into, &words, &messages);
  EXPECT_EQ(words, 1u);
  EXPECT_EQ(messages, 1u);
  EXPECT_EQ(describe_difference(copy, before), "");
}

TEST(RunLengthPixels, MergeKeepsTheNearerPixelAndGrowsTheRectangle) {
  Frame a = drawn_frame(64, 48, 7), b = drawn_frame(64, 48, 8);
  const Frame expected = serial_merge({a, b});
  const ActiveScan sa = scan_active_pixels(a), sb = scan_active_pixels(b);
  ASSERT_EQ(sa.max_key, sb.max_key);  // the same background
  ActiveFrame from{&b, empty_pixel(sb.max_key), sb.rect};
  ActiveFrame into{&a, empty_pixel(sa.max_key), sa.rect};
  size_t words = 0, messages = 0;
  stream(from, {0, a.pixel_count()}, 50, into, &words, &messages);
  EXPECT_EQ(describe_difference(a, expected), "");
  ActiveRect both = sa.rect;
  both.add(sb.rect);
  EXPECT_LE(into.rect.x0, both.x0);
  EXPECT_GE(into.rect.x1, both.x1);
  EXPECT_LE(into.rect.y0, both.y0);
  EXPECT_GE(into.rect.y1, both.y1);
}

TEST(RunLengthPixels, AMessageThatDoesNotFitTheRangeIsRefused) {
  Frame f = blank_frame(10, 10);
  ActiveFrame into{&f, empty_pixel(pack_pixel(kBackgroundDepth, kBackground)), {}};
  RunLengthDecoder decoder({0, 10});
  const uint64_t too_long[] = {uint64_t(11) | (uint64_t(1) << 63)};
  EXPECT_EQ(decoder.decode(too_long, 1, into).code, StatusCode::kInternal);
  RunLengthDecoder other({0, 10});
  const uint64_t run_past_end[] = {
      uint64_t(10) | (uint64_t(1) << 63), uint64_t(8) << 32 | 5, 0, 0, 0, 0, 0};
  EXPECT_EQ(other.decode(run_past_end, 7, into).code, StatusCode::kInternal);
}

}  // namespace
}  // namespace lantern::testing
