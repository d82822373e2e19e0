// An allocator whose large blocks are whole pages from the operating system, handed back to it
// when freed.
//
// Why: glibc's malloc raises its mmap threshold to the size of the largest mmapped block freed
// (up to 32 MiB), so after Lantern's first step its per-particle temporaries (the brick build's
// keys, culling's lists and scratch) would come from the heap, and freed heap memory stays
// resident between frames: bytes per particle the host simulation cannot use. Blocks of at least
// kPageBlockBytes here are mapped directly, glibc's threshold never sees them, and the host's own
// heap is left as it is (no process-wide trim). Smaller blocks come from operator new as usual.
//
// Freed blocks of up to kReusedBlockBytes are handed back lazily (MADV_FREE) and kept, up to
// kReusedBytes in all, for the next allocation of their size class: the kernel takes their pages
// whenever it needs memory (they are clean: nothing is written out), and until it does, a frame
// that asks for the same scratch again gets it without a page fault. A fault costs about 2 us on
// the 2-core VM of the benchmarks (mmap, zero fill, fault; 93 ns a page to rewrite a lazily freed
// one), and a 1 M-atom frame's per-frame buffers (depth pyramid, deflate output, draw lists,
// refit scratch) took about 860 of them a rank. Larger blocks are unmapped when freed. Lazily
// freed pages still count in the resident size (VmRSS) until the kernel takes them; they are
// listed as LazyFree in /proc/self/smaps_rollup (resident_bytes_in_use below leaves them out).
//
// Thread-safety: the kept blocks are shared by the process under a mutex; otherwise as operator
// new and mmap.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#include <sys/mman.h>
#define LANTERN_PAGE_ALLOCATOR_MMAP 1
#endif

namespace lantern {

// Blocks from this size on are mapped directly. A mapping costs a system call and its page
// faults; below 64 KiB the heap is cheaper and what it keeps is small. Per-frame buffers of a
// few hundred KiB (a frame's merged draw list and its sort scratch, compressed PNG bands, depth
// pyramids) are above it: freed between frames, they would otherwise leave their pages in the
// heap (about 2 MiB per rank at 1024^2).
inline constexpr size_t kPageBlockBytes = size_t(64) << 10;

// Freed mapped blocks up to this size are kept for reuse (lazily freed), at most kReusedBytes of
// them. Blocks up to kReusedBlockBytes are mapped at the next power of two (their size class), so
// that a block freed by one frame fits the same request of the next; only the pages written
// become resident.
inline constexpr size_t kReusedBlockBytes = size_t(16) << 20;
inline constexpr size_t kReusedBytes = size_t(64) << 20;

// Maps `bytes` (>= kPageBlockBytes) of pages, a kept block of its size class where there is
// one; throws std::bad_alloc when the system refuses (after handing back every kept block).
void *map_pages(size_t bytes);
// Frees a block from map_pages(bytes): kept for reuse, or unmapped.
void unmap_pages(void *p, size_t bytes) noexcept;
// Unmaps every kept block (for tests, and before giving up on an allocation).
void drop_reused_pages() noexcept;
// How many blocks are kept for reuse, and their mapped bytes.
struct ReusedPages {
  int64_t blocks = 0;
  int64_t bytes = 0;
};
ReusedPages reused_pages();
// This process's resident bytes less the lazily freed ones (VmRSS - LazyFree, from
// /proc/self/smaps_rollup): what it holds that the kernel cannot take back without asking.
// -1 where the system does not say.
int64_t resident_bytes_in_use();

// Returns `bytes` bytes aligned to `align`: mapped pages from kPageBlockBytes on, else from
// operator new.
inline void *allocate_pages_or_heap(size_t bytes, size_t align = __STDCPP_DEFAULT_NEW_ALIGNMENT__) {
#if defined(LANTERN_PAGE_ALLOCATOR_MMAP)
  if (bytes >= kPageBlockBytes) return map_pages(bytes);
#endif
  if (align > __STDCPP_DEFAULT_NEW_ALIGNMENT__)
    return ::operator new(bytes, std::align_val_t(align));
  return ::operator new(bytes);
}

// Frees a block from allocate_pages_or_heap(bytes, align) (the same `bytes` and `align`).
inline void free_pages_or_heap(void *p, size_t bytes,
                               size_t align = __STDCPP_DEFAULT_NEW_ALIGNMENT__) noexcept {
#if defined(LANTERN_PAGE_ALLOCATOR_MMAP)
  if (bytes >= kPageBlockBytes) {
    unmap_pages(p, bytes);
    return;
  }
#endif
  if (align > __STDCPP_DEFAULT_NEW_ALIGNMENT__)
    return ::operator delete(p, std::align_val_t(align));
  ::operator delete(p);
}

// Asks for transparent huge pages for a fresh mapped block of `bytes` at `p` (from
// allocate_pages_or_heap), before its first write: one fault and one clear per 2 MiB instead of
// per 4 KiB page. For blocks written whole at once (the brick build's per-particle arrays, a
// refit's scans); a block touched only in part would become resident in 2 MiB steps. A no-op on
// blocks from the heap and where the system has no transparent huge pages.
inline void ask_huge_pages(void *p, size_t bytes) {
#if defined(LANTERN_PAGE_ALLOCATOR_MMAP) && defined(MADV_HUGEPAGE)
  if (bytes < kPageBlockBytes) return;  // from the heap, not mapped for it
  const auto page = uintptr_t(4096);
  const uintptr_t a = (reinterpret_cast<uintptr_t>(p) + page - 1) & ~(page - 1);
  const uintptr_t b = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(page - 1);
  if (b > a) (void)madvise(reinterpret_cast<void *>(a), b - a, MADV_HUGEPAGE);
#else
  (void)p, (void)bytes;
#endif
}

template <typename T>
struct PageAllocator {
  using value_type = T;
  PageAllocator() = default;
  template <typename U>
  PageAllocator(const PageAllocator<U> &) noexcept {}

  T *allocate(size_t n) {
    if (n > size_t(-1) / sizeof(T)) throw std::bad_alloc();
    return static_cast<T *>(allocate_pages_or_heap(n * sizeof(T), alignof(T)));
  }
  void deallocate(T *p, size_t n) noexcept { free_pages_or_heap(p, n * sizeof(T), alignof(T)); }
};

template <typename T, typename U>
bool operator==(const PageAllocator<T> &, const PageAllocator<U> &) noexcept {
  return true;
}
template <typename T, typename U>
bool operator!=(const PageAllocator<T> &, const PageAllocator<U> &) noexcept {
  return false;
}

// A vector of per-particle (large) contents whose memory goes back to the system when freed.
template <typename T>
using PageVector = std::vector<T, PageAllocator<T>>;

}  // namespace lantern
