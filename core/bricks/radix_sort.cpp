#include "core/bricks/radix_sort.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <thread>

namespace lantern {
namespace {

constexpr int kDigitBits = 11;
constexpr size_t kBuckets = size_t(1) << kDigitBits;
constexpr size_t kTwoThreadsFrom = 200000;  // words; below, a helper thread does not pay
using Counts = std::array<uint32_t, kBuckets>;

// One stable counting pass on the digit (w >> shift) & mask. `offsets` holds the exclusive
// prefix sums of the digit's counts over all of src. With two threads, the first half's counts
// give the second half its own start offsets, so both halves scatter at once, still stably.
void scatter(const uint64_t *src, uint64_t *dst, size_t n, int shift, uint64_t mask,
             const Counts &offsets) {
  const auto run = [=](size_t begin, size_t end, Counts at) {
    for (size_t i = begin; i < end; ++i) {
      const uint64_t w = src[i];
      dst[at[(w >> shift) & mask]++] = w;
    }
  };
  if (n < kTwoThreadsFrom) {
    run(0, n, offsets);
    return;
  }
  const size_t mid = n / 2;
  Counts second = offsets;
  for (size_t i = 0; i < mid; ++i) ++second[(src[i] >> shift) & mask];
  std::thread helper(run, mid, n, second);
  run(0, mid, offsets);
  helper.join();
}

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
    scatter(words->data(), scratch->data(), n, shift, mask, c);
    words->swap(*scratch);
  }
}

}  // namespace lantern
