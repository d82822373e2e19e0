#include "core/render/cpu_sphere_pass.h"

#include <algorithm>
#include <cstring>

#include "core/bricks/radix_sort.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

// Pixels of slack around a sphere's outline for the CPU raster: its float per-pixel test errs by
// about 1e-4 px at most (column offsets of up to thousands of pixels times a float step).
constexpr double kRasterSlack = 0.05;

}  // namespace

void CpuSpherePass::begin_bonds(const BondDrawing &bonds, int count) {
  if (int(bond_drops_.size()) < count) bond_drops_.resize(size_t(count));
  if (int(bond_marks_.size()) < count) bond_marks_.resize(size_t(count));
  for (int k = 0; k < count; ++k) {
    if (count > 1) bond_marks_[size_t(k)].assign(bonds.recipe->halves->half_count(), 0);
    begin_bond_drops(*bonds.selection, &bond_drops_[size_t(k)]);
  }
  bond_drawn_ = 0, bond_strips_ = count;
}

template <typename Positions>
void CpuSpherePass::draw_bonds(int k, const Positions &pos, const ViewGeometry &g,
                               const Frustum &frustum, const CutPlanes &cuts, bool occlusion,
                               const BondDrawing &bonds, size_t from, size_t to) {
  CpuSphereRaster &raster = rasters_[size_t(k)];
  const StripState &strip = strips_[size_t(k)];
  // One strip draws each half at most once (visit_bond_brick visits it once): a count will do.
  uint8_t *marks = bond_strips_ > 1 ? bond_marks_[size_t(k)].data() : nullptr;
  const BondRecipe &recipe = *bonds.recipe;
  const BrickBonds &halves = *recipe.halves;
  const double radius = bonds.selection->radius;
  // A bond is hidden in this strip when its part of the strip is covered (or empty); the other
  // strips judge the rest (column_strips.h).
  struct StripHidden {
    const CpuSphereRaster &raster;
    const StripState &strip;
    bool occlusion;
    bool operator()(const PixelRect &r, double z) const {
      PixelRect in_strip = r;
      in_strip.x0 = std::max(in_strip.x0, strip.x0);
      in_strip.x1 = std::min(in_strip.x1, strip.x1);
      return in_strip.empty() || (occlusion && raster.covered(in_strip, z));
    }
    void warm(const PixelRect &r) const {
      if (occlusion) raster.prefetch_covered(r);
    }
  };
  const StripHidden hidden{raster, strip, occlusion};
  // The halves of one atom come one after another (brick_bonds.h); colored by atom (or plainly),
  // each takes its atom's color and opacity, so they are looked up once per atom's run. Colored
  // by type, a half's color is its bond's: looked up for each.
  const bool per_atom = recipe.by != BondColorBy::kType;
  uint32_t last_atom = UINT32_MAX;
  Rgb8 color{};
  uint8_t alpha = 255;
  const auto visit = [&](const HalfBondView &v) {
    const HalfBond &h = halves.halves[v.index];
    if (!per_atom || h.atom != last_atom) {
      color = recipe.color(h), alpha = recipe.alpha(h);
      last_atom = h.atom;
    }
    raster.draw_bond(v.a, v.b, radius, color.data(), v.rect, alpha);
    if (marks)
      marks[v.index] = 1;
    else
      ++bond_drawn_;
  };
  for (size_t b = from; b < to; ++b)
    visit_bond_brick(b, halves, *bonds.selection, pos, recipe.box, g, frustum, cuts, hidden, visit,
                     &bond_drops_[size_t(k)]);
}

