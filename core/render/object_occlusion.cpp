#include "core/render/object_occlusion.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/culling/cut_planes.h"
#include "core/particles/typed_access.h"

namespace lantern {

namespace {

// Deposit weights per axis, in 1/kSteps: a particle deposits kSteps^3 in all.
constexpr int kSteps = 16;
constexpr int64_t kParticleWeight = int64_t(kSteps) * kSteps * kSteps;
// The smoothing filter along each axis (binomial: standard deviation 1 node), and what the three
// passes multiply a deposit by.
constexpr int kFilterReach = 2;
constexpr int64_t kFilter[2 * kFilterReach + 1] = {1, 4, 6, 4, 1};
static_assert(kFilterReach == 2, "smooth() writes the five taps out");
constexpr int64_t kFilterWeight = 16 * 16 * 16;
// Bins of the histogram the bulk density is read from.
constexpr int kBulkBins = 4096;
// Offsets of the layers against the nodes that o_face averages over.
constexpr int kFacePhases = 64;

// The weight of the upper of two nodes for a fractional position f in [0, 1], in 1/kSteps.
int upper_weight(double f) {
  return std::clamp(int(f * kSteps + 0.5), 0, kSteps);
}

// One axis of the node grid: deposit on nodes i and i + 1 (i in [0, n - 2]) with fraction f.
void locate(double u, int n, int *i, double *f) {
  const double clamped = std::clamp(u, 0.0, double(n - 1));
  *i = std::min(int(clamped), n - 2);
  *f = std::min(clamped - double(*i), 1.0);
}

// o_face of the header for layers `spacing` nodes apart: the smoothed deposit of the outermost
// of half-infinite layers over that of layers on both sides, at the offset of the layers to the
// nodes where that is largest (it varies by a few per cent with the offset: a face must not
// darken at any).
double face_occupancy_of(double spacing) {
  if (!(spacing > 0.0) || !std::isfinite(spacing)) return 1.0;
  // A layer further than kFilterReach + 2 nodes from where it is read reaches it through no node
  // (deposit 1, filter kFilterReach, interpolation 1).
  const int layers = int(std::min((kFilterReach + 2) / spacing, 1e6)) + 2;
  constexpr int kReach = 6;  // nodes either side of the reading point that can hold a deposit
  double largest = 0.0;
  for (int phase = 0; phase < kFacePhases; ++phase) {
    const double at = double(phase) / kFacePhases;  // the outermost layer, in node units
    double deposit[2][2 * kReach + 1] = {};         // nodes -kReach .. kReach
    for (int k = -layers; k <= layers; ++k) {
      const double u = at - k * spacing;
      const double node = std::floor(u);
      if (node < -kReach || node + 1 > kReach) continue;
      const int w = upper_weight(u - node), i = int(node) + kReach;
      for (int side = 0; side < 2; ++side) {
        if (side == 0 && k < 0) continue;  // side 0: the half-space below the outermost layer
        deposit[side][i] += kSteps - w;
        deposit[side][i + 1] += w;
      }
    }
    double value[2];
    for (int side = 0; side < 2; ++side) {
      const double *d = deposit[side] + kReach;  // node 0
      double node0 = 0.0, node1 = 0.0;
      for (int k = -kFilterReach; k <= kFilterReach; ++k) {
        node0 += double(kFilter[k + kFilterReach]) * d[k];
        node1 += double(kFilter[k + kFilterReach]) * d[k + 1];
      }
      value[side] = node0 * (1.0 - at) + node1 * at;
    }
    if (value[1] > 0.0) largest = std::max(largest, value[0] / value[1]);
  }
  return largest > 0.0 ? largest : 1.0;
}

}  // namespace

void OcclusionVolume::set_grid(const Extent &global, double radius) {
  double cell = radius * kOcclusionCellPerRadius;
  if (!(cell > 0.0) || !std::isfinite(cell)) cell = 1.0;
  // Widen the spacing until the nodes fit (the node counts only fall as the spacing grows).
  for (int attempt = 0; attempt < 200; ++attempt) {
    double nodes = 1.0;
    for (int a = 0; a < 3; ++a) {
      const double along = std::floor(std::max(0.0, global.hi[a] - global.lo[a]) / cell) + 2.0;
      n_[a] = int(std::min(along, double(kMaxOcclusionNodes)));
      nodes *= along;
    }
    if (nodes <= double(kMaxOcclusionNodes)) break;
    cell *= std::cbrt(nodes / double(kMaxOcclusionNodes)) * 1.001;
  }
  cell_ = cell;
  inverse_cell_ = 1.0 / cell;
  for (int a = 0; a < 3; ++a) lo_[a] = global.lo[a];
}

// Trilinear deposits of this rank's drawn particles, kParticleWeight each. Per axis the position
// in 1/kSteps of a node, v = round(kSteps u), gives the lower node v / kSteps and the upper
// node's weight v mod kSteps (kSteps on the grid's last node): the weights of upper_weight().
void OcclusionVolume::deposit(const ParticleArrays &particles, const std::vector<CutPlane> &cuts,
                              std::vector<int64_t> *nodes) const {
  const CutPlanes planes(cuts);
  const size_t dy = size_t(n_[0]), dz = size_t(n_[0]) * size_t(n_[1]);
  int64_t *out = nodes->data();
  const double steps_per_unit = kSteps * inverse_cell_;
  int last[3];
  for (int a = 0; a < 3; ++a) last[a] = kSteps * (n_[a] - 1);
  // Consecutive particles often share their 8 nodes (a crystal's basis atoms, a brick's
  // neighbours): their deposits are summed here and added to the nodes when the nodes change
  // (integers: the same sums in any order).
  int64_t *held = nullptr;
  int64_t sum[8] = {};
  const auto flush = [&] {
    if (!held) return;
    for (int c = 0; c < 2; ++c)
      for (int b = 0; b < 2; ++b) {
        int64_t *row = held + size_t(b) * dy + size_t(c) * dz;
        row[0] += sum[4 * c + 2 * b];
        row[1] += sum[4 * c + 2 * b + 1];
      }
  };
  visit_kept(particles, [&](const auto &kept) {
    visit_positions(particles, [&](const auto &positions) {
      for (int64_t i = 0; i < particles.count(); ++i) {
        if (!kept.get(i)) continue;
        const glm::dvec3 x = positions.get(i);
        if (!(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z))) continue;
        if (!planes.empty() && planes.drops(x)) continue;
        int at[3];
        int64_t w[3][2];
        for (int a = 0; a < 3; ++a) {
          const double u = std::clamp((x[a] - lo_[a]) * steps_per_unit + 0.5, 0.0, double(last[a]));
          const int v = int(u);
          at[a] = std::min(v / kSteps, n_[a] - 2);
          w[a][1] = v - kSteps * at[a];
          w[a][0] = kSteps - w[a][1];
        }
        int64_t *node = out + index(at[0], at[1], at[2]);
        if (node != held) {
          flush();
          held = node;
          std::fill(sum, sum + 8, 0);
        }
        for (int c = 0; c < 2; ++c)
          for (int b = 0; b < 2; ++b) {
            const int64_t wyz = w[1][b] * w[2][c];
            sum[4 * c + 2 * b] += w[0][0] * wyz;
            sum[4 * c + 2 * b + 1] += w[0][1] * wyz;
          }
      }
    });
  });
  flush();
}

