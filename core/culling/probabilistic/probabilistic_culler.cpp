#include "core/culling/probabilistic/probabilistic_culler.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/culling/probabilistic/counter_random.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

constexpr float kNoHit = std::numeric_limits<float>::infinity();

glm::dvec3 corner(const glm::dvec3 &lo, const glm::dvec3 &hi, int k) {
  return {k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z};
}

// Screen rectangle, nearest and farthest view depth of a box of centres with spheres of radius r.
void box_view(const ViewGeometry &g, const glm::dvec3 &lo, const glm::dvec3 &hi, double r,
              PixelRect *rect, double *near, double *far) {
  glm::dvec3 grown[8];
  double n = std::numeric_limits<double>::infinity(), f = -n;
  for (int k = 0; k < 8; ++k) {
    const double d = ViewGeometry::depth_of(g.to_view(corner(lo, hi, k)));
    n = std::min(n, d), f = std::max(f, d);
    grown[k] = g.to_view(corner(lo - r, hi + r, k));
  }
  *near = n - r - g.eps, *far = f + r;
  *rect = g.box_rect(grown);
}

// The per-frame state of one run, so the helpers below need not pass a dozen arguments.
template <typename Positions, typename Radii>
struct Run {
  const Positions &pos;
  const Radii &radius;
  const BrickSet &bricks;
  const BrickSelection &sel;
  const MeshletSet &ml;
  const ProbabilisticConfig &cfg;
  const uint64_t step;
  std::vector<uint8_t> &cls;

  double meshlet_radius(const VisibleBrick &v, const Meshlet &m) const {
    return (sel.radius.per_particle ? m.max_radius : sel.radius.radius) * v.radius_scale;
  }
  template <typename F>
  void for_kept(const VisibleBrick &v, const Meshlet &m, F &&f) const {
    const Brick &b = bricks.bricks[v.brick];
    for (uint32_t j = 0; j < m.count; ++j) {
      const uint32_t slot = ml.slots[m.first + j];
      if (slot < v.keep) f(bricks.order[b.first + slot]);
    }
  }
};

}  // namespace

void ProbabilisticCuller::jitter_rays(const ViewGeometry &g, uint64_t kx, uint64_t ky) {
  const size_t n = size_t(g.width) * g.height;
  ray_x_.resize(n), ray_y_.resize(n), ray_l2_.resize(n);
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      const size_t p = size_t(y) * g.width + x;
      // The jitter is a float and (x + jitter) / width is evaluated in float, as it always was:
      // the rays, and so the samples, stay bit-identical to those of earlier releases.
      const float jx = float(unit_interval(splitmix64(kx ^ p)));
      const float jy = float(unit_interval(splitmix64(ky ^ p)));
      const double ndx = (x + jx) / g.width * 2.0 - 1.0;
      const double ndy = 1.0 - (y + jy) / g.height * 2.0;
      if (g.orthographic) {
        ray_x_[p] = (ndx - g.tx) / g.sx, ray_y_[p] = (ndy - g.ty) / g.sy;
      } else {
        const double rx = ndx / g.sx, ry = ndy / g.sy;
        ray_x_[p] = rx, ray_y_[p] = ry, ray_l2_[p] = rx * rx + ry * ry + 1.0;
      }
    }
}

