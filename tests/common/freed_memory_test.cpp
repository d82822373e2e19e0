// release_freed_memory: heap memory freed below a block still held stays resident until it is
// handed back; afterwards the resident size is lower by about what was freed.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/common/freed_memory.h"

namespace lantern {
namespace {

// The resident size in KiB (Linux), or -1.
double resident_kib() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6));
  return -1.0;
}

TEST(FreedMemory, FreedHeapBlocksLeaveTheResidentSize) {
  if (resident_kib() < 0) GTEST_SKIP() << "no /proc/self/status";
  // What a step does: a large block freed (glibc then serves blocks up to its size from the
  // heap), 64 MiB of temporaries from the heap, touched, and a block allocated after them, so
  // that freeing them leaves a hole the heap's top cannot give back.
  void *volatile large = std::malloc(24 << 20);  // volatile: the pair is not optimised away
  ASSERT_NE(large, nullptr);
  std::free(large);
  constexpr size_t kBlock = 8 << 20, kBlocks = 8;
  std::vector<void *> blocks(kBlocks);
  for (void *&b : blocks) {
    b = std::malloc(kBlock);
    ASSERT_NE(b, nullptr);
    std::memset(b, 1, kBlock);
  }
  void *above = std::malloc(1 << 20);
  std::memset(above, 1, 1 << 20);
  for (void *b : blocks) std::free(b);
  const double held = resident_kib();
  const bool released = release_freed_memory();
  const double after = resident_kib();
  std::free(above);
#if defined(__GLIBC__)
  ASSERT_TRUE(released);
  EXPECT_LT(after, held - 32 * 1024) << "held " << held << " KiB, after " << after << " KiB";
#else
  EXPECT_FALSE(released);
  (void)after;
#endif
}

}  // namespace
}  // namespace lantern