// The filter along each axis (nodes beyond the grid hold nothing), exact in integers, then in
// particles per cell^3. Written as loops over whole rows of nodes so that they vectorise.
void OcclusionVolume::smooth(const std::vector<int64_t> &deposits) {
  const size_t nx = size_t(n_[0]), plane = nx * size_t(n_[1]);
  std::vector<int64_t> a(deposits.size()), b(deposits.size());
  // Along x, straight from the deposits: the interior of each row in one loop, the kFilterReach
  // nodes at either end (whose taps fall off the grid) apart.
  for (size_t row = 0; row < deposits.size(); row += nx) {
    const int64_t *in = &deposits[row];
    int64_t *out = &a[row];
    const auto tap = [&](size_t x) {
      int64_t sum = 0;
      for (int k = -kFilterReach; k <= kFilterReach; ++k) {
        const ptrdiff_t at = ptrdiff_t(x) + k;
        if (at >= 0 && at < ptrdiff_t(nx)) sum += kFilter[k + kFilterReach] * in[at];
      }
      return sum;
    };
    const size_t inner_end = nx > size_t(kFilterReach) ? nx - size_t(kFilterReach) : 0;
    size_t x = 0;
    for (; x < std::min(size_t(kFilterReach), nx); ++x) out[x] = tap(x);
    for (; x < inner_end; ++x)
      out[x] = kFilter[0] * in[x - 2] + kFilter[1] * in[x - 1] + kFilter[2] * in[x] +
               kFilter[3] * in[x + 1] + kFilter[4] * in[x + 2];
    for (; x < nx; ++x) out[x] = tap(x);
  }
  // Along y, then z: whole rows of x at a time.
  for (int axis = 1; axis < 3; ++axis) {
    const size_t step = axis == 1 ? nx : plane;
    const int along = n_[axis];
    for (size_t row = 0; row < a.size(); row += nx) {
      const int at = axis == 1 ? int(row / nx % size_t(n_[1])) : int(row / plane);
      int64_t *out = &b[row];
      bool first = true;
      for (int k = -kFilterReach; k <= kFilterReach; ++k) {
        if (at + k < 0 || at + k >= along) continue;
        const int64_t *in = &a[size_t(ptrdiff_t(row) + k * ptrdiff_t(step))];
        const int64_t weight = kFilter[k + kFilterReach];
        if (first)
          for (size_t x = 0; x < nx; ++x) out[x] = weight * in[x];
        else
          for (size_t x = 0; x < nx; ++x) out[x] += weight * in[x];
        first = false;
      }
    }
    a.swap(b);
  }
  smoothed_.resize(a.size());
  const double scale = 1.0 / double(kParticleWeight * kFilterWeight);
  for (size_t i = 0; i < a.size(); ++i) smoothed_[i] = float(double(a[i]) * scale);
}

