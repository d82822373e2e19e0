#include "core/render/object_occlusion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <type_traits>
#include <utility>

#ifdef __SSE2__
#include <emmintrin.h>
#endif
#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "core/common/cpu_features.h"
#include "core/common/rank_threads.h"
#include "core/culling/cut_planes.h"
#include "core/particles/typed_access.h"

namespace lantern {

namespace object_occlusion_detail {

constexpr int kLocateChunk = 256;

// The node grid as locate_nodes() reads it: node i of an axis is node origin + i of the lattice
// of nodes `cell` apart from the coordinates' zero (origin16: kSteps origin, an integer).
struct NodeGrid {
  double origin16[3], last[3];  // last: kSteps (n - 1)
  double steps_per_unit;        // kSteps / cell
  int n[3];
};

// Per particle of a chunk: its lower node's index, and the table rows of its weights (code_x:
// the upper x weight; code_yz: wy (kSteps + 1) + wz).
struct NodeWeights {
  int32_t node[kLocateChunk], code_x[kLocateChunk], code_yz[kLocateChunk];
  int32_t lowest_z, highest_z;  // the lower nodes' planes of z: at least, at most (n > 0)
};

}  // namespace object_occlusion_detail

using object_occlusion_detail::kLocateChunk;
using object_occlusion_detail::NodeGrid;
using object_occlusion_detail::NodeWeights;

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

// The 8 corner weights of one deposit as 16-bit lanes 4 c + 2 b + a (a, b, c: the upper node
// along x, y, z): lane l of x[w] is the x weight of a = l & 1 for the upper weight w, lane l of
// yz[wy (kSteps + 1) + wz] the product of the y and z weights; their product (at most
// kSteps^3 = 4096) is the deposit.
struct CornerTables {
  alignas(16) uint16_t x[kSteps + 1][8];
  alignas(16) uint16_t yz[(kSteps + 1) * (kSteps + 1)][8];
};

const CornerTables &corner_tables() {
  static const CornerTables tables = [] {
    CornerTables t{};
    const auto weight = [](int upper, bool is_upper) { return is_upper ? upper : kSteps - upper; };
    for (int w = 0; w <= kSteps; ++w)
      for (int l = 0; l < 8; ++l) t.x[w][l] = uint16_t(weight(w, l & 1));
    for (int wy = 0; wy <= kSteps; ++wy)
      for (int wz = 0; wz <= kSteps; ++wz)
        for (int l = 0; l < 8; ++l)
          t.yz[wy * (kSteps + 1) + wz][l] = uint16_t(weight(wy, (l >> 1) & 1) * weight(wz, l >> 2));
    return t;
  }();
  return tables;
}

// The nodes and weights of OcclusionVolume::deposit() for n <= kLocateChunk particles, whose
// coordinate a is c[a][k * kStride]: one loop per axis without branches, so it vectorises, also
// for AVX2 where the processor has it (no FMA in that target: the same roundings as the
// baseline). Coordinates are finite.
template <int kStride>
inline __attribute__((always_inline)) void locate_nodes_of(const double *const c[3], int n,
                                                           const NodeGrid &grid, NodeWeights *out) {
  int32_t at[3][kLocateChunk], upper[3][kLocateChunk];
  for (int a = 0; a < 3; ++a) {
    const double origin16 = grid.origin16[a], top = grid.last[a];
    const double steps_per_unit = grid.steps_per_unit;
    const int32_t lower_last = grid.n[a] - 2;
    const double *ca = c[a];
    for (int k = 0; k < n; ++k) {
      const double u =
          std::clamp(std::floor(ca[k * kStride] * steps_per_unit + 0.5) - origin16, 0.0, top);
      const int32_t v = int32_t(u);  // >= 0: v / kSteps is v >> 4
      static_assert(kSteps == 16, "v / kSteps is v >> 4");
      at[a][k] = std::min(v >> 4, lower_last);
      upper[a][k] = v - kSteps * at[a][k];
    }
  }
  int32_t lowest = grid.n[2], highest = -1;
  for (int k = 0; k < n; ++k) {
    lowest = std::min(lowest, at[2][k]);
    highest = std::max(highest, at[2][k]);
  }
  out->lowest_z = lowest;
  out->highest_z = highest;
  const int32_t nx = grid.n[0], ny = grid.n[1];
  for (int k = 0; k < n; ++k) {
    out->node[k] = (at[2][k] * ny + at[1][k]) * nx + at[0][k];  // < the nodes: fits 32 bits
    out->code_x[k] = upper[0][k];
    out->code_yz[k] = upper[1][k] * (kSteps + 1) + upper[2][k];
  }
}

// Of gathered coordinates (coordinate[a][k]).
__attribute__((target_clones("avx2", "default"))) void locate_nodes(
    const double (*coordinate)[kLocateChunk], int n, const NodeGrid &grid, NodeWeights *out) {
  const double *const c[3] = {coordinate[0], coordinate[1], coordinate[2]};
  locate_nodes_of<1>(c, n, grid, out);
}

// Of n particles' positions x y z one after the other (xyz[3 k + a]) when all 3 n are finite
// (true), else nothing (false): the particles of a chunk without gathering them first.
__attribute__((target_clones("avx2", "default"))) bool locate_packed_nodes(const double *xyz, int n,
                                                                           const NodeGrid &grid,
                                                                           NodeWeights *out) {
  int not_finite = 0;  // no branch: it vectorises
  for (int k = 0; k < 3 * n; ++k)
    not_finite |= int(!(std::fabs(xyz[k]) <= std::numeric_limits<double>::max()));
  if (not_finite) return false;
  const double *const c[3] = {xyz, xyz + 1, xyz + 2};
  locate_nodes_of<3>(c, n, grid, out);
  return true;
}

#if defined(__x86_64__)
// locate_packed_nodes() in AVX2 intrinsics, four particles a step: their 12 coordinates loaded
// as three vectors and sorted into x, y and z by blends and one permute each, then every axis,
// the finite test and the node index in registers; the compiled loops above read the chunk once
// per axis through shuffles and keep each axis's nodes in memory between loops. Half of fcc 1 M
// (492 k particles, caches flushed): the volume 3.5-3.7 -> 3.2-3.4 ms. What is left is mostly
// reading the 12 MB of positions (a plain sum of them from memory: 0.6 ms, 0.8-0.9 ms with the
// other rank reading too). The same operations in the same order (no FMA): the same integers.
__attribute__((target("avx2"))) bool locate_packed_nodes_avx2(const double *xyz, int n,
                                                              const NodeGrid &grid,
                                                              NodeWeights *out) {
  if (n < 4) return locate_packed_nodes(xyz, n, grid, out);
  const __m256d magnitude = _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffffLL));
  const __m256d largest = _mm256_set1_pd(std::numeric_limits<double>::max());
  const __m256d half = _mm256_set1_pd(0.5), zero = _mm256_setzero_pd();
  const __m256d steps_per_unit = _mm256_set1_pd(grid.steps_per_unit);
  __m256d origin16[3], top[3];
  __m128i lower_last[3];
  for (int a = 0; a < 3; ++a) {
    origin16[a] = _mm256_set1_pd(grid.origin16[a]);
    top[a] = _mm256_set1_pd(grid.last[a]);
    lower_last[a] = _mm_set1_epi32(grid.n[a] - 2);
  }
  const __m128i nx = _mm_set1_epi32(grid.n[0]), ny = _mm_set1_epi32(grid.n[1]);
  const __m128i codes_per_y = _mm_set1_epi32(kSteps + 1);
  __m256d finite = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  __m128i lowest = _mm_set1_epi32(grid.n[2]), highest = _mm_set1_epi32(-1);
  static_assert(kSteps == 16, "v / kSteps is v >> 4");
  // The last step overlaps the one before where n is not a multiple of 4 (the same values
  // written again).
  for (int k0 = 0; k0 < n; k0 += 4) {
    const int k = std::min(k0, n - 4);
    const double *p = xyz + 3 * k;
    const __m256d a = _mm256_loadu_pd(p), b = _mm256_loadu_pd(p + 4), c = _mm256_loadu_pd(p + 8);
    for (const __m256d v : {a, b, c})
      finite =
          _mm256_and_pd(finite, _mm256_cmp_pd(_mm256_and_pd(v, magnitude), largest, _CMP_LE_OQ));
    // a = x0 y0 z0 x1, b = y1 z1 x2 y2, c = z2 x3 y3 z3.
    const __m256d along[3] = {
        _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, b, 0b0100), c, 0b0010),
                              _MM_SHUFFLE(1, 2, 3, 0)),  // x0 x3 x2 x1 -> x0 x1 x2 x3
        _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, b, 0b1001), c, 0b0100),
                              _MM_SHUFFLE(2, 3, 0, 1)),  // y1 y0 y3 y2 -> y0 y1 y2 y3
        _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, b, 0b0010), c, 0b1001),
                              _MM_SHUFFLE(3, 0, 1, 2))};  // z2 z1 z0 z3 -> z0 z1 z2 z3
    __m128i at[3], upper[3];
    for (int axis = 0; axis < 3; ++axis) {
      const __m256d w =
          _mm256_floor_pd(_mm256_add_pd(_mm256_mul_pd(along[axis], steps_per_unit), half));
      const __m256d u =
          _mm256_min_pd(_mm256_max_pd(_mm256_sub_pd(w, origin16[axis]), zero), top[axis]);
      const __m128i v = _mm256_cvttpd_epi32(u);
      at[axis] = _mm_min_epi32(_mm_srai_epi32(v, 4), lower_last[axis]);
      upper[axis] = _mm_sub_epi32(v, _mm_slli_epi32(at[axis], 4));
    }
    lowest = _mm_min_epi32(lowest, at[2]);
    highest = _mm_max_epi32(highest, at[2]);
    const __m128i node =
        _mm_add_epi32(_mm_mullo_epi32(_mm_add_epi32(_mm_mullo_epi32(at[2], ny), at[1]), nx), at[0]);
    const __m128i code_yz = _mm_add_epi32(_mm_mullo_epi32(upper[1], codes_per_y), upper[2]);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(out->node + k), node);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(out->code_x + k), upper[0]);
    _mm_storeu_si128(reinterpret_cast<__m128i *>(out->code_yz + k), code_yz);
  }
  if (_mm256_movemask_pd(finite) != 0xf) return false;
  alignas(16) int32_t low[4], high[4];
  _mm_store_si128(reinterpret_cast<__m128i *>(low), lowest);
  _mm_store_si128(reinterpret_cast<__m128i *>(high), highest);
  out->lowest_z = *std::min_element(low, low + 4);
  out->highest_z = *std::max_element(high, high + 4);
  return true;
}

