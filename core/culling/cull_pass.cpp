#include "core/culling/cull_pass.h"

#include <algorithm>
#include <limits>

namespace lantern {
namespace {

constexpr int kDepthBuckets = 64;

}  // namespace

void order_front_to_back(CandidateBuffers *b) {
  const std::vector<Candidate> &in = b->gathered;
  std::vector<Candidate> &out = b->sorted;
  out.resize(in.size());
  if (in.size() < 2) {
    out = in;
    return;
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Candidate &c : in) lo = std::min(lo, -c.c.z), hi = std::max(hi, -c.c.z);
  const double scale = hi > lo ? (kDepthBuckets - 1) / (hi - lo) : 0.0;
  std::vector<uint32_t> &counts = b->bucket_counts;
  counts.assign(kDepthBuckets + 1, 0);
  const auto bucket = [&](const Candidate &c) { return size_t((-c.c.z - lo) * scale); };
  for (const Candidate &c : in) ++counts[bucket(c) + 1];
  for (size_t k = 1; k < counts.size(); ++k) counts[k] += counts[k - 1];
  for (const Candidate &c : in) out[counts[bucket(c)]++] = c;
}

}  // namespace lantern
