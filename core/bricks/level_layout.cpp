#include "core/bricks/level_layout.h"

namespace lantern {
namespace {

int bits_for(uint32_t n) {
  int b = 0;
  while ((uint64_t(1) << b) < n) ++b;
  return b;
}

uint32_t reverse_bits(uint32_t v, int bits) {
  v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
  v = ((v >> 8) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8);
  v = (v >> 16) | (v << 16);
  return bits == 0 ? 0u : v >> (32 - bits);
}

}  // namespace

void apply_level_layout(uint32_t *items, uint32_t n, std::vector<uint32_t> *scratch) {
  if (n < 3) return;  // 0, 1 or 2 items are already in level order
  scratch->assign(items, items + n);
  const int bits = bits_for(n);
  uint32_t out = 0;
  for (uint32_t k = 0; out < n; ++k) {
    const uint32_t j = reverse_bits(k, bits);
    if (j < n) items[out++] = (*scratch)[j];
  }
}

uint32_t level_layout_source(uint32_t k, uint32_t n) {
  const int bits = bits_for(n);
  uint32_t seen = 0;
  for (uint32_t v = 0;; ++v) {
    const uint32_t j = reverse_bits(v, bits);
    if (j < n && seen++ == k) return j;
  }
}

}  // namespace lantern
