#include "core/culling/cull_pass.h"

#include <algorithm>
#include <array>
#include <limits>

#include <glm/common.hpp>

namespace lantern {
namespace {

constexpr int kDepthBuckets = 64;

}  // namespace

void order_front_to_back(CandidateBuffers *b) {
  const std::vector<Candidate> &in = b->gathered;
  std::vector<Candidate> &out = b->sorted;
  std::vector<DepthBucket> &buckets = b->buckets;
  out.resize(in.size());
  buckets.clear();
  if (in.empty()) return;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Candidate &c : in) lo = std::min(lo, -c.c.z), hi = std::max(hi, -c.c.z);
  const double scale = hi > lo ? (kDepthBuckets - 1) / (hi - lo) : 0.0;
  std::vector<uint32_t> &counts = b->bucket_counts;
  counts.assign(kDepthBuckets + 1, 0);
  const auto bucket = [&](const Candidate &c) { return size_t((-c.c.z - lo) * scale); };
  for (const Candidate &c : in) ++counts[bucket(c) + 1];
  for (size_t k = 1; k < counts.size(); ++k) counts[k] += counts[k - 1];
  // The non-empty buckets, nearest first; which[k]: bucket k's place among them.
  std::array<uint32_t, kDepthBuckets> which{};
  for (size_t k = 0; k < kDepthBuckets; ++k)
    if (counts[k + 1] > counts[k]) {
      which[k] = uint32_t(buckets.size());
      DepthBucket d;
      d.begin = counts[k], d.end = counts[k + 1];
      d.lo = glm::dvec3(std::numeric_limits<double>::infinity()), d.hi = -d.lo;
      d.near = std::numeric_limits<double>::infinity();
      buckets.push_back(d);
    }
  // Scatter into the buckets, growing each one's box.
  std::vector<uint32_t> &slot = counts;
  for (const Candidate &c : in) {
    const size_t k = bucket(c);
    DepthBucket &d = buckets[which[k]];
    d.lo = glm::min(d.lo, c.c - c.r), d.hi = glm::max(d.hi, c.c + c.r);
    d.near = std::min(d.near, -c.c.z - c.r);
    out[slot[k]++] = c;
  }
}

}  // namespace lantern