// GCC 12's AVX-512 headers leave an undefined vector for their intrinsics to fill, which it then
// warns about.
#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// locate_packed_nodes_avx2()'s steps on eight particles a step where the processor has AVX-512:
// x, y and z taken apart with two permutes each (as packed_prefixes_avx512 in core/bricks/
// morton.cpp does), the same double operations in the same order (no FMA: the same integers), and
// the integer steps on eight 32-bit lanes. Why: a timer on the 1 M-atom LJ frame (2 ranks, Intel
// Xeon with AVX-512) put the AVX2 kernel at 1.6 ms a rank with the positions in cache (2.1 ms
// from memory): 32 cycles for four particles, about 75 instructions with the shuffles and
// register spills. This kernel, fed from cache by the refit (take_tapped()): 0.76-0.81 ms.
__attribute__((target("avx512f,avx512vl,avx512dq"))) bool locate_packed_nodes_avx512(
    const double *xyz, int n, const NodeGrid &grid, NodeWeights *out) {
  if (n < 8) return locate_packed_nodes_avx2(xyz, n, grid, out);
  const __m512d largest = _mm512_set1_pd(std::numeric_limits<double>::max());
  const __m512d half = _mm512_set1_pd(0.5), zero = _mm512_setzero_pd();
  const __m512d steps_per_unit = _mm512_set1_pd(grid.steps_per_unit);
  __m512d origin16[3], top[3];
  __m256i lower_last[3];
  for (int a = 0; a < 3; ++a) {
    origin16[a] = _mm512_set1_pd(grid.origin16[a]);
    top[a] = _mm512_set1_pd(grid.last[a]);
    lower_last[a] = _mm256_set1_epi32(grid.n[a] - 2);
  }
  const __m256i nx = _mm256_set1_epi32(grid.n[0]), ny = _mm256_set1_epi32(grid.n[1]);
  // Particles 0-7's coordinates are doubles 0-23: a = 0-7, b = 8-15, c = 16-23. Each axis: its
  // first five or six from a and b, then the rest from c.
  const __m512i from_ab[3] = {_mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0),
                              _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0),
                              _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0)};
  const __m512i from_c[3] = {_mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13),
                             _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14),
                             _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15)};
  __mmask8 finite = 0xff;
  __m256i lowest = _mm256_set1_epi32(grid.n[2]), highest = _mm256_set1_epi32(-1);
  static_assert(kSteps == 16, "v / kSteps is v >> 4");
  // The last step overlaps the one before where n is not a multiple of 8 (the same values
  // written again).
  for (int k0 = 0; k0 < n; k0 += 8) {
    const int k = std::min(k0, n - 8);
    const double *p = xyz + 3 * k;
    const __m512d a = _mm512_loadu_pd(p), b = _mm512_loadu_pd(p + 8), c = _mm512_loadu_pd(p + 16);
    for (const __m512d v : {a, b, c})
      finite &= _mm512_cmp_pd_mask(_mm512_abs_pd(v), largest, _CMP_LE_OQ);
    __m256i at[3], upper[3];
    for (int axis = 0; axis < 3; ++axis) {
      const __m512d along =
          _mm512_permutex2var_pd(_mm512_permutex2var_pd(a, from_ab[axis], b), from_c[axis], c);
      const __m512d w =
          _mm512_roundscale_pd(_mm512_add_pd(_mm512_mul_pd(along, steps_per_unit), half),
                               _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
      const __m512d u =
          _mm512_min_pd(_mm512_max_pd(_mm512_sub_pd(w, origin16[axis]), zero), top[axis]);
      const __m256i v = _mm512_cvttpd_epi32(u);
      at[axis] = _mm256_min_epi32(_mm256_srai_epi32(v, 4), lower_last[axis]);
      upper[axis] = _mm256_sub_epi32(v, _mm256_slli_epi32(at[axis], 4));
    }
    lowest = _mm256_min_epi32(lowest, at[2]);
    highest = _mm256_max_epi32(highest, at[2]);
    const __m256i node = _mm256_add_epi32(
        _mm256_mullo_epi32(_mm256_add_epi32(_mm256_mullo_epi32(at[2], ny), at[1]), nx), at[0]);
    static_assert(kSteps + 1 == 17, "wy (kSteps + 1) is (wy << 4) + wy");
    const __m256i code_yz =
        _mm256_add_epi32(_mm256_add_epi32(_mm256_slli_epi32(upper[1], 4), upper[1]), upper[2]);
    _mm256_storeu_si256(reinterpret_cast<__m256i *>(out->node + k), node);
    _mm256_storeu_si256(reinterpret_cast<__m256i *>(out->code_x + k), upper[0]);
    _mm256_storeu_si256(reinterpret_cast<__m256i *>(out->code_yz + k), code_yz);
  }
  if (finite != 0xff) return false;
  alignas(32) int32_t low[8], high[8];
  _mm256_store_si256(reinterpret_cast<__m256i *>(low), lowest);
  _mm256_store_si256(reinterpret_cast<__m256i *>(high), highest);
  out->lowest_z = *std::min_element(low, low + 8);
  out->highest_z = *std::max_element(high, high + 8);
  return true;
}
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif

// The particles of locate_packed_nodes() with the fastest code the processor runs.
bool locate_packed(const double *xyz, int n, const NodeGrid &grid, NodeWeights *out) {
#if defined(__x86_64__)
  if (cpu_has_avx512_bw()) return locate_packed_nodes_avx512(xyz, n, grid, out);
  if (cpu_has_avx2()) return locate_packed_nodes_avx2(xyz, n, grid, out);
#endif
  return locate_packed_nodes(xyz, n, grid, out);
}

// Particles deposited on the quads before their sums could pass 32 bits: each adds at most
// kParticleWeight to a node, so a node's sum of fewer than 2^32 / kParticleWeight particles fits.
constexpr int64_t kMaxQuadParticles = (int64_t(1) << 32) / kParticleWeight - 1;
// The fewest particles a thread deposits: a thread costs tens of microseconds to start, a
// particle a few nanoseconds.
constexpr int64_t kMinParticlesPerPart = int64_t(1) << 16;

// Adds the 8 corner weights of each of n located particles to the quads (OcclusionVolume::
// deposit()): lanes 4 c + 2 b + a, c = 0 to the quad of the lower node, c = 1 to the quad one
// plane of z above (dz nodes on). Two 16-byte adds of 32-bit lanes a particle and no branch
// (SSE2 where there is one, else one lane at a time: the same integers).
//
// Quads, not node pairs along x with consecutive particles' sums held while they share their
// nodes: with nodes about a crystal cell apart few consecutive particles share them (fcc 1 M:
// 1.2 particles a run), so the run's test was a mispredicted branch and each run four 16-byte
// adds of 64-bit pairs; a quad's 16-byte add never half overlaps another's (each quad its own 16
// bytes), and a particle's add to the quad just written is forwarded from the store whole (fcc
// 1 M, rank 0's half in cache: the deposit 2.8-3.0 -> 1.9-2.1 ms; 2 M particles piled 57 to a
// cell of 2.3 in random order within the cell: 7.3-7.4 -> 5.0-5.5 ms).
void add_to_quads(const NodeWeights &located, int n, const CornerTables &tables, uint32_t *quads,
                  size_t dz) {
#ifdef __SSE2__
  const __m128i zero = _mm_setzero_si128();
  for (int k = 0; k < n; ++k) {
    auto *lower = reinterpret_cast<__m128i *>(quads + 4 * size_t(located.node[k]));
    auto *upper = reinterpret_cast<__m128i *>(quads + 4 * (size_t(located.node[k]) + dz));
    const __m128i w = _mm_mullo_epi16(
        _mm_load_si128(reinterpret_cast<const __m128i *>(tables.x[located.code_x[k]])),
        _mm_load_si128(reinterpret_cast<const __m128i *>(tables.yz[located.code_yz[k]])));
    _mm_storeu_si128(lower, _mm_add_epi32(_mm_loadu_si128(lower), _mm_unpacklo_epi16(w, zero)));
    _mm_storeu_si128(upper, _mm_add_epi32(_mm_loadu_si128(upper), _mm_unpackhi_epi16(w, zero)));
  }
#else
  for (int k = 0; k < n; ++k) {
    uint32_t *lower = quads + 4 * size_t(located.node[k]), *upper = lower + 4 * dz;
    const uint16_t *x = tables.x[located.code_x[k]], *yz = tables.yz[located.code_yz[k]];
    for (int l = 0; l < 4; ++l) {
      lower[l] += uint32_t(x[l]) * uint32_t(yz[l]);
      upper[l] += uint32_t(x[l + 4]) * uint32_t(yz[l + 4]);
    }
  }
#endif
}

}  // namespace

void OcclusionVolume::set_grid(const Extent &global, double radius, int64_t max_nodes) {
  max_nodes = std::clamp<int64_t>(max_nodes, 8, kLargestAoMaxNodes);
  double cell = radius * kOcclusionCellPerRadius;
  if (!(cell > 0.0) || !std::isfinite(cell)) cell = 1.0;
  // Widen the spacing in steps of kOcclusionCellWidening until the nodes fit (the node counts
  // only fall as the spacing grows). The steps, and the nodes on the lattice of multiples of
  // the spacing, keep the grid put while the bounds move a little from step to step.
  double origin[3] = {0.0, 0.0, 0.0}, along[3] = {2.0, 2.0, 2.0};
  // The nodes at spacing c: origin and count along each axis, and their product.
  const auto lay_out = [&](double c) {
    const double steps_per_unit = kSteps * (1.0 / c);
    double nodes = 1.0;
    for (int a = 0; a < 3; ++a) {
      // As locate_nodes() places a particle: the lattice step nearest to it, then its node.
      const double first = std::floor(std::floor(global.lo[a] * steps_per_unit + 0.5) / kSteps);
      const double last = std::floor(std::floor(global.hi[a] * steps_per_unit + 0.5) / kSteps);
      origin[a] = first;
      along[a] = last - first + 2.0;
      nodes *= along[a];
    }
    return nodes;
  };
  const auto fits = [max_nodes](double nodes) { return nodes <= double(max_nodes); };
  double nodes = lay_out(cell);
  for (int attempt = 1; !fits(nodes) && attempt < 4096; ++attempt)
    nodes = lay_out(cell *= kOcclusionCellWidening);
  if (!fits(nodes)) {
    // 4095 widenings (a factor of 1e77) were not enough: a radius far below the particles' span
    // (radius 1e-80 over a span of 1000, or zero radii over 1e80). The spacing straight from the
    // widest span, a cube root of max_nodes nodes along it, then widening steps again. Before,
    // the grid kept up to max_nodes nodes per axis (terabytes, an int overflow in a plane's
    // size, or NaN counts where positions times the steps per unit overflowed).
    double span = 0.0;
    for (int a = 0; a < 3; ++a) span = std::max(span, global.hi[a] - global.lo[a]);
    const double per_axis = std::floor(std::cbrt(double(max_nodes)));
    cell = std::max(cell, span / std::max(per_axis - 3.0, 1.0));
    nodes = lay_out(cell);
    for (int attempt = 0; !fits(nodes) && attempt < 64; ++attempt)
      nodes = lay_out(cell *= kOcclusionCellWidening);
  }
  cell_ = cell;
  inverse_cell_ = 1.0 / cell;
  for (int a = 0; a < 3; ++a) {
    origin_[a] = origin[a];
    n_[a] = along[a] >= 2.0 ? int(std::min(along[a], double(max_nodes))) : 2;  // NaN: 2
    lo_[a] = origin[a] * cell;
  }
}

