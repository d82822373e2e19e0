// lantern-bench-cues: the frame time of each depth cue (issue 13) against the same scene without
// it, through the whole pipeline (core/pipeline/runtime.h: bricks, culling, drawing, compositing,
// cues, PNG writing), every variant rendered at every step so the machine's noise hits them alike.
//
//   mpiexec -n 2 lantern-bench-cues [--scenes fcc1m,void_impact] [--size 1024] [--steps 5]
//                                   [--md-cells 30] [--out DIR]
//
// Per scene it prints the median over steps of the pipeline's own per-scene time (stats "ms.total",
// rank 0) of each variant and its ratio to the plain one. Particles: fcc split in blocks over the
// ranks; void_impact as mini_md's domain decomposition hands them out.
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
#include "core/pipeline/runtime.h"

namespace {

using lantern::bench::BenchScene;

struct Variant {
  const char *name;
  const char *keys;  // YAML added to the scene
};

const Variant kVariants[] = {
    {"plain", ""},
    {"screen_ao", "    ambient_occlusion: {method: screen}\n"},
    {"object_ao", "    ambient_occlusion: {method: object}\n"},
    {"outline", "    outline: {}\n"},
    {"depth_cue", "    depth_cue: {}\n"},
    {"all_screen", "    ambient_occlusion: {method: screen}\n    outline: {}\n    depth_cue: {}\n"},
};

std::string number(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

// The bench scene's configuration as YAML: size, radius, camera, cuts, colour by type.
std::string scene_yaml(const BenchScene &bs, const Variant &v, const std::string &dir) {
  const lantern::SceneConfig &c = bs.config;
  std::string y = std::string("  - name: ") + v.name + "\n    width: " + std::to_string(c.width) +
                  "\n    height: " + std::to_string(c.height) +
                  "\n    radius: " + number(c.radius) +
                  "\n    camera: {azimuth: " + number(c.camera.azimuth) +
                  ", elevation: " + number(c.camera.elevation) +
                  ", zoom: " + number(c.camera.zoom) + "}\n    color: {by: type}\n";
  if (!c.cuts.empty()) {
    y += "    cut_planes:\n";
    for (const lantern::CutPlane &p : c.cuts)
      y += "      - {normal: [" + number(p.normal[0]) + ", " + number(p.normal[1]) + ", " +
           number(p.normal[2]) + "], offset: " + number(p.offset) + "}\n";
  }
  return y + v.keys + "    output: {pattern: '" + dir + "/" + bs.name +
         "_{scene}_{step:04d}.png'}\n";
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  std::vector<std::string> scenes{"fcc1m", "void_impact"};
  int size = 1024, steps = 5, md_cells = 30;
  std::string out = "/tmp/lantern_bench_cues";
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
    }
  }
  if (rank == 0) std::system(("mkdir -p '" + out + "'").c_str());
  MPI_Barrier(MPI_COMM_WORLD);
  int failures = 0;
  for (const std::string &name : scenes) {
    BenchScene bs;
    std::string why;
    if (name == "fcc1m") {
      bs = lantern::bench::fcc_outside(63, size);
      // Blocks of the lattice order over the ranks (a spatial decomposition, roughly).
      const size_t n = bs.type.size(), lo = n * size_t(rank) / size_t(ranks),
                   hi = n * size_t(rank + 1) / size_t(ranks);
      bs.xyz = std::vector<double>(bs.xyz.begin() + 3 * lo, bs.xyz.begin() + 3 * hi);
      bs.type = std::vector<int32_t>(bs.type.begin() + lo, bs.type.begin() + hi);
    } else if (!lantern::bench::mini_md_scene(name, md_cells, size, &bs, &why)) {
      if (rank == 0) std::fprintf(stderr, "%s: %s\n", name.c_str(), why.c_str());
      ++failures;
      continue;
    }
    const std::string stats = out + "/" + name + "_stats.jsonl";
    if (rank == 0) std::remove(stats.c_str());
    std::string yaml = "stats: " + stats + "\nscenes:\n";
    for (const Variant &v : kVariants) yaml += scene_yaml(bs, v, out);
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
    std::map<std::string, std::vector<double>> ms, cues;
    std::ifstream in(stats);
    for (std::string line; std::getline(in, line);) {
      const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
      if (j.is_discarded() || !j.contains("scenes") || j.value("step", 0) == 0) continue;
      for (const auto &sc : j["scenes"]) {
        ms[sc["scene"]].push_back(sc["ms"]["total"]);
        cues[sc["scene"]].push_back(sc["ms"].value("cues", 0.0));
      }
    }
    std::printf("%s (%s), %dx%d, %d ranks, median of %d steps:\n", name.c_str(), bs.note.c_str(),
                size, size, ranks, steps);
    const double plain = median(ms["plain"]);
    for (const Variant &v : kVariants)
      std::printf("  %-11s %8.1f ms  x%.3f   (cue stage %6.1f ms = %5.1f%% of plain)\n", v.name,
                  median(ms[v.name]), median(ms[v.name]) / plain, median(cues[v.name]),
                  100.0 * median(cues[v.name]) / plain);
  }
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
