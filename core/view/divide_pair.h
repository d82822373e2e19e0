// Two double divisions in one packed SSE2 instruction where there is one. Each lane of a packed
// IEEE division gives the bits its own division would, so callers whose results must match a
// scalar path bit for bit (the casts' per-pixel results, the rays' reference pixel) may use it.
// Thread-safety: a pure function.
#pragma once

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lantern {

// *q0 = n0 / d0 and *q1 = n1 / d1.
inline void divide_pair(double n0, double n1, double d0, double d1, double *q0, double *q1) {
#if defined(__SSE2__)
  const __m128d q = _mm_div_pd(_mm_setr_pd(n0, n1), _mm_setr_pd(d0, d1));
  *q0 = _mm_cvtsd_f64(q), *q1 = _mm_cvtsd_f64(_mm_unpackhi_pd(q, q));
#else
  *q0 = n0 / d0, *q1 = n1 / d1;
#endif
}

}  // namespace lantern
