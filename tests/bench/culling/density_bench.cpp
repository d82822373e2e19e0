#include "density_bench.h"
#include "core/pipeline/scene_settings.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

#include <OpenImageIO/imagebuf.h>

#include "bench_timing.h"
#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/finish/density_transfer.h"
#include "core/particles/particle_scan.h"
#include "core/particles/typed_access.h"
#include "core/render/density_pass.h"
#include "core/render/density_splat.h"
#include "core/render/sphere_instances.h"
#include "image_metrics.h"
#include "sample_hash.h"

namespace lantern::bench {
namespace {

struct Sample {
  std::string mode;
  double fraction = 1.0;
  bool random = false;
  std::vector<double> ms, cpu_ms;
  int64_t drawn = 0, pixels = 0;
  DensityImage image;
  Frame frame;
};

// The uniform random sample: every brick particle kept with probability `fraction`, weighted by
// (particles / kept) over the whole set, so the total brightness matches.
int64_t render_random(const ParticleArrays &p, const BrickSet &bricks, const ViewGeometry &g,
                      const InstanceRecipe &recipe, double radius, double fraction,
                      DensityImage *image, int64_t *pixels) {
  const uint64_t limit = sample_limit(fraction);
  int64_t kept = 0;
  for (const uint32_t i : bricks.order) kept += index_hash(i) <= limit;
  const double weight = double(bricks.order.size()) / double(std::max<int64_t>(kept, 1));
  image->reset(g.width, g.height, density_channels(recipe.coloring.by));
  DensitySplatter splatter(g, image);
  int64_t drawn = 0;
  const Rgb8 none{0, 0, 0};
  visit_positions(p, [&](const auto &pos) {
    for (const uint32_t i : bricks.order)
      if (index_hash(i) <= limit)
        drawn += splatter.splat(g.to_view(pos.get(i)), radius * std::cbrt(1.0 / fraction), weight,
                                image->channels > 1 ? recipe.color(i) : none);
  });
  *pixels = splatter.pixels_written();
  return drawn;
}

bool write_png(const std::string &path, const Frame &f) {
  OIIO::ImageBuf buf(OIIO::ImageSpec(f.width, f.height, 4, OIIO::TypeDesc::UINT8));
  buf.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::UINT8, f.rgba.data());
  if (buf.write(path)) return true;
  std::fprintf(stderr, "lantern-bench: cannot write %s: %s\n", path.c_str(),
               buf.geterror().c_str());
  return false;
}

}  // namespace

const char *density_csv_header() {
  return "scene,mode,fraction,ms_per_frame,cpu_ms,drawn,particles_per_s,bytes_per_particle,psnr_db,"
         "ssim,"
         "psnr_box8_db\n";
}