BondCounts CpuSpherePass::count_bonds(const BondDrawing &bonds, int count) {
  // A half-bond is drawn when some strip drew its part of it. One strip counts as it draws; more
  // or their marks (0 or 1) into the first strip's, then sum them - loops the compiler vectorises.
  int64_t drawn = bond_drawn_;
  if (count > 1) {
    const size_t n = bonds.recipe->halves->half_count();
    uint8_t *const any = bond_marks_[0].data();
    for (int k = 1; k < count; ++k) {
      const uint8_t *const marks = bond_marks_[size_t(k)].data();
      for (size_t i = 0; i < n; ++i) any[i] |= marks[i];
    }
    drawn = 0;
    for (size_t i = 0; i < n; ++i) drawn += any[i];
  }
  for (std::vector<uint8_t> &m : bond_marks_) std::vector<uint8_t>().swap(m);  // per-frame scratch
  std::vector<const BondDrops *> passes(static_cast<size_t>(count));
  for (int k = 0; k < count; ++k) passes[size_t(k)] = &bond_drops_[size_t(k)];
  return bond_counts(*bonds.recipe->halves, *bonds.selection, passes.data(), count, drawn);
}

void CpuSpherePass::begin_strips(int count, const ViewGeometry &g, const Lighting *lighting,
                                 const uint8_t background[4], Frame *frame) {
  CpuSphereRaster::clear_target(g, background, frame);
  frame_ = frame;
  std::memcpy(background_, background, sizeof background_);
  strips_begun_ = count;
  if (int(rasters_.size()) < count) rasters_.resize(size_t(count));
  for (int k = 0; k < count; ++k) {
    CpuSphereRaster &raster = rasters_[size_t(k)];
    raster.begin_strip(g, frame, strips_[size_t(k)].x0, strips_[size_t(k)].x1);
    if (lighting) raster.set_lighting(*lighting);
  }
}

void CpuSpherePass::end_strips() {
  // What the strips drew, for compositing's scan (Frame::drawn_within): the rest of the frame is
  // begin_strips' clear.
  PixelRect drawn;
  for (int k = 0; k < strips_begun_; ++k) drawn.unite(rasters_[size_t(k)].touched());
  if (frame_ != nullptr) {
    DrawnWithin within;
    if (!drawn.empty())
      within.x0 = drawn.x0, within.y0 = drawn.y0, within.x1 = drawn.x1 + 1,
      within.y1 = drawn.y1 + 1;
    std::memcpy(within.background, background_, sizeof within.background);
    frame_->drawn_within = within;
  }
  frame_ = nullptr;
  strips_begun_ = 0;
  for (CpuSphereRaster &raster : rasters_) raster.end_strip();
}

