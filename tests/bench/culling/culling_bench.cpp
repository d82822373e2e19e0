// lantern-bench: every culling and level-of-detail mode on the same scenes, against brute force.
//
//   lantern-bench [--scenes fcc1m,fcc10m,inside,void_impact,droplet] [--size 1024] [--runs 5]
//                 [--md-cells 64] [--out DIR] [--images] [--modes hzb,cpu_raster+hzb]
//                 [--azimuths K] [--density] [--opaque-lod] [--scale 10,38,100]
//
// --density: style: density at LOD 100/50/25/10/1 % against random samples instead of the sphere
// modes (density_bench.h; DIR/density_bench.csv and .svg). Scene `clustered`: clustered_cloud;
// `film`: thin_film (500 k atoms in four layers).
// --opaque-lod: sphere LOD at 100/50/25/10/1 % against random samples, cpu raster + hzb in every
// mode (opaque_lod_bench.h; DIR/opaque_lod_bench.csv and .svg).
// A scene name may end in :uniform or :bimodal to give the particles mixed radii (assign_radii
// in bench_scenes.h), e.g. --scenes fcc1m:uniform,inside:bimodal. --azimuths K renders every
// scene from K azimuths evenly spaced about its vertical axis (same elevation and distance; the
// viewpoint-stability experiment of the nine-spheres paper's conference version, its Fig. 7) and
// ends each scene with min / median / max over the views of every mode's time and culled share.
//
// Per scene: the bricks are built once (as once per step in Lantern) and timed apart; then every
// mode runs `runs` times, modes interleaved run by run so that the machine's noise hits all of
// them alike. A frame's time is cull + instance building + render + readback (+ CPU splats).
// Prints a table per scene and writes DIR/culling_bench.csv and DIR/culling_bench.svg.
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <glm/geometric.hpp>

#include "bench_scenes.h"
#include "bench_timing.h"
#include "bond_bench.h"
#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/config/enum_names.h"
#include "core/culling/cull_stage.h"
#include "core/culling/cut_planes.h"
#include "core/particles/particle_scan.h"
#include "core/pipeline/scene_settings.h"
#include "core/render/cpu_sphere_pass.h"
#include "core/render/gl/gl_session.h"
#include "core/render/point_splats.h"
#include "core/render/sphere_instances.h"
#include "density_bench.h"
#include "error_plot.h"
#include "image_metrics.h"
#include "opaque_lod_bench.h"
#include "probabilistic_modes.h"
#include "scale_bench.h"
#include "supersampling_bench.h"