// The bulk density (kOcclusionBulkQuantile of the deposits lie at nodes of at most this
// smoothed value), then o_face for its mean spacing.
void OcclusionVolume::find_bulk(const std::vector<int64_t> &deposits) {
  bulk_ = 0.0;
  face_ = 1.0;
  int64_t total = 0;
  float top = 0.0f;
  for (size_t i = 0; i < deposits.size(); ++i) {
    total += deposits[i];
    top = std::max(top, smoothed_[i]);
  }
  if (total == 0 || !(top > 0.0f)) return;
  std::vector<int64_t> histogram(kBulkBins, 0);
  for (size_t i = 0; i < deposits.size(); ++i)
    if (deposits[i] > 0)
      histogram[size_t(std::min(kBulkBins - 1, int(smoothed_[i] / top * kBulkBins)))] +=
          deposits[i];
  const double wanted = kOcclusionBulkQuantile * double(total);
  int64_t below = 0;
  int bin = 0;
  for (; bin < kBulkBins - 1; ++bin) {
    below += histogram[size_t(bin)];
    if (double(below) >= wanted) break;
  }
  bulk_ = double(top) * (bin + 0.5) / kBulkBins;
  face_ = face_occupancy_of(std::cbrt(1.0 / bulk_));  // the mean spacing, in node units
}

Status OcclusionVolume::build(MPI_Comm comm, const ParticleArrays &particles, const Extent &global,
                              const std::vector<CutPlane> &cuts, double radius, double strength) {
  strength_ = float(strength);
  smoothed_.clear();
  enclosure_.clear();
  bulk_ = 0.0;
  face_ = 1.0;
  if (global.empty()) return {};  // the same on every rank: no reduction to skip
  set_grid(global, radius);
  const size_t nodes = size_t(n_[0]) * size_t(n_[1]) * size_t(n_[2]);
  std::vector<int64_t> deposits(nodes, 0);
  deposit(particles, cuts, &deposits);
  // One reduction of integers (in place): exact, so every split gives the same volume. A node's
  // sum stays below 2^63 for up to 2^51 particles on it.
  if (MPI_Allreduce(MPI_IN_PLACE, deposits.data(), int(nodes), MPI_INT64_T, MPI_SUM, comm) !=
      MPI_SUCCESS)
    return {StatusCode::kMpi, "ambient_occlusion (object): MPI_Allreduce of the density failed"};
  smooth(deposits);
  find_bulk(deposits);
  // Layers too far apart for the smoothing to see a surface (o_face near 1): nothing darkens.
  if (bulk_ > 0.0 && face_ < 0.999) {
    enclosure_.resize(smoothed_.size());
    const double per_bulk = 1.0 / bulk_, open = 1.0 / (1.0 - face_);
    for (size_t i = 0; i < smoothed_.size(); ++i)
      enclosure_[i] = float((double(smoothed_[i]) * per_bulk - face_) * open);
  }
  std::vector<float>().swap(smoothed_);
  return {};
}

// The trilinear interpolation of the enclosure at x, in float (the factors are 8-bit colours).
float OcclusionVolume::enclosure_at(const glm::dvec3 &x) const {
  int i0[3];
  float t[3];
  for (int a = 0; a < 3; ++a) {
    double f;
    locate((x[a] - lo_[a]) * inverse_cell_, n_[a], &i0[a], &f);
    t[a] = float(f);
  }
  const float *node = &enclosure_[index(i0[0], i0[1], i0[2])];
  const size_t dy = size_t(n_[0]), dz = size_t(n_[0]) * size_t(n_[1]);
  const auto along_x = [&](const float *row) { return row[0] + t[0] * (row[1] - row[0]); };
  const float y0 = along_x(node) + t[1] * (along_x(node + dy) - along_x(node));
  const float y1 = along_x(node + dz) + t[1] * (along_x(node + dz + dy) - along_x(node + dz));
  return y0 + t[2] * (y1 - y0);
}

double OcclusionVolume::occupancy(const glm::dvec3 &x) const {
  if (enclosure_.empty()) return 0.0;
  return face_ + double(enclosure_at(x)) * (1.0 - face_);
}

float OcclusionVolume::factor(const glm::dvec3 &x) const {
  if (enclosure_.empty()) return 1.0f;
  // The share of the open half-space that is filled, twice: as the screen method, a particle
  // half enclosed (the wall of a narrow pit, a deep crease) darkens by the whole strength.
  return 1.0f - strength_ * std::clamp(2.0f * enclosure_at(x), 0.0f, 1.0f);
}

}  // namespace lantern
