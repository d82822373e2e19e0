#include "core/common/page_allocator.h"

#include <cstdio>
#include <memory>
#include <mutex>
#include <type_traits>

namespace lantern {
namespace {

// Size classes: a block of class k is mapped at 2^k bytes, from kPageBlockBytes to
// kReusedBlockBytes.
constexpr int kFirstClass = 16, kLastClass = 24;
static_assert(size_t(1) << kFirstClass == kPageBlockBytes, "the first class is the first block");
static_assert(size_t(1) << kLastClass == kReusedBlockBytes, "the last class is the largest kept");
// Kept blocks per class: a frame's scratch of one size class (its draw lists, its PNG bands) is
// a handful of blocks.
constexpr int kSlots = 16;

int size_class(size_t bytes) {
  int k = kFirstClass;
  while ((size_t(1) << k) < bytes) ++k;
  return k;
}

// The kept blocks. Trivially destructible, so that blocks freed by other static objects'
// destructors at exit still find it (it is never destroyed).
struct KeptBlocks {
  std::mutex mutex;
  void *slots[kLastClass - kFirstClass + 1][kSlots];
  int count[kLastClass - kFirstClass + 1];
  size_t bytes;
};
static_assert(std::is_trivially_destructible_v<KeptBlocks>, "must outlive every static object");

KeptBlocks &kept() {
  static KeptBlocks blocks{};
  return blocks;
}

#if defined(LANTERN_PAGE_ALLOCATOR_MMAP)
void *map_fresh(size_t bytes) {
  void *p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  return p == MAP_FAILED ? nullptr : p;
}

// map_fresh, or once more after handing back every kept block; std::bad_alloc if still refused.
void *map_or_throw(size_t bytes) {
  void *p = map_fresh(bytes);
  if (!p) {
    drop_reused_pages();
    p = map_fresh(bytes);
  }
  if (!p) throw std::bad_alloc();
  return p;
}
#endif

}  // namespace

void *map_pages(size_t bytes) {
#if defined(LANTERN_PAGE_ALLOCATOR_MMAP)
  if (bytes > kReusedBlockBytes) return map_or_throw(bytes);
  const int k = size_class(bytes);
  {
    KeptBlocks &b = kept();
    const std::lock_guard<std::mutex> lock(b.mutex);
    int &count = b.count[k - kFirstClass];
    if (count > 0) {
      b.bytes -= size_t(1) << k;
      return b.slots[k - kFirstClass][--count];
    }
  }
  return map_or_throw(size_t(1) << k);
#else
  return ::operator new(bytes);
#endif
}

void unmap_pages(void *p, size_t bytes) noexcept {
#if defined(LANTERN_PAGE_ALLOCATOR_MMAP)
  if (bytes > kReusedBlockBytes) {
    munmap(p, bytes);
    return;
  }
  const int k = size_class(bytes);
  const size_t mapped = size_t(1) << k;
#if defined(MADV_FREE)
  // Lazily: the pages stay mapped until the kernel needs them (then they read as zeros).
  if (madvise(p, mapped, MADV_FREE) == 0) {
    KeptBlocks &b = kept();
    const std::lock_guard<std::mutex> lock(b.mutex);
    int &count = b.count[k - kFirstClass];
    if (count < kSlots && b.bytes + mapped <= kReusedBytes) {
      b.slots[k - kFirstClass][count++] = p;
      b.bytes += mapped;
      return;
    }
  }
#endif
  munmap(p, mapped);
#else
  (void)bytes;
  ::operator delete(p);
#endif
}

void drop_reused_pages() noexcept {
#if defined(LANTERN_PAGE_ALLOCATOR_MMAP)
  KeptBlocks &b = kept();
  const std::lock_guard<std::mutex> lock(b.mutex);
  for (int k = kFirstClass; k <= kLastClass; ++k) {
    int &count = b.count[k - kFirstClass];
    for (; count > 0; --count) munmap(b.slots[k - kFirstClass][count - 1], size_t(1) << k);
  }
  b.bytes = 0;
#endif
}

ReusedPages reused_pages() {
  KeptBlocks &b = kept();
  const std::lock_guard<std::mutex> lock(b.mutex);
  ReusedPages r;
  for (int k = kFirstClass; k <= kLastClass; ++k) r.blocks += b.count[k - kFirstClass];
  r.bytes = int64_t(b.bytes);
  return r;
}

int64_t resident_bytes_in_use() {
  std::unique_ptr<FILE, int (*)(FILE *)> f(std::fopen("/proc/self/smaps_rollup", "r"),
                                           &std::fclose);
  if (!f) return -1;
  int64_t rss_kib = -1, lazy_kib = 0;
  char line[256];
  while (std::fgets(line, sizeof line, f.get())) {
    long long kib = 0;
    if (std::sscanf(line, "Rss: %lld kB", &kib) == 1) rss_kib = kib;
    if (std::sscanf(line, "LazyFree: %lld kB", &kib) == 1) lazy_kib = kib;
  }
  return rss_kib < 0 ? -1 : (rss_kib - lazy_kib) * 1024;
}

}  // namespace lantern
