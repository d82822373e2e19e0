// lantern-bench-budget: scenes under `budget_ms`, through the whole pipeline
// (core/pipeline/runtime.h), against the same scene at full quality.
//
//   mpiexec -n 2 lantern-bench-budget [--scenes fcc1m,void_impact] [--size 1024] [--steps 8]
//                                     [--budgets 10,20,40,80] [--md-cells 30] [--out DIR]
//                                     [--ao screen|object]
//
// Full quality is the bench scene with `samples: 4` and screen ambient occlusion at
// `resolution: full` (`--ao object`: object-space ambient occlusion at its defaults instead). One
// run per scene holds, as scenes of one configuration rendered at every step (so the machine's
// noise hits them alike): a copy that pays for the step's bricks (not reported), every rung of the
// budget's ladder written out as plain settings (rung 0 is full quality), and the full-quality
// scene once per budget with `budget_ms`. The particles do not move, so every step's full-quality
// frame is the same picture.
//
// Prints, per scene, the ladder (median ms of each rung over the steps, its cost relative to the
// rung above against the prior the controller starts from, PSNR and SSIM against full quality
// against the controller's estimate) and, per budget, the median ms, the largest ms after the
// third rendered step and its ratio to the budget, the rungs chosen at each step, and PSNR / SSIM
// of the last step's image against the full-quality frame.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_scenes.h"
#include "bench_timing.h"
#include "core/pipeline/render_budget.h"
#include "core/pipeline/runtime.h"
#include "frame_file.h"
#include "image_metrics.h"

