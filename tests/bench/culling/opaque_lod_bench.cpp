#include "opaque_lod_bench.h"
#include "core/pipeline/scene_settings.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "bench_timing.h"
#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/culling/brick_selection.h"
#include "core/culling/draw_list.h"
#include "core/culling/level_of_detail.h"
#include "core/particles/particle_scan.h"
#include "core/particles/radius_rule.h"
#include "core/render/cpu_sphere_pass.h"
#include "core/render/point_splats.h"
#include "core/render/sphere_instances.h"
#include "image_metrics.h"
#include "sample_hash.h"

namespace lantern::bench {
namespace {

// The particles of the uniform random sample of `fraction`, each grown as level of detail grows
// the spheres it keeps (level_of_detail.h, LodGrowth::kCoverage): by (1 / fraction)^(1/2) where
// its sphere projects under kCoveragePixels in radius (seen through `g`), else by the cube root.
BenchScene random_sample(const BenchScene &bs, const ViewGeometry &g, double fraction) {
  BenchScene s;
  s.name = bs.name;
  s.config = bs.config;
  s.config.per_particle_radius = true;  // the growth depends on the particle's depth
  const uint64_t limit = sample_limit(fraction);
  for (size_t i = 0; i < bs.type.size(); ++i) {
    if (index_hash(i) > limit) continue;
    const glm::dvec3 x{bs.xyz[3 * i], bs.xyz[3 * i + 1], bs.xyz[3 * i + 2]};
    const double r = bs.radius.empty() ? bs.config.radius : bs.radius[i];
    const double px = r * g.pixels_per_unit(std::max(-g.to_view(x).z, g.near_plane));
    const double grow =
        px < kCoveragePixels ? std::sqrt(1.0 / fraction) : std::cbrt(1.0 / fraction);
    s.xyz.insert(s.xyz.end(), bs.xyz.begin() + 3 * i, bs.xyz.begin() + 3 * i + 3);
    s.type.push_back(bs.type[i]);
    s.radius.push_back(r * grow);
  }
  return s;
}

// The particles at `indices` (their own radii): the set a frame ray-cast.
BenchScene subset(const BenchScene &bs, const PageVector<uint64_t> &entries) {
  BenchScene s;
  s.name = bs.name;
  s.config = bs.config;
  s.config.per_particle_radius = true;
  for (const uint64_t e : entries) {
    const size_t i = entry_index(e);
    s.xyz.insert(s.xyz.end(), bs.xyz.begin() + 3 * i, bs.xyz.begin() + 3 * i + 3);
    s.type.push_back(bs.type[i]);
    s.radius.push_back(bs.radius.empty() ? bs.config.radius : bs.radius[i]);
  }
  return s;
}

// One set of particles as drawn: its arrays and bricks (built once, as once per step).
struct Drawable {
  BenchScene scene;
  ParticleArrays arrays;
  BrickSet bricks;
  InstanceRecipe recipe;
};

struct Sample {
  std::string mode;
  double fraction = 1.0;
  const Drawable *particles = nullptr;
  LodConfig lod;
  std::vector<double> ms;
  int64_t drawn = 0, splatted = 0;
  Frame frame;
};

class Renderer {
 public:
  // Draws `d` with `lod` through the CPU raster under hzb (and splats its points). Returns the
  // view geometry it drew with.
  ViewGeometry draw(const Drawable &d, const Camera &cam, const LodConfig &lod, Sample *s) {
    SceneConfig sc = d.scene.config;
    sc.culling.occlusion = OcclusionMode::kHzb;
    sc.culling.frustum = true;
    sc.renderer = RendererChoice::kCpu;
    sc.lod = lod;
    const Rgb8 bg = to_rgb8(sc.background);
    const uint8_t background[4] = {bg[0], bg[1], bg[2], 255};
    const CullSettings cull = cull_settings(sc);
    select_bricks(d.bricks, cam, cull, radius_rule(sc, d.arrays), &selection_);
    const CullStats st = pass_.run(d.arrays, d.bricks, cull, sc.lighting, selection_, d.recipe,
                                   background, &s->frame, &draw_);
    if (!draw_.points.empty())
      splat_points(
          d.arrays, d.recipe.per_particle_radius, d.recipe.radius, draw_.points, selection_.g,
          [&d](int64_t i) { return d.recipe.color(i); }, &s->frame);
    s->drawn = st.drawn;
    s->splatted = st.splatted;
    return selection_.g;
  }

  // The last draw's ray-cast spheres.
  const PageVector<uint64_t> &ray_cast() const { return draw_.spheres; }

