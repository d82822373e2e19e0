#include "core/composite/compositing_schedule.h"

#include <algorithm>
#include <functional>

namespace lantern {
namespace {

std::vector<int> prime_factors(int n) {
  std::vector<int> primes;
  for (int f = 2; f * f <= n; ++f)
    while (n % f == 0) primes.push_back(f), n /= f;
  if (n > 1) primes.push_back(n);
  return primes;
}

// The prime factors of q grouped into radices of at most `k` (a prime above k stays alone),
// first fit, largest primes first: as few rounds as the radix allows.
std::vector<int> radices_near(int q, int k) {
  std::vector<int> primes = prime_factors(q);
  std::sort(primes.begin(), primes.end(), std::greater<int>());
  std::vector<int> bins;
  for (const int prime : primes) {
    auto fits = std::find_if(bins.begin(), bins.end(),
                             [&](int bin) { return int64_t(bin) * prime <= int64_t(k); });
    if (fits == bins.end()) {
      bins.push_back(prime);
    } else {
      *fits *= prime;
    }
  }
  std::sort(bins.begin(), bins.end(), std::greater<int>());
  return bins;
}

int largest_power_of_two_at_most(int n) {
  int q = 1;
  while (q <= n / 2) q *= 2;
  return q;
}

int largest_3_smooth_at_most(int n) {
  int best = 1;
  for (int64_t three = 1; three <= n; three *= 3)
    for (int64_t v = three; v <= n; v *= 2) best = std::max(best, int(v));
  return best;
}

// Stride of digit `round`: the product of the radices after it.
int stride_of(const std::vector<int> &radices, int round) {
  int stride = 1;
  for (size_t j = size_t(round) + 1; j < radices.size(); ++j) stride *= radices[j];
  return stride;
}

PixelRange blocks_span(const std::vector<PixelRange> &blocks, int first, int count) {
  return {blocks[size_t(first)].lo, blocks[size_t(first + count - 1)].hi};
}

}  // namespace

int CompositingSchedule::base() const {
  if (tree) return ranks;
  int q = 1;
  for (const int k : radices) q *= k;
  return q;
}

int CompositingSchedule::extras() const {
  return ranks - base();
}

bool CompositingSchedule::valid() const {
  if (tree) return radices.empty() && ranks >= 1;
  int64_t q = 1;
  for (const int k : radices) {
    if (k < 2) return false;
    q *= k;
    if (q > ranks) return false;
  }
  return 2 * q >= ranks;
}

std::string CompositingSchedule::name() const {
  if (tree) return "tree_reduce";
  std::string text;
  const bool all_two = std::all_of(radices.begin(), radices.end(), [](int k) { return k == 2; });
  if (radices.empty()) {
    text = "none";
  } else if (all_two) {
    text = "binary_swap";
  } else if (radices.size() == 1) {
    text = "direct_send";
  } else {
    text = "radix_k ";
    for (size_t j = 0; j < radices.size(); ++j) text += (j ? "x" : "") + std::to_string(radices[j]);
  }
  if (extras() > 0) text += " fold " + std::to_string(extras());
  return text;
}

int CompositingSchedule::group_of(int rank) const {
  const int e = extras();
  return rank < 2 * e ? rank / 2 : rank - e;
}

int CompositingSchedule::base_rank(int group) const {
  const int e = extras();
  return group < e ? 2 * group : group + e;
}

int CompositingSchedule::extra_rank(int group) const {
  return group < extras() ? 2 * group + 1 : -1;
}

std::vector<CompositingSchedule> candidate_schedules(int ranks, bool to_root) {
  std::vector<CompositingSchedule> out;
  const auto add = [&](std::vector<int> radices) {
    CompositingSchedule s{ranks, std::move(radices), false};
    if (!s.valid()) return;
    for (const CompositingSchedule &seen : out)
      if (seen.radices == s.radices) return;
    out.push_back(std::move(s));
  };
  std::vector<int> bases = {ranks, largest_3_smooth_at_most(ranks),
                            largest_power_of_two_at_most(ranks)};
  for (const int q : bases) {
    if (q < 2) continue;
    add({q});  // direct send
    for (const int k : {2, 4, 8, 16, 32, 64}) {
      std::vector<int> r = radices_near(q, k);
      add(r);
      std::reverse(r.begin(), r.end());
      add(r);
    }
  }
  if (to_root) out.push_back({ranks, {}, true});
  return out;
}

std::vector<PixelRange> equal_blocks(size_t pixels, int groups) {
  std::vector<PixelRange> blocks(static_cast<size_t>(groups));
  const size_t q = size_t(groups);
  for (size_t i = 0; i < q; ++i) blocks[i] = {pixels * i / q, pixels * (i + 1) / q};
  return blocks;
}

RoundPlan round_plan(const CompositingSchedule &schedule, int group, int round,
                     const std::vector<PixelRange> &blocks) {
  const int k = schedule.radices[size_t(round)];
  const int stride = stride_of(schedule.radices, round);
  const int span = k * stride;
  const int start = group / span * span;  // first block this group holds before the round
  const int digit = group / stride % k;
  RoundPlan plan;
  plan.keep = blocks_span(blocks, start + digit * stride, stride);
  for (int d = 0; d < k; ++d) {
    if (d == digit) continue;
    plan.partners.push_back(schedule.base_rank(group + (d - digit) * stride));
    plan.give.push_back(blocks_span(blocks, start + d * stride, stride));
  }
  return plan;
}

}  // namespace lantern
