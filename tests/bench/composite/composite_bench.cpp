// lantern-bench-composite: compositing on the ranks it is launched with, in three modes
// (tests/bench/composite.sh runs them and builds the tables).
//
// Methods (default): times composite_frames for each method and image size on synthetic frames.
// Each timing is root's wall time inside composite_frames after a barrier, including scratch
// allocation, packing and unpacking; the median of --reps runs after --warmup runs is printed:
//   ranks=<p> size=<w>x<h> method=<name> ran=<method that ran> median_ms=<m> min_ms=<m> runs=<n>
//
// Scaling (--scene=fcc:<cells>): one fixed scene split spatially over the ranks (scene_frames.h),
// composited by today's dense methods and by active pixels (the model's schedule and fixed ones)
// as the pipeline composites it: to one root with one sample, into row bands with --samples. Per
// configuration, one line from rank 0 with bytes and messages per rank (max and mean over the
// ranks), active pixels, the cost model's estimate, the CPU time of each rank's own compositing
// work (scan, encode, merge; medians over --reps, never wall time: ranks share cores), root's wall
// time (meaningful only when every rank has a core), and whether the image is byte-identical to the
// first configuration's (and, with --check, to the scene drawn on one rank):
//   scale ranks=<p> target=root|bands config=<c> method=<m> schedule=<s> bytes_sent_max=<b> ...
// Configurations run interleaved, run by run, each run starting one configuration further, so
// machine drift and position hit them alike.
//
// Model (--model --ranks=<p> --pixels=<n> --active=<a> --latency-us=<l> --gb-per-s=<g>, and the
// CPU figures per pixel --scan-ns, --encode-ns, --merge-ns, --dense-merge-ns): the cost model's
// estimates for one case, no MPI traffic (for extrapolating beyond the ranks at hand).
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/composite/band_compositing.h"
#include "core/composite/composite_cost_model.h"
#include "core/composite/compositing_schedule.h"
#include "core/composite/depth_compositor.h"
#include "core/view/frame.h"
#include "scene_frames.h"

namespace {

struct Options {
  std::vector<std::pair<int, int>> sizes{{1024, 1024}, {1920, 1080}, {4096, 4096}, {6144, 3072}};
  std::vector<std::string> methods{"reduce64",    "reduce_scatter", "binary_swap",
                                   "direct_send", "active_pixels",  "auto"};
  int reps = 7;
  int warmup = 2;
  size_t chunk = 0;
  // Scaling mode.
  int scene_cells = 0;            // > 0: --scene=fcc:<cells>
  int samples = 1;                // rays per pixel (1, 4, 16): > 1 adds the row-band target
  bool check = false;             // compare with the scene drawn on one rank
  std::vector<std::string> only;  // --configs=a,b: run only these configurations (and the first)
  // Model mode.
  bool model = false;
  long long model_ranks = 0, model_pixels = 0, model_active = 0;
  double latency_us = 0, gb_per_s = 0;
  double scan_ns = 0, encode_ns = 0, merge_ns = 0, dense_merge_ns = 0;  // CPU per pixel
};

std::vector<std::string> split(const std::string &text, char sep) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, sep);)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

bool parse_options(int argc, char **argv, Options *o) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&](const char *name) -> const char * {
      const std::string prefix = std::string(name) + "=";
      return arg.rfind(prefix, 0) == 0 ? argv[i] + prefix.size() : nullptr;
    };
    if (const char *v = value("--sizes")) {
      o->sizes.clear();
      for (const std::string &s : split(v, ',')) {
        int w = 0, h = 0;
        if (std::sscanf(s.c_str(), "%dx%d", &w, &h) != 2 || w <= 0 || h <= 0) return false;
        o->sizes.emplace_back(w, h);
      }
    } else if (const char *v = value("--methods")) {
      o->methods = split(v, ',');
    } else if (const char *v = value("--reps")) {
      o->reps = std::max(1, std::atoi(v));
    } else if (const char *v = value("--warmup")) {
      o->warmup = std::max(0, std::atoi(v));
    } else if (const char *v = value("--chunk")) {
      o->chunk = size_t(std::strtoull(v, nullptr, 10));
    } else if (const char *v = value("--scene")) {
      if (std::sscanf(v, "fcc:%d", &o->scene_cells) != 1 || o->scene_cells <= 0) return false;
    } else if (const char *v = value("--samples")) {
      o->samples = std::atoi(v);
      if (o->samples != 1 && o->samples != 4 && o->samples != 16) return false;
    } else if (const char *v = value("--configs")) {
      o->only = split(v, ',');
    } else if (arg == "--check") {
      o->check = true;
    } else if (arg == "--model") {
      o->model = true;
    } else if (const char *v = value("--ranks")) {
      o->model_ranks = std::atoll(v);
    } else if (const char *v = value("--pixels")) {
      o->model_pixels = std::atoll(v);
    } else if (const char *v = value("--active")) {
      o->model_active = std::atoll(v);
    } else if (const char *v = value("--latency-us")) {
      o->latency_us = std::atof(v);
    } else if (const char *v = value("--gb-per-s")) {
      o->gb_per_s = std::atof(v);
    } else if (const char *v = value("--scan-ns")) {
      o->scan_ns = std::atof(v);
    } else if (const char *v = value("--encode-ns")) {
      o->encode_ns = std::atof(v);
    } else if (const char *v = value("--merge-ns")) {
      o->merge_ns = std::atof(v);
    } else if (const char *v = value("--dense-merge-ns")) {
      o->dense_merge_ns = std::atof(v);
    } else {
      return false;
    }
  }
  return true;
}