void ProbabilisticCuller::sample_sphere(const ViewGeometry &g, const glm::dvec3 &c, double r) {
  const double d = -c.z;
  if (!(r > 0.0) || d - r <= g.near_plane) return;  // reaching the near plane: no occluder
  // Jittered positions lie within half a pixel diagonal (0.71 px) of their pixel's centre.
  const PixelRect rect = g.sphere_rect_tight(c, r, 0.75);
  // The sample's depth is the ray's hit depth at the jittered position, as a rasterised
  // sub-pixel sample of the paper's.
  const double r_px = r * g.pixels_per_unit(d);
  const double area_px = M_PI * r_px * r_px;
  double cx, cy;  // the projected centre in pixels
  if (g.orthographic) {
    cx = ((g.sx * c.x + g.tx) + 1.0) * 0.5 * g.width,
    cy = (1.0 - (g.sy * c.y + g.ty)) * 0.5 * g.height;
  } else {
    cx = (g.sx * c.x / d + 1.0) * 0.5 * g.width, cy = (1.0 - g.sy * c.y / d) * 0.5 * g.height;
  }
  const double r2 = r * r, c2 = glm::dot(c, c);
  for (int y = rect.y0; y <= rect.y1; ++y)
    for (int x = rect.x0; x <= rect.x1; ++x) {
      const size_t p = size_t(y) * g.width + x;
      double depth;
      if (g.orthographic) {
        const double dx = c.x - ray_x_[p], dy = c.y - ray_y_[p];
        const double q2 = dx * dx + dy * dy;
        if (q2 >= r2) continue;
        depth = d - std::sqrt(r2 - q2);
      } else {
        // Ray t (rx, ry, -1), whose view depth is t: a hit when its distance to c is below r.
        const double rx = ray_x_[p], ry = ray_y_[p], l2 = ray_l2_[p];
        const double cd = c.x * rx + c.y * ry - c.z;
        const double disc = r2 * l2 - (c2 * l2 - cd * cd);
        if (disc <= 0.0) continue;
        depth = (cd - std::sqrt(disc)) / l2;
      }
      // Only a nearer hit replaces the pixel's sample, so the size (a square root) is worked out
      // for those alone.
      if (!(depth < pass_depth_[p])) continue;
      // Ibrahim et al.'s alpha, the expected share of the pixel the particle covers: its projected
      // area for sub-pixel spheres; for larger ones the disc clipped to the pixel, approximated
      // by the distance of the pixel centre to the outline across the pixel's diagonal.
      const double ex = x + 0.5 - cx, ey = y + 0.5 - cy;
      const double dist = std::sqrt(ex * ex + ey * ey);
      const float alpha = float(
          std::min({1.0, area_px, std::max(0.0, (r_px + M_SQRT1_2 - dist) / (2.0 * M_SQRT1_2))}));
      if (!(alpha > 0.0f)) continue;
      pass_depth_[p] = float(depth), pass_alpha_[p] = alpha;
    }
}

