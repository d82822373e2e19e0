#include "core/culling/cull_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "core/bricks/radix_sort.h"
#include "core/particles/typed_access.h"
#include "core/culling/cut_planes.h"
#include "core/culling/frustum.h"
#include "core/culling/level_of_detail.h"
#include "core/culling/occlusion_estimate.h"

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;

// Spheres whose projected radius is below this many pixels take the CPU point path (when on):
// they cover at most one pixel centre or two.
constexpr double kSplatPixels = 0.5;
constexpr int kDepthBuckets = 64;
// Pixels of slack around a sphere's outline for the CPU raster: its float per-pixel test errs by
// about 1e-4 px at most (column offsets of up to thousands of pixels times a float step).
constexpr double kRasterSlack = 0.05;
constexpr int kTwoStripsFrom = 256;  // image width from which hzb runs on two threads  //
                                     // front-to-back order inside a brick: a bucket sort suffices

glm::dvec3 box_corner(const glm::dvec3 &lo, const glm::dvec3 &hi, int k) {
  return {k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z};
}

// A length bounding |x - origin| for every sphere and the eye: the scale of float rounding.
double scene_scale(const BrickSet &set, const Camera &camera, double max_radius) {
  double s = 0.0;
  for (int k = 0; k < 8; ++k)
    s = std::max(s, glm::length(box_corner(set.lo, set.hi, k) - camera.origin));
  return s + max_radius;
}

// Screen rectangle and nearest depth of a brick whose spheres have radius <= r.
void footprint(const ViewGeometry &g, const Brick &b, double r, VisibleBrick *v) {
  glm::dvec3 grown[8];
  double nearest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 8; ++k) {
    nearest = std::min(nearest, ViewGeometry::depth_of(g.to_view(box_corner(b.lo, b.hi, k))));
    grown[k] = g.to_view(box_corner(b.lo - r, b.hi + r, k));
  }
  v->near_depth = nearest - r - g.eps;
  v->rect = g.box_rect(grown);
}

// The reference pixel of seed 000: the pixel the projected centre falls in.
bool reference_pixel(const ViewGeometry &g, const glm::dvec3 &c, int *x, int *y) {
  double xn, yn;
  if (g.orthographic) {
    xn = g.sx * c.x + g.tx, yn = g.sy * c.y + g.ty;
  } else {
    const double d = -c.z;
    if (d <= g.near_plane) return false;
    xn = g.sx * c.x / d, yn = g.sy * c.y / d;
  }
  const double fx = std::floor((xn + 1.0) * 0.5 * g.width),
               fy = std::floor((1.0 - yn) * 0.5 * g.height);
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

}  // namespace

std::string occlusion_mode_name(OcclusionMode mode) {
  switch (mode) {
    case OcclusionMode::kAuto:
      return "auto";
    case OcclusionMode::kNone:
      return "none";
    case OcclusionMode::kNineSpheres:
      return "nine_spheres";
    case OcclusionMode::kNineSpheresSorted:
      return "nine_spheres_sorted";
    case OcclusionMode::kHzb:
      return "hzb";
  }
  return "?";
}