namespace {

// One scene at one footprint radius (`smoothing` times the scene's sphere radius).
bool run_at(const BenchScene &bs, const ParticleArrays &p, const BrickSet &bricks, double smoothing,
            int runs, const std::string &image_dir, std::ostream &csv,
            std::vector<PlotPoint> *plot) {
  SceneConfig sc = bs.config;
  sc.style = SceneStyle::kDensity;
  sc.cuts.clear();  // density sums through the whole sample: no cross-section
  sc.radius *= smoothing;
  char label_text[64];
  std::snprintf(label_text, sizeof label_text, "%s_%d@r%g", bs.name.c_str(), sc.width, sc.radius);
  const std::string name = label_text;
  const Extent ext = scan_particles(p, sc.per_particle_radius, sc.radius);
  const RadiusRule radius = radius_rule(sc, p);
  Camera cam;
  const glm::dvec3 lo{ext.lo[0], ext.lo[1], ext.lo[2]}, hi{ext.hi[0], ext.hi[1], ext.hi[2]};
  if (Status s = make_camera(sc.camera, lo, hi, radius.max_radius(ext), sc.width, sc.height, &cam);
      !s.ok()) {
    std::printf("%s: camera: %s\n", name.c_str(), s.message.c_str());
    return true;
  }
  const InstanceRecipe recipe = make_recipe(p, shading_settings(sc), radius, cam, ext);
  std::vector<Sample> samples;
  for (const double f : {1.0, 0.5, 0.25, 0.1, 0.01}) {
    const std::string pct = std::to_string(int(std::lround(f * 100))) + "%";
    samples.push_back({"prefix_" + pct, f, false, {}, {}, 0, 0, {}, {}});
    if (f < 1.0) samples.push_back({"random_" + pct, f, true, {}, {}, 0, 0, {}, {}});
  }
  BrickSelection sel;
  const CullSettings cull = cull_settings(sc);
  // Run 0 warms up (first touch of every image's pages) and is not timed.
  for (int run = 0; run <= runs; ++run)
    for (Sample &s : samples) {
      const auto t0 = Clock::now();
      const double cpu0 = thread_cpu_ms();
      if (s.random) {
        select_density_bricks(bricks, cam, cull, radius, &sel, nullptr);  // the geometry
        s.drawn =
            render_random(p, bricks, sel.g, recipe, sc.radius, s.fraction, &s.image, &s.pixels);
      } else {
        CullSettings lod = cull;
        lod.lod.fraction = s.fraction;
        select_density_bricks(bricks, cam, lod, radius, &sel, nullptr);
        s.drawn = render_density(p, bricks, lod, sel, recipe, &s.image, &s.pixels).drawn;
      }
      if (run == 0) continue;
      s.ms.push_back(ms_since(t0));
      s.cpu_ms.push_back(thread_cpu_ms() - cpu0);
    }
  // One range for all: the full image's auto range, so the samples are mapped alike.
  sc.density.transfer = DensityTransfer::kAsinh;
  sc.density.colormap = "viridis";
  const DensityRange full_range = density_range(samples[0].image, sc.density);
  sc.density.range = std::array<double, 2>{full_range.lo, full_range.hi};
  const Rgb8 bg = to_rgb8({0.0, 0.0, 0.0});
  const uint8_t background[4] = {bg[0], bg[1], bg[2], 255};
  const Colormap map = *Colormap::named(sc.density.colormap);
  for (Sample &s : samples) map_density(s.image, sc.density, map, background, &s.frame);
  const Frame ref_box = box_filtered8(samples[0].frame);

  const int channels = samples[0].image.channels;
  std::printf("\n== %s (density, footprint radius %g): %s, %dx%d, %s, asinh over [0, %.3g]\n",
              name.c_str(), sc.radius, bs.note.c_str(), sc.width, sc.height,
              channels == 1 ? "one intensity" : "colored by type (4 channels)", full_range.hi);
  std::printf("   %-14s %9s %8s %10s %11s %9s %8s %7s %10s\n", "mode", "ms/frame", "cpu ms",
              "drawn", "M part/s", "B/part", "PSNR dB", "SSIM", "PSNR box8");
  bool ok = true;
  for (const Sample &s : samples) {
    const double ms = median(s.ms);
    const ImageError e = compare_frames(samples[0].frame, s.frame);
    const ImageError eb = compare_frames(ref_box, box_filtered8(s.frame));
    // Bytes read per particle: its index (4), position (3 x 4 or 8), type when colored (4), and
    // every pixel of its footprint read once (channels x 8; written back as well).
    const double pos_bytes = 3.0 * double(p.position_array(0).type() == DataType::kFloat32 ? 4 : 8);
    const double bytes = 4.0 + pos_bytes + (channels > 1 ? 4.0 : 0.0) +
                         double(s.pixels) / double(std::max<int64_t>(s.drawn, 1)) * channels * 8.0;
    const double cpu_ms = median(s.cpu_ms);
    const double rate = double(s.drawn) / (cpu_ms * 1e-3) * 1e-6;  // per core: CPU time
    std::printf("   %-14s %9.1f %8.1f %10lld %11.1f %9.0f %8.2f %7.4f %10.2f\n", s.mode.c_str(), ms,
                cpu_ms, static_cast<long long>(s.drawn), rate, bytes, e.psnr, e.ssim, eb.psnr);
    csv << name << ',' << s.mode << ',' << s.fraction << ',' << ms << ',' << cpu_ms << ','
        << s.drawn << ',' << rate * 1e6 << ',' << bytes << ',' << e.psnr << ',' << e.ssim << ','
        << eb.psnr << '\n';
    plot->push_back({name + " density", s.mode, ms, e.psnr});
    if (!image_dir.empty() && (s.fraction == 1.0 || s.fraction == 0.1))
      ok &= write_png(image_dir + "/" + name + "_density_" + s.mode + ".png", s.frame);
  }
  return ok;
}

}  // namespace

bool run_density_bench(const BenchScene &bs, int runs, const std::string &image_dir,
                       std::ostream &csv, std::vector<PlotPoint> *plot) {
  const ParticleArrays p = bs.arrays();
  const BrickSet bricks = build_bricks(p, BrickOptions{});
  bool ok = true;
  // The sphere radius (sigma = r / 3: particles stay distinct), and 3 r (sigma = r, a smoothing
  // length of about one spacing in a dense liquid or crystal: a smooth density field).
  for (const double smoothing : {1.0, 3.0})
    ok &= run_at(bs, p, bricks, smoothing, runs, image_dir, csv, plot);
  return ok;
}

}  // namespace lantern::bench
