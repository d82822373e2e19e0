#include "core/bricks/radix_sort.h"

#include <algorithm>
#include <array>
#include <cstddef>

namespace lantern {
namespace {

constexpr int kDigitBits = 11;
constexpr size_t kBuckets = size_t(1) << kDigitBits;

}  // namespace

void radix_sort_words(std::vector<uint64_t> *words, std::vector<uint64_t> *scratch, int lo_bit,
                      int hi_bit) {
  const size_t n = words->size();
  scratch->resize(n);
  if (n < 2) return;
  const int passes = (hi_bit - lo_bit + kDigitBits - 1) / kDigitBits;
  // All histograms in one read of the data.
  std::vector<std::array<uint32_t, kBuckets>> counts(static_cast<size_t>(passes));
  for (auto &c : counts) c.fill(0);
  const uint64_t *in = words->data();
  for (size_t i = 0; i < n; ++i) {
    const uint64_t w = in[i];
    for (int p = 0; p < passes; ++p) {
      const int shift = lo_bit + p * kDigitBits;
      const int bits = std::min(kDigitBits, hi_bit - shift);
      ++counts[size_t(p)][(w >> shift) & ((uint64_t(1) << bits) - 1)];
    }
  }
  for (int p = 0; p < passes; ++p) {
    auto &c = counts[size_t(p)];
    const int shift = lo_bit + p * kDigitBits;
    const int bits = std::min(kDigitBits, hi_bit - shift);
    const uint64_t mask = (uint64_t(1) << bits) - 1;
    // A digit every word shares does not reorder anything.
    bool trivial = false;
    for (size_t b = 0; b < kBuckets; ++b)
      if (c[b] != 0) {
        trivial = c[b] == n;
        break;
      }
    if (trivial) continue;
    uint32_t sum = 0;
    for (size_t b = 0; b < kBuckets; ++b) {
      const uint32_t k = c[b];
      c[b] = sum;
      sum += k;
    }
    const uint64_t *src = words->data();
    uint64_t *dst = scratch->data();
    for (size_t i = 0; i < n; ++i) {
      const uint64_t w = src[i];
      dst[c[(w >> shift) & mask]++] = w;
    }
    words->swap(*scratch);
  }
}

}  // namespace lantern
