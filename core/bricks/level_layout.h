// The z-order multi-level layout inside a brick (Rizzi et al. 2015, §3.5, Fig. 3): the brick's
// particles, already in z-order, are re-laid so that level 0 (the first particle) comes first and
// each next level refines the previous one. We visit z-order positions in bit-reversed order (0,
// n/2, n/4, 3n/4, n/8, ...): at a level boundary this is exactly Fig. 3's layout, and inside a
// level the bit reversal spreads the partial level over the whole brick, so ANY prefix - not only
// whole levels - is a spatially uniform sample of the brick.
#pragma once

#include <cstdint>
#include <vector>

namespace lantern {

namespace level_layout_detail {

inline int bits_for(uint32_t n) {
  int b = 0;
  while ((uint64_t(1) << b) < n) ++b;
  return b;
}

inline uint32_t reverse_bits(uint32_t v, int bits) {
  v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
  v = ((v >> 8) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8);
  v = (v >> 16) | (v << 16);
  return bits == 0 ? 0u : v >> (32 - bits);
}

}  // namespace level_layout_detail

// Calls emit(j) with the z-order positions j of n items in level-layout order: emit(j) for the
// k-th call is the z-order position of the layout's k-th item.
template <typename Emit>
void for_each_in_level_layout(uint32_t n, Emit &&emit) {
  if (n < 3) {  // 0, 1 or 2 items are already in level order
    for (uint32_t j = 0; j < n; ++j) emit(j);
    return;
  }
  const int bits = level_layout_detail::bits_for(n);
  uint32_t out = 0;
  for (uint32_t k = 0; out < n; ++k) {
    const uint32_t j = level_layout_detail::reverse_bits(k, bits);
    if (j < n) emit(j), ++out;
  }
}

// out[k] = get(j) for the z-order position j of the layout's k-th item, k < n: what
// for_each_in_level_layout emits, without its branch on whether a bit-reversed counter falls
// below n (taken about half the time in no pattern: a mispredict every other step). Every step
// writes out[done] - a value got for a position inside, overwritten by the next step when the
// counter was outside - and counts it only when inside; nothing past out[n - 1] is written. The
// counter goes 8 at a time while 8 more items fit: reversing k = 8a + b in `bits` bits gives
// reverse(b) in the top 3 bits above reverse(a), so a block of 8 is one reversal and 8 additions.
template <typename Get>
void gather_in_level_layout(uint32_t n, Get &&get, uint32_t *out) {
  using level_layout_detail::reverse_bits;
  if (n < 3) {  // 0, 1 or 2 items are already in level order
    for (uint32_t j = 0; j < n; ++j) out[j] = get(j);
    return;
  }
  const int bits = level_layout_detail::bits_for(n);
  uint32_t done = 0, k = 0;
  if (bits >= 3) {
    const int high = bits - 3;
    uint32_t low[8];
    for (uint32_t b = 0; b < 8; ++b) low[b] = reverse_bits(b, 3) << high;
    for (uint32_t a = 0; done + 8 <= n; ++a, k += 8) {
      const uint32_t base = reverse_bits(a, high);
      for (uint32_t b = 0; b < 8; ++b) {
        const uint32_t j = base + low[b];
        const uint32_t inside = j < n ? 1u : 0u;
        out[done] = get(inside ? j : 0u);
        done += inside;
      }
    }
  }
  for (; done < n; ++k) {
    const uint32_t j = level_layout_detail::reverse_bits(k, bits);
    const uint32_t inside = j < n ? 1u : 0u;
    out[done] = get(inside ? j : 0u);
    done += inside;
  }
}

// Reorders `items[0, n)` (in z-order) into the level layout. `scratch` is reused between calls.
void apply_level_layout(uint32_t *items, uint32_t n, std::vector<uint32_t> *scratch);

// The z-order position (0-based) of the k-th item of the level layout of n items; exposed for
// tests. k < n.
uint32_t level_layout_source(uint32_t k, uint32_t n);

}  // namespace lantern
