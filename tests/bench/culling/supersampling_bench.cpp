#include "supersampling_bench.h"
#include "core/pipeline/scene_settings.h"

#include <mpi.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "bench_timing.h"
#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/culling/brick_selection.h"
#include "core/finish/sample_downsampling.h"
#include "core/particles/particle_scan.h"
#include "core/pipeline/runtime.h"
#include "core/render/cpu_sphere_pass.h"
#include "core/render/sphere_instances.h"
#include "image_metrics.h"

namespace lantern::bench {
namespace {

int axis_of(int samples) {
  SceneConfig s;
  s.samples = samples;
  return s.samples_per_axis();
}

double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

struct Image {
  Frame frame;  // the final image
  std::vector<double> ms, downsample_ms;
  CullStats stats;
};

// Renders bs at `samples` per pixel with the CPU raster (occlusion `mode`), down-sampled.
class SampledRenderer {
 public:
  SampledRenderer(const BenchScene &bs, const ParticleArrays &p, const Extent &ext,
                  const BrickSet &bricks)
      : bs_(bs), p_(p), ext_(ext), bricks_(bricks) {}

  void frame(int samples, OcclusionMode mode, Image *out) {
    const int s = axis_of(samples);
    SceneConfig sc = bs_.config;
    sc.width *= s;
    sc.height *= s;
    sc.samples = 1;  // this class does the down-sampling itself
    sc.culling.occlusion = mode;
    sc.renderer = RendererChoice::kCpu;
    const RadiusRule rule = radius_rule(sc, p_);
    Camera cam;
    const glm::dvec3 lo{ext_.lo[0], ext_.lo[1], ext_.lo[2]}, hi{ext_.hi[0], ext_.hi[1], ext_.hi[2]};
    if (Status st =
            make_camera(sc.camera, lo, hi, rule.max_radius(ext_), sc.width, sc.height, &cam);
        !st.ok()) {
      std::printf("camera: %s\n", st.message.c_str());
      return;
    }
    const InstanceRecipe recipe = make_recipe(p_, shading_settings(sc), rule, cam, ext_);
    const Rgb8 bg = to_rgb8(sc.background);
    const uint8_t background[4] = {bg[0], bg[1], bg[2], 255};
    const CullSettings cull = cull_settings(sc);
    const auto t0 = Clock::now();
    select_bricks(bricks_, cam, cull, rule, &selection_);
    Frame &target = s > 1 ? samples_ : out->frame;
    out->stats =
        pass_.run(p_, bricks_, cull, sc.lighting, selection_, recipe, background, &target, &draw_);
    const auto t1 = Clock::now();
    if (s > 1) downsample_frame(samples_, s, &out->frame);
    out->downsample_ms.push_back(ms_since(t1));
    out->ms.push_back(ms_since(t0));
  }

