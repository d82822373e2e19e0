// lantern-bench-cues: the frame time of each depth cue against the same scene without
// it, through the whole pipeline (core/pipeline/runtime.h: bricks, culling, drawing, compositing,
// cues, PNG writing), every variant rendered at every step so the machine's noise hits them alike.
//
//   mpiexec -n 2 lantern-bench-cues [--scenes fcc1m,void_impact] [--size 1024] [--steps 5]
//                                   [--md-cells 30] [--out DIR] [--kernels REPS]
//                                   [--object-nodes N,N,...] [--samples 1]
//
// Per scene it prints the median over steps of the pipeline's own per-scene time (stats "ms.total",
// rank 0) of each variant and its ratio to the plain one (an unreported copy of the plain scene
// renders first in every step and pays for the step's bricks, which the others reuse). Particles:
// fcc split in blocks over the ranks; void_impact as mini_md's domain decomposition hands them out.
// --samples N gives every variant `samples: N` (the plain one too): the cues' share of a
// super-sampled frame.
//
// --kernels REPS adds, per scene, the screen ambient occlusion kernels alone on rank 0: the whole
// scene drawn once by the CPU raster, then each kernel run REPS times on the whole frame (one
// band), alternated, timed in the thread's CPU time (what the machine's other load does not
// inflate), with the images of the half-resolution kernels compared against the full-resolution
// one (PSNR, SSIM; the plain frame's too, for how much the cue changes the image at all); and the
// object-space AO density volume of the whole scene against the CPU raster pass, alike.
//
// --object-nodes adds object AO variants with `max_nodes` at each count, in the same steps, and
// compares each one's last image with that of the largest count (the finest volume: give one at
// which the nodes are radius / 2 apart for the method's own reference): PSNR, SSIM and differing
// pixels against the time of its stage.
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_scenes.h"
#include "bench_timing.h"
#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/common/cpu_features.h"
#include "core/culling/brick_selection.h"
#include "core/finish/screen_ambient_occlusion.h"
#include "core/finish/view_positions.h"
#include "core/particles/particle_scan.h"
#include "core/pipeline/runtime.h"
#include "core/pipeline/scene_settings.h"
#include "core/render/cpu_sphere_pass.h"
#include "core/render/object_occlusion.h"
#include "core/render/sphere_instances.h"
#include "frame_file.h"
#include "image_metrics.h"

