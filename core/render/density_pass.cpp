#include "core/render/density_pass.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>
#include <vector>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#endif

#include "core/common/cpu_features.h"
#include "core/culling/cut_planes.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define LANTERN_COLORS_X86 1
// The colours of types[k, n) (int32, contiguous) from a table of 64 packed words, 16 at a time
// while all 16 lie in [0, 64); returns where it stopped: n less its last n - k mod 16, or the
// first block holding a type beyond the table (the caller colours those one by one). Why: one
// load, two permutes and four stores per 16 particles instead of a load, a bounds test and two
// loads and stores each: 3 % of a weight-1 density frame (fcc 10 M, 1024^2, an AVX-512 EPYC).
__attribute__((target("avx512f,avx512vl,avx512dq,avx512bw"))) int fill_table16(
    const int32_t *types, const uint32_t *packed, int k, int n, Rgb8 *out) {
  const __m512i t0 = _mm512_load_si512(packed), t1 = _mm512_load_si512(packed + 16);
  const __m512i t2 = _mm512_load_si512(packed + 32), t3 = _mm512_load_si512(packed + 48);
  // Each 128-bit lane's four words to its first 12 bytes (r, g, b of each).
  const __m512i squeeze =
      _mm512_broadcast_i32x4(_mm_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1));
  auto *bytes = reinterpret_cast<unsigned char *>(out);
  for (; k + 16 <= n; k += 16) {
    const __m512i t = _mm512_loadu_si512(types + k);
    if (_mm512_cmpge_epu32_mask(t, _mm512_set1_epi32(64)) != 0) break;  // a type beyond the table
    const __m512i low = _mm512_permutex2var_epi32(t0, t, t1);           // types 0 .. 31 (bits 0-4)
    const __m512i high = _mm512_permutex2var_epi32(t2, t, t3);          // types 32 .. 63
    const __m512i c = _mm512_shuffle_epi8(
        _mm512_mask_blend_epi32(_mm512_test_epi32_mask(t, _mm512_set1_epi32(32)), low, high),
        squeeze);
    unsigned char *o = bytes + size_t(k) * 3;
    _mm_mask_storeu_epi8(o, 0x0fff, _mm512_castsi512_si128(c));
    _mm_mask_storeu_epi8(o + 12, 0x0fff, _mm512_extracti32x4_epi32(c, 1));
    _mm_mask_storeu_epi8(o + 24, 0x0fff, _mm512_extracti32x4_epi32(c, 2));
    _mm_mask_storeu_epi8(o + 36, 0x0fff, _mm512_extracti32x4_epi32(c, 3));
  }
  return k;
}
#else
#define LANTERN_COLORS_X86 0
#endif

// The colour of particle i. By type without object-space occlusion (the common case), types
// 0 .. 63 read a table made once: the palette's own lookup costs two integer divisions (type mod
// size), measured at 7 % of a splat pass on fcc 1 M at 256^2.
class DensityColors {
 public:
  DensityColors(const InstanceRecipe &recipe, bool colored) : recipe_(recipe), colored_(colored) {
    by_table_ = colored && recipe.coloring.by == ColorBy::kType && !recipe.occlusion &&
                recipe.particles->has_type();
    if (by_table_)
      for (int t = 0; t < kTypes; ++t) {
        const Rgb8 c = recipe.coloring.palette.at(t);
        table_[size_t(t)] = c;
        packed_[size_t(t)] = uint32_t(c[0]) | uint32_t(c[1]) << 8 | uint32_t(c[2]) << 16;
      }
  }
  // operator() of particles [from, from + n) into out[0, n): the table case as one loop over
  // the type array's own integers (no per-particle type dispatch), with the same colours.
  void fill(int64_t from, int n, Rgb8 *out) const {
    if (by_table_) {
      const StridedArray &a = recipe_.particles->type_array();
      if (a.type() == DataType::kInt32) return fill_table<int32_t>(a, from, n, out);
      if (a.type() == DataType::kInt64) return fill_table<int64_t>(a, from, n, out);
    }
    for (int k = 0; k < n; ++k) out[k] = (*this)(from + k);
  }
  bool colored() const { return colored_; }
  Rgb8 operator()(int64_t i) const {
    if (!colored_) return {0, 0, 0};
    if (by_table_) {
      const int64_t t = recipe_.particles->type(i);
      if (t >= 0 && t < kTypes) return table_[size_t(t)];
    }
    return recipe_.color(i);
  }

