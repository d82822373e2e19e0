// Scratch storage that is not zero-filled on allocation or growth.
//
// Why: every element is written (packed or received) before it is read, and zero-filling would
// cost a pass over memory as long as the packing itself. Large buffers are mapped pages, returned
// to the system when freed (page_allocator.h).
#pragma once

#include <cstdint>
#include <new>
#include <utility>
#include <vector>

#include "core/common/page_allocator.h"

namespace lantern {

template <typename T>
struct DefaultInitAllocator : PageAllocator<T> {
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U> &) noexcept {}

  // Value-initialisation without arguments becomes default-initialisation (no write for PODs).
  template <typename U>
  void construct(U *p) noexcept {
    ::new (static_cast<void *>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U *p, Args &&...args) {
    ::new (static_cast<void *>(p)) U(std::forward<Args>(args)...);
  }
};

template <typename T>
using UninitializedBuffer = std::vector<T, DefaultInitAllocator<T>>;
using PackedBuffer = UninitializedBuffer<uint64_t>;

}  // namespace lantern
