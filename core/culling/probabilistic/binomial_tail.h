// The upper tail of a binomial distribution, P(X >= k) for X ~ Binomial(n, p): eq. 21 of
// Ibrahim et al. 2022, the probability that at least k of the next n samples land nearer than a
// candidate depth.
//
// The paper evaluates eq. 21 by a normal approximation (its appendix, after Feller 1945); so does
// binomial_tail(), with the continuity correction, where the variance n p (1 - p) is at least
// kNormalMinVariance: there the approximation's error is below about 0.01 (Feller's bound is of
// order 1 / sqrt(n p (1 - p)); the unit test measures it against the exact sums). Below that the
// distribution is too skewed for a normal and n is small, so the exact sum (at most n + 1 terms,
// in log space) is both cheap and right.
// Thread-safety: pure functions.
#pragma once

namespace lantern {

inline constexpr double kNormalMinVariance = 9.0;

// Exact: sum_{j=k}^{n} C(n, j) p^j (1 - p)^(n - j). 1 for k <= 0, 0 for k > n.
double binomial_tail_exact(int n, double p, int k);
// Normal approximation with continuity correction: 1 - Phi((k - 0.5 - n p) / sqrt(n p (1 - p))).
double binomial_tail_normal(int n, double p, int k);
// The normal approximation where it is accurate (variance >= kNormalMinVariance), else exact.
double binomial_tail(int n, double p, int k);

}  // namespace lantern
