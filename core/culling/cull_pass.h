// The per-particle side of culling, shared by the culler's passes (cull_stage.h) and the CPU
// sphere pass (core/render/cpu_sphere_pass.h): one context struct for a frame's pass instead of
// the same seven parameters through every function, the candidates a brick yields, and their
// front-to-back order.
//
// Ownership: a CullPass borrows everything it names for the duration of one pass.
// Thread-safety: read-only; the passes run it from one or two threads, each with its own
// buffers.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include <glm/vec3.hpp>

#include "core/bricks/brick_set.h"
#include "core/common/uninitialized_buffer.h"
#include "core/culling/cull_stats.h"
#include "core/culling/cut_planes.h"
#include "core/culling/draw_list.h"
#include "core/culling/front_selection.h"
#include "core/culling/frustum.h"
#include "core/culling/visible_brick.h"
#include "core/view/view_geometry.h"

namespace lantern {

// One frame's pass over particles read through typed readers (core/particles/typed_access.h).
template <typename Positions, typename Radii>
struct CullPass {
  const Positions &pos;
  const Radii &radius;
  const ViewGeometry &g;
  const Frustum &frustum;
  const CutPlanes &cuts;
  bool point_path;  // lod.point_path: sub-pixel spheres go to the CPU splats
  const BrickSet &bricks;
};

// A particle that survived cuts, frustum and level of detail, in view space.
struct Candidate {
  glm::dvec3 c;  // view-space centre
  double r;      // drawn radius
  uint32_t index;
  float scale;  // level-of-detail radius scale
};
// An array of candidates is also one of x, y, z, r doubles with a stride of five
// (ViewGeometry::sphere_rects_tight reads it so).
static_assert(std::is_standard_layout_v<Candidate> && offsetof(Candidate, c) == 0 &&
                  sizeof(glm::dvec3) == 3 * sizeof(double) &&
                  offsetof(Candidate, r) == 3 * sizeof(double) &&
                  sizeof(Candidate) % sizeof(double) == 0,
              "a Candidate begins with its centre's x, y, z and its radius as doubles");

// A bucket of a brick's candidates (order_front_to_back: a cell of a depth slab): sorted[begin,
// end), and the view-space box holding their spheres, nearest point first.
struct DepthBucket {
  uint32_t begin = 0, end = 0;
  glm::dvec3 lo{0.0}, hi{0.0};  // bounds of c - r and c + r
  double near = 0.0;            // least -c.z - r
};

// Buffers of one thread's pass, reused from brick to brick and frame to frame.
struct CandidateBuffers {
  // Not zero-filled as they grow: gather and order_front_to_back write every candidate first.
  UninitializedBuffer<Candidate> gathered, sorted;
  std::vector<uint8_t> cells;           // order_front_to_back: each gathered candidate's cell
  std::vector<DepthBucket> buckets;     // the non-empty ones, nearest first
  std::vector<PixelRect> bucket_rects;  // walk_strip: each bucket's bucket_rect
  FrontScratch front;                   // lod.select: nearest (front_selection.h)
};

// Spheres whose projected radius is below this many pixels take the CPU point path (when on):
// they cover at most one pixel centre or two.
inline constexpr double kSplatPixels = 0.5;

// True when the sphere is small enough for the point path and wholly beyond the near plane.
inline bool splat_sized(const ViewGeometry &g, const glm::dvec3 &c, double r) {
  return -c.z - r > g.near_plane && r * g.pixels_per_unit(-c.z) < kSplatPixels;
}

// A survivor of occlusion culling: an impostor, or a CPU splat when it is that small.
inline void accept(const ViewGeometry &g, const Candidate &c, bool point_path, DrawList *out) {
  (point_path && splat_sized(g, c.c, c.r) ? out->points : out->spheres)
      .push_back(draw_entry(c.index, c.scale));
}

// The kept particles of brick `v` (the prefix, or its front: front_selection.h) after cuts,
// per-particle frustum and the point path: straight into `out` (keep_candidates false), or into
// b->gathered when occlusion still has to judge them. Counts per-particle cut and frustum drops
// in *counts. hidden(view centre, radius): the caller's depth pyramid proves the sphere hidden
// (only asked under lod.select: nearest).
template <typename Positions, typename Radii, typename Hidden>
void gather(const CullPass<Positions, Radii> &pass, const VisibleBrick &v, bool keep_candidates,
            const Hidden &hidden, CandidateBuffers *b, CullStats *counts, DrawList *out) {
  const Brick &brick = pass.bricks.bricks[v.brick];
  const uint32_t *idx = pass.bricks.order.data() + brick.first;
  float scale = v.radius_scale;
  if (v.nearest && select_front(pass.pos, pass.radius, pass.g, pass.bricks, v, hidden, &b->front)) {
    idx = b->front.kept.data();
    scale = 1.0f;  // they stand for nothing: what they hide is dropped
  }
  const bool straddle = v.containment == Containment::kStraddling;
  const bool point_path = pass.point_path;
  if (!keep_candidates && !straddle && !v.cut_each && !point_path) {
    for (uint32_t k = 0; k < v.keep; ++k) out->spheres.push_back(draw_entry(idx[k], scale));
    return;
  }
  // Positions are read in brick order; where the published order is not spatial (a gas beside
  // a crystal) each read would miss cache and TLB in turn, so the reads ahead are overlapped.
  // The prefetch changes no value read: decisions and images stay as they were.
  constexpr uint32_t kAhead = 16;
  for (uint32_t k = 0; k < std::min(kAhead, v.keep); ++k) pass.pos.prefetch(idx[k]);
  // Candidates are written in place (room for every kept particle, trimmed after the loop): no
  // call per candidate.
  UninitializedBuffer<Candidate> &gathered = b->gathered;
  size_t count = gathered.size();
  if (keep_candidates) gathered.resize(count + v.keep);
  for (uint32_t k = 0; k < v.keep; ++k) {
    const uint32_t i = idx[k];
    if (k + kAhead < v.keep) pass.pos.prefetch(idx[k + kAhead]);
    const glm::dvec3 p = pass.pos.get(i);
    if (v.cut_each && pass.cuts.drops(p)) {
      ++counts->cut_culled;
      continue;
    }
    const double r = pass.radius.get(i) * scale;
    const glm::dvec3 c = pass.g.to_view(p);
    if (straddle && pass.frustum.classify_sphere(c, r) == Containment::kOutside) {
      ++counts->frustum_culled;
      continue;
    }
    if (!keep_candidates) {
      (point_path && splat_sized(pass.g, c, r) ? out->points : out->spheres)
          .push_back(draw_entry(i, scale));
      continue;
    }
    gathered[count++] = {c, r, i, scale};
  }
  if (keep_candidates) gathered.resize(count);
}

// The same without a depth pyramid: nothing is proven hidden.
template <typename Positions, typename Radii>
void gather(const CullPass<Positions, Radii> &pass, const VisibleBrick &v, bool keep_candidates,
            CandidateBuffers *b, CullStats *counts, DrawList *out) {
  gather(
      pass, v, keep_candidates, [](const glm::dvec3 &, double) { return false; }, b, counts, out);
}

// b->gathered -> b->sorted, nearest first by depth slab (inside a brick a bucket sort suffices:
// the order only makes occluders come early, it decides nothing exact), and b->buckets: each
// slab's candidates split further into cells by view x and y, so that a bucket's box is small
// across the view as well as in depth (bucket_hidden then hides the cells behind a surface).
void order_front_to_back(CandidateBuffers *b);

// The rectangle bucket_hidden tests for bucket `d` (before its clamp to the strip): box_rect of
// the box's bounds, the rectangle of its 8 corners bit for bit, in 2 divisions.
inline PixelRect bucket_rect(const ViewGeometry &g, const DepthBucket &d) {
  return g.box_rect(d.lo - g.eps, d.hi + g.eps);
}

// True when the depth test `covered` (a strip's pyramid over columns [x0, x1]) proves every
// sphere of bucket `d` hidden: the rectangle of the bucket's box holds every sphere's rectangle
// (sphere_rect and sphere_rect_tight alike) and its nearest point is nearer than any sphere's,
// so each sphere would have been found covered on its own, at its turn (the pyramid only gets
// nearer). Skipping the bucket then decides exactly what testing each sphere would: in a brick
// at the surface, the layers behind the first cost one test each instead of one per particle.
// A bucket of one sphere is not tested: the sphere's own test decides the same at half the cost
// (a sphere's rectangle against the box's eight projected corners). `r` is the bucket's
// bucket_rect, worked out by the caller: a brick's are worked out together, so that their
// divisions overlap instead of each waiting on the test before.
template <typename Covered>
bool bucket_hidden(const ViewGeometry &g, const DepthBucket &d, PixelRect r, int x0, int x1,
                   const Covered &covered) {
  if (d.end - d.begin < 2) return false;
  r.x0 = std::max(r.x0, x0), r.x1 = std::min(r.x1, x1);
  return r.empty() || covered(r, d.near - g.eps);
}

// The same, working out the rectangle.
template <typename Covered>
bool bucket_hidden(const ViewGeometry &g, const DepthBucket &d, int x0, int x1,
                   const Covered &covered) {
  if (d.end - d.begin < 2) return false;
  return bucket_hidden(g, d, bucket_rect(g, d), x0, x1, covered);
}

}  // namespace lantern
