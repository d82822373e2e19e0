// Culler: the per-particle occlusion traversal over a brick selection (cull_stage.h).
#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/bricks/radix_sort.h"
#include "core/common/page_allocator.h"
#include "core/culling/cull_stage.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

// The reference pixel of the nine-spheres paper: the pixel the projected centre falls in.
bool reference_pixel(const ViewGeometry &g, const glm::dvec3 &c, int *x, int *y) {
  double px, py;
  if (!g.pixel_position(c, &px, &py)) return false;
  const double fx = std::floor(px), fy = std::floor(py);
  if (!(fx >= 0 && fy >= 0 && fx < g.width && fy < g.height)) return false;
  *x = int(fx), *y = int(fy);
  return true;
}

uint32_t float_key(double depth) {
  const float f = float(std::max(depth, 0.0));  // non-negative floats sort like their bits
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}

// Nothing to judge per particle: every particle drawn, in brute force's order.
bool trivial(const CullSettings &cull, const BrickSelection &sel) {
  const CullStats &st = sel.stats;
  return sel.mode == OcclusionMode::kNone && !sel.reduced && !cull.lod.point_path &&
         !st.per_particle_frustum && st.frustum_culled == 0 && st.cut_culled == 0 &&
         std::none_of(sel.visible.begin(), sel.visible.end(),
                      [](const VisibleBrick &v) { return v.cut_each; });
}

}  // namespace

CullStats Culler::run(const ParticleArrays &particles, const BrickSet &bricks, const Camera &camera,
                      const CullSettings &settings, const RadiusRule &radius, DrawList *out) {
  select_bricks(bricks, camera, settings, radius, &selection_);
  return cull(particles, bricks, settings, selection_, out);
}

CullStats Culler::cull(const ParticleArrays &particles, const BrickSet &bricks,
                       const CullSettings &settings, const BrickSelection &sel, DrawList *out,
                       int threads) {
  CullStats st = sel.stats;
  out->clear();
  const OcclusionMode mode = sel.mode;
  if (mode == OcclusionMode::kHzb) hzb_[0].reset(sel.g);
  if (mode == OcclusionMode::kNineSpheres || mode == OcclusionMode::kNineSpheresSorted)
    nine_.reset(sel.g.width, sel.g.height);
  nine_equivalent_ = settings.nine_spheres_radius == NineSpheresRadius::kEquivalent;
  if (nine_equivalent_ &&
      (mode == OcclusionMode::kNineSpheres || mode == OcclusionMode::kNineSpheresSorted))
    st.occlusion += " (equivalent radius)";
  hzb_strips_ = mode == OcclusionMode::kHzb ? 1 : 0;  // process_strips sets its strip count
  if (trivial(settings, sel)) {
    out->everything = true;  // nothing to cull: brute force order, no per-particle pass
    st.drawn = st.candidates;
    return st;
  }
  const Frustum frustum(sel.g);
  const CutPlanes cuts(settings.cuts);
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, sel.radius.per_particle, sel.radius.radius, [&](const auto &radius) {
      const CullPass<std::decay_t<decltype(pos)>, std::decay_t<decltype(radius)>> pass{
          pos, radius, sel.g, frustum, cuts, settings.lod.point_path, bricks};
      if (mode == OcclusionMode::kNineSpheresSorted)
        process_sorted(pass, sel, &st, out);
      else if (mode == OcclusionMode::kHzb && threads > 1 && sel.g.width >= kTwoStripsFrom)
        process_strips(pass, sel, threads, &st, out);
      else
        process(pass, sel, &st, out);
    });
  });
  // Published order, as brute force draws (see draw_list.h).
  radix_sort_words(&out->spheres, &scratch_, 32, 64);
  radix_sort_words(&out->points, &scratch_, 32, 64);
  PageVector<uint64_t>().swap(scratch_);  // per-frame scratch: keep nothing between frames
  st.drawn = int64_t(out->spheres.size());
  st.splatted = int64_t(out->points.size());
  return st;
}

bool Culler::covered(const PixelRect &rect, double z) const {
  if (hzb_strips_ == 0 || rect.empty()) return false;
  for (int k = 0; k < hzb_strips_; ++k) {
    PixelRect part = rect;
    if (hzb_strips_ > 1)
      part.x0 = std::max(part.x0, strips_[k].x0), part.x1 = std::min(part.x1, strips_[k].x1);
    if (!part.empty() && !hzb_[k].covered(part, z)) return false;
  }
  return true;
}

bool Culler::occluded(OcclusionMode mode, const ViewGeometry &g, const Candidate &cand, int strip) {
  if (mode == OcclusionMode::kHzb) {
    PixelRect rect = g.sphere_rect(cand.c, cand.r);
    const StripState &s = strips_[size_t(strip)];
    rect.x0 = std::max(rect.x0, s.x0), rect.x1 = std::min(rect.x1, s.x1);
    if (hzb_[size_t(strip)].covered(rect, -cand.c.z - cand.r - g.eps)) return true;
    hzb_[size_t(strip)].add_occluder(cand.c, cand.r, rect);
    return false;
  }
  int x, y;
  if (!reference_pixel(g, cand.c, &x, &y)) return false;
  const double d = -cand.c.z;
  const double r = nine_equivalent_ ? equivalent_radius(g, d, cand.r) : cand.r;
  return nine_.test_and_record(x, y, float(d), float(r));
}