OcclusionVolume::QuadGrid OcclusionVolume::volume_grid() const {
  QuadGrid g;
  for (int a = 0; a < 3; ++a) g.origin[a] = origin_[a], g.n[a] = n_[a];
  return g;
}

std::array<int, 3> OcclusionVolume::quad_offset() const {
  std::array<int, 3> off{};
  for (int a = 0; a < 3; ++a) off[size_t(a)] = int(origin_[a] - quad_grid_.origin[a]);
  return off;
}

// Trilinear deposits of this rank's drawn particles, kParticleWeight each. Per axis the position
// in 1/kSteps of a node, v = round(kSteps u), gives the lower node v / kSteps and the upper
// node's weight v mod kSteps (kSteps on the grid's last node): the weights of upper_weight().
// v is rounded on the lattice of all nodes (node k at k cell from the coordinates' zero) and
// then counted from the grid's first node, so the same particle lands on the same lattice nodes
// in any grid that holds it: the bricks' refit can deposit on last step's grid, widened, before
// this step's bounds are known (take_tapped()).
//
// In chunks: the drawn particles' coordinates are gathered, then turned into nodes and weights in
// one loop per axis (no branches: it vectorises), then the 8 corner weights of each particle are
// one product of two small tables in 16-bit lanes (at most kSteps^3 = 4096), added to a part's
// quads (add_to_quads()). Integers: the same sums in any order, so the same volume as one particle
// at a time.
//
// Quad i holds, in lane a + 2 b, what node i + a + b dy received from the particles whose lower
// node along x and y is node i (both in the plane of node i): nodes_of() sums a node's four. In
// 32 bits: after kMaxQuadParticles particles the quads are added to the 64-bit sums and
// zeroed. The quads are zeroed plane by plane as the chunks' deposits reach them (`occupied`: a
// domain decomposition's rank reaches only its own planes and those along its boundaries), and
// kept between builds (not zero-filled when allocated).
//
// With several parts (threads), each deposits its particles on quads of its own, and
// merge_parts() adds them to the first's: integer sums, so the same quads, or the same 64-bit
// sums where 32 bits could overflow, as one part. (Why: at one rank with two threads, fcc 1 M's
// object AO stage took 7.1-8.6 ms with the deposit on one thread, 4.0-4.2 in parts;
// lantern-bench-cues, tests/bench/cues/results/cues_threads_ab.txt.)
void OcclusionVolume::start_deposit(const QuadGrid &grid, int parts) {
  quad_grid_ = grid;
  // Parts beyond `parts` keep their quads for a later step (no allocation, no page faults).
  parts = std::max(1, parts);
  if (deposits_.size() < size_t(parts)) deposits_.resize(size_t(parts));
  for (size_t p = 0; p < size_t(parts); ++p) {
    QuadDeposit &d = deposits_[p];
    d.quads.resize(4 * size_t(grid.n[0]) * size_t(grid.n[1]) * size_t(grid.n[2]));
    d.spilled.clear();
    d.zeroed = Planes{};
    d.on_quads = 0;
  }
}

void OcclusionVolume::zero_planes(QuadDeposit &d, Planes planes) {
  if (planes.empty()) return;
  const size_t dz = size_t(quad_grid_.n[0]) * size_t(quad_grid_.n[1]);
  uint32_t *quads = d.quads.data();
  const auto zero = [&](int first, int end) {
    if (first < end)
      std::fill(quads + 4 * dz * size_t(first), quads + 4 * dz * size_t(end), uint32_t(0));
  };
  if (d.zeroed.empty()) {
    zero(planes.first, planes.end);
    d.zeroed = planes;
  } else {
    zero(planes.first, d.zeroed.first);
    zero(d.zeroed.end, planes.end);
    d.zeroed = {std::min(d.zeroed.first, planes.first), std::max(d.zeroed.end, planes.end)};
  }
}

void OcclusionVolume::merge_parts(int parts) {
  QuadDeposit &to = deposits_[0];
  const size_t dz = size_t(quad_grid_.n[0]) * size_t(quad_grid_.n[1]);
  for (size_t p = 1; p < std::min(deposits_.size(), size_t(std::max(1, parts))); ++p) {
    QuadDeposit &from = deposits_[p];
    if (from.zeroed.empty()) continue;  // nothing deposited
    zero_planes(to, from.zeroed);
    if (from.spilled.empty() && to.spilled.empty() &&
        to.on_quads + from.on_quads <= kMaxQuadParticles) {
      // Every lane's sum stays within 32 bits (kMaxQuadParticles).
      const uint32_t *a = from.quads.data() + 4 * dz * size_t(from.zeroed.first);
      uint32_t *b = to.quads.data() + 4 * dz * size_t(from.zeroed.first);
      const size_t lanes = 4 * dz * size_t(from.zeroed.count());
      for (size_t i = 0; i < lanes; ++i) b[i] += a[i];
      to.on_quads += from.on_quads;
      continue;
    }
    // Else in 64 bits: both parts' quads spilled, the sums added.
    spill(to);
    to.on_quads = 0;
    spill(from);
    for (size_t i = 0; i < to.spilled.size(); ++i) to.spilled[i] += from.spilled[i];
  }
}

NodeGrid OcclusionVolume::located_grid() const {
  NodeGrid g{};
  g.steps_per_unit = kSteps * inverse_cell_;
  for (int a = 0; a < 3; ++a) {
    g.origin16[a] = kSteps * quad_grid_.origin[a];
    g.last[a] = double(kSteps * (quad_grid_.n[a] - 1));
    g.n[a] = quad_grid_.n[a];
  }
  return g;
}

void OcclusionVolume::add_located(QuadDeposit &to, const NodeWeights &located, int n) {
  const size_t dz = size_t(quad_grid_.n[0]) * size_t(quad_grid_.n[1]);
  if (to.on_quads + n > kMaxQuadParticles) {  // before a sum could pass 32 bits
    spill(to);
    to.on_quads = 0;
  }
  to.on_quads += n;
  // A deposit reaches the plane above its lower node's.
  zero_planes(to, Planes{int(located.lowest_z), int(located.highest_z) + 2});
  add_to_quads(located, n, corner_tables(), to.quads.data(), dz);
}