ProbabilisticStats ProbabilisticCuller::run(const ParticleArrays &particles, const BrickSet &bricks,
                                            const ProbabilisticConfig &cfg,
                                            const BrickSelection &sel, int64_t step) {
  if (meshlets_.generation == 0 || meshlets_.generation != bricks.generation)
    meshlets_.build(particles, bricks);
  const ViewGeometry &g = sel.g;
  const int W = g.width, H = g.height;
  classes_.assign(meshlets_.meshlets.size(), uint8_t(OcclusionClass::kPotentiallyVisible));
  pixels_.assign(size_t(W) * H, ConfidencePixel::empty());
  pass_depth_.resize(size_t(W) * H), pass_alpha_.resize(size_t(W) * H);
  rects_.assign(meshlets_.meshlets.size(), PixelRect{});
  nears_.assign(meshlets_.meshlets.size(), 0.0);
  ProbabilisticStats st;

  visit_positions(particles, [&](const auto &pos) {
    visit_radii(particles, sel.radius.per_particle, sel.radius.radius, [&](const auto &radius) {
      const Run<std::decay_t<decltype(pos)>, std::decay_t<decltype(radius)>> run{
          pos, radius, bricks, sel, meshlets_, cfg, uint64_t(step), classes_};
      // Meshlet footprints, the depth range, and the density volume of the kept particles.
      double z0 = std::numeric_limits<double>::infinity(), z1 = -z0;
      glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
      int64_t kept = 0;
      for (const VisibleBrick &v : sel.visible) {
        const Brick &b = bricks.bricks[v.brick];
        lo = glm::min(lo, b.lo), hi = glm::max(hi, b.hi);
        kept += v.keep;
        for (uint32_t m = meshlets_.first_of_brick[v.brick];
             m < meshlets_.first_of_brick[v.brick + 1]; ++m) {
          double far;
          box_view(g, meshlets_.meshlets[m].lo, meshlets_.meshlets[m].hi,
                   run.meshlet_radius(v, meshlets_.meshlets[m]), &rects_[m], &nears_[m], &far);
          z0 = std::min(z0, nears_[m]), z1 = std::max(z1, far);
        }
      }
      if (sel.visible.empty()) return;
      z0 = std::max(z0, g.near_plane);
      double typical_radius = sel.radius.radius;  // the scene's, or the first brick's largest
      if (sel.radius.per_particle) typical_radius = bricks.bricks[sel.visible[0].brick].max_radius;
      volume_.reset(lo, hi, kept);
      // The occluder spheres, gathered once in meshlet order: a pass then reads each sampled
      // meshlet's spheres from one contiguous run instead of chasing slot, brick order and
      // position through memory for every particle (those cache misses were most of a pass).
      spheres_.clear(), spheres_.reserve(size_t(kept));
      sphere_span_.resize(meshlets_.meshlets.size());
      for (const VisibleBrick &v : sel.visible)
        for (uint32_t m = meshlets_.first_of_brick[v.brick];
             m < meshlets_.first_of_brick[v.brick + 1]; ++m) {
          sphere_span_[m].first = uint32_t(spheres_.size());
          run.for_kept(v, meshlets_.meshlets[m], [&](uint32_t i) {
            const glm::dvec3 p = pos.get(i);
            volume_.add(p);
            spheres_.push_back({g.to_view(p), radius.get(i) * v.radius_scale});
          });
          sphere_span_[m].second = uint32_t(spheres_.size());
        }

      // Every meshlet starts in P.
      open_p_.resize(sel.visible.size()), open_l_.assign(sel.visible.size(), 0);
      for (size_t vi = 0; vi < sel.visible.size(); ++vi)
        open_p_[vi] = meshlets_.first_of_brick[sel.visible[vi].brick + 1] -
                      meshlets_.first_of_brick[sel.visible[vi].brick];
      bool dirty = true;
      int quiet = 0;
      std::vector<uint32_t> pool;
      for (int it = 0; it < kMaxIterations; ++it) {
        if (dirty) volume_.cast(g, z0, std::max(z1, z0 * 1.0001), typical_radius), dirty = false;
        for (int s = 0; s < kPassesPerIteration; ++s) {
          const uint64_t sample = uint64_t(st.samples);
          // One jittered sample position per pixel, keyed by (step, pixel, sample, iteration).
          jitter_rays(g, counter_hash(run.step, 0, sample, it, RandomStream::kJitterX),
                      counter_hash(run.step, 0, sample, it, RandomStream::kJitterY));
          std::fill(pass_depth_.begin(), pass_depth_.end(), kNoHit);
          for (size_t vi = 0; vi < sel.visible.size(); ++vi) {
            const VisibleBrick &v = sel.visible[vi];
            // Occluder selection (§5.2): `budget` of the node's P meshlets, then of its L ones,
            // in a keyed random order. Most nodes soon hold neither (all M or O): their counts
            // skip them without a look at their meshlets.
            const uint32_t want_count[2] = {open_p_[vi], open_l_[vi]};
            if (want_count[0] + want_count[1] == 0) continue;
            const uint32_t m0 = meshlets_.first_of_brick[v.brick],
                           m1 = meshlets_.first_of_brick[v.brick + 1];
            uint64_t h = counter_hash(run.step, v.brick, sample, it, RandomStream::kShuffle);
            int chosen = 0;
            for (const OcclusionClass want :
                 {OcclusionClass::kPotentiallyVisible, OcclusionClass::kLow}) {
              if (chosen >= cfg.budget || want_count[int(want)] == 0) continue;  // nothing drawn
              pool.clear();
              for (uint32_t m = m0; m < m1; ++m)
                if (classes_[m] == uint8_t(want)) pool.push_back(m);
              for (size_t k = 0; k < pool.size() && chosen < cfg.budget; ++k, ++chosen) {
                h = splitmix64(h);
                std::swap(pool[k], pool[k + h % (pool.size() - k)]);
                for (uint32_t j = sphere_span_[pool[k]].first; j < sphere_span_[pool[k]].second;
                     ++j)
                  sample_sphere(g, spheres_[j].c, spheres_[j].r);
              }
            }
          }
          for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
              const size_t p = size_t(y) * W + x;
              if (pass_depth_[p] == kNoHit) continue;
              // The acceptance draw matters only for a sample nearer than the accumulated depth
              // (update_pixel reads it there alone): the hash is skipped for the rest.
              const double u = pass_depth_[p] < pixels_[p].d
                                   ? unit_interval(counter_hash(run.step, p, sample, it,
                                                                RandomStream::kAcceptance))
                                   : 1.0;
              update_pixel(&pixels_[p], pass_depth_[p], pass_alpha_[p], volume_.ray(x, y), u,
                           cfg.random_acceptance);
            }
          ++st.samples;
        }
        ++st.iterations;
        pyramid_.build(pixels_, W, H);
        int64_t changed = 0, active = 0;
        const auto promote = [&](uint32_t m, OcclusionClass c) {
          if (uint8_t(c) <= classes_[m]) return;
          classes_[m] = uint8_t(c), ++changed;
          dirty = dirty || c == OcclusionClass::kOccluded;
        };
        for (size_t vi = 0; vi < sel.visible.size(); ++vi) {
          const VisibleBrick &v = sel.visible[vi];
          const uint32_t m0 = meshlets_.first_of_brick[v.brick],
                         m1 = meshlets_.first_of_brick[v.brick + 1];
          const ConfidencePyramid::Verdict node = pyramid_.test(v.rect, v.near_depth);
          const bool node_occluded = node.failed && node.confidence > cfg.confidence;
          open_p_[vi] = open_l_[vi] = 0;
          for (uint32_t m = m0; m < m1; ++m) {
            if (classes_[m] == uint8_t(OcclusionClass::kOccluded)) continue;
            ++active;
            OcclusionClass c = OcclusionClass::kOccluded;
            if (!node_occluded) {
              const ConfidencePyramid::Verdict t = pyramid_.test(rects_[m], nears_[m]);
              c = !t.failed                             ? OcclusionClass::kPotentiallyVisible
                  : t.confidence > cfg.confidence       ? OcclusionClass::kOccluded
                  : t.confidence > 0.5 * cfg.confidence ? OcclusionClass::kMedium
                                                        : OcclusionClass::kLow;
            }
            const bool to_occluded = c == OcclusionClass::kOccluded;
            promote(m, c);
            if (to_occluded && classes_[m] == uint8_t(OcclusionClass::kOccluded))
              run.for_kept(v, meshlets_.meshlets[m],
                           [&](uint32_t i) { volume_.remove(pos.get(i)); });
            open_p_[vi] += classes_[m] == uint8_t(OcclusionClass::kPotentiallyVisible);
            open_l_[vi] += classes_[m] == uint8_t(OcclusionClass::kLow);
          }
        }
        // §5.3's "no class changed", with a tolerance of cfg.quiet_share of the meshlets still
        // open: on 10^5 meshlets hundreds creeping from M to O every iteration would otherwise
        // keep it sampling until the cap (exactly "none" below 1 / quiet_share meshlets).
        quiet = double(changed) <= cfg.quiet_share * double(active) ? quiet + 1 : 0;
        if (quiet >= cfg.patience) break;
      }
    });
  });
  std::vector<ViewSphere>().swap(spheres_);  // 32 bytes per particle: not kept between frames
  for (const VisibleBrick &v : sel.visible)
    for (uint32_t m = meshlets_.first_of_brick[v.brick]; m < meshlets_.first_of_brick[v.brick + 1];
         ++m) {
      ++st.meshlets[classes_[m]];
      if (classes_[m] == uint8_t(OcclusionClass::kOccluded)) {
        const Meshlet &ml = meshlets_.meshlets[m];
        for (uint32_t j = 0; j < ml.count; ++j)
          st.particles_culled += meshlets_.slots[ml.first + j] < v.keep;
      }
    }
  return st;
}

}  // namespace lantern