namespace {

using lantern::bench::BenchScene;

std::string number(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

// The bench scene as a YAML scene named `name` with `keys` added, its images under dir; drawn by
// the CPU raster with hzb.
std::string scene_yaml(const BenchScene &bs, const std::string &name, const std::string &keys,
                       const std::string &dir) {
  return "  - name: " + name + "\n" + lantern::bench::scene_yaml_keys(bs) +
         "    renderer: cpu\n    culling: {occlusion: hzb}\n" + keys + "    output: {pattern: '" +
         dir + "/" + bs.name + "_{scene}_{step:04d}.png'}\n";
}

// A rung's settings written out as configuration keys.
std::string rung_keys(const lantern::SceneConfig &full, const lantern::BudgetRung &r) {
  const lantern::SceneConfig s = lantern::scene_at_rung(full, r);
  std::string k = "    samples: " + std::to_string(s.samples) + "\n";
  if (s.lod.fraction < 1.0) k += "    lod: {fraction: " + number(s.lod.fraction) + "}\n";
  if (s.ambient_occlusion.enabled &&
      s.ambient_occlusion.method == lantern::AmbientOcclusionMethod::kObject)
    k += "    ambient_occlusion: {method: object, max_nodes: " +
         std::to_string(s.ambient_occlusion.max_nodes) + "}\n";
  else if (s.ambient_occlusion.enabled)
    k += std::string("    ambient_occlusion: {method: screen, resolution: ") +
         (s.ambient_occlusion.resolution == lantern::AoResolution::kFull ? "full" : "half") + "}\n";
  return k;
}

}  // namespace

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  std::vector<std::string> scenes{"fcc1m", "void_impact"};
  std::vector<double> budgets{10, 20, 40, 80};
  int size = 1024, steps = 8, md_cells = 30;
  std::string out = "/tmp/lantern_bench_budget";
  bool object_ao = false;
  // An option the bench does not know, or one without its value, stops it: a typo must not run
  // the default benchmark for minutes and print it as what was asked for.
  const auto usage = [&](const std::string &why) {
    if (rank == 0)
      std::fprintf(stderr,
                   "lantern-bench-budget: %s\nusage: lantern-bench-budget [--scenes "
                   "fcc1m,void_impact] [--size 1024] [--steps 8] [--budgets 10,20,40,80] "
                   "[--md-cells 30] [--out DIR] [--ao screen|object]\n",
                   why.c_str());
    MPI_Finalize();
    return 2;
  };
  if (argc % 2 == 0) return usage(std::string(argv[argc - 1]) + " has no value");
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    std::stringstream list(v);
    if (a == "--scenes") {
      scenes.clear();
      for (std::string s; std::getline(list, s, ',');) scenes.push_back(s);
    } else if (a == "--budgets") {
      budgets.clear();
      for (std::string s; std::getline(list, s, ',');) budgets.push_back(std::stod(s));
    } else if (a == "--size") {
      size = std::stoi(v);
    } else if (a == "--steps") {
      steps = std::stoi(v);
    } else if (a == "--md-cells") {
      md_cells = std::stoi(v);
    } else if (a == "--out") {
      out = v;
    } else if (a == "--ao") {
      if (v != "screen" && v != "object") {
        if (rank == 0) std::fprintf(stderr, "--ao: screen or object, not '%s'\n", v.c_str());
        MPI_Finalize();
        return 2;
      }
      object_ao = v == "object";
    } else {
      return usage("unknown option " + a);
    }
  }
  const std::string full_keys =
      object_ao ? "    samples: 4\n    ambient_occlusion: {method: object}\n"
                : "    samples: 4\n    ambient_occlusion: {method: screen, resolution: full}\n";
  const char *full_name = object_ao ? "object AO" : "screen AO full";
  if (rank == 0) std::system(("mkdir -p '" + out + "'").c_str());
  MPI_Barrier(MPI_COMM_WORLD);
  int failures = 0;
  for (const std::string &name : scenes) {
    BenchScene bs;
    std::string why;
    if (name == "fcc1m" || name == "fcc10m") {
      bs = lantern::bench::fcc_outside(name == "fcc1m" ? 63 : 136, size);
      lantern::bench::keep_rank_block(&bs, rank, ranks);
    } else if (!lantern::bench::mini_md_scene(name, md_cells, size, &bs, &why)) {
      if (rank == 0) std::fprintf(stderr, "%s: %s\n", name.c_str(), why.c_str());
      ++failures;
      continue;
    }
    lantern::SceneConfig full = bs.config;
    full.samples = 4;
    full.ambient_occlusion.enabled = true;
    if (object_ao)
      full.ambient_occlusion.method = lantern::AmbientOcclusionMethod::kObject;
    else
      full.ambient_occlusion.resolution = lantern::AoResolution::kFull;
    const std::vector<lantern::BudgetRung> ladder = lantern::budget_ladder(full);

    const std::string stats = out + "/" + bs.name + "_stats.jsonl";
    if (rank == 0) std::remove(stats.c_str());
    std::string yaml = "stats: " + stats + "\nscenes:\n" + scene_yaml(bs, "bricks", "", out);
    for (size_t r = 0; r < ladder.size(); ++r)
      yaml += scene_yaml(bs, "rung" + std::to_string(r), rung_keys(full, ladder[r]), out);
    for (double b : budgets)
      yaml += scene_yaml(bs, "budget" + number(b), full_keys + "    budget_ms: " + number(b) + "\n",
                         out);
    std::unique_ptr<lantern::Runtime> rt;
    lantern::ParticleDescription d;
    d.count = int64_t(bs.type.size());
    d.position = {bs.xyz.data(), lantern::DataType::kFloat64, 0};
    d.type = {bs.type.data(), lantern::DataType::kInt32, 0};
    lantern::Status s = lantern::Runtime::open(yaml, MPI_COMM_WORLD, &rt);
    if (s.ok()) s = rt->publish(d);
    for (int step = 0; s.ok() && step < steps; ++step) s = rt->execute(step, step);
    if (s.ok()) s = rt->finish();
    rt.reset();
    if (!s.ok()) {
      if (rank == 0) std::fprintf(stderr, "%s: %s\n", name.c_str(), s.message.c_str());
      ++failures;
      continue;
    }
    if (rank != 0) continue;
    // Per scene: ms.total of every step, and the budget objects.
    std::map<std::string, std::vector<double>> ms;
    std::map<std::string, std::vector<nlohmann::json>> chosen;
    std::ifstream in(stats);
    for (std::string line; std::getline(in, line);) {
      const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
      if (j.is_discarded() || !j.contains("scenes")) continue;
      for (const auto &sc : j["scenes"]) {
        ms[sc["scene"]].push_back(sc["ms"]["total"]);
        if (sc.contains("budget")) chosen[sc["scene"]].push_back(sc["budget"]);
      }
    }
    const auto image = [&](const std::string &scene, int step) {
      char file[64];
      std::snprintf(file, sizeof file, "_%04d.png", step);
      return lantern::bench::read_frame(out + "/" + bs.name + "_" + scene + file);
    };
    const lantern::Frame reference = image("rung0", steps - 1);
    std::printf("%s (%s), %dx%d, %d ranks, %d steps; full quality: samples 4, %s\n", name.c_str(),
                bs.note.c_str(), size, size, ranks, steps, full_name);
    std::printf("  ladder (median ms over steps 1..%d; PSNR/SSIM against rung 0):\n", steps - 1);
    std::printf("    %-4s %-10s %5s %7s %5s %-8s %9s %7s %11s\n", "rung", "gives_up", "lod",
                "samples", "ao", "ms", "cost/up", "prior", "PSNR SSIM  est.");
    double above = 0.0;
    for (size_t r = 0; r < ladder.size(); ++r) {
      const std::string sc = "rung" + std::to_string(r);
      std::vector<double> t(ms[sc].begin() + 1, ms[sc].end());  // step 0 pays first-touch costs
      const double m = lantern::bench::median(t);
      const lantern::bench::ImageError e =
          lantern::bench::compare_frames(reference, image(sc, steps - 1));
      std::printf("    %-4zu %-10s %5.2f %7d %5s %8.1f %9.2f %7.2f %6.2f %6.4f %5.1f\n", r,
                  r == 0 ? "-" : ladder[r].gives_up.c_str(), ladder[r].lod_fraction,
                  ladder[r].samples, lantern::budget_ao_name(full, ladder[r]).c_str(), m,
                  r == 0 ? 1.0 : m / above, ladder[r].step_cost, e.psnr, e.ssim,
                  std::isinf(ladder[r].psnr_db) ? 99.0 : ladder[r].psnr_db);
      above = m;
    }
    std::printf(
        "  budgets (median ms over all steps; max ms from step 3 on; last step's image):\n");
    std::printf("    %-7s %8s %8s %8s  %-26s %7s %7s %6s\n", "budget", "median", "max>=3",
                "max/bud", "rungs chosen, step 0..", "PSNR", "SSIM", "est.");
    for (double b : budgets) {
      const std::string sc = "budget" + number(b);
      const std::vector<double> &t = ms[sc];
      double late = 0.0;
      for (size_t i = 3; i < t.size(); ++i) late = std::max(late, t[i]);
      std::string rungs;
      for (const nlohmann::json &c : chosen[sc]) rungs += std::to_string(c["rung"].get<int>());
      const nlohmann::json &last = chosen[sc].back();
      const lantern::bench::ImageError e =
          lantern::bench::compare_frames(reference, image(sc, steps - 1));
      std::printf("    %-7.0f %8.1f %8.1f %8.2f  %-26s %7.2f %7.4f %6s%s\n", b,
                  lantern::bench::median(t), late, late / b,
                  (rungs + " (" + last["gives_up"].get<std::string>() + ")").c_str(), e.psnr,
                  e.ssim,
                  last["psnr_db"].is_null()
                      ? "exact"
                      : std::to_string(int(last["psnr_db"].get<double>() + 0.5)).c_str(),
                  last["unmet"].get<bool>() ? "  unmet" : "");
      std::string skipped;
      for (const auto &g : last.value("skipped", nlohmann::json::array()))
        skipped += (skipped.empty() ? "" : ", ") + g.get<std::string>();
      if (!skipped.empty()) std::printf("            skipped as not paying: %s\n", skipped.c_str());
    }
    std::fflush(stdout);
  }
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