void OcclusionVolume::deposit(const ParticleArrays &particles, const CutPlanes &planes, int threads,
                              Planes *occupied) {
  const int64_t count = particles.count();
  const int parts = parts_for(threads, count, kMinParticlesPerPart);
  start_deposit(volume_grid(), parts);
  const NodeGrid grid = located_grid();
  constexpr int kChunk = kLocateChunk;
  static_assert(kChunk <= kMaxQuadParticles, "a chunk fits on the quads");
  visit_kept(particles, [&](const auto &kept) {
    visit_positions(particles, [&](const auto &positions) {
      constexpr bool kAllKept = std::is_same_v<std::decay_t<decltype(kept)>, KeepAll>;
      const bool every = kAllKept && planes.empty();
      // Every particle, positions as x y z doubles one after the other: located in place.
      const double *packed = nullptr;
      if constexpr (std::is_same_v<std::decay_t<decltype(positions)>, InterleavedPositions<double>>)
        if (every && positions.stride == int64_t(3 * sizeof(double)) &&
            reinterpret_cast<uintptr_t>(positions.base) % alignof(double) == 0)  // the API allows
          packed = reinterpret_cast<const double *>(positions.base);             // any address
      run_in_parts(parts, count, [&](int part, int64_t first, int64_t last) {
        QuadDeposit &to = deposits_[size_t(part)];
        double coordinate[3][kChunk];
        NodeWeights located;
        for (int64_t i0 = first; i0 < last; i0 += kChunk) {
          const int64_t end = std::min(last, i0 + kChunk);
          int n = 0;
          const bool in_place =
              packed != nullptr && locate_packed(packed + 3 * i0, int(end - i0), grid, &located);
          if (in_place) {
            n = int(end - i0);
          } else if (every) {  // no branch per particle: each is written, and kept when finite
            for (int64_t i = i0; i < end; ++i) {
              const glm::dvec3 x = positions.get(i);
              coordinate[0][n] = x.x, coordinate[1][n] = x.y, coordinate[2][n] = x.z;
              n += int(std::isfinite(x.x)) & int(std::isfinite(x.y)) & int(std::isfinite(x.z));
            }
          } else {
            for (int64_t i = i0; i < end; ++i) {
              if (!kept.get(i)) continue;
              const glm::dvec3 x = positions.get(i);
              if (!(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z))) continue;
              if (!planes.empty() && planes.drops(x)) continue;
              coordinate[0][n] = x.x, coordinate[1][n] = x.y, coordinate[2][n] = x.z;
              ++n;
            }
          }
          if (n == 0) continue;
          if (!in_place) locate_nodes(coordinate, n, grid, &located);
          add_located(to, located, n);
        }
      });
    });
  });
  merge_parts(parts);
  const Planes zeroed = deposits_[0].zeroed;
  *occupied = zeroed.empty() ? Planes{0, 0} : zeroed;
}

bool OcclusionVolume::arm_tap() {
  tap_ = TapState{};
  if (!tappable_) return false;
  // Last step's grid with a node more on every side: this step's grid still lies inside it
  // unless the bounds moved by more than a node or the spacing was widened.
  QuadGrid wider = volume_grid();
  for (int a = 0; a < 3; ++a) wider.origin[a] -= 1.0, wider.n[a] += 2;
  start_deposit(wider, 1);
  tap_.armed = true;
  tap_.cell = cell_;
  tap_.planes = built_planes_;
  tap_.parts.assign(1, PartTap{});
  return true;
}

void OcclusionVolume::begin_tapped_parts(int parts) {
  if (!tap_.armed) return;
  parts = std::max(1, parts);
  start_deposit(quad_grid_, parts);  // the armed grid, in parts
  tap_.parts.assign(size_t(parts), PartTap{});
}