namespace lantern::bench {
namespace {

struct Options {
  std::vector<std::string> scenes{"fcc1m", "fcc10m", "inside", "void_impact", "droplet"};
  int size = 1024;
  int runs = 5;
  int md_cells = 64;
  std::string out = ".";
  bool images = false;
  std::vector<std::string> modes;  // --modes a,b: only these (brute_force always runs: reference)
  int azimuths = 1;                // --azimuths K: views per scene, evenly spaced about its up axis
  std::vector<int>
      samples;  // --samples 1,4,16: the super-sampling table instead (supersampling_bench.h)
  bool pipeline = false;  // --pipeline: with --samples, whole frames through the pipeline instead
  bool density = false;   // --density: style: density LOD against random samples (density_bench.h)
  bool opaque_lod = false;  // --opaque-lod: sphere LOD against random samples (opaque_lod_bench.h)
  ScaleOptions scale;       // --scale 10,38,100: whole frames at millions of particles
  std::vector<std::string> bond_scenes;  // --bond-scenes melt,network: bonded scenes (bond_bench.h)
  int64_t bond_atoms = 1000000;          // --bond-atoms N: their size
};

struct Mode {
  std::string name;
  bool brute = false;
  OcclusionMode occlusion = OcclusionMode::kNone;
  bool frustum = true;
  LodConfig lod;
  bool cpu = false;  // drawn by the CPU raster (renderer: cpu) instead of OpenGL
  NineSpheresRadius nine_radius = NineSpheresRadius::kWorld;  // culling.nine_spheres_radius
  ProbabilisticConfig probabilistic;  // culling.confidence etc. (probabilistic_modes.h)
};

std::vector<Mode> modes() {
  std::vector<Mode> m;
  m.push_back({"brute_force", true, OcclusionMode::kNone, false, {}});
  m.push_back({"frustum", false, OcclusionMode::kNone, true, {}});
  m.push_back({"nine_spheres", false, OcclusionMode::kNineSpheres, true, {}});
  m.push_back({"nine_spheres_sorted", false, OcclusionMode::kNineSpheresSorted, true, {}});
  for (const OcclusionMode nine :
       {OcclusionMode::kNineSpheres, OcclusionMode::kNineSpheresSorted}) {
    Mode eq{std::string(name_of(nine)) + "+equivalent", false, nine, true, {}};
    eq.nine_radius = NineSpheresRadius::kEquivalent;  // the conference version's radius
    m.push_back(eq);
  }
  m.push_back({"hzb", false, OcclusionMode::kHzb, true, {}});
  m.push_back({"auto", false, OcclusionMode::kAuto, true, {}});
  m.push_back({"cpu_raster", false, OcclusionMode::kNone, true, {}, true});
  m.push_back({"cpu_raster+hzb", false, OcclusionMode::kHzb, true, {}, true});
  for (const double f : {0.5, 0.25, 0.1}) {
    Mode lod{"lod_" + std::to_string(int(f * 100)) + "%", false, OcclusionMode::kNone, true, {}};
    lod.lod.fraction = f;
    m.push_back(lod);
  }
  Mode budget{"auto+budget_100k", false, OcclusionMode::kAuto, true, {}};
  budget.lod.budget = 100000;
  m.push_back(budget);
  Mode px{"auto+min_px_1", false, OcclusionMode::kAuto, true, {}};
  px.lod.min_pixels = 1.0;
  m.push_back(px);
  Mode points{"auto+point_path", false, OcclusionMode::kAuto, true, {}};
  points.lod.point_path = true;
  m.push_back(points);
  for (const ProbabilisticMode &p : probabilistic_modes()) {  // Ibrahim et al. 2022 (CPU raster)
    Mode prob{p.name, false, OcclusionMode::kProbabilistic, true, {}, true};
    prob.probabilistic = p.config;
    m.push_back(prob);
  }
  return m;
}

// `camera` turned by `degrees` about the vertical axis through what it looks at: the automatic
// camera through its azimuth (its distance does not depend on it), an explicit one by rotating
// its position about the up vector through look_at.
CameraConfig turned_about_up(const CameraConfig &camera, double degrees) {
  CameraConfig c = camera;
  if (!c.position) {
    c.azimuth += degrees;
    return c;
  }
  const glm::dvec3 target{c.look_at[0], c.look_at[1], c.look_at[2]};
  const glm::dvec3 axis = glm::normalize(glm::dvec3{c.up[0], c.up[1], c.up[2]});
  const glm::dvec3 v = glm::dvec3{(*c.position)[0], (*c.position)[1], (*c.position)[2]} - target;
  const double a = degrees * M_PI / 180.0;
  // Rodrigues' rotation of v about the unit axis.
  const glm::dvec3 turned = v * std::cos(a) + glm::cross(axis, v) * std::sin(a) +
                            axis * glm::dot(axis, v) * (1.0 - std::cos(a));
  const glm::dvec3 eye = target + turned;
  c.position = std::array<double, 3>{eye.x, eye.y, eye.z};
  return c;
}

struct Result {
  std::vector<double> total, cull, cull_cpu, render;
  CullStats stats;
  int64_t drawn = 0, splatted = 0;
  ImageError error;
  Frame frame;
};

class Bench {
 public:
  Bench(SphereRenderer *renderer, const Options &opt) : renderer_(renderer), opt_(opt) {}