 private:
  BrickSelection selection_;
  CpuSpherePass pass_;
  DrawList draw_;
};

std::string percent(double f) {
  return std::to_string(int(std::lround(f * 100))) + "%";
}

}  // namespace

const char *opaque_lod_csv_header() {
  return "scene,mode,fraction,ms_per_frame,drawn,splatted,psnr_db,ssim,psnr_box8_db,speedup\n";
}

void run_opaque_lod_bench(const BenchScene &bs, int runs, std::ostream &csv,
                          std::vector<PlotPoint> *plot) {
  const ParticleArrays full_arrays = bs.arrays();
  const Extent ext = scan_particles(full_arrays, bs.config.per_particle_radius, bs.config.radius);
  const double max_radius = radius_rule(bs.config, full_arrays).max_radius(ext);
  Camera cam;
  const glm::dvec3 lo{ext.lo[0], ext.lo[1], ext.lo[2]}, hi{ext.hi[0], ext.hi[1], ext.hi[2]};
  char label[96];
  std::snprintf(label, sizeof label, "%s_%d", bs.name.c_str(), bs.config.width);
  if (Status s = make_camera(bs.config.camera, lo, hi, max_radius, bs.config.width,
                             bs.config.height, &cam);
      !s.ok()) {
    std::printf("%s: camera: %s\n", label, s.message.c_str());
    return;
  }
  const auto drawable = [&](BenchScene scene) {
    auto d = std::make_unique<Drawable>();
    d->scene = std::move(scene);
    d->arrays = d->scene.arrays();
    d->bricks = build_bricks(d->arrays, BrickOptions{});
    // The full scene's extent: a sample is colored and framed as the whole.
    d->recipe = make_recipe(d->arrays, shading_settings(d->scene.config),
                            radius_rule(d->scene.config, d->arrays), cam, ext);
    return d;
  };
  const double fractions[] = {1.0, 0.5, 0.25, 0.1, 0.01};
  std::vector<std::unique_ptr<Drawable>> sets;
  sets.push_back(drawable(bs));
  Renderer renderer;
  Sample probe;  // the full scene's view geometry, for the random samples' growth rule
  const ViewGeometry g = renderer.draw(*sets[0], cam, LodConfig{}, &probe);
  std::vector<Sample> samples;
  samples.push_back({"no_lod", 1.0, sets[0].get(), {}, {}, 0, 0, {}});
  // What no level of detail ray-cast, alone: the picture of the full scene at the least any
  // selection that keeps it can draw (as if the visible set were known, e.g. from the frame
  // before with nothing moving). Its bricks are built once, untimed, as the random samples'.
  const double visible_fraction = double(renderer.ray_cast().size()) / double(bs.type.size());
  sets.push_back(drawable(subset(bs, renderer.ray_cast())));
  samples.push_back({"visible_set", visible_fraction, sets.back().get(), {}, {}, 0, 0, {}});
  for (const double f : fractions) {
    LodConfig lod;
    lod.fraction = f;
    samples.push_back({"lod_" + percent(f), f, sets[0].get(), lod, {}, 0, 0, {}});
    LodConfig points = lod;  // the same with sub-pixel spheres splatted (lod.point_path)
    points.point_path = true;
    samples.push_back({"lod+points_" + percent(f), f, sets[0].get(), points, {}, 0, 0, {}});
    LodConfig nearest = lod;  // lod.select: nearest: opaque bricks keep their front
    nearest.select = LodSelect::kNearest;
    samples.push_back({"lod_nearest_" + percent(f), f, sets[0].get(), nearest, {}, 0, 0, {}});
    if (f == 1.0) {  // a budget of every particle runs the LOD code keeping all of them
      lod.budget = int64_t(bs.type.size());
      samples.push_back({"lod_budget_all", f, sets[0].get(), lod, {}, 0, 0, {}});
      continue;
    }
    sets.push_back(drawable(random_sample(bs, g, f)));
    samples.push_back({"random_" + percent(f), f, sets.back().get(), {}, {}, 0, 0, {}});
  }
  // Run 0 warms up (first touch of every frame's pages) and is not timed.
  for (int run = 0; run <= runs; ++run)
    for (Sample &s : samples) {
      const auto t0 = Clock::now();
      renderer.draw(*s.particles, cam, s.lod, &s);
      if (run > 0) s.ms.push_back(ms_since(t0));
    }
  const Frame ref_box = box_filtered8(samples[0].frame);
  const double ref_ms = median(samples[0].ms);
  std::printf(
      "\n== %s (opaque spheres, cpu raster + hzb in every mode): %s, %dx%d, %lld "
      "particles\n",
      label, bs.note.c_str(), bs.config.width, bs.config.height,
      static_cast<long long>(bs.type.size()));
  std::printf("   %-18s %9s %10s %9s %8s %7s %10s %9s\n", "mode", "ms/frame", "ray-cast",
              "splatted", "PSNR dB", "SSIM", "PSNR box8", "speed-up");
  for (const Sample &s : samples) {
    const double ms = median(s.ms);
    const ImageError e = compare_frames(samples[0].frame, s.frame);
    const ImageError eb = compare_frames(ref_box, box_filtered8(s.frame));
    std::printf("   %-18s %9.1f %10lld %9lld %8.2f %7.4f %10.2f %8.2fx\n", s.mode.c_str(), ms,
                static_cast<long long>(s.drawn), static_cast<long long>(s.splatted), e.psnr, e.ssim,
                eb.psnr, ref_ms / ms);
    csv << label << ',' << s.mode << ',' << s.fraction << ',' << ms << ',' << s.drawn << ','
        << s.splatted << ',' << e.psnr << ',' << e.ssim << ',' << eb.psnr << ',' << ref_ms / ms
        << '\n';
    plot->push_back({std::string(label) + " opaque", s.mode, ms, e.psnr});
  }
}

}  // namespace lantern::bench