void OcclusionVolume::take_tapped(int part, const double *xyz, int64_t first, int64_t end) {
  if (!tap_.armed || part < 0 || size_t(part) >= tap_.parts.size()) return;
  PartTap &t = tap_.parts[size_t(part)];
  if (t.failed) return;
  const auto t0 = std::chrono::steady_clock::now();
  if (t.next < 0)
    t.first = first;
  else if (first != t.next)
    t.failed = true;  // never: the refit hands each part's stripes in order
  QuadDeposit &to = deposits_[size_t(part)];
  const NodeGrid grid = located_grid();
  NodeWeights located;
  const CutPlanes &planes = tap_.planes;
  double kept[3 * kLocateChunk];  // behind cutting planes: the chunk's particles they leave
  for (int64_t i0 = first; i0 < end && !t.failed; i0 += kLocateChunk) {
    int n = int(std::min<int64_t>(kLocateChunk, end - i0));
    const double *chunk = xyz + 3 * i0;
    if (!planes.empty()) {
      int m = 0;
      for (int k = 0; k < n; ++k) {
        const glm::dvec3 x(chunk[3 * k], chunk[3 * k + 1], chunk[3 * k + 2]);
        // A coordinate that is not finite fails the tap below unless a plane drops the
        // particle; either way it is deposited nowhere, as in the deposit of build()'s own.
        if (planes.drops(x)) continue;
        kept[3 * m] = x.x, kept[3 * m + 1] = x.y, kept[3 * m + 2] = x.z;
        ++m;
      }
      chunk = kept, n = m;
      if (n == 0) continue;
    }
    if (!locate_packed(chunk, n, grid, &located)) {
      t.failed = true;  // a coordinate is not finite: build() deposits on its own
      break;
    }
    add_located(to, located, n);
  }
  t.next = end;
  t.ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

bool OcclusionVolume::tap_complete(const TapState &tap, int64_t count, double *ms) {
  *ms = 0.0;
  bool complete = tap.armed;
  int64_t expected = 0;
  for (const PartTap &t : tap.parts) {
    *ms = std::max(*ms, t.ms);  // the parts ran at once
    if (t.failed) complete = false;
    if (t.next < 0) continue;  // a part that got nothing
    if (t.first != expected) complete = false;
    expected = t.next;
  }
  return complete && expected == count;
}

// The quads of the planes d.zeroed added to d.spilled (zero-filled on the first spill), and
// zeroed again. In the quads' own grid.
void OcclusionVolume::spill(QuadDeposit &d) {
  const size_t nx = size_t(quad_grid_.n[0]), ny = size_t(quad_grid_.n[1]), plane = nx * ny;
  if (d.spilled.empty()) d.spilled.assign(plane * size_t(quad_grid_.n[2]), 0);
  std::vector<int64_t> nodes(plane);
  for (int z = d.zeroed.first; z < d.zeroed.end; ++z) {
    nodes_from_quads(d, z, 0, 0, nx, ny, nodes.data());
    int64_t *to = &d.spilled[size_t(z) * plane];
    for (size_t i = 0; i < plane; ++i) to[i] += nodes[i];
  }
  if (!d.zeroed.empty())
    std::fill(&d.quads[4 * plane * size_t(d.zeroed.first)],
              &d.quads[4 * plane * size_t(d.zeroed.end)], uint32_t(0));
}

namespace {

// One row of nodes from a row of quads (quad x of the row of node y: lane a + 2 b goes to node
// x + a of row y + b): node x of the row is lane 0 of quad x, lane 1 of quad x - 1, and, carried
// from the row below, lanes 2 and 3 of its quads x and x - 1; `carry` is the row's lanes 2 and 3
// for the row above (what the row below left on entry). Below 2^32 each (kMaxQuadParticles).
void nodes_of_row(const uint32_t *quads, size_t nx, uint32_t *carry, int64_t *out) {
  size_t x = 0;
#ifdef __SSE2__
  __m128i before = _mm_setzero_si128();  // quad x - 1
  for (; x + 4 <= nx; x += 4) {
    __m128i v[4];
    for (int k = 0; k < 4; ++k) {
      const __m128i q = _mm_loadu_si128(reinterpret_cast<const __m128i *>(quads + 4 * (x + k)));
      v[k] = _mm_add_epi32(q, _mm_srli_epi64(before, 32));  // lane 0: a = 0 + 1, lane 2: b = 1
      before = q;
    }
    const __m128i lo01 = _mm_unpacklo_epi32(v[0], v[1]), hi01 = _mm_unpackhi_epi32(v[0], v[1]);
    const __m128i lo23 = _mm_unpacklo_epi32(v[2], v[3]), hi23 = _mm_unpackhi_epi32(v[2], v[3]);
    auto *c = reinterpret_cast<__m128i *>(carry + x);
    const __m128i nodes = _mm_add_epi32(_mm_unpacklo_epi64(lo01, lo23), _mm_loadu_si128(c));
    _mm_storeu_si128(c, _mm_unpacklo_epi64(hi01, hi23));
    const __m128i zero = _mm_setzero_si128();
    _mm_storeu_si128(reinterpret_cast<__m128i *>(out + x), _mm_unpacklo_epi32(nodes, zero));
    _mm_storeu_si128(reinterpret_cast<__m128i *>(out + x + 2), _mm_unpackhi_epi32(nodes, zero));
  }
#endif
  for (; x < nx; ++x) {
    const uint32_t *q = quads + 4 * x, *before = x > 0 ? q - 4 : nullptr;
    const uint32_t low = q[0] + (before ? before[1] : 0u), high = q[2] + (before ? before[3] : 0u);
    out[x] = int64_t(low + carry[x]);
    carry[x] = high;
  }
}

}  // namespace

// Nodes [x0, x0 + nx) x [y0, y0 + ny) of plane z of the quads' grid from the quads alone (the
// quads left of x0 and below y0 hold nothing: no particle's lower node is there).
void OcclusionVolume::nodes_from_quads(const QuadDeposit &d, int z, size_t x0, size_t y0, size_t nx,
                                       size_t ny, int64_t *out) const {
  const size_t qx = size_t(quad_grid_.n[0]), qy = size_t(quad_grid_.n[1]);
  uint32_t carry_on_stack[256];
  std::vector<uint32_t> carry_on_heap(nx > 256 ? nx : 0);
  uint32_t *carry = nx > 256 ? carry_on_heap.data() : carry_on_stack;
  std::fill(carry, carry + nx, 0u);  // no row below the first
  const uint32_t *quads = &d.quads[4 * ((size_t(z) * qy + y0) * qx + x0)];
  for (size_t y = 0; y < ny; ++y) nodes_of_row(quads + 4 * y * qx, nx, carry, out + y * nx);
}

void OcclusionVolume::nodes_of(Planes occupied, Planes planes, int64_t *out) const {
  const size_t nx = size_t(n_[0]), ny = size_t(n_[1]), plane = nx * ny;
  const size_t qx = size_t(quad_grid_.n[0]), qy = size_t(quad_grid_.n[1]);
  const std::array<int, 3> off = quad_offset();
  for (int z = planes.first; z < planes.end; ++z) {
    int64_t *to = out + size_t(z - planes.first) * plane;
    if (z < occupied.first || z >= occupied.end) {  // nothing reached it: spilled is zero too
      std::fill(to, to + plane, int64_t(0));
      continue;
    }
    const int qz = z + off[2];
    const QuadDeposit &d = deposits_[0];
    nodes_from_quads(d, qz, size_t(off[0]), size_t(off[1]), nx, ny, to);
    if (d.spilled.empty()) continue;
    for (size_t y = 0; y < ny; ++y) {
      const int64_t *spilled =
          &d.spilled[(size_t(qz) * qy + y + size_t(off[1])) * qx + size_t(off[0])];
      for (size_t x = 0; x < nx; ++x) to[y * nx + x] += spilled[x];
    }
  }
}

namespace {

// out[i] = in[i] + 4 in[i + 1] + 6 in[i + 2] + 4 in[i + 3] + in[i + 4] (the filter kFilter) for
// i in [0, count), each tap its own row: shifts and adds, so it vectorises (SSE2 has no 64-bit
// multiply); in 64- or 32-bit lanes (smooth()), with AVX2 where the processor has it (integers:
// the same sums).
template <typename T>
inline __attribute__((always_inline)) void filter_rows_of(const T *const in[5], T *out,
                                                          size_t count) {
  static_assert(
      kFilter[0] == 1 && kFilter[1] == 4 && kFilter[2] == 6 && kFilter[3] == 4 && kFilter[4] == 1,
      "filter_rows() writes the taps out");
  const T *a = in[0], *b = in[1], *c = in[2], *d = in[3], *e = in[4];
  for (size_t i = 0; i < count; ++i)
    out[i] = (a[i] + e[i]) + ((b[i] + d[i]) << 2) + (c[i] << 2) + (c[i] << 1);
}

__attribute__((target_clones("avx2", "default"))) void filter_rows64(const int64_t *const in[5],
                                                                     int64_t *out, size_t count) {
  filter_rows_of(in, out, count);
}

__attribute__((target_clones("avx2", "default"))) void filter_rows32(const int32_t *const in[5],
                                                                     int32_t *out, size_t count) {
  filter_rows_of(in, out, count);
}

template <typename T>
void filter_rows(const T *const in[5], T *out, size_t count) {
  if constexpr (std::is_same_v<T, int32_t>)
    filter_rows32(in, out, count);
  else
    filter_rows64(in, out, count);
}

// Deposits on a node below this keep every sum of the filter within 32 bits (the filter's
// weights sum to kFilterWeight).
constexpr int64_t kDeposits32 = int64_t(1) << 19;
static_assert(kDeposits32 * kFilterWeight - 1 <= std::numeric_limits<int32_t>::max(),
              "the 32-bit filter's sums fit");

// Whether all of the n deposits (at least 0) are below kDeposits32: their bits above it are
// zero (an OR, which vectorises).
bool fit_32_bits(const int64_t *deposits, size_t n) {
  uint64_t bits = 0;
  for (size_t i = 0; i < n; ++i) bits |= uint64_t(deposits[i]);
  return bits < uint64_t(kDeposits32);
}

}  // namespace

// The planes of z a rank smooths: the r-th of `ranks` nearly equal slabs (empty where there
// are more ranks than planes).
OcclusionVolume::Planes OcclusionVolume::slab_of(int rank, int ranks) const {
  const int64_t nz = n_[2];
  return {int(nz * rank / ranks), int(nz * (rank + 1) / ranks)};
}

// The planes whose deposits the smoothing of `slab` reads: kFilterReach more on either side,
// within the grid (none for an empty slab).
OcclusionVolume::Planes OcclusionVolume::reach_of(Planes slab) const {
  if (slab.empty()) return slab;
  return {std::max(0, slab.first - kFilterReach), std::min(n_[2], slab.end + kFilterReach)};
}

// The deposits of every rank summed over the planes `reach` (`summed`, plane after plane), from
// this rank's quads (deposit(): held on the planes `occupied` only). Each rank
// sends every other only its occupied planes that the other's reach holds, so a domain
// decomposition exchanges little more than the planes along the ranks' boundaries. Integers:
// the same sums in any order. Collective over comm.
Status OcclusionVolume::sum_over_ranks(MPI_Comm comm, Planes occupied, Planes reach,
                                       UninitializedBuffer<int64_t> *summed) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const int plane = n_[0] * n_[1];  // <= kLargestAoMaxNodes: every count below fits an int
  const auto both = [](Planes a, Planes b) {
    const Planes c{std::max(a.first, b.first), std::min(a.end, b.end)};
    return c.empty() ? Planes{0, 0} : c;
  };
  int mine[2] = {occupied.first, occupied.end};
  std::vector<int> occupied_by(2 * size_t(ranks));
  if (MPI_Allgather(mine, 2, MPI_INT, occupied_by.data(), 2, MPI_INT, comm) != MPI_SUCCESS)
    return {StatusCode::kMpi, "ambient_occlusion (object): MPI_Allgather of the planes failed"};
  const size_t all = static_cast<size_t>(ranks);
  std::vector<int> send_count(all, 0), send_at(all, 0), receive_count(all, 0), receive_at(all, 0);
  std::vector<Planes> received(all);
  int received_total = 0;
  Planes sent{n_[2], 0};  // every plane sent to any rank (within `occupied`)
  for (int q = 0; q < ranks; ++q) {
    if (q == rank) continue;
    const Planes out = both(occupied, reach_of(slab_of(q, ranks)));
    if (out.empty()) continue;
    sent = {std::min(sent.first, out.first), std::max(sent.end, out.end)};
  }
  if (sent.empty()) sent = {0, 0};
  outgoing_.resize(size_t(sent.count()) * size_t(plane));
  nodes_of(occupied, sent, outgoing_.data());
  for (int q = 0; q < ranks; ++q) {
    if (q == rank) continue;  // this rank's own deposits are taken below
    const Planes out = both(occupied, reach_of(slab_of(q, ranks)));
    send_count[size_t(q)] = out.count() * plane;
    send_at[size_t(q)] = out.empty() ? 0 : (out.first - sent.first) * plane;
    const Planes in = both({occupied_by[2 * size_t(q)], occupied_by[2 * size_t(q) + 1]}, reach);
    received[size_t(q)] = in;
    receive_count[size_t(q)] = in.count() * plane;
    receive_at[size_t(q)] = received_total;
    received_total += receive_count[size_t(q)];
  }
  incoming_.resize(static_cast<size_t>(received_total));
  if (MPI_Alltoallv(outgoing_.data(), send_count.data(), send_at.data(), MPI_INT64_T,
                    incoming_.data(), receive_count.data(), receive_at.data(), MPI_INT64_T,
                    comm) != MPI_SUCCESS)
    return {StatusCode::kMpi, "ambient_occlusion (object): MPI_Alltoallv of the density failed"};
  summed->resize(size_t(reach.count()) * size_t(plane));
  nodes_of(occupied, reach, summed->data());
  for (int q = 0; q < ranks; ++q) {
    const Planes in = received[size_t(q)];
    if (in.empty()) continue;
    int64_t *to = summed->data() + ptrdiff_t(in.first - reach.first) * plane;
    const int64_t *from = incoming_.data() + receive_at[size_t(q)];
    for (ptrdiff_t i = 0; i < ptrdiff_t(in.count()) * plane; ++i) to[i] += from[i];
  }
  return {};
}