  // Runs every mode on one scene; appends CSV rows and plot points.
  void run_scene(const BenchScene &bs, std::ostream &csv, std::vector<PlotPoint> *plot) {
    const ParticleArrays p = bs.arrays();
    const Extent ext = scan_particles(p, bs.config.per_particle_radius, bs.config.radius);
    const double max_radius = radius_rule(bs.config, p).max_radius(ext);
    // Bricks: once per step in Lantern; timed apart (median of 3 builds).
    std::vector<double> build;
    BrickSet bricks;
    BrickBuildTimings bt;
    for (int k = 0; k < 3; ++k) {
      bricks = BrickSet();
      const auto t0 = Clock::now();
      bricks = build_bricks(p, BrickOptions{}, &bt);
      build.push_back(ms_since(t0));
    }
    std::printf("\n== %s: %s, %dx%d\n", bs.name.c_str(), bs.note.c_str(), bs.config.width,
                bs.config.height);
    std::printf(
        "   bricks: %zu (<= 1024 particles), built in %.1f ms median of 3 (bounds %.1f, "
        "keys %.1f, scatter %.1f, cells %.1f; last build); once per step, "
        "shared by all scenes, not in the times below\n",
        bricks.bricks.size(), median(build), bt.bounds_ms, bt.keys_ms, bt.scatter_ms, bt.cells_ms);
    std::vector<Mode> all = modes();
    if (!opt_.modes.empty())
      all.erase(std::remove_if(all.begin() + 1, all.end(),
                               [this](const Mode &m) {
                                 return std::find(opt_.modes.begin(), opt_.modes.end(), m.name) ==
                                        opt_.modes.end();
                               }),
                all.end());
    const int views = std::max(1, opt_.azimuths);
    std::vector<std::vector<Result>> per_view(size_t(views), std::vector<Result>(all.size()));
    for (int k = 0; k < views; ++k) {
      BenchScene view;  // the scene's settings seen from azimuth k; particles stay in bs
      view.name = bs.name;
      view.config = bs.config;
      if (views > 1) {
        const double turn = 360.0 * k / views;
        view.config.camera = turned_about_up(bs.config.camera, turn);
        view.name += "@az+" + std::to_string(int(std::lround(turn)));
        std::printf("   -- view %d of %d: azimuth +%.1f degrees\n", k + 1, views, turn);
      }
      Camera cam;
      const glm::dvec3 lo{ext.lo[0], ext.lo[1], ext.lo[2]}, hi{ext.hi[0], ext.hi[1], ext.hi[2]};
      if (Status s = make_camera(view.config.camera, lo, hi, max_radius, view.config.width,
                                 view.config.height, &cam);
          !s.ok()) {
        std::printf("%s: camera: %s\n", view.name.c_str(), s.message.c_str());
        return;
      }
      const InstanceRecipe recipe =
          make_recipe(p, shading_settings(view.config), radius_rule(view.config, p), cam, ext);
      std::vector<Result> &results = per_view[size_t(k)];
      for (int run = 0; run < opt_.runs; ++run)
        for (size_t m = 0; m < all.size(); ++m)
          frame(view, p, bricks, cam, recipe, all[m], run == 0, &results[m]);
      print_and_record(view, int64_t(bs.type.size()), all, &results, csv, plot);
    }
    if (views > 1) print_stability(all, per_view, int64_t(bs.type.size()));
  }

  // False if an image of --images could not be written (each failure was printed).
  bool images_written() const { return images_written_; }

 private:
  void frame(const BenchScene &bs, const ParticleArrays &p, const BrickSet &bricks,
             const Camera &cam, const InstanceRecipe &recipe, const Mode &mode, bool keep,
             Result *r) {
    SceneConfig sc = bs.config;
    sc.culling.occlusion = mode.occlusion;
    sc.culling.frustum = mode.frustum;
    sc.culling.nine_spheres_radius = mode.nine_radius;
    sc.culling.probabilistic = mode.probabilistic;
    sc.lod = mode.lod;
    sc.renderer = mode.cpu ? RendererChoice::kCpu : RendererChoice::kOpenGl;
    const CullSettings cull = cull_settings(sc);  // resolved outside the timed work
    Frame &f = keep ? r->frame : scratch_frame_;
    if (mode.cpu) {  // one fused pass: culling and drawing
      const Rgb8 bg = to_rgb8(sc.background);
      const uint8_t background[4] = {bg[0], bg[1], bg[2], 255};
      const auto t0 = Clock::now();
      const double cpu0 = thread_cpu_ms();
      select_bricks(bricks, cam, cull, radius_rule(sc, p), &selection_);
      r->stats =
          cpu_pass_.run(p, bricks, cull, sc.lighting, selection_, recipe, background, &f, &draw_);
      r->drawn = r->stats.drawn;
      r->cull_cpu.push_back(thread_cpu_ms() - cpu0);
      r->cull.push_back(ms_since(t0));
      r->render.push_back(0.0);
      r->total.push_back(ms_since(t0));
      return;
    }
    const auto t0 = Clock::now();
    const double cpu0 = thread_cpu_ms();
    if (mode.brute) {
      brute_force_instances(p, sc, recipe);
      r->drawn = int64_t(instances_.size());
    } else {
      r->stats = culler_.run(p, bricks, cam, cull, radius_rule(sc, p), &draw_);
      if (draw_.everything)
        build_all_instances(recipe, &instances_);
      else
        build_selected_instances(recipe, draw_.spheres, &instances_);
      r->drawn = r->stats.drawn;
      r->splatted = r->stats.splatted;
    }
    const double cull_ms = ms_since(t0);
    r->cull_cpu.push_back(thread_cpu_ms() - cpu0);
    const auto t1 = Clock::now();
    const Rgb8 bg = to_rgb8(sc.background);
    const uint8_t background[4] = {bg[0], bg[1], bg[2], 255};
    RenderTimings t;
    if (Status s = renderer_->render(cam.render_view(background), instances_.data(),
                                     instances_.size(), &f, &t);
        !s.ok())
      std::printf("render failed: %s\n", s.message.c_str());
    if (!mode.brute && !draw_.points.empty())
      splat_points(
          p, recipe.per_particle_radius, recipe.radius, draw_.points, culler_.geometry(),
          [&recipe](int64_t i) { return recipe.color(i); }, &f);
    r->render.push_back(ms_since(t1));
    r->cull.push_back(cull_ms);
    r->total.push_back(ms_since(t0));
  }