CullStats CpuSpherePass::run(const ParticleArrays &particles, const BrickSet &bricks,
                             const CullSettings &cull, const Lighting &lighting,
                             const BrickSelection &sel, const InstanceRecipe &recipe,
                             const uint8_t background[4], Frame *frame, DrawList *out, int64_t step,
                             int threads, const BondDrawing *bonds) {
  if (sel.mode == OcclusionMode::kProbabilistic) {
    CullStats st = run_probabilistic(particles, bricks, cull, sel, recipe, background, frame, out,
                                     step, threads);
    if (!bonds) {
      end_strips();
      return st;
    }
    // The probabilistic culler judges particles only; bonds are culled exactly, against the
    // depth the raster drew (the strips run_probabilistic split, with their rasters).
    const int count = split_strips(sel.g.width, threads, &strips_);
    begin_bonds(*bonds, count);
    const Frustum frustum(sel.g);
    const CutPlanes cuts(cull.cuts);
    const size_t bricks_of_bonds = bonds->selection->visible.size();
    visit_positions(particles, [&](const auto &pos) {
      run_strips(count, [&](int k) {
        draw_bonds(k, pos, sel.g, frustum, cuts, true, *bonds, 0, bricks_of_bonds);
      });
    });
    st.bonds = count_bonds(*bonds, count);
    end_strips();
    return st;
  }
  CullStats st = sel.stats;
  out->clear();
  const ViewGeometry &g = sel.g;
  const bool occlusion = sel.mode == OcclusionMode::kHzb;
  const bool point_path = cull.lod.point_path;
  const int count = split_strips(g.width, threads, &strips_);
  begin_strips(count, g, &lighting, background, frame);
  if (rects_.size() < size_t(count)) rects_.resize(size_t(count));
  if (bonds) begin_bonds(*bonds, count);

  const Frustum frustum(g);
  const CutPlanes cuts(cull.cuts);
  const InstanceRecipe::Prefetcher colour_ahead = recipe.prefetcher();
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, sel.radius.per_particle, sel.radius.radius, [&](const auto &radius) {
      const CullPass<std::decay_t<decltype(pos)>, std::decay_t<decltype(radius)>> pass{
          pos, radius, g, frustum, cuts, point_path, bricks};
      const auto strip = [&](int k) {
        CpuSphereRaster &raster = rasters_[size_t(k)];
        const auto covered = [&raster](const PixelRect &r, double z) {
          return raster.covered(r, z);
        };
        // The bucket's rectangles, worked out together before its candidates are visited: each
        // is a chain of a square root and divisions, which one at a time between the depth
        // tests would wait out in turn (and two share a vector: sphere_rects_tight).
        const Candidate *bucket_first = nullptr;
        std::vector<PixelRect> &rects = rects_[size_t(k)];
        const auto bucket = [&](const Candidate *first, uint32_t n) {
          bucket_first = first;
          if (rects.size() < n) rects.resize(n);
          g.sphere_rects_tight(reinterpret_cast<const double *>(first),
                               sizeof(Candidate) / sizeof(double), int(n), kRasterSlack,
                               rects.data());
        };
        const auto visit = [&](const Candidate &c, StripState *s) {
          if (point_path && splat_sized(g, c.c, c.r)) {
            s->out.points.push_back(draw_entry(c.index, c.scale));  // splatted after the raster
            return;
          }
          // The raster tests and casts exactly the pixels its per-pixel test can accept (up to
          // kRasterSlack), not sphere_rect's extra pixel that OpenGL's float rasterisation needs.
          PixelRect r = rects[size_t(&c - bucket_first)];
          if (r.empty()) {  // covers no pixel centre: drawn, as OpenGL would, with nothing to cast
            s->out.spheres.push_back(draw_entry(c.index, c.scale));
            return;
          }
          r.x0 = std::max(r.x0, s->x0), r.x1 = std::min(r.x1, s->x1);
          if (r.empty() || (occlusion && raster.covered(r, -c.c.z - c.r - g.eps))) return;
          const Rgb8 color = recipe.color(c.index);
          raster.draw(c.c, c.r, color.data(), r, recipe.alpha(c.index));
          s->out.spheres.push_back(draw_entry(c.index, c.scale));
        };
        // Bond bricks are drawn front to back with the particles' bricks (each after the last
        // particle brick that is no farther, by draw_depth: right after its own particles), so
        // that bonds hide the particles and bonds behind them as particles do and an atom hides
        // its own halves' hidden parts; the image does not depend on the order
        // (cpu_sphere_raster.h).
        const size_t bricks_of_bonds = bonds ? bonds->selection->visible.size() : 0;
        size_t next_bonds = 0;
        const auto bonds_between = [&](double depth) {
          size_t end = next_bonds;
          while (end < bricks_of_bonds && bonds->selection->visible[end].draw_depth <= depth) ++end;
          if (end == next_bonds) return;
          draw_bonds(k, pos, g, frustum, cuts, occlusion, *bonds, next_bonds, end);
          next_bonds = end;
        };
        // Splats skip the depth test (visit): a hidden bucket may still hold one to splat.
        // The colour inputs of every gathered particle are asked for once the brick is gathered
        // (exact: only a hint to the cache): its bucket tests and ordering then cover the
        // misses, which the host's own step between frames has made likely.
        walk_strip(pass, sel.visible, occlusion, occlusion && !point_path, covered, visit,
                   &strips_[size_t(k)], bonds_between, colour_ahead, bucket);
        if (next_bonds < bricks_of_bonds)
          draw_bonds(k, pos, g, frustum, cuts, occlusion, *bonds, next_bonds, bricks_of_bonds);
      };
      run_strips(count, strip);
    });
  });
  // The merged lists are already in published order (draw_list.h).
  merge_strips(sel.visible, bricks, &strips_, count, &scratch_, &st, out);
  PageVector<uint64_t>().swap(scratch_);  // per-frame scratch: keep nothing between frames
  st.drawn = int64_t(out->spheres.size());
  st.splatted = int64_t(out->points.size());
  if (bonds) st.bonds = count_bonds(*bonds, count);
  end_strips();
  return st;
}