// The filter along each axis (nodes beyond the grid hold nothing: taps that fall off it add
// zeros), exact in integers, then in particles per cell^3, for the planes `slab` from the
// deposits of the planes `given` (reach_of(slab): every plane the filter reads) into smoothed_.
// Plane by plane of z: each plane is filtered along x and y into a ring of the last five, from
// which the plane two behind is filtered along z; the working set (six planes of 64^2 nodes at
// the default max_nodes) stays in cache, and the deposits are read once and the result written once
// (fcc 1 M: 1.8 -> 0.5 ms). Returns the largest sum of the slab (0 for an empty one).
template <typename T>
int64_t OcclusionVolume::smooth(const int64_t *deposits, Planes given, Planes slab) {
  const size_t nx = size_t(n_[0]), ny = size_t(n_[1]), plane = nx * ny;
  const int nz = n_[2];
  smoothed_.resize(size_t(slab.count()) * plane);
  if (slab.empty()) return 0;
  constexpr size_t kPad = kFilterReach;
  // A row of deposits with kPad zeros either side; a plane filtered along x with kPad zero rows
  // above and below; the ring of planes filtered along x and y; a plane of zeros (off the grid);
  // a plane filtered along all three.
  std::vector<T> row(nx + 2 * kPad, 0), along_x((ny + 2 * kPad) * nx, 0), ring(5 * plane, 0),
      zeros(plane, 0), along_xyz(plane);
  const double scale = 1.0 / double(kParticleWeight * kFilterWeight);
  T largest = 0;
  for (int z = given.first; z < slab.end + kFilterReach; ++z) {
    if (z < given.end) {
      const int64_t *in = deposits + size_t(z - given.first) * plane;
      for (size_t y = 0; y < ny; ++y) {
        for (size_t x = 0; x < nx; ++x) row[kPad + x] = T(in[y * nx + x]);
        const T *taps[5] = {&row[0], &row[1], &row[2], &row[3], &row[4]};
        filter_rows(taps, &along_x[(y + kPad) * nx], nx);
      }
      T *xy = &ring[size_t(z) % 5 * plane];
      for (size_t y = 0; y < ny; ++y) {
        const T *taps[5];
        for (size_t k = 0; k < 5; ++k) taps[k] = &along_x[(y + k) * nx];
        filter_rows(taps, xy + y * nx, nx);
      }
    }
    const int out = z - kFilterReach;  // the plane whose five neighbours along z are in the ring
    if (out < slab.first) continue;
    const T *taps[5];
    for (int k = 0; k < 5; ++k) {
      const int at = out + k - kFilterReach;  // in `given` when on the grid
      taps[k] = at >= 0 && at < nz ? &ring[size_t(at) % 5 * plane] : zeros.data();
    }
    filter_rows(taps, along_xyz.data(), plane);
    float *to = &smoothed_[size_t(out - slab.first) * plane];
    for (size_t i = 0; i < plane; ++i) {
      to[i] = float(double(along_xyz[i]) * scale);
      largest = std::max(largest, along_xyz[i]);
    }
  }
  return int64_t(largest);
}

namespace {

// The histogram's bins of n values in [0, top]: one loop without branches (it vectorises: the
// divisions), with AVX2 where the processor has it (no FMA in that target: the same roundings).
__attribute__((target_clones("avx2", "default"))) void bins_of(const float *value, size_t n,
                                                               float top, int32_t *bins) {
  for (size_t k = 0; k < n; ++k) bins[k] = std::min(kBulkBins - 1, int(value[k] / top * kBulkBins));
}

}  // namespace