  // Every finite particle, in published order; cutting planes are part of the scene, so brute
  // force applies them too (per particle, no bricks).
  void brute_force_instances(const ParticleArrays &p, const SceneConfig &sc,
                             const InstanceRecipe &recipe) {
    if (sc.cuts.empty()) {
      build_all_instances(recipe, &instances_);
      return;
    }
    const CutPlanes cuts(sc.cuts);
    instances_.clear();
    for (int64_t i = 0; i < p.count(); ++i) {
      const glm::dvec3 x = p.position(i);
      if (finite_position(x) && !cuts.drops(x)) instances_.push_back(recipe.make(i));
    }
  }

  // Fig. 7 of the nine-spheres paper's conference version: per mode, min / median / max over the
  // views of the frame time and the culled share, and the worst error of any view.
  static void print_stability(const std::vector<Mode> &all,
                              const std::vector<std::vector<Result>> &per_view, int64_t n) {
    std::printf(
        "   viewpoint stability over %zu azimuths (ms per frame and culled %%: min / "
        "median / max over the views; worst view's error)\n",
        per_view.size());
    std::printf("   %-30s %26s %26s %10s %8s\n", "mode", "ms/frame min/med/max",
                "culled % min/med/max", "max diff", "min PSNR");
    for (size_t m = 0; m < all.size(); ++m) {
      std::vector<double> ms, culled;
      int64_t worst_diff = 0;
      double worst_psnr = INFINITY;
      for (const std::vector<Result> &view : per_view) {
        const Result &r = view[m];
        ms.push_back(median(r.total));
        culled.push_back(culled_percent(r, n));
        worst_diff = std::max(worst_diff, r.error.differing_pixels);
        worst_psnr = std::min(worst_psnr, r.error.psnr);
      }
      const auto [ms_lo, ms_hi] = std::minmax_element(ms.begin(), ms.end());
      const auto [c_lo, c_hi] = std::minmax_element(culled.begin(), culled.end());
      std::printf("   %-30s %8.1f %8.1f %8.1f %7.1f%% %7.1f%% %7.1f%% %10lld %8.2f\n",
                  all[m].name.c_str(), *ms_lo, median(ms), *ms_hi, *c_lo, median(culled), *c_hi,
                  static_cast<long long>(worst_diff), worst_psnr);
    }
  }

  // The exact CPU image (cpu_raster+hzb, else cpu_raster) when it ran, for probabilistic's
  // level differences; nullptr otherwise.
  static const Frame *exact_cpu_frame(const std::vector<Mode> &all,
                                      const std::vector<Result> &results) {
    for (const char *name : {"cpu_raster+hzb", "cpu_raster"})
      for (size_t m = 0; m < all.size(); ++m)
        if (all[m].name == name) return &results[m].frame;
    return nullptr;
  }

