#include "core/dump/particle_frame.h"

#include <algorithm>

namespace lantern {
namespace {

template <typename T>
BorrowedArray array_of(const std::vector<T> &v, DataType type) {
  if (v.empty()) return {};
  return {v.data(), type, 0};
}

}  // namespace

ParticleDescription ParticleFrame::view() const {
  ParticleDescription p{};
  p.count = count();
  if (p.count == 0) return p;
  p.position = array_of(position, DataType::kFloat64);
  p.type = array_of(type, DataType::kInt64);
  p.id = array_of(id, DataType::kInt64);
  p.scalar = array_of(scalar, DataType::kFloat64);
  p.radius = array_of(radius, DataType::kFloat64);
  return p;
}

std::pair<int64_t, int64_t> rank_share(int64_t n, int rank, int size) {
  const int64_t base = n / size, extra = n % size;
  const int64_t begin = rank * base + std::min<int64_t>(rank, extra);
  return {begin, begin + base + (rank < extra ? 1 : 0)};
}

}  // namespace lantern