 private:
  static constexpr int kTypes = 64;
  template <typename T>
  void fill_table(const StridedArray &a, int64_t from, int n, Rgb8 *out) const {
    const auto *base = static_cast<const unsigned char *>(a.data());
    const int64_t stride = a.stride_bytes();
    const auto one = [&](int k) {
      const int64_t t = int64_t(load_unaligned<T>(base + (from + k) * stride));
      out[k] = t >= 0 && t < kTypes ? table_[size_t(t)] : recipe_.color(from + k);
    };
#if LANTERN_COLORS_X86
    if constexpr (std::is_same_v<T, int32_t>)
      if (stride == 4 && cpu_has_avx512_bw()) {
        const auto *types = reinterpret_cast<const int32_t *>(base + from * 4);
        // Sixteen at a time; a block holding a type beyond the table, and the tail, one by one.
        for (int k = 0; k < n;) {
          k = fill_table16(types, packed_.data(), k, n, out);
          for (const int stop = std::min(n, k + 16); k < stop; ++k) one(k);
        }
        return;
      }
#endif
    for (int k = 0; k < n; ++k) one(k);
  }
  const InstanceRecipe &recipe_;
  bool colored_ = false, by_table_ = false;
  std::array<Rgb8, kTypes> table_{};
  alignas(64) std::array<uint32_t, kTypes> packed_{};  // table_ as words: r | g << 8 | b << 16
};

// Prefetches what gathering particle i reads: its position (and type, when colours come from
// it). Issued for the next brick while this one is splatted, so the loads of a scattered
// published order are in cache by the time they are gathered.
class GatherPrefetch {
 public:
  GatherPrefetch(const ParticleArrays &p, bool type) {
    const int arrays = p.interleaved() ? 1 : 3;
    for (int a = 0; a < arrays; ++a) add(p.position_array(a));
    if (type && p.has_type()) add(p.type_array());
  }
  void operator()(uint32_t i) const {
    // Into L2: a brick's worth would not fit L1 beside the image's working set.
    for (int a = 0; a < count_; ++a) __builtin_prefetch(base_[a] + int64_t(i) * stride_[a], 0, 2);
  }

 private:
  void add(const StridedArray &array) {
    base_[count_] = static_cast<const char *>(array.data());
    stride_[count_++] = array.stride_bytes();
  }
  const char *base_[4] = {};
  int64_t stride_[4] = {};
  int count_ = 0;
};

}  // namespace

void select_density_bricks(const BrickSet &bricks, const Camera &camera, const CullSettings &cull,
                           const RadiusRule &radius, BrickSelection *out,
                           BrickCutCounts *cut_counts) {
  CullSettings all = cull;
  all.frustum = false;
  all.occlusion = OcclusionMode::kNone;
  select_bricks(bricks, camera, all, radius, out, cut_counts);
}

int density_channels(ColorBy by) {
  return by == ColorBy::kSolid ? 1 : 4;
}