  static double culled_percent(const Result &r, int64_t n) {
    return 100.0 * double(n - r.drawn - r.splatted) / double(std::max<int64_t>(n, 1));
  }

  // `bs` names the view (bs.config its settings); n: the scene's particle count.
  void print_and_record(const BenchScene &bs, int64_t n, const std::vector<Mode> &all,
                        std::vector<Result> *results, std::ostream &csv,
                        std::vector<PlotPoint> *plot) {
    const Result &brute = (*results)[0];
    const double brute_ms = median(brute.total);
    std::printf("   %-30s %9s %8s %8s %9s %10s %8s %10s %8s %7s %8s  %s\n", "mode", "ms/frame",
                "cull ms", "cull cpu", "render ms", "drawn", "culled", "diff px", "PSNR dB", "SSIM",
                "speed-up", "occlusion");
    for (size_t m = 0; m < all.size(); ++m) {
      Result &r = (*results)[m];
      r.error = m == 0 ? ImageError{0, 0, INFINITY, 1.0} : compare_frames(brute.frame, r.frame);
      const double ms = median(r.total);
      const double culled = culled_percent(r, n);
      char psnr[32];
      if (std::isinf(r.error.psnr))
        std::snprintf(psnr, sizeof psnr, "inf");
      else
        std::snprintf(psnr, sizeof psnr, "%.2f", r.error.psnr);
      std::string occ = all[m].brute ? "-" : r.stats.occlusion;
      if (all[m].occlusion == OcclusionMode::kProbabilistic)
        occ += probabilistic_note(r.stats.probabilistic, r.frame, exact_cpu_frame(all, *results));
      std::string drawn = std::to_string(r.drawn);
      if (r.splatted) drawn += "+" + std::to_string(r.splatted) + "pt";
      std::printf("   %-30s %9.1f %8.1f %8.1f %9.1f %10s %7.1f%% %10lld %8s %7.4f %7.1fx  %s\n",
                  all[m].name.c_str(), ms, median(r.cull), median(r.cull_cpu), median(r.render),
                  drawn.c_str(), culled, static_cast<long long>(r.error.differing_pixels), psnr,
                  r.error.ssim, brute_ms / ms, occ.c_str());
      csv << bs.name << ',' << all[m].name << ',' << ms << ',' << median(r.cull) << ','
          << median(r.cull_cpu) << ',' << median(r.render) << ',' << r.drawn << ',' << r.splatted
          << ',' << culled << ',' << r.error.differing_pixels << ',' << r.error.differing_depth
          << ',' << psnr << ',' << r.error.ssim << ',' << brute_ms / ms << ",\"" << occ << "\"\n";
      plot->push_back({bs.name, all[m].name, ms, r.error.psnr});
      if (opt_.images && (m == 0 || all[m].name == "hzb" || all[m].name == "nine_spheres" ||
                          all[m].name == "nine_spheres+equivalent" || all[m].name == "lod_25%" ||
                          all[m].name == "auto+point_path"))
        write_png(opt_.out + "/" + bs.name + "_" + all[m].name + ".png", r.frame);
    }
  }

  void write_png(const std::string &path, const Frame &f) {
    OIIO::ImageBuf buf(OIIO::ImageSpec(f.width, f.height, 4, OIIO::TypeDesc::UINT8));
    buf.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::UINT8, f.rgba.data());
    if (!buf.write(path)) {
      std::fprintf(stderr, "lantern-bench: cannot write %s: %s\n", path.c_str(),
                   buf.geterror().c_str());
      images_written_ = false;
    }
  }

  bool images_written_ = true;

