// An allocator whose large blocks are whole pages from the operating system, returned to it when
// freed.
//
// Why: glibc's malloc raises its mmap threshold to the size of the largest mmapped block freed
// (up to 32 MiB), so after Lantern's first step its per-particle temporaries (the brick build's
// keys, culling's lists and scratch) would come from the heap, and freed heap memory stays
// resident between frames: bytes per particle the host simulation cannot use. Blocks of at least
// kPageBlockBytes here are mapped and unmapped directly: freeing one drops the resident size at
// once, glibc's threshold never sees them, and the host's own heap is left as it is (no
// process-wide trim). Smaller blocks come from operator new as usual. The cost: each page of a
// fresh block is faulted in on first touch, so buffers that every frame needs again are kept by
// their owners (counted as retained) rather than freed and mapped anew.
//
// Thread-safety: stateless; as operator new and mmap.
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

// Returns `bytes` bytes aligned to `align`: mapped pages from kPageBlockBytes on, else from
// operator new.
inline void *allocate_pages_or_heap(size_t bytes, size_t align = __STDCPP_DEFAULT_NEW_ALIGNMENT__) {
#if defined(LANTERN_PAGE_ALLOCATOR_MMAP)
  if (bytes >= kPageBlockBytes) {
    void *p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    return p;
  }
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
    munmap(p, bytes);
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
