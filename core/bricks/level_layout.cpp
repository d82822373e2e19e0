#include "core/bricks/level_layout.h"

namespace lantern {

void apply_level_layout(uint32_t *items, uint32_t n, std::vector<uint32_t> *scratch) {
  if (n < 3) return;  // 0, 1 or 2 items are already in level order
  scratch->assign(items, items + n);
  uint32_t out = 0;
  for_each_in_level_layout(n, [&](uint32_t j) { items[out++] = (*scratch)[j]; });
}

uint32_t level_layout_source(uint32_t k, uint32_t n) {
  uint32_t seen = 0, found = 0;
  for_each_in_level_layout(n, [&](uint32_t j) {
    if (seen++ == k) found = j;
  });
  return found;
}

}  // namespace lantern
