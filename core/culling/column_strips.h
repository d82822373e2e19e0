// Occlusion traversal in column strips: the image split into strips of columns, one per thread,
// each walked over every visible brick and particle in the same front-to-back order, each with
// its own depth pyramid (the hzb culler's, or the CPU sphere raster's).
//
// Why that is exact, and the same decisions as one thread: a strip skips a brick or particle when
// ITS part of the rectangle is covered, and keeps (and, for the raster, draws into its strip)
// what its part shows. A particle shown in one strip but covered in another is not drawn there
// - which changes nothing, since covered means every pixel of that part already holds something
// nearer than the particle's nearest point. So each strip's pyramid equals the one-thread pyramid
// on those columns, and "shown in some strip" equals "not covered over the whole rectangle". The
// strips' particle lists are merged (union) afterwards.
//
// Ownership: a StripState owns its output lists. Thread-safety: run_strips runs strip 0 on the
// calling thread and the others on helpers, joined before it returns; nothing else is shared.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/common/page_allocator.h"
#include "core/common/rank_threads.h"
#include "core/culling/cull_pass.h"

namespace lantern {

// The narrowest strip: below twice this width an image is walked as one strip.
inline constexpr int kMinStripWidth = 128;
// Image width from which two threads split it into strips.
inline constexpr int kTwoStripsFrom = 2 * kMinStripWidth;

// What one strip kept, and the per-particle drops of each visible brick it gathered.
struct StripState {
  int x0 = 0, x1 = -1;  // the strip's columns
  CandidateBuffers buffers;
  DrawList out;
  std::vector<int64_t> frustum_pp, cut_pp;  // per visible brick; -1: not gathered (covered)
};

// Splits columns [0, width) into one strip per thread, none narrower than kMinStripWidth, at
// multiples of 64 columns (so no tile of the pyramid levels up to 64 px straddles a boundary),
// into (*s)[0, count). Returns the count (1 for narrow images or one thread).
inline int split_strips(int width, int threads, std::vector<StripState> *s) {
  const int count = std::max(1, std::min(threads, width / kMinStripWidth));
  if (int(s->size()) < count) s->resize(size_t(count));
  for (int k = 0; k < count; ++k) {
    StripState &st = (*s)[size_t(k)];
    st.x0 = k == 0 ? 0 : int(int64_t(width) * k / count) / 64 * 64;
    st.x1 = k + 1 == count ? width - 1 : int(int64_t(width) * (k + 1) / count) / 64 * 64 - 1;
  }
  return count;
}

// Walks the visible bricks for one strip. covered(rect, depth) says the strip's part of rect holds
// something nearer than depth everywhere (the strip's depth pyramid); bricks are tested with it
// when `bricks_first`, and a brick's depth buckets (bucket_hidden) when `buckets_first` - only
// where visit() would find a covered particle hidden whatever else it is; visit(candidate,
// state) judges and keeps one particle.
// between(depth) is called between two bricks with the nearest depth of the one just walked, for
// a caller that draws other primitives (bonds) front to back along with the bricks, so that they
// occlude and are occluded too. ahead(index) is called for each particle a brick gathered, before
// any of them is visited: for a caller that asks the cache for what visit() will read of it.
// bucket(first, count) is called before the `count` candidates from `first` on are visited one by
// one: for a caller that works them out together (independent computations overlap).
template <typename Positions, typename Radii, typename Covered, typename Visit, typename Between,
          typename Ahead, typename Bucket>
void walk_strip(const CullPass<Positions, Radii> &pass, const VisibleBricks &visible,
                bool bricks_first, bool buckets_first, const Covered &covered, Visit &&visit,
                StripState *s, Between &&between, Ahead &&ahead, Bucket &&bucket) {
  s->out.clear();
  s->frustum_pp.assign(visible.size(), -1);
  s->cut_pp.assign(visible.size(), 0);
  for (size_t k = 0; k < visible.size(); ++k) {
    if (k > 0) between(visible[k - 1].near_depth);
    const VisibleBrick &v = visible[k];
    PixelRect rect = v.rect;
    rect.x0 = std::max(rect.x0, s->x0), rect.x1 = std::min(rect.x1, s->x1);
    if (rect.empty()) continue;
    if (bricks_first && covered(rect, v.near_depth)) continue;
    CullStats brick;
    s->buffers.gathered.clear();
    // lod.select: nearest asks what the strip's pyramid already hides (conservative rectangle).
    const auto hidden = [&](const glm::dvec3 &c, double r) {
      if (!bricks_first) return false;
      PixelRect pr = pass.g.sphere_rect(c, r);
      pr.x0 = std::max(pr.x0, s->x0), pr.x1 = std::min(pr.x1, s->x1);
      return pr.empty() || covered(pr, -c.z - r - pass.g.eps);
    };
    gather(pass, v, true, hidden, &s->buffers, &brick, &s->out);
    s->frustum_pp[k] = brick.frustum_culled;
    s->cut_pp[k] = brick.cut_culled;
    for (const Candidate &c : s->buffers.gathered) ahead(c.index);
    order_front_to_back(&s->buffers);
    const std::vector<DepthBucket> &buckets = s->buffers.buckets;
    std::vector<PixelRect> &rects = s->buffers.bucket_rects;
    if (buckets_first) {
      if (rects.size() < buckets.size()) rects.resize(buckets.size());
      for (size_t b = 0; b < buckets.size(); ++b)
        if (buckets[b].end - buckets[b].begin >= 2) rects[b] = bucket_rect(pass.g, buckets[b]);
    }
    for (size_t b = 0; b < buckets.size(); ++b) {
      const DepthBucket &d = buckets[b];
      if (buckets_first && bucket_hidden(pass.g, d, rects[b], s->x0, s->x1, covered)) continue;
      bucket(s->buffers.sorted.data() + d.begin, d.end - d.begin);
      for (uint32_t k = d.begin; k < d.end; ++k) visit(s->buffers.sorted[k], s);
    }
  }
}

template <typename Positions, typename Radii, typename Covered, typename Visit>
void walk_strip(const CullPass<Positions, Radii> &pass, const VisibleBricks &visible,
                bool bricks_first, bool buckets_first, const Covered &covered, Visit &&visit,
                StripState *s) {
  walk_strip(
      pass, visible, bricks_first, buckets_first, covered, std::forward<Visit>(visit), s,
      [](double) {}, [](uint32_t) {}, [](const Candidate *, uint32_t) {});
}

// Runs strip(k) for every k < count: strip 0 on the calling thread, the others on helpers.
template <typename Strip>
void run_strips(int count, Strip &&strip) {
  run_in_parts(count, count, [&strip](int k, int64_t, int64_t) { strip(k); });
}

// The union of what strips (*s)[0, count) kept, in published order (draw_list.h), and the counts:
// a brick gathered by any strip had the same per-particle frustum and cut drops. The strips' lists
// are consumed (released: they keep no memory between frames). `scratch` is the radix sort's
// buffer.
void merge_strips(const VisibleBricks &visible, const BrickSet &bricks, std::vector<StripState> *s,
                  int count, PageVector<uint64_t> *scratch, CullStats *stats, DrawList *out);

}  // namespace lantern