namespace {

// Particles deposited between two passes over the bins: bounds the bins' memory (10 bytes a
// particle) whatever the particle count.
constexpr int64_t kBinBatch = int64_t(1) << 20;

// Without level of detail every kept particle of every brick is deposited with weight 1, and
// the sum does not depend on the order: the particles are read in published order (a sequential
// stream instead of the bricks' scattered gathers), with the cut test per particle (what a
// brick wholly cut away drops), binned by image tile and deposited tile by tile. Interleaved
// double positions are projected where they lie (DensitySplatter::project_xyz), the next batch
// prefetched during this one's pixel work: on fcc 10 M at 1024^2 copying them into arrays first
// was about a sixth of the pass.
void render_every_particle(const ParticleArrays &particles, const std::vector<CutPlane> &cut_planes,
                           const BrickSelection &sel, const DensityColors &colors,
                           DensitySplatter *splatter, CullStats *st) {
  const ViewGeometry &g = sel.g;
  const CutPlanes cuts(cut_planes);
  const bool per_particle = sel.radius.per_particle && particles.has_radius();
  constexpr int kChunk = 1024;
  double xs[kChunk], ys[kChunk], zs[kChunk], rs[kChunk];
  Rgb8 color[kChunk];
  DensityFootprints footprints;
  DensityBins bins;
  bins.reset(g.width, g.height);
  int64_t cut = 0, drawn = 0, missed = 0, binned = 0;
  visit_kept(particles, [&](const auto &kept) {
    constexpr bool kKeepAll = std::is_same_v<std::decay_t<decltype(kept)>, KeepAll>;
    const bool simple = kKeepAll && cuts.empty();
    visit_positions(particles, [&](const auto &pos) {
      visit_radii(particles, sel.radius.per_particle, sel.radius.radius, [&](const auto &radius) {
        const int64_t count = particles.count();
        for (int64_t i0 = 0; i0 < count; i0 += kChunk) {
          const int m = int(std::min<int64_t>(kChunk, count - i0));
          int n = 0;
          bool projected = false;
          // Interleaved double positions (the common layout): projected straight from them, and
          // the next batch's bytes asked for between this one's pixel work.
          if constexpr (std::is_same_v<std::decay_t<decltype(pos)>, InterleavedPositions<double>>)
            if (simple && !per_particle && pos.stride == 24 &&
                splatter->project_xyz(pos.base + i0 * 24, sel.radius.radius, m, &footprints)) {
              colors.fill(i0, m, color);
              n = m, projected = true;
              const int64_t ahead = std::min<int64_t>(kChunk, count - i0 - m);
              DensityStreamAhead next;
              next.at[0] = reinterpret_cast<const char *>(pos.base + (i0 + m) * 24);
              next.bytes[0] = size_t(ahead) * 24;
              if (colors.colored() && particles.has_type()) {
                const StridedArray &t = particles.type_array();
                next.at[1] = static_cast<const char *>(t.data()) + (i0 + m) * t.stride_bytes();
                next.bytes[1] = size_t(ahead * t.stride_bytes());
              }
              splatter->stream_ahead(next);
            }
          // Every particle kept and no cutting plane: copied without a branch, and kept as they
          // are when all are finite (else the loop below drops the others).
          bool gathered = projected;
          if (simple && !projected) {
            bool finite = true;
            for (int k = 0; k < m; ++k) {
              const glm::dvec3 x = pos.get(i0 + k);
              xs[k] = x.x, ys[k] = x.y, zs[k] = x.z;
              finite &= (x.x - x.x == 0.0) & (x.y - x.y == 0.0) & (x.z - x.z == 0.0);
            }
            if (finite) {
              if (per_particle)
                for (int k = 0; k < m; ++k) rs[k] = radius.get(i0 + k);
              colors.fill(i0, m, color);
              n = m, gathered = true;
            }
          }
          for (int64_t i = i0; !gathered && i < i0 + m; ++i) {
            if (!kept.get(i)) continue;
            const glm::dvec3 x = pos.get(i);
            if (!(std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z))) continue;
            if (!cuts.empty() && cuts.drops(x)) {
              ++cut;
              continue;
            }
            xs[n] = x.x, ys[n] = x.y, zs[n] = x.z;
            if (per_particle) rs[n] = radius.get(i);
            color[n++] = colors(i);
          }
          if (!projected)
            splatter->project_all(xs, ys, zs, per_particle ? rs : nullptr, sel.radius.radius, 1.0,
                                  n, &footprints);
          const int64_t touched = splatter->bin_all(footprints, color, n, &bins);
          drawn += touched;
          missed += n - touched;
          binned += n;
          if (binned >= kBinBatch) {
            splatter->deposit_bins(bins);
            bins.reset(g.width, g.height);
            binned = 0;
          }
        }
      });
    });
  });
  splatter->deposit_bins(bins);
  // Bricks wholly cut away were counted by the selection; each of their particles is cut here.
  st->cut_culled = cut;
  st->drawn += drawn;
  st->frustum_culled += missed;
}

}  // namespace