// One thread, bricks front to back: none (with per-particle work), hzb on narrow images, and
// nine_spheres.
template <typename Positions, typename Radii>
void Culler::process(const CullPass<Positions, Radii> &pass, const BrickSelection &sel,
                     CullStats *st, DrawList *out) {
  const bool occlusion = sel.mode != OcclusionMode::kNone;
  StripState &s = strips_[0];
  s.x0 = 0, s.x1 = sel.g.width - 1;
  for (const VisibleBrick &v : sel.visible) {
    const Brick &b = pass.bricks.bricks[v.brick];
    st->lod_dropped += b.count - v.keep;
    if (sel.mode == OcclusionMode::kHzb && hzb_[0].covered(v.rect, v.near_depth)) {
      ++st->bricks_occluded;
      st->occlusion_culled += v.keep;
      continue;
    }
    s.buffers.gathered.clear();
    const auto hidden = [&](const glm::dvec3 &c, double r) {
      return sel.mode == OcclusionMode::kHzb &&
             hzb_[0].covered(sel.g.sphere_rect(c, r), -c.z - r - sel.g.eps);
    };
    gather(pass, v, occlusion, hidden, &s.buffers, st, out);
    if (!occlusion) continue;
    order_front_to_back(&s.buffers);
    const Hzb &hzb = hzb_[0];
    const auto covered = [&hzb](const PixelRect &r, double z) { return hzb.covered(r, z); };
    for (const DepthBucket &d : s.buffers.buckets) {
      if (sel.mode == OcclusionMode::kHzb && bucket_hidden(sel.g, d, s.x0, s.x1, covered)) {
        st->occlusion_culled += d.end - d.begin;
        continue;
      }
      for (uint32_t k = d.begin; k < d.end; ++k) {
        const Candidate &c = s.buffers.sorted[k];
        if (occluded(sel.mode, sel.g, c, 0))
          ++st->occlusion_culled;
        else
          accept(sel.g, c, pass.point_path, out);
      }
    }
  }
}

// hzb on several threads, one column strip each (column_strips.h).
template <typename Positions, typename Radii>
void Culler::process_strips(const CullPass<Positions, Radii> &pass, const BrickSelection &sel,
                            int threads, CullStats *st, DrawList *out) {
  const ViewGeometry &g = sel.g;
  const int count = split_strips(g.width, threads, &strips_);
  hzb_strips_ = count;
  if (int(hzb_.size()) < count) hzb_.resize(size_t(count));
  for (int k = 1; k < count; ++k) hzb_[size_t(k)].reset(g);
  const bool point_path = pass.point_path;
  const auto strip = [&](int k) {
    const Hzb &hzb = hzb_[size_t(k)];
    const auto covered = [&hzb](const PixelRect &r, double z) { return hzb.covered(r, z); };
    const auto visit = [&](const Candidate &c, StripState *s) {
      PixelRect r = g.sphere_rect(c.c, c.r);
      r.x0 = std::max(r.x0, s->x0), r.x1 = std::min(r.x1, s->x1);
      if (r.empty()) return;
      if (hzb_[size_t(k)].covered(r, -c.c.z - c.r - g.eps)) return;
      hzb_[size_t(k)].add_occluder(c.c, c.r, r);
      accept(g, c, point_path, &s->out);
    };
    walk_strip(pass, sel.visible, true, true, covered, visit, &strips_[size_t(k)]);
  };
  run_strips(count, strip);
  merge_strips(sel.visible, pass.bricks, &strips_, count, &scratch_, st, out);
}

// nine_spheres_sorted: every candidate first (as the paper sorts all particles), then one global
// depth order.
template <typename Positions, typename Radii>
void Culler::process_sorted(const CullPass<Positions, Radii> &pass, const BrickSelection &sel,
                            CullStats *st, DrawList *out) {
  CandidateBuffers &b = strips_[0].buffers;
  PageVector<Candidate> all;
  for (const VisibleBrick &v : sel.visible) {
    st->lod_dropped += pass.bricks.bricks[v.brick].count - v.keep;
    b.gathered.clear();
    gather(pass, v, true, &b, st, out);
    all.insert(all.end(), b.gathered.begin(), b.gathered.end());
  }
  PageVector<uint64_t> keys(all.size());
  for (size_t k = 0; k < all.size(); ++k)
    keys[k] = uint64_t(float_key(-all[k].c.z)) << 32 | uint32_t(k);
  radix_sort_words(&keys, &scratch_, 32, 64);
  for (const uint64_t key : keys) {
    const Candidate &c = all[uint32_t(key)];
    if (occluded(OcclusionMode::kNineSpheresSorted, sel.g, c, 0))
      ++st->occlusion_culled;
    else
      accept(sel.g, c, pass.point_path, out);
  }
}

}  // namespace lantern
