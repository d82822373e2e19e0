// PageAllocator: a large block freed leaves the resident size in use at once, whatever glibc's
// heap holds (its pages are unmapped or lazily freed, never handed to malloc), a freed block of up
// to kReusedBlockBytes serves the next request of its size class, and small blocks still work as
// usual; so do the frames and the bricks' permutation and runs, which live from step to step.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/bricks/index_runs.h"
#include "core/common/page_allocator.h"
#include "core/common/uninitialized_buffer.h"
#include "core/view/frame.h"
#include "core/view/max_depth_pyramid.h"

namespace lantern {
namespace {

// Resident bytes of this process (/proc/self/statm), lazily freed pages included; -1 where
// unknown.
int64_t resident_bytes_with_lazy() {
  std::unique_ptr<FILE, int (*)(FILE *)> f(std::fopen("/proc/self/statm", "r"), &std::fclose);
  long long size = 0, resident = 0;
  if (!f || std::fscanf(f.get(), "%lld %lld", &size, &resident) != 2) return -1;
  return int64_t(resident) * int64_t(sysconf(_SC_PAGESIZE));
}

// Resident bytes less the lazily freed ones, which the kernel takes back whenever it needs them.
int64_t resident_bytes() {
  return resident_bytes_in_use();
}

constexpr int64_t kMiB = int64_t(1) << 20;

#if defined(__SANITIZE_THREAD__)
#define LANTERN_UNDER_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define LANTERN_UNDER_TSAN 1
#endif
#endif

// Why this process's resident size cannot show a freed block's pages going back, or null where
// it can. Under ThreadSanitizer the shadow of the pages (several bytes per byte touched) stays
// resident after they are unmapped: a 16 MiB block freed left 64 MiB more resident.
const char *resident_size_unmeasurable() {
#ifdef LANTERN_UNDER_TSAN
  return "ThreadSanitizer keeps the shadow of freed pages resident";
#else
  if (resident_bytes_with_lazy() < 0 || resident_bytes() < 0)
    return "no /proc/self/statm or smaps_rollup";
  return nullptr;
#endif
}

// Raises glibc's dynamic mmap threshold to 24 MiB (and its trim threshold to 48 MiB), as a host
// that freed a large array does: blocks below that from malloc then come from the heap and stay
// resident when freed.
void raise_malloc_threshold() {
  std::vector<uint8_t> warm(size_t(24 * kMiB), 1);
  volatile uint8_t sink = warm[warm.size() / 2];
  (void)sink;
}

TEST(PageAllocator, FreedLargeVectorLeavesTheResidentSize) {
  if (const char *why = resident_size_unmeasurable()) GTEST_SKIP() << why;
  // First grow and free a heap block of the same size through malloc, so that glibc's dynamic
  // mmap threshold is raised (to 24 MiB) as after a rendered step: a 16 MiB block from malloc
  // would now come from the heap and stay resident when freed.
  raise_malloc_threshold();
  const int64_t before = resident_bytes();
  {
    PageVector<uint64_t> v(size_t(16 * kMiB) / sizeof(uint64_t), 7);  // every page touched
    ASSERT_GE(resident_bytes() - before, 15 * kMiB);
    EXPECT_EQ(v[v.size() - 1], 7u);
  }
  EXPECT_LT(resident_bytes() - before, 2 * kMiB) << "the freed block's pages are still resident";
}

TEST(PageAllocator, UninitializedBufferReleasesToo) {
  if (const char *why = resident_size_unmeasurable()) GTEST_SKIP() << why;
  const int64_t before = resident_bytes();
  {
    UninitializedBuffer<uint32_t> keys(size_t(12 * kMiB) / sizeof(uint32_t));
    for (size_t i = 0; i < keys.size(); i += 1024) keys[i] = uint32_t(i);
    ASSERT_GE(resident_bytes() - before, 11 * kMiB);
  }
  EXPECT_LT(resident_bytes() - before, 2 * kMiB);
}

TEST(PageAllocator, FramesAndBrickSetsReleaseTheirPages) {
  if (const char *why = resident_size_unmeasurable()) GTEST_SKIP() << why;
  raise_malloc_threshold();
  const int64_t before = resident_bytes();
  {
    Frame frame(2048, 1024);  // 8 MiB of colour and 8 MiB of depth
    const uint8_t grey[4] = {9, 9, 9, 255};
    frame.clear(grey);
    ASSERT_GE(resident_bytes() - before, 15 * kMiB);
  }
  EXPECT_LT(resident_bytes() - before, 2 * kMiB) << "a freed frame's pages are still resident";
  {
    BrickSet set;
    set.order.assign(size_t(12 * kMiB) / sizeof(uint32_t), 5);
    for (uint32_t k = 0; k < uint32_t(3 * kMiB / 8); ++k)  // 8 bytes a run, 8 indices long
      set.runs.push_back({k * 8, k % 7, kNoBrick});
    set.in_other.assign(size_t(2 * kMiB) / sizeof(uint64_t), 1);
    ASSERT_GE(resident_bytes() - before, 16 * kMiB);
  }
  EXPECT_LT(resident_bytes() - before, 2 * kMiB) << "a freed brick set's pages are still resident";
}

// A depth pyramid's kept levels (3 and up: a 63rd of its image's depth) leave the resident size
// when it is released between frames, and a pyramid reset after release() answers as a fresh
// one.
TEST(PageAllocator, ReleasedDepthPyramidLeavesTheResidentSize) {
  if (const char *why = resident_size_unmeasurable()) GTEST_SKIP() << why;
  raise_malloc_threshold();
  std::vector<float> depth(size_t(4096) * 4096, 1.0f);  // 64 MiB: levels 3.. about 1.33 MiB
  MaxDepthPyramid pyramid;
  const int64_t before = resident_bytes();
  pyramid.reset(depth.data(), 4096, 4096, 1.0f);
  ASSERT_GE(resident_bytes() - before, kMiB);
  pyramid.release();
  EXPECT_LT(resident_bytes() - before, kMiB / 4)
      << "a released pyramid's levels are still resident";
  pyramid.reset(depth.data(), 4096, 4096, 1.0f);
  const PixelRect all{0, 0, 4095, 4095}, corner{0, 0, 600, 700};
  EXPECT_FALSE(pyramid.covered(all, 1.0f));
  for (int y = 0; y <= 700; ++y) std::fill_n(&depth[size_t(y) * 4096], 601, 0.25f);
  pyramid.propagate(corner);
  EXPECT_TRUE(pyramid.covered(corner, 0.5f));
  EXPECT_FALSE(pyramid.covered(PixelRect{0, 0, 601, 700}, 0.5f));
  EXPECT_FALSE(pyramid.covered(corner, 0.25f));
}

// Frame::reset gives what Frame(w, h) gives, in the same buffers when the size is unchanged (a
// density or OpenGL frame made every step then maps and faults in no new pages).
TEST(PageAllocator, FrameResetReusesItsBuffers) {
  Frame f(512, 512);  // 1 MiB of colour, 1 MiB of depth: mapped pages
  f.rgba[7] = 9, f.depth[3] = 0.5f;
  const uint8_t *rgba = f.rgba.data();
  const float *depth = f.depth.data();
  f.reset(512, 512);
  EXPECT_EQ(f.rgba.data(), rgba);
  EXPECT_EQ(f.depth.data(), depth);
  const Frame fresh(512, 512);
  EXPECT_TRUE(f.rgba == fresh.rgba);
  EXPECT_TRUE(f.depth == fresh.depth);
  f.reset(256, 1024);  // the same pixel count in another shape
  EXPECT_EQ(f.width, 256);
  EXPECT_EQ(f.height, 1024);
  EXPECT_EQ(f.rgba.data(), rgba);
  f.reset(100, 30);
  EXPECT_EQ(f.width, 100);
  EXPECT_EQ(f.height, 30);
  EXPECT_EQ(f.rgba.size(), 4u * 100 * 30);
  EXPECT_EQ(f.depth.size(), 100u * 30);
}

// A freed block of up to kReusedBlockBytes is kept, lazily freed, and handed to the next request
// of its size class (its pages then need no fault); larger ones are unmapped at once; what is
// kept never exceeds kReusedBytes; drop_reused_pages() unmaps it all.
TEST(PageAllocator, FreedBlocksServeTheNextRequestOfTheirClass) {
  drop_reused_pages();
  ASSERT_EQ(reused_pages().blocks, 0);
  const uint8_t *first = nullptr;
  {
    PageVector<uint8_t> block(size_t(700) << 10, 1);  // class 1 MiB
    first = block.data();
  }
  EXPECT_EQ(reused_pages().blocks, 1);
  EXPECT_EQ(reused_pages().bytes, int64_t(1) << 20);
  {
    PageVector<uint8_t> again(size_t(900) << 10, 2);  // the same class: the same pages
    EXPECT_EQ(again.data(), first);
    EXPECT_EQ(reused_pages().blocks, 0);
    for (size_t i = 0; i < again.size(); i += 4096) ASSERT_EQ(again[i], 2);
  }
  {
    PageVector<uint8_t> other(size_t(300) << 10, 3);  // another class: fresh pages
    EXPECT_NE(other.data(), first);
    EXPECT_EQ(reused_pages().blocks, 1);
  }
  EXPECT_EQ(reused_pages().blocks, 2);
  // Many blocks freed at once: no more than kReusedBytes kept.
  {
    std::vector<PageVector<uint8_t>> many;
    for (int i = 0; i < 12; ++i) many.emplace_back(kReusedBlockBytes, uint8_t(i));
  }
  EXPECT_LE(reused_pages().bytes, int64_t(kReusedBytes));
  EXPECT_GT(reused_pages().bytes, int64_t(kReusedBytes) - int64_t(kReusedBlockBytes));
  drop_reused_pages();
  EXPECT_EQ(reused_pages().blocks, 0);
  EXPECT_EQ(reused_pages().bytes, 0);
}

// Lazily freed pages leave the resident size in use at once, and the whole resident size when
// unmapped; blocks above kReusedBlockBytes leave it at once.
TEST(PageAllocator, KeptBlocksLeaveTheResidentSizeInUse) {
  if (const char *why = resident_size_unmeasurable()) GTEST_SKIP() << why;
  drop_reused_pages();
  const int64_t before = resident_bytes_with_lazy();
  { PageVector<uint64_t> large(size_t(24 * kMiB) / sizeof(uint64_t), 5); }
  EXPECT_LT(resident_bytes_with_lazy() - before, 2 * kMiB) << "a block above the kept size stayed";
  const int64_t in_use = resident_bytes();
  { PageVector<uint64_t> kept(size_t(12 * kMiB) / sizeof(uint64_t), 5); }
  EXPECT_EQ(reused_pages().blocks, 1);
  EXPECT_LT(resident_bytes() - in_use, 2 * kMiB) << "a kept block's pages still count as in use";
  drop_reused_pages();
  EXPECT_LT(resident_bytes_with_lazy() - before, 2 * kMiB) << "dropped pages are still resident";
}

TEST(PageAllocator, SmallAndGrowingVectorsKeepTheirContents) {
  PageVector<int> v;
  for (int i = 0; i < 1 << 20; ++i) v.push_back(i);  // crosses kPageBlockBytes while growing
  PageVector<int> w = v;
  v.clear();
  v.shrink_to_fit();
  ASSERT_EQ(w.size(), size_t(1) << 20);
  for (int i = 0; i < 1 << 20; i += 4099) EXPECT_EQ(w[size_t(i)], i);
  PageVector<int> small(16, 3);
  EXPECT_EQ(small[15], 3);
}

}  // namespace
}  // namespace lantern
