#include "core/bricks/radix_sort.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

#include "core/common/rank_threads.h"

namespace lantern {
namespace {

constexpr int kDigitBits = 11;
constexpr size_t kBuckets = size_t(1) << kDigitBits;
constexpr int64_t kWordsPerThread = 100000;  // below, a helper thread does not pay
using Counts = std::array<uint32_t, kBuckets>;

// One stable counting pass on the digit (w >> shift) & mask. `offsets` holds the exclusive
// prefix sums of the digit's counts over all of src. In parts, each part's start offsets are the
// earlier parts' counts on top, so all parts scatter at once, still stably.
void scatter(const uint64_t *src, uint64_t *dst, size_t n, int shift, uint64_t mask,
             const Counts &offsets, int threads) {
  const int parts = parts_for(threads, int64_t(n), kWordsPerThread);
  std::vector<Counts> at(size_t(parts), offsets);
  for (int p = 1; p < parts; ++p) {
    at[size_t(p)] = at[size_t(p - 1)];
    for (int64_t i = part_begin(p - 1, parts, int64_t(n)); i < part_begin(p, parts, int64_t(n));
         ++i)
      ++at[size_t(p)][(src[i] >> shift) & mask];
  }
  run_in_parts(parts, int64_t(n), [&](int p, int64_t begin, int64_t end) {
    Counts &a = at[size_t(p)];
    for (int64_t i = begin; i < end; ++i) {
      const uint64_t w = src[i];
      dst[a[(w >> shift) & mask]++] = w;
    }
  });
}

}  // namespace

void radix_sort_words(PageVector<uint64_t> *words, PageVector<uint64_t> *scratch, int lo_bit,
                      int hi_bit, int threads) {
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
    scatter(words->data(), scratch->data(), n, shift, mask, c, threads);
    words->swap(*scratch);
  }
}

}  // namespace lantern