CullStats Culler::run(const ParticleArrays &particles, const BrickSet &bricks, const Camera &camera,
                      const SceneConfig &scene, DrawList *out, const RasterTarget *raster) {
  const auto t0 = Clock::now();
  CullStats st;
  out->clear();
  st.candidates = bricks.particle_count();
  st.bricks = int64_t(bricks.bricks.size());
  const bool per_particle = scene.per_particle_radius && particles.has_radius();
  double max_r = per_particle ? 0.0 : scene.radius;
  if (per_particle)
    for (const Brick &b : bricks.bricks) max_r = std::max(max_r, b.max_radius);
  g_ = ViewGeometry::from_camera(camera, scene_scale(bricks, camera, max_r));
  const Frustum frustum(g_);
  const CutPlanes cuts(scene.cuts);

  // Bricks: frustum and cutting planes.
  visible_.clear();
  for (uint32_t i = 0; i < bricks.bricks.size(); ++i) {
    const Brick &b = bricks.bricks[i];
    const double r = per_particle ? b.max_radius : scene.radius;
    VisibleBrick v;
    v.brick = i;
    v.radius = r;
    v.keep = b.count;
    if (scene.culling.frustum) {
      glm::dvec3 corners[8];
      for (int k = 0; k < 8; ++k) corners[k] = g_.to_view(box_corner(b.lo, b.hi, k));
      v.containment = frustum.classify_box(corners, r);
      if (v.containment == Containment::kOutside) {
        ++st.bricks_outside;
        st.frustum_culled += b.count;
        continue;
      }
    }
    if (!cuts.empty()) {
      const CutPlanes::Side side = cuts.classify_box(b.lo, b.hi);
      if (side == CutPlanes::Side::kDropped) {
        st.cut_culled += b.count;
        continue;
      }
      v.cut_each = side == CutPlanes::Side::kBoth;
    }
    if (v.containment == Containment::kInside) ++st.bricks_inside;
    st.per_particle_frustum |= v.containment == Containment::kStraddling;
    footprint(g_, b, r, &v);
    visible_.push_back(v);
  }

  // Level of detail, then footprints of the bricks whose spheres grew.
  const LodConfig &lod = scene.lod;
  const bool lod_on = lod.budget > 0 || lod.fraction < 1.0 || lod.min_pixels > 0.0;
  bool reduced = false;
  if (lod_on) reduced = apply_level_of_detail(lod, bricks, g_, &visible_);
  for (VisibleBrick &v : visible_)
    if (v.radius_scale != 1.0f)
      footprint(g_, bricks.bricks[v.brick], v.radius * v.radius_scale, &v);

  OcclusionMode mode = scene.culling.occlusion;
  const auto front_to_back = [](const VisibleBrick &a, const VisibleBrick &b) {
    return a.near_depth < b.near_depth;
  };
  if (mode == OcclusionMode::kAuto) {
    std::stable_sort(visible_.begin(), visible_.end(), front_to_back);
    const OcclusionChoice choice = choose_occlusion(visible_, g_);
    mode = choice.mode;
    st.occlusion = occlusion_mode_name(mode) + " (auto: " + choice.reason +
                   (st.per_particle_frustum ? "" : "; all in view, no per-particle frustum") + ")";
  } else {
    st.occlusion = occlusion_mode_name(mode);
    if (mode != OcclusionMode::kNone)
      std::stable_sort(visible_.begin(), visible_.end(), front_to_back);
  }
  // The CPU raster, when the caller asks for it: fused with hzb, or alone under `none`.
  raster_ = nullptr;
  occlusion_ = mode == OcclusionMode::kHzb;
  if (raster && raster->frame && raster->owner &&
      (mode == OcclusionMode::kHzb || mode == OcclusionMode::kNone))
    raster_ = raster;
  st.renderer = raster_ ? "cpu" : "opengl";
  if (mode == OcclusionMode::kHzb && !raster_) ws_[0].hzb.reset(g_);
  if (mode == OcclusionMode::kNineSpheres || mode == OcclusionMode::kNineSpheresSorted)
    nine_.reset(g_.width, g_.height);

  const bool trivial = !raster_ && mode == OcclusionMode::kNone && !reduced && !lod.point_path &&
                       !st.per_particle_frustum && st.frustum_culled == 0 && st.cut_culled == 0 &&
                       std::none_of(visible_.begin(), visible_.end(),
                                    [](const VisibleBrick &v) { return v.cut_each; });
  if (trivial) {
    out->everything = true;  // nothing to cull: brute force order, no per-particle pass
    st.drawn = st.candidates;
  } else {
    visit_positions(particles, [&](const auto &pos) {
      visit_radii(particles, per_particle, scene.radius, [&](const auto &radius) {
        if (mode == OcclusionMode::kNineSpheresSorted)
          process_sorted(pos, radius, frustum, cuts, scene, bricks, &st, out);
        else if (raster_ || (mode == OcclusionMode::kHzb && g_.width >= kTwoStripsFrom))
          process_strips(pos, radius, frustum, cuts, scene, bricks, &st, out);
        else
          process(pos, radius, frustum, cuts, scene, bricks, mode, &st, out);
      });
    });
    // Published order, as brute force draws (see draw_list.h).
    radix_sort_words(&out->spheres, &scratch_, 32, 64);
    radix_sort_words(&out->points, &scratch_, 32, 64);
    std::vector<uint64_t>().swap(scratch_);  // per-frame scratch: keep nothing between frames
    st.drawn = int64_t(out->spheres.size());
    st.splatted = int64_t(out->points.size());
  }
  out->rasterized = raster_ != nullptr;
  raster_ = nullptr;
  st.ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  return st;
}