// Something like a rendered frame: a diagonal depth ramp over half the image, background
// elsewhere, different per rank so the merge has real work to do.
lantern::Frame test_frame(int width, int height, int rank) {
  lantern::Frame f(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = f.index(x, y);
      const bool drawn = ((x / 64 + y / 64 + rank) % 2) == 0;
      f.depth[i] = drawn ? float((x + y + 7 * rank) % 1000) / 1000.0f : lantern::kBackgroundDepth;
      for (int c = 0; c < 4; ++c) f.rgba[4 * i + c] = uint8_t(drawn ? 40 * rank + c : 0);
    }
  }
  return f;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Schedule names hold spaces ("radix_k 4x2"); key=value lines cannot.
std::string no_spaces(std::string text) {
  std::replace(text.begin(), text.end(), ' ', '_');
  return text.empty() ? "-" : text;
}

bool same_pixels(const lantern::Frame &a, const lantern::Frame &b, size_t first, size_t last) {
  return std::memcmp(a.depth.data() + first, b.depth.data() + first, 4 * (last - first)) == 0 &&
         std::memcmp(a.rgba.data() + 4 * first, b.rgba.data() + 4 * first, 4 * (last - first)) == 0;
}

// Every rank's pixels [lo, hi) of `mine` into *full on rank 0 (same size as mine there).
void gather_bands(const lantern::Frame &mine, size_t lo, size_t hi, int ranks,
                  lantern::Frame *full) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const int count = int(hi - lo), first = int(lo);
  std::vector<int> counts(static_cast<size_t>(ranks)), firsts(static_cast<size_t>(ranks));
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  MPI_Gather(&first, 1, MPI_INT, firsts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (rank == 0) *full = lantern::Frame(mine.width, mine.height);
  MPI_Gatherv(mine.depth.data() + lo, count, MPI_FLOAT, rank == 0 ? full->depth.data() : nullptr,
              counts.data(), firsts.data(), MPI_FLOAT, 0, MPI_COMM_WORLD);
  MPI_Gatherv(mine.rgba.data() + 4 * lo, count, MPI_UINT32_T,
              rank == 0 ? full->rgba.data() : nullptr, counts.data(), firsts.data(), MPI_UINT32_T,
              0, MPI_COMM_WORLD);
}

// ---- methods mode ------------------------------------------------------------------------------

int run_methods(const Options &options, int rank, int ranks) {
  int status = 0;
  for (const auto &[width, height] : options.sizes) {
    lantern::Frame frame = test_frame(width, height, rank);
    for (const std::string &name : options.methods) {
      lantern::CompositeMethod method;
      if (!lantern::parse_composite_method(name, &method)) {
        if (rank == 0) std::fprintf(stderr, "unknown method %s\n", name.c_str());
        status = 2;
        continue;
      }
      std::vector<double> times;
      std::string ran;
      for (int run = 0; run < options.warmup + options.reps; ++run) {
        MPI_Barrier(MPI_COMM_WORLD);
        lantern::CompositeStats stats;
        const lantern::Status composited =
            lantern::composite_frames(MPI_COMM_WORLD, frame, 0, method, options.chunk, &stats);
        if (!composited.ok()) {
          if (rank == 0) std::fprintf(stderr, "%s: %s\n", name.c_str(), composited.message.c_str());
          status = 1;
          break;
        }
        ran = stats.method;
        if (run >= options.warmup) times.push_back(stats.milliseconds);
      }
      if (rank == 0 && !times.empty())
        std::printf("ranks=%d size=%dx%d method=%s ran=%s median_ms=%.3f min_ms=%.3f runs=%zu\n",
                    ranks, width, height, name.c_str(), ran.c_str(), median(times),
                    *std::min_element(times.begin(), times.end()), times.size());
      std::fflush(stdout);
    }
  }
  return status;
}