CullStats CpuSpherePass::run_probabilistic(const ParticleArrays &particles, const BrickSet &bricks,
                                           const CullSettings &cull, const BrickSelection &sel,
                                           const InstanceRecipe &recipe,
                                           const uint8_t background[4], Frame *frame, DrawList *out,
                                           int64_t step, int threads) {
  CullStats st = sel.stats;
  out->clear();
  st.probabilistic = probabilistic_.run(particles, bricks, cull.probabilistic, sel, step);
  st.occlusion_culled = st.probabilistic.particles_culled;
  const ViewGeometry &g = sel.g;
  const bool point_path = cull.lod.point_path;
  const int count = split_strips(g.width, threads, &strips_);
  // The lighting the rasters last had (as before).
  begin_strips(count, g, nullptr, background, frame);
  const MeshletSet &ml = probabilistic_.meshlets();
  const Frustum frustum(g);
  const CutPlanes cuts(cull.cuts);
  for (const VisibleBrick &v : sel.visible) st.lod_dropped += bricks.bricks[v.brick].count - v.keep;
  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, sel.radius.per_particle, sel.radius.radius, [&](const auto &radius) {
      // Both strips walk the same particles; strip 0 alone records them and their counts.
      const auto strip = [&](int k) {
        StripState &s = strips_[size_t(k)];
        s.out.clear();
        CullStats counts;
        for (const VisibleBrick &v : sel.visible) {
          const Brick &b = bricks.bricks[v.brick];
          const bool straddle = v.containment == Containment::kStraddling;
          for (uint32_t m = ml.first_of_brick[v.brick]; m < ml.first_of_brick[v.brick + 1]; ++m) {
            if (probabilistic_.class_of(m) == OcclusionClass::kOccluded) continue;
            const Meshlet &mesh = ml.meshlets[m];
            for (uint32_t j = 0; j < mesh.count; ++j) {
              const uint32_t slot = ml.slots[mesh.first + j];
              if (slot >= v.keep) continue;
              const uint32_t i = bricks.order[b.first + slot];
              const glm::dvec3 p = pos.get(i);
              if (v.cut_each && cuts.drops(p)) {
                ++counts.cut_culled;
                continue;
              }
              const double r = radius.get(i) * v.radius_scale;
              const glm::dvec3 c = g.to_view(p);
              if (straddle && frustum.classify_sphere(c, r) == Containment::kOutside) {
                ++counts.frustum_culled;
                continue;
              }
              if (point_path && splat_sized(g, c, r)) {
                if (k == 0) s.out.points.push_back(draw_entry(i, v.radius_scale));
                continue;
              }
              PixelRect rect = g.sphere_rect_tight(c, r, kRasterSlack);
              if (k == 0) s.out.spheres.push_back(draw_entry(i, v.radius_scale));
              rect.x0 = std::max(rect.x0, s.x0), rect.x1 = std::min(rect.x1, s.x1);
              if (rect.empty()) continue;
              const Rgb8 color = recipe.color(i);
              rasters_[size_t(k)].draw(c, r, color.data(), rect);
            }
          }
        }
        if (k == 0) st.cut_culled += counts.cut_culled, st.frustum_culled += counts.frustum_culled;
      };
      run_strips(count, strip);
    });
  });
  // Published order (draw_list.h).
  out->spheres = std::move(strips_[0].out.spheres);
  out->points = std::move(strips_[0].out.points);
  radix_sort_words(&out->spheres, &scratch_, 32, 64);
  radix_sort_words(&out->points, &scratch_, 32, 64);
  PageVector<uint64_t>().swap(scratch_);
  st.drawn = int64_t(out->spheres.size());
  st.splatted = int64_t(out->points.size());
  return st;
}

}  // namespace lantern
