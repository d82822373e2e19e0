// LSD radix sort of 64-bit words by a range of their bits: the workhorse of the z-order sort.
//
// Stable, 11-bit digits, one histogram pass for all digits, and digits on which every word
// agrees are skipped (a rank's keys usually share their top bits). Memory: the caller's words
// plus one scratch buffer of the same size. With `threads` > 1, from 200 k words each pass
// scatters in that many parts at once (the result is the same). Thread-safety: a pure function of
// its arguments.
#pragma once

#include <cstdint>
#include <vector>
#include "core/common/page_allocator.h"

namespace lantern {

// Sorts `words` by bits [lo_bit, hi_bit) (0 <= lo_bit < hi_bit <= 64), stably. `scratch` is
// resized to words->size() and left with unspecified contents (reuse it or free it).
void radix_sort_words(PageVector<uint64_t> *words, PageVector<uint64_t> *scratch, int lo_bit,
                      int hi_bit, int threads = 1);

}  // namespace lantern