// ---- scaling mode ------------------------------------------------------------------------------

struct Config {
  std::string name;  // what the table calls it
  bool bands = false;
  lantern::CompositeOptions options;
};

struct Runs {
  std::vector<double> cpu_ms, wall_ms;
  lantern::CompositeStats last;
  bool identical = true;
  std::string error;
};

std::vector<Config> scaling_configs(int ranks, int samples_per_axis,
                                    const lantern::CompositeCostModel &model) {
  using lantern::CompositeMethod;
  std::vector<Config> configs;
  const auto add = [&](const std::string &name, bool bands, CompositeMethod m,
                       std::optional<lantern::CompositingSchedule> schedule = std::nullopt) {
    Config c{name, bands, {}};
    c.options.method = m;
    c.options.model = &model;
    c.options.schedule = std::move(schedule);
    configs.push_back(c);
  };
  // What the pipeline runs: to the root with one sample, into row bands with more. Today's
  // methods first: every other configuration's image is compared with theirs.
  if (samples_per_axis > 1) {
    add("dense_direct_send_bands", true, CompositeMethod::kDirectSend);
    add("active_auto_bands", true, CompositeMethod::kAuto);
    return configs;
  }
  add("dense_binary_swap", false, CompositeMethod::kBinarySwap);
  add("dense_direct_send", false, CompositeMethod::kDirectSend);
  add("active_auto", false, CompositeMethod::kAuto);
  for (const lantern::CompositingSchedule &s : lantern::candidate_schedules(ranks, true)) {
    const std::string name = s.name();
    if (name == "direct_send" || name == "tree_reduce" || name.rfind("binary_swap", 0) == 0)
      add("active_" + name.substr(0, name.find(' ')), false, CompositeMethod::kActivePixels, s);
  }
  return configs;
}

