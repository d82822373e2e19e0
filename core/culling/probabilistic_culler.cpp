#include "core/culling/probabilistic_culler.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/culling/counter_random.h"
#include "core/particles/typed_access.h"

namespace lantern {
namespace {

constexpr float kNoHit = std::numeric_limits<float>::infinity();
constexpr double kQuietShare = 0.01;

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
      const double ndx = (x + jitter_x_[p]) / g.width * 2.0 - 1.0;
      const double ndy = 1.0 - (y + jitter_y_[p]) / g.height * 2.0;
      double depth;
      if (g.orthographic) {
        const double dx = c.x - (ndx - g.tx) / g.sx, dy = c.y - (ndy - g.ty) / g.sy;
        const double q2 = dx * dx + dy * dy;
        if (q2 >= r2) continue;
        depth = d - std::sqrt(r2 - q2);
      } else {
        // Ray t (rx, ry, -1), whose view depth is t: a hit when its distance to c is below r.
        const double rx = ndx / g.sx, ry = ndy / g.sy;
        const double l2 = rx * rx + ry * ry + 1.0, cd = c.x * rx + c.y * ry - c.z;
        const double disc = r2 * l2 - (c2 * l2 - cd * cd);
        if (disc <= 0.0) continue;
        depth = (cd - std::sqrt(disc)) / l2;
      }
      // Seed 004's alpha, the expected share of the pixel the particle covers: its projected
      // area for sub-pixel spheres; for larger ones the disc clipped to the pixel, approximated
      // by the distance of the pixel centre to the outline across the pixel's diagonal.
      const double ex = x + 0.5 - cx, ey = y + 0.5 - cy;
      const double dist = std::sqrt(ex * ex + ey * ey);
      const float alpha = float(
          std::min({1.0, area_px, std::max(0.0, (r_px + M_SQRT1_2 - dist) / (2.0 * M_SQRT1_2))}));
      if (!(alpha > 0.0f)) continue;
      if (depth < pass_depth_[p]) pass_depth_[p] = float(depth), pass_alpha_[p] = alpha;
    }
}

ProbabilisticStats ProbabilisticCuller::run(const ParticleArrays &particles, const BrickSet &bricks,
                                            const SceneConfig &scene, const BrickSelection &sel,
                                            int64_t step) {
  if (meshlets_.generation == 0 || meshlets_.generation != bricks.generation)
    meshlets_.build(particles, bricks);
  const ViewGeometry &g = sel.g;
  const int W = g.width, H = g.height;
  classes_.assign(meshlets_.meshlets.size(), uint8_t(OcclusionClass::kPotentiallyVisible));
  pixels_.assign(size_t(W) * H, ConfidencePixel::empty());
  pass_depth_.resize(size_t(W) * H), pass_alpha_.resize(size_t(W) * H);
  jitter_x_.resize(size_t(W) * H), jitter_y_.resize(size_t(W) * H);
  rects_.assign(meshlets_.meshlets.size(), PixelRect{});
  nears_.assign(meshlets_.meshlets.size(), 0.0);
  ProbabilisticStats st;
  const ProbabilisticConfig &cfg = scene.culling.probabilistic;

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
      for (const VisibleBrick &v : sel.visible)
        for (uint32_t m = meshlets_.first_of_brick[v.brick];
             m < meshlets_.first_of_brick[v.brick + 1]; ++m)
          run.for_kept(v, meshlets_.meshlets[m], [&](uint32_t i) { volume_.add(pos.get(i)); });

      bool dirty = true;
      int quiet = 0;
      std::vector<uint32_t> pool;
      for (int it = 0; it < kMaxIterations; ++it) {
        if (dirty) volume_.cast(g, z0, std::max(z1, z0 * 1.0001), typical_radius), dirty = false;
        for (int s = 0; s < kPassesPerIteration; ++s) {
          const uint64_t sample = uint64_t(st.samples);
          // One jittered sample position per pixel, keyed by (step, pixel, sample, iteration).
          const uint64_t kx = counter_hash(run.step, 0, sample, it, RandomStream::kJitterX);
          const uint64_t ky = counter_hash(run.step, 0, sample, it, RandomStream::kJitterY);
          for (size_t p = 0; p < jitter_x_.size(); ++p) {
            jitter_x_[p] = float(unit_interval(splitmix64(kx ^ p)));
            jitter_y_[p] = float(unit_interval(splitmix64(ky ^ p)));
          }
          std::fill(pass_depth_.begin(), pass_depth_.end(), kNoHit);
          for (const VisibleBrick &v : sel.visible) {
            // Occluder selection (§5.2): `budget` of the node's P meshlets, then of its L ones,
            // in a keyed random order.
            const uint32_t m0 = meshlets_.first_of_brick[v.brick],
                           m1 = meshlets_.first_of_brick[v.brick + 1];
            uint64_t h = counter_hash(run.step, v.brick, sample, it, RandomStream::kShuffle);
            int chosen = 0;
            for (const OcclusionClass want :
                 {OcclusionClass::kPotentiallyVisible, OcclusionClass::kLow}) {
              pool.clear();
              for (uint32_t m = m0; m < m1; ++m)
                if (classes_[m] == uint8_t(want)) pool.push_back(m);
              for (size_t k = 0; k < pool.size() && chosen < cfg.budget; ++k, ++chosen) {
                h = splitmix64(h);
                std::swap(pool[k], pool[k + h % (pool.size() - k)]);
                run.for_kept(v, meshlets_.meshlets[pool[k]], [&](uint32_t i) {
                  sample_sphere(g, g.to_view(pos.get(i)), radius.get(i) * v.radius_scale);
                });
              }
            }
          }
          for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
              const size_t p = size_t(y) * W + x;
              if (pass_depth_[p] == kNoHit) continue;
              const double u =
                  unit_interval(counter_hash(run.step, p, sample, it, RandomStream::kAcceptance));
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
        for (const VisibleBrick &v : sel.visible) {
          const uint32_t m0 = meshlets_.first_of_brick[v.brick],
                         m1 = meshlets_.first_of_brick[v.brick + 1];
          const ConfidencePyramid::Verdict node = pyramid_.test(v.rect, v.near_depth);
          const bool node_occluded = node.failed && node.confidence > cfg.confidence;
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
          }
        }
        // §5.3's "no class changed", with a tolerance of kQuietShare of the meshlets still open:
        // on 10^5 meshlets hundreds creeping from M to O every iteration would otherwise keep it
        // sampling until the cap for little gain (exactly "none" below 1 / kQuietShare).
        quiet = double(changed) <= kQuietShare * double(active) ? quiet + 1 : 0;
        if (quiet >= cfg.patience) break;
      }
    });
  });
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