 private:
  const BenchScene &bs_;
  const ParticleArrays &p_;
  const Extent &ext_;
  const BrickSet &bricks_;
  BrickSelection selection_;
  CpuSpherePass pass_;
  DrawList draw_;
  Frame samples_;  // the sample-resolution frame, reused
};

std::string psnr_text(double psnr) {
  char buf[32];
  if (std::isinf(psnr))
    std::snprintf(buf, sizeof buf, "inf");
  else
    std::snprintf(buf, sizeof buf, "%.2f", psnr);
  return buf;
}

}  // namespace

const char *supersampling_csv_header() {
  return "scene,samples,mode,ms_per_frame,downsample_ms,culled_percent,differing_pixels_vs_ref64,"
         "psnr_db_vs_ref64,ssim_vs_ref64,differing_pixels_vs_brute_same_n,speedup_vs_brute_n1,"
         "cost_vs_same_mode_n1,sample_frame_bytes\n";
}

void run_supersampling_scene(const BenchScene &bs, const std::vector<int> &samples, int runs,
                             std::ostream &csv, std::vector<PlotPoint> *plot) {
  const ParticleArrays p = bs.arrays();
  const Extent ext = scan_particles(p, bs.config.per_particle_radius, bs.config.radius);
  const BrickSet bricks = build_bricks(p, BrickOptions{});
  const int64_t n = int64_t(bs.type.size());
  SampledRenderer renderer(bs, p, ext, bricks);
  std::printf("\n== %s: %s, %dx%d, super-sampled (CPU raster), %d runs per row (median)\n",
              bs.name.c_str(), bs.note.c_str(), bs.config.width, bs.config.height, runs);
  // The reference: 64 samples per pixel, brute force, once.
  Image reference;
  renderer.frame(64, OcclusionMode::kNone, &reference);
  std::printf("   reference: 64 samples, brute force, %.0f ms (%dx%d sample frame)\n",
              reference.ms.back(), bs.config.width * 8, bs.config.height * 8);

  const OcclusionMode modes[] = {OcclusionMode::kNone, OcclusionMode::kHzb};
  const char *names[] = {"brute_force", "hzb"};
  std::vector<std::vector<Image>> images(samples.size(), std::vector<Image>(2));
  for (int run = 0; run < runs; ++run)  // interleaved: the machine's noise hits every row alike
    for (size_t k = 0; k < samples.size(); ++k)
      for (int m = 0; m < 2; ++m) renderer.frame(samples[k], modes[m], &images[k][size_t(m)]);

  std::printf("   %7s %-12s %9s %9s %8s %10s %8s %7s %12s %9s %9s %10s\n", "samples", "mode",
              "ms/frame", "downs ms", "culled", "diff px", "PSNR dB", "SSIM", "diff vs brute",
              "speed-up", "cost/N=1", "frame MiB");
  const double brute_n1 = median(images[0][0].ms);
  for (size_t k = 0; k < samples.size(); ++k)
    for (int m = 0; m < 2; ++m) {
      const Image &im = images[k][size_t(m)];
      const ImageError e = compare_frames(reference.frame, im.frame);
      const ImageError vs_brute = compare_frames(images[k][0].frame, im.frame);
      const double ms = median(im.ms);
      const double culled =
          100.0 * double(n - im.stats.drawn - im.stats.splatted) / double(std::max<int64_t>(n, 1));
      const int s = axis_of(samples[k]);
      const double bytes = 8.0 * bs.config.width * s * bs.config.height * s;
      const double cost = ms / median(images[0][size_t(m)].ms);
      std::printf("   %7d %-12s %9.1f %9.1f %7.1f%% %10lld %8s %7.4f %12lld %8.2fx %8.2fx %10.1f\n",
                  samples[k], names[m], ms, median(im.downsample_ms), culled,
                  static_cast<long long>(e.differing_pixels), psnr_text(e.psnr).c_str(), e.ssim,
                  static_cast<long long>(vs_brute.differing_pixels), brute_n1 / ms, cost,
                  bytes / (1 << 20));
      csv << bs.name << ',' << samples[k] << ',' << names[m] << ',' << ms << ','
          << median(im.downsample_ms) << ',' << culled << ',' << e.differing_pixels << ','
          << psnr_text(e.psnr) << ',' << e.ssim << ',' << vs_brute.differing_pixels << ','
          << brute_n1 / ms << ',' << cost << ',' << int64_t(bytes) << '\n';
      plot->push_back(
          {bs.name, std::string(names[m]) + " N=" + std::to_string(samples[k]), ms, e.psnr});
    }
  std::printf("   peak RSS of the process so far: %.0f MiB\n", peak_rss_mib());
}

void run_supersampling_pipeline(const BenchScene &bs, const std::vector<int> &samples, int runs,
                                const std::string &out) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (rank == 0)
    std::printf(
        "\n== %s through the pipeline (Runtime::execute: cull + draw + composite + "
        "down-sample + PNG), %d ranks, occlusion hzb, %d steps per N (median)\n",
        bs.name.c_str(), ranks, runs);
  // This rank's share of the particles: a slab of the published order.
  const int64_t n = int64_t(bs.type.size());
  const int64_t first = n * rank / ranks, last = n * (rank + 1) / ranks;
  ParticleDescription d{};
  d.count = last - first;
  d.position = {bs.xyz.data() + 3 * first, DataType::kFloat64, 0};
  d.type = {bs.type.data() + first, DataType::kInt32, 0};
  double first_ms = 0.0;
  if (rank == 0)
    std::printf("   %7s %9s %10s %12s %14s\n", "samples", "ms/frame", "cost/first", "frame MiB",
                "peak RSS MiB");
  for (const int samples : samples) {
    const std::string yaml = "stats: '" + out + "/pipeline_stats.jsonl'\nscenes:\n  - name: ssaa" +
                             std::to_string(samples) +
                             "\n    width: " + std::to_string(bs.config.width) +
                             "\n    height: " + std::to_string(bs.config.height) +
                             "\n    radius: " + std::to_string(bs.config.radius) +
                             "\n    samples: " + std::to_string(samples) +
                             "\n    culling: {occlusion: hzb}\n    output: {pattern: '" + out +
                             "/pipeline_{scene}_{step:04d}.png'}\n";
    std::unique_ptr<Runtime> rt;
    if (Status s = Runtime::open(yaml, MPI_COMM_WORLD, &rt); !s.ok()) {
      if (rank == 0) std::printf("   samples %d: %s\n", samples, s.message.c_str());
      continue;
    }
    if (Status s = rt->publish(d); !s.ok()) std::printf("publish: %s\n", s.message.c_str());
    std::vector<double> ms;
    for (int step = 0; step <= runs; ++step) {
      MPI_Barrier(MPI_COMM_WORLD);
      const auto t0 = Clock::now();
      if (Status s = rt->execute(step, 0.0); !s.ok() && rank == 0)
        std::printf("   execute: %s\n", s.message.c_str());
      if (step > 0) ms.push_back(ms_since(t0));  // step 0 builds the bricks and warms up
    }
    (void)rt->finish();
    rt.reset();
    double rss = peak_rss_mib(), max_rss = 0.0, med = median(ms), slowest = 0.0;
    MPI_Reduce(&rss, &max_rss, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    MPI_Reduce(&med, &slowest, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    if (first_ms == 0.0) first_ms = slowest;
    const int s = axis_of(samples);
    if (rank == 0)
      std::printf("   %7d %9.1f %9.2fx %12.1f %14.0f\n", samples, slowest, slowest / first_ms,
                  8.0 * bs.config.width * s * bs.config.height * s / (1 << 20), max_rss);
  }
}

}  // namespace lantern::bench