// The histogram of smoothed_ (the nodes of one slab, whose summed deposits are `deposits`),
// weighted by the deposits, into `histogram` (kBulkBins bins of [0, top]).
void OcclusionVolume::bin_slab(const int64_t *deposits, float top, int64_t *histogram) const {
  // The bins (bins_of()), then the deposits added to them (a node without deposits adds nothing),
  // neighbouring nodes to different copies of the histogram: they often share a bin, and adds to
  // one counter wait for each other.
  constexpr size_t kCopies = 4;
  std::vector<int64_t> histograms(kCopies * kBulkBins, 0);
  constexpr size_t kChunk = 1024;
  static_assert(kChunk % kCopies == 0, "every chunk starts at copy 0");
  int32_t bins[kChunk];
  const size_t nodes = smoothed_.size();
  for (size_t i0 = 0; i0 < nodes; i0 += kChunk) {
    const size_t n = std::min(kChunk, nodes - i0);
    const float *value = &smoothed_[i0];
    bins_of(value, n, top, bins);
    for (size_t k = 0; k < n; ++k)
      histograms[k % kCopies * kBulkBins + size_t(bins[k])] += deposits[i0 + k];
  }
  for (size_t c = 0; c < kCopies; ++c)
    for (size_t b = 0; b < size_t(kBulkBins); ++b) histogram[b] += histograms[c * kBulkBins + b];
}

// The bulk density (kOcclusionBulkQuantile of the deposits lie at nodes of at most this
// smoothed value) from the histogram of every node, then o_face for its mean spacing.
void OcclusionVolume::find_bulk(const std::vector<int64_t> &histogram, float top) {
  bulk_ = 0.0;
  face_ = 1.0;
  const int64_t total = std::accumulate(histogram.begin(), histogram.end(), int64_t(0));
  if (total == 0 || !(top > 0.0f)) return;
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

// Every rank deposits its particles on the whole grid; then each smooths, bins and turns into
// enclosures its own slab of planes of z (the deposits it reads summed over ranks: its slab and
// kFilterReach planes either side), and the slabs' enclosures are gathered on every rank. Every
// step is exact or per node, so the volume is the same for any split of the particles and any
// number of ranks (fcc 1 M on 2 ranks: each rank smooths half the planes, and the ranks
// exchange their boundary planes instead of summing the whole grid).
Status OcclusionVolume::build(MPI_Comm comm, const ParticleArrays &particles, const Extent &global,
                              const std::vector<CutPlane> &cuts, double radius, double strength,
                              int threads, int64_t max_nodes) {
  strength_ = float(strength);
  smoothed_.clear();
  enclosure_.clear();
  bulk_ = 0.0;
  face_ = 1.0;
  const TapState tap = std::exchange(tap_, TapState{});
  last_tapped_ = false;
  const bool tap_whole = tap_complete(tap, particles.count(), &last_tap_ms_);  // ms: spent anyway
  const CutPlanes planes(cuts);
  const bool ungrouped = !particles.has_mask();
  tappable_ = false;
  built_planes_ = planes;
  if (global.empty()) return {};  // the same on every rank: no reduction to skip
  set_grid(global, radius, max_nodes);
  tappable_ = ungrouped;
  const size_t nodes = size_t(n_[0]) * size_t(n_[1]) * size_t(n_[2]);
  const int plane = n_[0] * n_[1];
  Planes occupied;
  const auto holds_grid = [this] {  // this step's grid lies inside the quads' grid
    for (int a = 0; a < 3; ++a)
      if (origin_[a] < quad_grid_.origin[a] ||
          origin_[a] + n_[a] > quad_grid_.origin[a] + quad_grid_.n[a])
        return false;
    return true;
  };
  last_tapped_ =
      tap_whole && ungrouped && tap.planes.same_as(planes) && tap.cell == cell_ && holds_grid();
  if (last_tapped_) {
    merge_parts(int(tap.parts.size()));
    const int off = quad_offset()[2];
    const Planes zeroed = deposits_[0].zeroed;
    occupied = {std::max(0, zeroed.first - off), std::min(n_[2], zeroed.end - off)};
    if (zeroed.empty() || occupied.empty()) occupied = {0, 0};
  } else {
    deposit(particles, planes, threads, &occupied);
  }
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  const Planes slab = slab_of(rank, ranks), reach = reach_of(slab);
  // A node's sum stays below 2^63 for up to 2^51 particles on it.
  UninitializedBuffer<int64_t> &summed = summed_;  // the planes `reach`
  if (ranks > 1) {
    if (Status s = sum_over_ranks(comm, occupied, reach, &summed); !s.ok()) return s;
  } else {
    summed.resize(nodes);
    nodes_of(occupied, reach, summed.data());
  }
  const int64_t *slab_deposits = summed.data();
  // In 32-bit lanes where the sums fit them (fcc 1 M, half the planes: 0.28-0.29 -> 0.14-0.15
  // ms), else 64: the same integers (a rank's choice need not be another's).
  int64_t largest = fit_32_bits(slab_deposits, summed.size())
                        ? smooth<int32_t>(slab_deposits, reach, slab)
                        : smooth<int64_t>(slab_deposits, reach, slab);
  if (ranks > 1 &&
      MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_INT64_T, MPI_MAX, comm) != MPI_SUCCESS)
    return {StatusCode::kMpi, "ambient_occlusion (object): MPI_Allreduce of the largest failed"};
  // The conversion does not decrease: the largest value is that of the largest sum.
  const float top = float(double(largest) * (1.0 / double(kParticleWeight * kFilterWeight)));
  std::vector<int64_t> histogram(kBulkBins, 0);
  if (largest > 0) {  // else nothing anywhere: no bins (the same on every rank)
    bin_slab(slab_deposits + ptrdiff_t(slab.first - reach.first) * plane, top, histogram.data());
    if (ranks > 1 && MPI_Allreduce(MPI_IN_PLACE, histogram.data(), kBulkBins, MPI_INT64_T, MPI_SUM,
                                   comm) != MPI_SUCCESS)
      return {StatusCode::kMpi, "ambient_occlusion (object): MPI_Allreduce of the bins failed"};
  }
  find_bulk(histogram, top);
  // Layers too far apart for the smoothing to see a surface (o_face near 1): nothing darkens.
  if (bulk_ > 0.0 && face_ < 0.999) {
    enclosure_.resize(nodes);
    const double per_bulk = 1.0 / bulk_, open = 1.0 / (1.0 - face_);
    float *to = enclosure_.data() + ptrdiff_t(slab.first) * plane;
    for (size_t i = 0; i < smoothed_.size(); ++i)
      to[i] = float((double(smoothed_[i]) * per_bulk - face_) * open);
    if (ranks > 1) {
      std::vector<int> count(static_cast<size_t>(ranks)), at(count.size());
      for (int q = 0; q < ranks; ++q) {
        const Planes other = slab_of(q, ranks);
        count[size_t(q)] = other.count() * plane;
        at[size_t(q)] = other.first * plane;
      }
      if (MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, enclosure_.data(), count.data(),
                         at.data(), MPI_FLOAT, comm) != MPI_SUCCESS)
        return {StatusCode::kMpi,
                "ambient_occlusion (object): MPI_Allgatherv of the volume failed"};
    }
  }
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
