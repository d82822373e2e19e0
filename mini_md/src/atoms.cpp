#include "atoms.h"

#include <cassert>

namespace mini_md {

void Atoms::add_owned(const Vec3 &pos, const Vec3 &vel, int64_t gid, int32_t t) {
  assert(nghost == 0);
  x.push_back(pos);
  f.push_back(Vec3{0, 0, 0});
  v.push_back(vel);
  id.push_back(gid);
  type.push_back(t);
  scalar.push_back(0.0);
  x_build.push_back(pos);
  ++nlocal;
}

void Atoms::clear_ghosts() {
  nghost = 0;
  x.resize(nlocal);
  f.resize(nlocal);
  id.resize(nlocal);
}

void Atoms::resize_ghosts(int n) {
  nghost = n;
  x.resize(ntotal());
  f.resize(ntotal());
  id.resize(ntotal());
}

void Atoms::remove_owned(int i) {
  assert(nghost == 0);
  const int last = nlocal - 1;
  x[i] = x[last];
  f[i] = f[last];
  v[i] = v[last];
  id[i] = id[last];
  type[i] = type[last];
  scalar[i] = scalar[last];
  x_build[i] = x_build[last];
  --nlocal;
  x.resize(nlocal);
  f.resize(nlocal);
  v.resize(nlocal);
  id.resize(nlocal);
  type.resize(nlocal);
  scalar.resize(nlocal);
  x_build.resize(nlocal);
}

namespace {
template <typename T>
void apply_order(std::vector<T> &a, const std::vector<int> &order, std::vector<T> &scratch) {
  scratch.resize(order.size());
  for (size_t k = 0; k < order.size(); ++k) scratch[k] = a[order[k]];
  a.swap(scratch);
}
}  // namespace

void Atoms::permute_owned(const std::vector<int> &order) {
  assert(nghost == 0 && static_cast<int>(order.size()) == nlocal);
  std::vector<Vec3> s3;
  apply_order(x, order, s3);
  apply_order(v, order, s3);
  apply_order(f, order, s3);
  apply_order(x_build, order, s3);
  std::vector<int64_t> s64;
  apply_order(id, order, s64);
  std::vector<int32_t> s32;
  apply_order(type, order, s32);
  std::vector<double> sd;
  apply_order(scalar, order, sd);
}

}  // namespace mini_md