template <typename Positions, typename Radii>
void Culler::gather(const Positions &pos, const Radii &radius, const Frustum &frustum,
                    const CutPlanes &cuts, const SceneConfig &scene, const BrickSet &bricks,
                    const VisibleBrick &v, bool keep_candidates, Workspace *w, CullStats *st,
                    DrawList *out) const {
  const Brick &b = bricks.bricks[v.brick];
  const uint32_t *idx = bricks.order.data() + b.first;
  const bool straddle = v.containment == Containment::kStraddling;
  const bool point_path = scene.lod.point_path;
  const float scale = v.radius_scale;
  if (!keep_candidates && !straddle && !v.cut_each && !point_path) {
    for (uint32_t k = 0; k < v.keep; ++k) out->spheres.push_back(draw_entry(idx[k], scale));
    return;
  }
  for (uint32_t k = 0; k < v.keep; ++k) {
    const uint32_t i = idx[k];
    const glm::dvec3 p = pos.get(i);
    if (v.cut_each && cuts.drops(p)) {
      ++st->cut_culled;
      continue;
    }
    const double r = radius.get(i) * scale;
    const glm::dvec3 c = g_.to_view(p);
    if (straddle && frustum.classify_sphere(c, r) == Containment::kOutside) {
      ++st->frustum_culled;
      continue;
    }
    if (!keep_candidates) {
      (point_path && splat_sized(c, r) ? out->points : out->spheres)
          .push_back(draw_entry(i, scale));
      continue;
    }
    w->buffer.push_back({c, r, i, scale});
  }
}

void Culler::order_front_to_back(Workspace *w) {
  const std::vector<Candidate> &in = w->buffer;
  std::vector<Candidate> &out = w->sorted;
  out.resize(in.size());
  if (in.size() < 2) {
    out = in;
    return;
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Candidate &c : in) lo = std::min(lo, -c.c.z), hi = std::max(hi, -c.c.z);
  const double scale = hi > lo ? (kDepthBuckets - 1) / (hi - lo) : 0.0;
  std::vector<uint32_t> &counts = w->bucket_counts;
  counts.assign(kDepthBuckets + 1, 0);
  const auto bucket = [&](const Candidate &c) { return size_t((-c.c.z - lo) * scale); };
  for (const Candidate &c : in) ++counts[bucket(c) + 1];
  for (size_t k = 1; k < counts.size(); ++k) counts[k] += counts[k - 1];
  for (const Candidate &c : in) out[counts[bucket(c)]++] = c;
}

bool Culler::splat_sized(const glm::dvec3 &c, double r) const {
  return -c.z - r > g_.near_plane && r * g_.pixels_per_unit(-c.z) < kSplatPixels;
}

// A survivor of occlusion culling: an impostor, or a CPU splat when it is that small.
void Culler::accept(const Candidate &c, bool point_path, DrawList *out) const {
  (point_path && splat_sized(c.c, c.r) ? out->points : out->spheres)
      .push_back(draw_entry(c.index, c.scale));
}

bool Culler::occluded(OcclusionMode mode, const Candidate &cand, Workspace *w) {
  if (mode == OcclusionMode::kHzb) {
    PixelRect rect = g_.sphere_rect(cand.c, cand.r);
    rect.x0 = std::max(rect.x0, w->x0), rect.x1 = std::min(rect.x1, w->x1);
    if (w->hzb.covered(rect, -cand.c.z - cand.r - g_.eps)) return true;
    w->hzb.add_occluder(cand.c, cand.r, rect);
    return false;
  }
  int x, y;
  if (!reference_pixel(g_, cand.c, &x, &y)) return false;
  return nine_.test_and_record(x, y, float(-cand.c.z), float(cand.r));
}