CullStats render_density(const ParticleArrays &particles, const BrickSet &bricks,
                         const CullSettings &cull, const BrickSelection &sel,
                         const InstanceRecipe &recipe, DensityImage *image,
                         int64_t *pixels_written) {
  CullStats st = sel.stats;
  const ViewGeometry &g = sel.g;
  // Splatted into rows padded apart (DensityImage::padded_pitch), then made dense again.
  image->reset_padded(g.width, g.height, density_channels(recipe.coloring.by));
  DensitySplatter splatter(g, image);
  const CutPlanes cuts(cull.cuts);
  const DensityColors colors(recipe, image->channels > 1);
  const bool everything =
      std::all_of(sel.visible.begin(), sel.visible.end(), [&](const VisibleBrick &v) {
        return v.keep == bricks.bricks[v.brick].count && v.radius_scale == 1.0f;
      });
  if (everything) {
    render_every_particle(particles, cull.cuts, sel, colors, &splatter, &st);
    image->compact();
    if (pixels_written) *pixels_written = splatter.pixels_written();
    return st;
  }
  // A brick's kept particles are gathered first (positions, radii, colours: loads that do not
  // depend on each other, so the cache misses of a scattered published order overlap; measured
  // 3x faster than splatting as it reads on a randomly ordered cloud), one array per coordinate;
  // then the whole brick is projected in one vectorised loop (project_all), then deposited.
  const bool per_particle = sel.radius.per_particle && particles.has_radius();
  std::vector<double> xs, ys, zs, rs;
  std::vector<Rgb8> color;
  std::vector<uint8_t> cut;
  DensityFootprints footprints;
  const GatherPrefetch prefetch(particles, image->channels > 1);
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, sel.radius.per_particle, sel.radius.radius, [&](const auto &radius) {
      for (size_t at = 0; at < sel.visible.size(); ++at) {
        const VisibleBrick &v = sel.visible[at];
        const Brick &b = bricks.bricks[v.brick];
        if (at + 1 < sel.visible.size()) {
          const VisibleBrick &next = sel.visible[at + 1];
          const uint32_t *ahead = bricks.order.data() + bricks.bricks[next.brick].first;
          for (uint32_t k = 0; k < next.keep; ++k) prefetch(ahead[k]);
        }
        st.lod_dropped += int64_t(b.count) - int64_t(v.keep);
        // Each kept particle stands for count / keep of them (the brightness rule of Rizzi et al.
        // 2015).
        const double weight = double(b.count) / double(v.keep);
        const uint32_t *index = bricks.order.data() + b.first;
        const int n = int(v.keep);
        xs.resize(size_t(n)), ys.resize(size_t(n)), zs.resize(size_t(n)), color.resize(size_t(n));
        if (per_particle) rs.resize(size_t(n));
        for (int k = 0; k < n; ++k) {
          const uint32_t i = index[k];
          const glm::dvec3 x = pos.get(i);
          xs[size_t(k)] = x.x, ys[size_t(k)] = x.y, zs[size_t(k)] = x.z;
          if (per_particle) rs[size_t(k)] = radius.get(i);
          color[size_t(k)] = colors(i);
        }
        cut.assign(size_t(n), 0);
        if (v.cut_each)
          for (int k = 0; k < n; ++k)
            cut[size_t(k)] = cuts.drops({xs[size_t(k)], ys[size_t(k)], zs[size_t(k)]});
        splatter.project_all(xs.data(), ys.data(), zs.data(), per_particle ? rs.data() : nullptr,
                             sel.radius.radius, double(v.radius_scale), n, &footprints);
        int64_t candidates = n;
        if (v.cut_each)
          for (int k = 0; k < n; ++k) candidates -= cut[size_t(k)];
        const int64_t drawn = splatter.deposit_all(footprints, cut.data(), color.data(), n, weight);
        st.cut_culled += n - candidates;
        st.drawn += drawn;
        st.frustum_culled += candidates - drawn;
      }
    });
  });
  image->compact();
  if (pixels_written) *pixels_written = splatter.pixels_written();
  return st;
}

}  // namespace lantern