  SphereRenderer *renderer_;
  const Options &opt_;
  Culler culler_;
  DrawList draw_;
  std::vector<SphereInstance> instances_;
  Frame scratch_frame_;
  BrickSelection selection_;  // CPU modes: the visible bricks
  CpuSpherePass cpu_pass_;    // CPU modes: culling and drawing in one pass
};

bool parse(int argc, char **argv, Options *o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--scenes") {
      o->scenes.clear();
      std::stringstream ss(value());
      for (std::string s; std::getline(ss, s, ',');) o->scenes.push_back(s);
    } else if (a == "--size") {
      o->size = std::stoi(value());
    } else if (a == "--runs") {
      o->runs = std::max(1, std::stoi(value()));
    } else if (a == "--md-cells") {
      o->md_cells = std::stoi(value());
    } else if (a == "--out") {
      o->out = value();
    } else if (a == "--images") {
      o->images = true;
    } else if (a == "--modes") {
      std::stringstream ss(value());
      for (std::string s; std::getline(ss, s, ',');) o->modes.push_back(s);
    } else if (a == "--azimuths") {
      o->azimuths = std::max(1, std::stoi(value()));
    } else if (a == "--samples") {
      std::stringstream ss(value());
      for (std::string s; std::getline(ss, s, ',');) o->samples.push_back(std::stoi(s));
    } else if (a == "--pipeline") {
      o->pipeline = true;
    } else if (a == "--density") {
      o->density = true;
    } else if (a == "--opaque-lod") {
      o->opaque_lod = true;
    } else if (a == "--scale") {
      std::stringstream ss(value());
      for (std::string s; std::getline(ss, s, ',');) o->scale.millions.push_back(std::stod(s));
    } else if (a == "--bond-scenes") {
      std::stringstream ss(value());
      for (std::string s; std::getline(ss, s, ',');) o->bond_scenes.push_back(s);
    } else if (a == "--bond-atoms") {
      o->bond_atoms = std::max<int64_t>(8, std::stoll(value()));
    } else if (a == "--scale-scenes") {
      o->scale.scenes.clear();
      std::stringstream ss(value());
      for (std::string s; std::getline(ss, s, ',');) o->scale.scenes.push_back(s);
    } else {
      std::fprintf(stderr,
                   "usage: lantern-bench [--scenes fcc1m,fcc10m,inside,void_impact,droplet] "
                   "[--size 1024] [--runs 5] [--md-cells 64] [--out DIR] [--images] "
                   "[--modes hzb,cpu_raster+hzb,...] [--azimuths K] [--samples 1,4,16 "
                   "[--pipeline]] [--density] [--opaque-lod] [--scale 10,38,100 "
                   "[--scale-scenes fcc,heterogeneous]] "
                   "[--bond-scenes melt,network [--bond-atoms 1000000]]\n"
                   "  a scene name may end in :uniform or :bimodal (mixed radii)\n");
      return false;
    }
  }
  return true;
}