template <typename Positions, typename Radii>
void Culler::process(const Positions &pos, const Radii &radius, const Frustum &frustum,
                     const CutPlanes &cuts, const SceneConfig &scene, const BrickSet &bricks,
                     OcclusionMode mode, CullStats *st, DrawList *out) {
  const bool occlusion = mode != OcclusionMode::kNone;
  Workspace &w = ws_[0];
  w.x0 = 0, w.x1 = g_.width - 1;
  for (const VisibleBrick &v : visible_) {
    const Brick &b = bricks.bricks[v.brick];
    st->lod_dropped += b.count - v.keep;
    if (mode == OcclusionMode::kHzb && w.hzb.covered(v.rect, v.near_depth)) {
      ++st->bricks_occluded;
      st->occlusion_culled += v.keep;
      continue;
    }
    w.buffer.clear();
    gather(pos, radius, frustum, cuts, scene, bricks, v, occlusion, &w, st, out);
    if (!occlusion) continue;
    order_front_to_back(&w);
    for (const Candidate &c : w.sorted) {
      if (occluded(mode, c, &w))
        ++st->occlusion_culled;
      else
        accept(c, scene.lod.point_path, out);
    }
  }
}

// hzb on two threads, each owning a strip of columns with its own pyramid, both walking all
// bricks and particles in the same order. Exact, and the same decisions as one thread: a strip
// skips a brick or particle when ITS part of the rectangle is covered, and draws (and rasterises
// into its strip) what its part shows. A particle shown in one strip but covered in the other
// is not rasterised there - which changes nothing, since covered means every pixel of that part
// already holds something nearer than the particle's nearest point. So each strip's pyramid
// equals the one-thread pyramid on those columns, and "shown in some strip" equals "not covered
// over the whole rectangle". The particle lists are merged (union) afterwards.
template <typename Positions, typename Radii>
void Culler::run_strip(const Positions &pos, const Radii &radius, const Frustum &frustum,
                       const CutPlanes &cuts, const SceneConfig &scene, const BrickSet &bricks,
                       Workspace *w) {
  w->out.clear();
  w->frustum_pp.assign(visible_.size(), -1);
  w->cut_pp.assign(visible_.size(), 0);
  for (size_t k = 0; k < visible_.size(); ++k) {
    const VisibleBrick &v = visible_[k];
    PixelRect rect = v.rect;
    rect.x0 = std::max(rect.x0, w->x0), rect.x1 = std::min(rect.x1, w->x1);
    if (rect.empty()) continue;
    if (occlusion_ &&
        (raster_ ? w->raster.covered(rect, v.near_depth) : w->hzb.covered(rect, v.near_depth)))
      continue;
    CullStats brick;
    w->buffer.clear();
    gather(pos, radius, frustum, cuts, scene, bricks, v, true, w, &brick, &w->out);
    w->frustum_pp[k] = brick.frustum_culled;
    w->cut_pp[k] = brick.cut_culled;
    order_front_to_back(w);
    for (const Candidate &c : w->sorted) {
      const double nearest = -c.c.z - c.r - g_.eps;
      if (raster_) {
        if (scene.lod.point_path && splat_sized(c.c, c.r)) {
          w->out.points.push_back(draw_entry(c.index, c.scale));  // splatted after the raster
          continue;
        }
        // The CPU raster tests and casts exactly the pixels its per-pixel test can accept (up to
        // kRasterSlack), not sphere_rect's extra pixel that OpenGL's float rasterisation needs.
        PixelRect r = g_.sphere_rect_tight(c.c, c.r, kRasterSlack);
        if (r.empty()) {  // covers no pixel centre: drawn, as OpenGL would, with nothing to cast
          w->out.spheres.push_back(draw_entry(c.index, c.scale));
          continue;
        }
        r.x0 = std::max(r.x0, w->x0), r.x1 = std::min(r.x1, w->x1);
        if (r.empty() || (occlusion_ && w->raster.covered(r, nearest))) continue;
        uint8_t rgb[3];
        raster_->colour(c.index, rgb);
        w->raster.draw(c.c, c.r, rgb, c.index, r);
        w->out.spheres.push_back(draw_entry(c.index, c.scale));
        continue;
      }
      PixelRect r = g_.sphere_rect(c.c, c.r);
      r.x0 = std::max(r.x0, w->x0), r.x1 = std::min(r.x1, w->x1);
      if (r.empty()) continue;
      if (w->hzb.covered(r, nearest)) continue;
      w->hzb.add_occluder(c.c, c.r, r);
      accept(c, scene.lod.point_path, &w->out);
    }
  }
}

