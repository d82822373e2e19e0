// Two doubles worked on together, lane by lane: the x and y of a vector in one SSE2 register where
// the target has SSE2, else two doubles. Every operation is the IEEE operation scalar code does on
// each lane, and min/max are glm's ((o < a) ? o : a, (a < o) ? o : a), so code written on pairs
// gives the bits of the same code written on doubles and glm vectors, with half the instructions.
// Used where a hot loop works on x and y alike (bond refit, a brick's candidate boxes).
//
// Ownership: a value type. Thread-safety: none needed.
#pragma once

#include <cfloat>
#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lantern {

#if defined(__SSE2__)
struct DoublePair {
  __m128d v;
  static DoublePair of(double x, double y) { return {_mm_set_pd(y, x)}; }
  // p[0] and p[1], from memory of any alignment.
  static DoublePair load(const double *p) { return {_mm_loadu_pd(p)}; }
  double x() const { return _mm_cvtsd_f64(v); }
  double y() const { return _mm_cvtsd_f64(_mm_unpackhi_pd(v, v)); }
  DoublePair operator+(DoublePair o) const { return {_mm_add_pd(v, o.v)}; }
  DoublePair operator-(DoublePair o) const { return {_mm_sub_pd(v, o.v)}; }
  DoublePair operator*(DoublePair o) const { return {_mm_mul_pd(v, o.v)}; }
  // glm::min(*this, o), glm::max(*this, o): (o < a) ? o : a and (a < o) ? o : a per lane.
  DoublePair min(DoublePair o) const { return {_mm_min_pd(o.v, v)}; }
  DoublePair max(DoublePair o) const { return {_mm_max_pd(o.v, v)}; }
  // Whether 2 |lane| <= limit's lane in both lanes.
  bool twice_within(DoublePair limit) const {
    const __m128d magnitude = _mm_and_pd(v, _mm_castsi128_pd(_mm_set1_epi64x(INT64_MAX)));
    return _mm_movemask_pd(_mm_cmple_pd(_mm_add_pd(magnitude, magnitude), limit.v)) == 3;
  }
  // Whether both lanes are finite.
  bool finite() const {
    const __m128d magnitude = _mm_and_pd(v, _mm_castsi128_pd(_mm_set1_epi64x(INT64_MAX)));
    return _mm_movemask_pd(_mm_cmple_pd(magnitude, _mm_set1_pd(DBL_MAX))) == 3;
  }
};
#else
struct DoublePair {
  double a, b;
  static DoublePair of(double x, double y) { return {x, y}; }
  static DoublePair load(const double *p) { return {p[0], p[1]}; }
  double x() const { return a; }
  double y() const { return b; }
  DoublePair operator+(DoublePair o) const { return {a + o.a, b + o.b}; }
  DoublePair operator-(DoublePair o) const { return {a - o.a, b - o.b}; }
  DoublePair operator*(DoublePair o) const { return {a * o.a, b * o.b}; }
  DoublePair min(DoublePair o) const { return {o.a < a ? o.a : a, o.b < b ? o.b : b}; }
  DoublePair max(DoublePair o) const { return {a < o.a ? o.a : a, b < o.b ? o.b : b}; }
  bool twice_within(DoublePair limit) const {
    return 2.0 * std::abs(a) <= limit.a && 2.0 * std::abs(b) <= limit.b;
  }
  bool finite() const { return std::isfinite(a) && std::isfinite(b); }
};
#endif

}  // namespace lantern