int run(int argc, char **argv) {
  Options opt;
  if (!parse(argc, argv, &opt)) return 2;
  // The output directory first (a missing one is created): a run of minutes must not end in a
  // file that cannot be written.
  std::error_code ec;
  std::filesystem::create_directories(opt.out, ec);
  if (ec) {
    std::fprintf(stderr, "lantern-bench: --out %s: cannot create the directory: %s\n",
                 opt.out.c_str(), ec.message().c_str());
    return 1;
  }
  if (!opt.scale.millions.empty()) {  // whole frames through the pipeline, under mpiexec
    opt.scale.runs = opt.runs;
    opt.scale.size = opt.size;
    opt.scale.out = opt.out;
    return run_scale_bench(opt.scale) ? 0 : 1;
  }
  if (!opt.bond_scenes.empty()) {  // bonded scenes on the CPU raster, instead of the table
    const std::string path = opt.out + "/bond_bench.csv";
    std::ofstream csv(path);
    csv << bond_csv_header();
    std::printf("lantern-bench: bonded scenes, LP_NUM_THREADS=%s, %d runs per mode (median)\n",
                std::getenv("LP_NUM_THREADS") ? std::getenv("LP_NUM_THREADS") : "(default)",
                opt.runs);
    bool exact = true;
    for (const std::string &name : opt.bond_scenes)
      if (!run_bond_bench(name, opt.bond_atoms, opt.size, opt.runs, csv, &exact))
        std::printf("\n== %s: unknown bonded scene (melt or network)\n", name.c_str());
    csv.close();
    if (csv.fail()) {
      std::fprintf(stderr, "lantern-bench: cannot write %s\n", path.c_str());
      return 1;
    }
    std::printf("\nwrote %s\n", path.c_str());
    return exact ? 0 : 1;  // an exact mode that is not is a failure
  }
  const std::string table = opt.density           ? "density_bench"
                            : opt.opaque_lod      ? "opaque_lod_bench"
                            : opt.samples.empty() ? "culling_bench"
                                                  : "supersampling_bench";
  const std::string csv_path = opt.out + "/" + table + ".csv";
  const std::string svg_path = opt.out + "/" + table + ".svg";
  std::shared_ptr<GlSession> session;
  SphereRenderer *renderer = nullptr;
  if (const Status gl = acquire_renderer(GlBackend::kAuto, &session, &renderer); !gl.ok()) {
    std::fprintf(stderr, "lantern-bench: %s\n", gl.message.c_str());
    return 1;
  }
  const char *threads = std::getenv("LP_NUM_THREADS");
  std::printf("lantern-bench: %s, LP_NUM_THREADS=%s, %d runs per mode (median)\n",
              session->description().c_str(), threads ? threads : "(default)", opt.runs);
  std::ofstream csv(csv_path);
  if (!csv) {
    std::fprintf(stderr, "lantern-bench: cannot write %s: %s\n", csv_path.c_str(),
                 std::strerror(errno));
    return 1;
  }
  if (opt.density)
    csv << density_csv_header();
  else if (opt.opaque_lod)
    csv << opaque_lod_csv_header();
  else if (opt.samples.empty())
    csv << "scene,mode,ms_per_frame,cull_ms,cull_cpu_ms,render_ms,drawn,splatted,culled_percent,"
           "differing_pixels,differing_depth,psnr_db,ssim,speedup,occlusion\n";
  else
    csv << supersampling_csv_header();
  std::vector<PlotPoint> plot;
  Bench bench(renderer, opt);
  bool density_images_ok = true;
  for (const std::string &requested : opt.scenes) {
    BenchScene s;
    std::string why;
    const size_t colon = requested.find(':');  // name:uniform / name:bimodal: mixed radii
    const std::string name = requested.substr(0, colon);
    const std::string radii = colon == std::string::npos ? "" : requested.substr(colon + 1);
    if (name == "fcc1m") {
      s = fcc_outside(63, opt.size);
    } else if (name == "fcc10m") {
      s = fcc_outside(136, opt.size);
    } else if (name == "inside") {
      s = fcc_inside(63, opt.size);
    } else if (name == "heterogeneous") {
      s = heterogeneous(63, opt.size);
    } else if (name == "fcc_small") {
      s = fcc_outside(24, opt.size);
    } else if (name == "clustered") {
      s = clustered_cloud(4000000, opt.size);
    } else if (name == "film") {
      s = thin_film(250, opt.size);
    } else if (name == "void_impact" || name == "droplet") {
      if (!mini_md_scene(name, opt.md_cells, opt.size, &s, &why)) {
        std::printf("\n== %s: skipped: %s\n", name.c_str(), why.c_str());
        continue;
      }
    } else {
      std::printf("\n== %s: unknown scene\n", name.c_str());
      continue;
    }
    if (!radii.empty() && !assign_radii(radii, &s)) {
      std::printf("\n== %s: unknown radius mix '%s' (uniform or bimodal)\n", name.c_str(),
                  radii.c_str());
      continue;
    }
    if (opt.density) {
      density_images_ok &= run_density_bench(s, opt.runs, opt.images ? opt.out : "", csv, &plot);
    } else if (opt.opaque_lod) {
      run_opaque_lod_bench(s, opt.runs, csv, &plot);
    } else if (opt.samples.empty()) {
      bench.run_scene(s, csv, &plot);
    } else {
      if (opt.pipeline)  // instead of the table: MPI-parallel, every rank renders its share
        run_supersampling_pipeline(s, opt.samples, opt.runs, opt.out);
      else
        run_supersampling_scene(s, opt.samples, opt.runs, csv, &plot);
    }
    std::fflush(stdout);
  }
  // Say only what was written; any file that was not makes the exit status 1.
  csv.close();
  bool ok = !csv.fail();
  if (!ok)
    std::fprintf(stderr, "lantern-bench: cannot write %s\n", csv_path.c_str());
  else
    std::printf("\nwrote %s\n", csv_path.c_str());
  if (auto e = write_error_plot(svg_path, plot); !e.empty()) {
    std::fprintf(stderr, "lantern-bench: %s\n", e.c_str());
    ok = false;
  } else {
    std::printf("wrote %s\n", svg_path.c_str());
  }
  return ok && bench.images_written() && density_images_ok ? 0 : 1;
}

}  // namespace
}  // namespace lantern::bench

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  const int rc = lantern::bench::run(argc, argv);
  MPI_Finalize();
  return rc;
}