template <typename Positions, typename Radii>
void Culler::process_strips(const Positions &pos, const Radii &radius, const Frustum &frustum,
                            const CutPlanes &cuts, const SceneConfig &scene, const BrickSet &bricks,
                            CullStats *st, DrawList *out) {
  const bool two = g_.width >= kTwoStripsFrom;
  // On a tile boundary of the pyramid levels up to 64 px, so no tile of those straddles it.
  const int split = two ? (g_.width / 2) / 64 * 64 : g_.width;
  ws_[0].x0 = 0, ws_[0].x1 = split - 1;
  ws_[1].x0 = split, ws_[1].x1 = g_.width - 1;
  if (raster_) {
    CpuSphereRaster::clear_target(g_, raster_->background, raster_->frame, raster_->owner);
    for (Workspace &w : ws_) w.raster.begin_strip(g_, raster_->frame, raster_->owner, w.x0, w.x1);
  } else {
    ws_[1].hzb.reset(g_);
  }
  if (two) {
    std::thread helper([&] { run_strip(pos, radius, frustum, cuts, scene, bricks, &ws_[1]); });
    run_strip(pos, radius, frustum, cuts, scene, bricks, &ws_[0]);
    helper.join();
  } else {
    run_strip(pos, radius, frustum, cuts, scene, bricks, &ws_[0]);
    ws_[1].out.clear();
    ws_[1].frustum_pp.assign(visible_.size(), -1);
  }
  // Union of what either strip shows (a particle both show appears twice: same entry).
  const auto merge = [this](const std::vector<uint64_t> &a, const std::vector<uint64_t> &b,
                            std::vector<uint64_t> *merged) {
    *merged = a;
    merged->insert(merged->end(), b.begin(), b.end());
    radix_sort_words(merged, &scratch_, 32, 64);
    merged->erase(std::unique(merged->begin(), merged->end()), merged->end());
  };
  merge(ws_[0].out.spheres, ws_[1].out.spheres, &out->spheres);
  merge(ws_[0].out.points, ws_[1].out.points, &out->points);
  // Counts: a brick gathered by either strip had the same per-particle frustum and cut drops.
  int64_t judged = 0;
  for (size_t k = 0; k < visible_.size(); ++k) {
    const VisibleBrick &v = visible_[k];
    st->lod_dropped += bricks.bricks[v.brick].count - v.keep;
    const int s = ws_[0].frustum_pp[k] >= 0 ? 0 : ws_[1].frustum_pp[k] >= 0 ? 1 : -1;
    if (s < 0) {
      ++st->bricks_occluded;
      st->occlusion_culled += v.keep;
      continue;
    }
    st->frustum_culled += ws_[s].frustum_pp[k];
    st->cut_culled += ws_[s].cut_pp[k];
    judged += v.keep - ws_[s].frustum_pp[k] - ws_[s].cut_pp[k];
  }
  st->occlusion_culled += judged - int64_t(out->spheres.size() + out->points.size());
}

template <typename Positions, typename Radii>
void Culler::process_sorted(const Positions &pos, const Radii &radius, const Frustum &frustum,
                            const CutPlanes &cuts, const SceneConfig &scene, const BrickSet &bricks,
                            CullStats *st, DrawList *out) {
  // Every candidate first (as the paper sorts all particles), then one global depth order.
  std::vector<Candidate> all;
  for (const VisibleBrick &v : visible_) {
    st->lod_dropped += bricks.bricks[v.brick].count - v.keep;
    ws_[0].buffer.clear();
    gather(pos, radius, frustum, cuts, scene, bricks, v, true, &ws_[0], st, out);
    all.insert(all.end(), ws_[0].buffer.begin(), ws_[0].buffer.end());
  }
  std::vector<uint64_t> keys(all.size());
  for (size_t k = 0; k < all.size(); ++k)
    keys[k] = uint64_t(float_key(-all[k].c.z)) << 32 | uint32_t(k);
  radix_sort_words(&keys, &scratch_, 32, 64);
  for (const uint64_t key : keys) {
    const Candidate &c = all[uint32_t(key)];
    if (occluded(OcclusionMode::kNineSpheresSorted, c, &ws_[0]))
      ++st->occlusion_culled;
    else
      accept(c, scene.lod.point_path, out);
  }
}

}  // namespace lantern