namespace {

using lantern::bench::BenchScene;

struct Variant {
  std::string name;
  std::string keys;  // YAML added to the scene
};

// The first scene of a step also builds the step's bricks (the other scenes reuse them): a
// copy of the plain scene goes first to take that cost, and is not reported.
const std::vector<Variant> kVariants = {
    {"bricks", ""},
    {"plain", ""},
    {"screen_ao", "    ambient_occlusion: {method: screen}\n"},
    {"screen_ao_full", "    ambient_occlusion: {method: screen, resolution: full}\n"},
    {"object_ao", "    ambient_occlusion: {method: object}\n"},
    {"outline", "    outline: {}\n"},
    {"depth_cue", "    depth_cue: {}\n"},
    {"all_screen", "    ambient_occlusion: {method: screen}\n    outline: {}\n    depth_cue: {}\n"},
};

// The bench scene's configuration as YAML: size, radius, camera, cuts, colour by type, samples.
std::string scene_yaml(const BenchScene &bs, const Variant &v, int samples,
                       const std::string &dir) {
  return std::string("  - name: ") + v.name + "\n" + lantern::bench::scene_yaml_keys(bs) + v.keys +
         "    samples: " + std::to_string(samples) + "\n" + "    output: {pattern: '" + dir + "/" +
         bs.name + "_{scene}_{step:04d}.png'}\n";
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// Every rank's particles of `mine` on rank 0 (collective); other ranks get theirs back unchanged.
BenchScene gathered(const BenchScene &mine, int rank, int ranks) {
  const int count = int(mine.type.size());
  std::vector<int> counts(static_cast<size_t>(ranks)), offsets(counts.size());
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  BenchScene all = mine;
  int total = 0;
  for (int r = 0; r < ranks; ++r) offsets[size_t(r)] = total, total += counts[size_t(r)];
  if (rank == 0) all.type.resize(size_t(total));
  MPI_Gatherv(mine.type.data(), count, MPI_INT32_T, all.type.data(), counts.data(), offsets.data(),
              MPI_INT32_T, 0, MPI_COMM_WORLD);
  for (int r = 0; r < ranks; ++r) counts[size_t(r)] *= 3, offsets[size_t(r)] *= 3;
  if (rank == 0) all.xyz.resize(size_t(total) * 3);
  MPI_Gatherv(mine.xyz.data(), 3 * count, MPI_DOUBLE, all.xyz.data(), counts.data(), offsets.data(),
              MPI_DOUBLE, 0, MPI_COMM_WORLD);
  return all;
}

struct AoKernel {
  const char *name;
  bool half;
  lantern::AoVectorPath path;
};

// The screen ambient occlusion kernels on one frame of `bs` (rank 0 only; see the header).
void kernel_table(const BenchScene &bs, int reps) {
  using namespace lantern;
  const ParticleArrays p = bs.arrays();
  SceneConfig sc = bs.config;
  sc.renderer = RendererChoice::kCpu;
  sc.culling.occlusion = OcclusionMode::kHzb;
  const Extent ext = scan_particles(p, sc.per_particle_radius, sc.radius);
  const RadiusRule radius = radius_rule(sc, p);
  Camera cam;
  const glm::dvec3 lo{ext.lo[0], ext.lo[1], ext.lo[2]}, hi{ext.hi[0], ext.hi[1], ext.hi[2]};
  if (Status s = make_camera(sc.camera, lo, hi, radius.max_radius(ext), sc.width, sc.height, &cam);
      !s.ok()) {
    std::printf("  kernels: camera: %s\n", s.message.c_str());
    return;
  }
  const BrickSet bricks = build_bricks(p, BrickOptions{});
  const InstanceRecipe recipe = make_recipe(p, shading_settings(sc), radius, cam, ext);
  const CullSettings cull = cull_settings(sc);
  BrickSelection selection;
  select_bricks(bricks, cam, cull, radius, &selection);
  CpuSpherePass pass;
  DrawList draw;
  BandFrame plain;
  const Rgb8 bg = to_rgb8(sc.background);
  const uint8_t background[4] = {bg[0], bg[1], bg[2], 255};
  pass.run(p, bricks, cull, sc.lighting, selection, recipe, background, &plain.frame, &draw);
  plain.owned = {0, sc.height};
  AmbientOcclusionStyle style;
  style.radius = float(kDefaultAoRadiusInSphereRadii * radius.max_radius(ext));
  // Paths the CPU lacks would run the portable pass: left out.
  std::vector<AoKernel> kernels = {{"full", false, AoVectorPath::kAuto},
                                   {"half", true, AoVectorPath::kAuto}};
  if (cpu_has_avx512_bw()) {
    kernels.push_back({"half_avx512", true, AoVectorPath::kAvx512});
  }
  if (cpu_has_avx2()) {
    kernels.push_back({"half_avx2_gather", true, AoVectorPath::kAvx2Gather});
    kernels.push_back({"half_avx2", true, AoVectorPath::kAvx2});
  }
  kernels.push_back({"half_portable", true, AoVectorPath::kPortable});
  std::vector<double> positions_ms;
  std::vector<std::vector<double>> ms(kernels.size());
  std::vector<BandFrame> out(kernels.size());
  for (int rep = 0; rep < reps; ++rep) {
    double t0 = bench::thread_cpu_ms();
    ViewPositions v;
    v.build(plain, cam);
    positions_ms.push_back(bench::thread_cpu_ms() - t0);
    for (size_t k = 0; k < kernels.size(); ++k) {
      out[k] = plain;
      style.half_resolution = kernels[k].half;
      t0 = bench::thread_cpu_ms();
      apply_screen_ambient_occlusion(v, style, &out[k], kernels[k].path);
      ms[k].push_back(bench::thread_cpu_ms() - t0);
    }
  }
  const double full_ms = bench::median(ms[0]);
  std::printf(
      "  screen AO kernels on one %dx%d frame (CPU raster, %d reps, thread CPU ms, "
      "medians; view positions %.1f ms):\n",
      sc.width, sc.height, reps, bench::median(positions_ms));
  const bench::ImageError none = bench::compare_frames(out[0].frame, plain.frame);
  std::printf("    %-16s %8.1f ms  x%.3f   (plain frame vs full: PSNR %.2f dB, SSIM %.4f)\n",
              kernels[0].name, full_ms, 1.0, none.psnr, none.ssim);
  for (size_t k = 1; k < kernels.size(); ++k) {
    const bench::ImageError e = bench::compare_frames(out[0].frame, out[k].frame);
    std::printf(
        "    %-16s %8.1f ms  x%.3f   vs full: PSNR %.2f dB, SSIM %.4f, %lld pixels differ%s\n",
        kernels[k].name, bench::median(ms[k]), bench::median(ms[k]) / full_ms, e.psnr, e.ssim,
        static_cast<long long>(e.differing_pixels),
        k >= 2 && out[k].frame.rgba != out[1].frame.rgba ? "  (NOT the same bits as half)" : "");
  }
  // Object-space AO: the density volume of the whole scene built on this one rank, against the
  // CPU raster pass (culling and drawing) of the same scene, alternated, in thread CPU time. One
  // volume built again each time, as a scene keeps it from step to step (its buffers kept).
  std::vector<double> volume_ms, pass_ms;
  const double ao_radius = kDefaultAoRadiusInSphereRadii * radius.max_radius(ext);
  OcclusionVolume kept;
  for (int rep = 0; rep < reps; ++rep) {
    double t0 = bench::thread_cpu_ms();
    (void)kept.build(MPI_COMM_SELF, p, ext, {}, ao_radius, sc.ambient_occlusion.strength);
    volume_ms.push_back(bench::thread_cpu_ms() - t0);
    BandFrame again;
    DrawList list;
    t0 = bench::thread_cpu_ms();
    pass.run(p, bricks, cull, sc.lighting, selection, recipe, background, &again.frame, &list);
    pass_ms.push_back(bench::thread_cpu_ms() - t0);
  }
  const double volume = bench::median(volume_ms), raster = bench::median(pass_ms);
  std::printf(
      "  object AO volume of the whole scene on one rank (%d reps, thread CPU ms, medians): "
      "%.1f ms against %.1f ms for the CPU raster pass (culling + drawing): %.1f %% of the two\n",
      reps, volume, raster, 100.0 * volume / (volume + raster));
}

}  // namespace

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  std::vector<std::string> scenes{"fcc1m", "void_impact"};
  int size = 1024, steps = 5, md_cells = 30, kernel_reps = 0, samples = 1;
  std::vector<int64_t> object_nodes;
  std::string out = "/tmp/lantern_bench_cues";
  // An option the bench does not know, or one without its value, stops it: a typo must not run
  // the default benchmark for minutes and print it as what was asked for.
  const auto usage = [&](const std::string &why) {
    if (rank == 0)
      std::fprintf(stderr,
                   "lantern-bench-cues: %s\nusage: lantern-bench-cues [--scenes fcc1m,void_impact] "
                   "[--size 1024] [--steps 5] [--md-cells 30] [--out DIR] [--kernels REPS] "
                   "[--object-nodes N,N,...] [--samples 1]\n",
                   why.c_str());
    MPI_Finalize();
    return 2;
  };
  if (argc % 2 == 0) return usage(std::string(argv[argc - 1]) + " has no value");
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--scenes") {
      scenes.clear();
      std::stringstream list(v);
      for (std::string s; std::getline(list, s, ',');) scenes.push_back(s);
    } else if (a == "--size") {
      size = std::stoi(v);
    } else if (a == "--steps") {
      steps = std::stoi(v);
    } else if (a == "--md-cells") {
      md_cells = std::stoi(v);
    } else if (a == "--out") {
      out = v;
    } else if (a == "--samples") {
      samples = std::stoi(v);
    } else if (a == "--kernels") {
      kernel_reps = std::stoi(v);
    } else if (a == "--object-nodes") {
      std::stringstream list(v);
      for (std::string n; std::getline(list, n, ',');) object_nodes.push_back(std::stoll(n));
      std::sort(object_nodes.begin(), object_nodes.end());
    } else {
      return usage("unknown option " + a);
    }
  }
  std::vector<Variant> variants = kVariants;
  for (const int64_t n : object_nodes)
    variants.push_back(
        {"object_ao_n" + std::to_string(n),
         "    ambient_occlusion: {method: object, max_nodes: " + std::to_string(n) + "}\n"});
  if (rank == 0) std::system(("mkdir -p '" + out + "'").c_str());
  MPI_Barrier(MPI_COMM_WORLD);
  int failures = 0;
  for (const std::string &name : scenes) {
    BenchScene bs;
    std::string why;
    if (name == "fcc1m") {
      bs = lantern::bench::fcc_outside(63, size);
      lantern::bench::keep_rank_block(&bs, rank, ranks);
    } else if (!lantern::bench::mini_md_scene(name, md_cells, size, &bs, &why)) {
      if (rank == 0) std::fprintf(stderr, "%s: %s\n", name.c_str(), why.c_str());
      ++failures;
      continue;
    }
    if (kernel_reps > 0) {
      const BenchScene all = gathered(bs, rank, ranks);
      if (rank == 0) {
        std::printf("%s (%s):\n", name.c_str(), bs.note.c_str());
        kernel_table(all, kernel_reps);
        std::fflush(stdout);
      }
    }
    if (steps == 0) continue;  // --steps 0: the kernels alone
    const std::string stats = out + "/" + name + "_stats.jsonl";
    if (rank == 0) std::remove(stats.c_str());
    std::string yaml = "stats: " + stats + "\nscenes:\n";
    for (const Variant &v : variants) yaml += scene_yaml(bs, v, samples, out);
    std::unique_ptr<lantern::Runtime> rt;
    lantern::ParticleDescription d;
    d.count = int64_t(bs.type.size());
    d.position = {bs.xyz.data(), lantern::DataType::kFloat64, 0};
    d.type = {bs.type.data(), lantern::DataType::kInt32, 0};
    lantern::Status s = lantern::Runtime::open(yaml, MPI_COMM_WORLD, &rt);
    if (s.ok()) s = rt->publish(d);
    for (int step = 0; s.ok() && step <= steps; ++step) s = rt->execute(step, step);  // 0: warm-up
    if (s.ok()) s = rt->finish();
    rt.reset();
    if (!s.ok()) {
      if (rank == 0) std::fprintf(stderr, "%s: %s\n", name.c_str(), s.message.c_str());
      ++failures;
      continue;
    }
    if (rank != 0) continue;
    std::map<std::string, std::vector<double>> ms, cues, band;
    std::ifstream in(stats);
    for (std::string line; std::getline(in, line);) {
      const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
      if (j.is_discarded() || !j.contains("scenes") || j.value("step", 0) == 0) continue;
      for (const auto &sc : j["scenes"]) {
        ms[sc["scene"]].push_back(sc["ms"]["total"]);
        cues[sc["scene"]].push_back(sc["ms"].value("cues", 0.0));
        // With one sample, the stats' down-sampling is the time spent putting the merged rows
        // into the band the cues work on: a cost of the cues too. With more, it is the
        // down-sampling itself (printed as such).
        band[sc["scene"]].push_back(sc["ms"].value("downsample", 0.0));
      }
    }
    std::printf("%s (%s), %dx%d, %d sample%s, %d ranks, median of %d steps:\n", name.c_str(),
                bs.note.c_str(), size, size, samples, samples == 1 ? "" : "s", ranks, steps);
    const double plain = median(ms["plain"]);
    for (const Variant &v : variants)
      if (v.name != "bricks")
        std::printf(
            "  %-14s %8.1f ms  x%.3f   (cue stage %6.1f ms = %5.1f%% of plain; %s %4.2f ms)\n",
            v.name.c_str(), median(ms[v.name]), median(ms[v.name]) / plain, median(cues[v.name]),
            100.0 * median(cues[v.name]) / plain, samples == 1 ? "band" : "downsample",
            median(band[v.name]));
    if (object_nodes.empty()) continue;
    // Each object AO volume's last image against the finest one's.
    char file[32];
    std::snprintf(file, sizeof file, "_%04d.png", steps);
    const auto image = [&](int64_t n) {
      return lantern::bench::read_frame(out + "/" + bs.name + "_object_ao_n" + std::to_string(n) +
                                        file);
    };
    const lantern::Frame finest = image(object_nodes.back());
    std::printf("  object AO images at step %d against max_nodes %lld's:\n", steps,
                static_cast<long long>(object_nodes.back()));
    for (const int64_t n : object_nodes) {
      const lantern::bench::ImageError e = lantern::bench::compare_frames(finest, image(n));
      const std::string name = "object_ao_n" + std::to_string(n);
      std::printf(
          "    max_nodes %8lld: cue stage %6.1f ms (%5.1f%% of plain)  PSNR %6.2f dB  SSIM "
          "%.4f  %6.2f%% of the pixels differ\n",
          static_cast<long long>(n), median(cues[name]), 100.0 * median(cues[name]) / plain, e.psnr,
          e.ssim, 100.0 * double(e.differing_pixels) / double(finest.pixel_count()));
    }
  }
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