int run_scaling(const Options &options, int rank, int ranks) {
  const int s = options.samples == 16 ? 4 : options.samples == 4 ? 2 : 1;
  const int width = options.sizes.front().first, height = options.sizes.front().second;
  const lantern::bench::SceneFrame scene =
      lantern::bench::draw_fcc_share(MPI_COMM_WORLD, options.scene_cells, width, height, s);
  int drawn_ok = scene.error.empty(), all_ok = 0;
  MPI_Allreduce(&drawn_ok, &all_ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (!all_ok) {
    if (!scene.error.empty()) std::fprintf(stderr, "rank %d: %s\n", rank, scene.error.c_str());
    return 1;
  }
  // The model every rank chooses schedules by, measured here as the pipeline measures it.
  lantern::CompositeCostModel model;
  if (ranks > 1 && !lantern::measure_cost_model(MPI_COMM_WORLD, &model).ok()) return 1;
  if (ranks == 1) model = lantern::default_cost_model();
  if (rank == 0) {
    std::printf("scene ranks=%d note=\"%s\"\n", ranks, scene.note.c_str());
    std::printf(
        "model ranks=%d latency_us=%.3f gb_per_s=%.3f scan_ns=%.3f encode_ns=%.3f merge_ns=%.3f "
        "dense_merge_ns=%.3f measured=%d\n",
        ranks, model.latency_s * 1e6, model.bytes_per_s * 1e-9, model.scan_s * 1e9,
        model.encode_s * 1e9, model.merge_s * 1e9, model.dense_merge_s * 1e9, int(model.measured));
  }
  std::vector<Config> configs = scaling_configs(ranks, s, model);
  if (!options.only.empty()) {
    // The first configuration stays: it is the reference image.
    std::vector<Config> kept{configs.front()};
    for (size_t c = 1; c < configs.size(); ++c)
      if (std::find(options.only.begin(), options.only.end(), configs[c].name) !=
          options.only.end())
        kept.push_back(configs[c]);
    configs = kept;
  }
  std::vector<Runs> runs(configs.size());
  // Byte-identity: root images against the first root configuration's (on rank 0); each rank's
  // band against the first band configuration's (on every rank). Only those are kept.
  const lantern::RowBand band = lantern::row_band(height * s, ranks, rank, s);
  const size_t band_lo = size_t(band.y0) * size_t(width * s),
               band_hi = size_t(band.y1) * size_t(width * s);
  lantern::Frame root_reference, band_reference;
  bool have_root = false, have_band = false;
  for (int run = 0; run < options.warmup + options.reps; ++run) {
    // Each timed run after the first starts one configuration further, so no configuration always
    // follows the same one (the machine's state after a method is not charged to the next one
    // alone); the first, which checks the images, runs in order.
    const size_t offset = run > options.warmup ? size_t(run - options.warmup) : 0;
    for (size_t k = 0; k < configs.size(); ++k) {
      const size_t c = (k + offset) % configs.size();
      lantern::Frame frame = scene.frame;  // compositing consumes its frame
      MPI_Barrier(MPI_COMM_WORLD);
      lantern::CompositeStats stats;
      lantern::Status st;
      const bool bands = configs[c].bands;
      if (bands) {
        lantern::RowBand owned;
        st = lantern::composite_to_row_bands(MPI_COMM_WORLD, frame, s, &owned, configs[c].options,
                                             &stats);
      } else {
        st = lantern::composite_frames(MPI_COMM_WORLD, frame, 0, configs[c].options, &stats);
      }
      if (!st.ok()) runs[c].error = st.message;
      if (run < options.warmup) continue;
      runs[c].cpu_ms.push_back(stats.traffic.work_cpu_ms);
      runs[c].wall_ms.push_back(stats.milliseconds);
      runs[c].last = stats;
      if (run != options.warmup) continue;
      if (bands) {
        if (!have_band) band_reference = frame, have_band = true;
        runs[c].identical = same_pixels(frame, band_reference, band_lo, band_hi);
      } else if (rank == 0) {
        if (!have_root) root_reference = frame, have_root = true;
        runs[c].identical = same_pixels(frame, root_reference, 0, frame.pixel_count());
      }
    }
  }
  std::string one_rank = "-";
  if (options.check) {
    // The scene drawn whole on rank 0 alone, against the composited image of today's method
    // (with bands: every rank's band gathered on rank 0 first).
    if (s > 1) gather_bands(band_reference, band_lo, band_hi, ranks, &root_reference);
    int same = 1;
    if (rank == 0) {
      const lantern::bench::SceneFrame alone =
          lantern::bench::draw_fcc_share(MPI_COMM_SELF, options.scene_cells, width, height, s);
      same = alone.error.empty() &&
             same_pixels(alone.frame, root_reference, 0, alone.frame.pixel_count());
    }
    MPI_Bcast(&same, 1, MPI_INT, 0, MPI_COMM_WORLD);
    one_rank = same ? "yes" : "NO";
  }
  int failures = 0;
  for (size_t c = 0; c < configs.size(); ++c) {
    const Runs &r = runs[c];
    const lantern::CompositeStats &st = r.last;
    const lantern::CompositeTraffic &t = st.traffic;
    // Max and sum over the ranks in one reduction each.
    double mine[7] = {double(t.bytes_sent),
                      double(t.bytes_received),
                      double(t.messages_sent),
                      double(t.messages_received),
                      double(st.active_pixels),
                      median(r.cpu_ms),
                      double(r.identical && r.error.empty())};
    double most[7], sum[7], least[7];
    MPI_Reduce(mine, most, 7, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    MPI_Reduce(mine, sum, 7, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
    MPI_Reduce(mine, least, 7, MPI_DOUBLE, MPI_MIN, 0, MPI_COMM_WORLD);
    if (rank != 0) continue;
    const bool ok = least[6] > 0;
    failures += !ok;
    std::printf(
        "scale ranks=%d target=%s config=%s method=%s schedule=%s size=%dx%d samples=%d "
        "bytes_sent_max=%.0f bytes_sent_mean=%.0f bytes_received_max=%.0f "
        "messages_sent_max=%.0f messages_received_max=%.0f active_max=%.0f active_mean=%.0f "
        "model_ms=%.4f cpu_ms_max=%.3f cpu_ms_mean=%.3f wall_ms=%.3f wall_min_ms=%.3f identical=%s "
        "one_rank=%s runs=%zu%s%s\n",
        ranks, configs[c].bands ? "bands" : "root", configs[c].name.c_str(), st.method.c_str(),
        no_spaces(st.schedule).c_str(), width, height, options.samples, most[0], sum[0] / ranks,
        most[1], most[2], most[3], most[4], sum[4] / ranks, st.model_ms, most[5], sum[5] / ranks,
        median(r.wall_ms),
        r.wall_ms.empty() ? 0.0 : *std::min_element(r.wall_ms.begin(), r.wall_ms.end()),
        ok ? "yes" : "NO", one_rank.c_str(), r.wall_ms.size(),
        r.error.empty() ? "" : " error=", r.error.c_str());
  }
  std::fflush(stdout);
  return failures == 0 && one_rank != "NO" ? 0 : 1;
}

// ---- model mode --------------------------------------------------------------------------------

int run_model(const Options &o) {
  lantern::CompositeCostModel model;
  model.latency_s = o.latency_us * 1e-6;
  model.bytes_per_s = o.gb_per_s * 1e9;
  model.scan_s = o.scan_ns * 1e-9;
  model.encode_s = o.encode_ns * 1e-9;
  model.merge_s = o.merge_ns * 1e-9;
  model.dense_merge_s = o.dense_merge_ns * 1e-9;
  model.measured = false;
  if (o.model_ranks < 2 || o.model_pixels <= 0 || model.latency_s <= 0 || model.bytes_per_s <= 0)
    return 2;
  const int p = int(o.model_ranks);
  const size_t n = size_t(o.model_pixels), a = size_t(std::max(0LL, o.model_active));
  // Today's method: dense binary swap (every pixel sent, no scan), to the root.
  lantern::CompositingSchedule dense_schedule;
  for (const lantern::CompositingSchedule &s : lantern::candidate_schedules(p, true))
    if (s.name().rfind("binary_swap", 0) == 0) {
      dense_schedule = s;
      break;
    }
  const lantern::CostEstimate dense = lantern::estimate_dense_binary_swap(p, n, model);
  lantern::CostEstimate active;
  const lantern::CompositingSchedule best =
      lantern::cheapest_schedule(p, n, a, true, model, &active);
  const lantern::CostEstimate active_binary =
      lantern::estimate_active_pixels(dense_schedule, n, a, true, model);
  std::printf(
      "model ranks=%d pixels=%zu active=%zu latency_us=%.3f gb_per_s=%.3f "
      "dense_schedule=%s dense_ms=%.4f dense_bytes_sent=%.0f dense_messages=%.0f "
      "active_binary_ms=%.4f active_binary_bytes_sent=%.0f "
      "active_schedule=%s active_ms=%.4f active_bytes_sent=%.0f active_messages=%.0f\n",
      p, n, a, o.latency_us, o.gb_per_s, no_spaces(dense_schedule.name()).c_str(),
      dense.seconds * 1e3, dense.bytes_sent, dense.messages_sent, active_binary.seconds * 1e3,
      active_binary.bytes_sent, no_spaces(best.name()).c_str(), active.seconds * 1e3,
      active.bytes_sent, active.messages_sent);
  return 0;
}

}  // namespace

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  Options options;
  if (!parse_options(argc, argv, &options)) {
    if (rank == 0)
      std::fprintf(stderr,
                   "usage: lantern-bench-composite [--sizes=1024x1024,...] [--methods=reduce64,"
                   "reduce_scatter,binary_swap,direct_send,active_pixels,auto] [--reps=7] "
                   "[--warmup=2] [--chunk=pixels]\n"
                   "       lantern-bench-composite --scene=fcc:<cells> [--sizes=WxH] "
                   "[--samples=1|4|16] [--check] [--reps=N] [--warmup=N]\n"
                   "       lantern-bench-composite --model --ranks=P --pixels=N --active=A "
                   "--latency-us=L --gb-per-s=G [--scan-ns=S --encode-ns=E --merge-ns=M "
                   "--dense-merge-ns=D]\n");
    MPI_Finalize();
    return 2;
  }
  int status = 0;
  if (options.model) {
    status = rank == 0 ? run_model(options) : 0;
  } else if (options.scene_cells > 0) {
    status = run_scaling(options, rank, ranks);
  } else {
    status = run_methods(options, rank, ranks);
  }
  MPI_Finalize();
  return status;
}
