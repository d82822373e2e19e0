// Occlusion traversal in column strips: the image split into one or two strips of columns, each
// walked by its own thread over every visible brick and particle in the same front-to-back
// order, each with its own depth pyramid (the hzb culler's, or the CPU sphere raster's).
//
// Why that is exact, and the same decisions as one thread: a strip skips a brick or particle when
// ITS part of the rectangle is covered, and keeps (and, for the raster, draws into its strip)
// what its part shows. A particle shown in one strip but covered in the other is not drawn there
// - which changes nothing, since covered means every pixel of that part already holds something
// nearer than the particle's nearest point. So each strip's pyramid equals the one-thread pyramid
// on those columns, and "shown in some strip" equals "not covered over the whole rectangle". The
// strips' particle lists are merged (union) afterwards.
//
// Ownership: a StripState owns its output lists. Thread-safety: run_strips runs the two strips
// on two threads (the caller's and one helper, joined before it returns); nothing else is shared.
#pragma once

#include <algorithm>
#include <cstdint>
#include <thread>
#include <vector>

#include "core/culling/cull_pass.h"

namespace lantern {

// Image width from which the strips run on two threads.
inline constexpr int kTwoStripsFrom = 256;

// What one strip kept, and the per-particle drops of each visible brick it gathered.
struct StripState {
  int x0 = 0, x1 = -1;  // the strip's columns
  CandidateBuffers buffers;
  DrawList out;
  std::vector<int64_t> frustum_pp, cut_pp;  // per visible brick; -1: not gathered (covered)
};

// Splits columns [0, width) into the strips of s[0] and s[1] (s[1] empty below kTwoStripsFrom):
// on a tile boundary of the pyramid levels up to 64 px, so no tile of those straddles it.
inline bool split_strips(int width, StripState s[2]) {
  const bool two = width >= kTwoStripsFrom;
  const int split = two ? (width / 2) / 64 * 64 : width;
  s[0].x0 = 0, s[0].x1 = split - 1;
  s[1].x0 = split, s[1].x1 = width - 1;
  return two;
}

// Walks the visible bricks for one strip. `test` is the strip's depth pyramid: test.covered(rect,
// depth) says the strip's part of rect holds something nearer than depth everywhere (bricks are
// tested only when `bricks_first`); visit(candidate, state) judges and keeps one particle.
template <typename Positions, typename Radii, typename Covered, typename Visit>
void walk_strip(const CullPass<Positions, Radii> &pass, const std::vector<VisibleBrick> &visible,
                bool bricks_first, const Covered &covered, Visit &&visit, StripState *s) {
  s->out.clear();
  s->frustum_pp.assign(visible.size(), -1);
  s->cut_pp.assign(visible.size(), 0);
  for (size_t k = 0; k < visible.size(); ++k) {
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
    order_front_to_back(&s->buffers);
    for (const Candidate &c : s->buffers.sorted) visit(c, s);
  }
}

// Runs strip(0) and, when `two`, strip(1) on a helper thread; a lone strip's partner is left
// empty with nothing gathered.
template <typename Strip>
void run_strips(bool two, const std::vector<VisibleBrick> &visible, Strip &&strip,
                StripState s[2]) {
  if (two) {
    std::thread helper([&] { strip(1); });
    strip(0);
    helper.join();
  } else {
    strip(0);
    s[1].out.clear();
    s[1].frustum_pp.assign(visible.size(), -1);
  }
}

// The union of what either strip kept, in published order (draw_list.h), and the counts: a brick
// gathered by either strip had the same per-particle frustum and cut drops. `scratch` is the radix
// sort's buffer.
void merge_strips(const std::vector<VisibleBrick> &visible, const BrickSet &bricks,
                  const StripState s[2], std::vector<uint64_t> *scratch, CullStats *stats,
                  DrawList *out);

}  // namespace lantern
