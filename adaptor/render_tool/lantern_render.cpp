// lantern-render CONFIG.yaml INPUT [--steps a,b,c | --steps a:b] [--split space|rows]
//                [--bonds DATA]
//
// Renders particle dumps after the run through the same pipeline as in situ: it is a client of
// the public C API (open, publish, set_box, execute with the dump's step and time, close), so a
// configuration gives the same images offline as in the simulation. MPI-parallel: each rank
// reads only its share of every frame (hyperslabs for H5MD, its rows for LAMMPS text dumps);
// then, by default, the ranks trade particles so that each renders one contiguous run of the
// frame's z-order curve (spatial_split.h) instead of its rows of the file.
// The configuration's `schedule:` still applies to the dump's steps; to render every selected
// frame, give a configuration without a schedule. --bonds DATA takes the bonds from a LAMMPS data
// file or dump local (bond_topology.h) for the scenes with a `bonds:` section; without it, an
// H5MD input's own bonds (its /connectivity, as Lantern's dumps write it) are drawn where a scene
// has a `bonds:` section. With bonds every rank reads every frame whole, to find the ghost atoms
// its bonds end at.
//
// Exit codes: 0 success, 1 bad input or a failed step (message on stderr), 2 usage.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "bond_topology.h"
#include "c_translation.h"
#include "command_line/usage_reply.h"
#include "core/config/config_loader.h"
#include "frame_source.h"
#include "lantern/lantern.h"
#include "spatial_split.h"
#include "step_selection.h"

namespace {

constexpr const char *kUsage =
    "usage: lantern-render CONFIG.yaml INPUT [--steps a,b,c | --steps a:b] [--split space|rows]\n"
    "                      [--bonds DATA]\n"
    "       lantern-render --help | --version\n"
    "  INPUT: an H5MD file (Lantern's dump: output) or a LAMMPS text dump (dump atom/custom)\n"
    "  --split: space gives each rank a contiguous run of the frame's z-order curve (the default,\n"
    "           unless the configuration writes a dump: a conversion keeps the file's order);\n"
    "           rows gives each rank its rows of the file as read\n"
    "  DATA: a LAMMPS data file whose Bonds section gives the bonds (by atom id), or a dump\n"
    "  local of the bonds' atom ids per step (compute property/local batom1 batom2 [btype]);\n"
    "  an H5MD INPUT with bonds (/connectivity, as Lantern's dumps write it) needs none\n";

struct Options {
  std::string config, input, steps, bonds;
  std::string split;  // --split: space, rows, or "" (space, unless the configuration dumps)
};

// "" and *out, "help" or "version" when asked, or a usage error.
std::string parse_options(int argc, char **argv, Options *out) {
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--steps") {
      if (i + 1 >= argc) return "--steps needs a value (a,b,c or a:b)";
      out->steps = argv[++i];
    } else if (arg.rfind("--steps=", 0) == 0) {
      out->steps = arg.substr(8);
    } else if (arg == "--bonds") {
      if (i + 1 >= argc) return "--bonds needs a LAMMPS data file";
      out->bonds = argv[++i];
    } else if (arg == "--split" || arg.rfind("--split=", 0) == 0) {
      std::string value;
      if (arg == "--split") {
        if (i + 1 >= argc) return "--split needs a value (space or rows)";
        value = argv[++i];
      } else {
        value = arg.substr(8);
      }
      if (value != "space" && value != "rows")
        return "--split must be space or rows, not '" + value + "'";
      out->split = value;
    } else if (arg == "-h" || arg == "--help") {
      return "help";
    } else if (arg == "--version") {
      return "version";
    } else if (arg.rfind("--", 0) == 0) {
      return "unknown option " + arg;
    } else {
      positional.push_back(arg);
    }
  }
  if (positional.size() != 2) return "expected CONFIG.yaml and INPUT";
  out->config = positional[0];
  out->input = positional[1];
  return {};
}

// Collective: the message of the lowest-numbered rank that has one, on every rank ("" if none).
std::string agree(const std::string &local) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int first = local.empty() ? size : rank;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == size) return {};
  int length = static_cast<int>(local.size());
  MPI_Bcast(&length, 1, MPI_INT, first, MPI_COMM_WORLD);
  std::string message = rank == first ? local : std::string(static_cast<size_t>(length), ' ');
  MPI_Bcast(message.data(), length, MPI_CHAR, first, MPI_COMM_WORLD);
  return message;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Owns the Lantern context for the run.
struct ContextCloser {
  void operator()(lantern_context *ctx) const { lantern_close(ctx); }
};
using Context = std::unique_ptr<lantern_context, ContextCloser>;

// This rank's bonds of `share` as lantern_bonds, borrowing its vectors.
lantern_bonds bonds_of(const lantern::BondedShare &share) {
  lantern_bonds b{};
  b.count = static_cast<int64_t>(share.first.size());
  b.first = {share.first.data(), LANTERN_INT64, 0};
  b.second = {share.second.data(), LANTERN_INT64, 0};
  b.type = {share.type.data(), LANTERN_INT64, 0};
  b.ghost_count = share.frame.count() - share.owned;
  b.listing = LANTERN_BONDS_LISTED_ONCE;
  return b;
}

// Reads, publishes and renders one frame, with the bonds of `bonds` if given. "" or an error
// (the same on every rank).
// With `spatial`, the particles go through the spatial split, whose spread of particles over the
// ranks goes to *split; with bonds, each rank then finds its atoms and its bonds' ghosts among the
// rows of the whole frame.
std::string render_frame(lantern_context *ctx, const lantern::FrameSource &source, size_t index,
                         const std::string &input, const lantern::BondTopology *topology, int rank,
                         int size, bool spatial, lantern::SplitStats *split) {
  const lantern::FrameInfo &info = source.frames()[index];
  if (info.count == 0) return input + ": step " + std::to_string(info.step) + " has zero particles";
  const auto [begin, end] = lantern::rank_share(info.count, rank, size);
  lantern::ParticleFrame frame;
  lantern::BondedShare share;
  const std::string where = input + ": step " + std::to_string(info.step) + ": ";
  if (topology) {  // the whole frame, for the ghosts of this rank's bonds
    lantern::ParticleFrame all;
    if (auto e = agree(source.read(index, 0, info.count, &all)); !e.empty()) return e;
    std::vector<int64_t> rows(size_t(end - begin));
    std::iota(rows.begin(), rows.end(), begin);
    if (spatial) {  // this rank's run of the curve, found in the whole frame by atom id
      if (auto e = agree(source.read(index, begin, end, &frame)); !e.empty()) return e;
      if (auto e = lantern::split_spatially(MPI_COMM_WORLD, &frame, split); !e.empty())
        return where + e;
      if (auto e = agree(lantern::rows_of_ids(all, frame.id, &rows)); !e.empty()) return where + e;
    }
    std::string e = lantern::share_with_bonds(all, rows, *topology, &share);
    if (auto agreed = agree(e.empty() ? e : where + e); !agreed.empty()) return agreed;
    if (rank == 0 && share.skipped > 0)
      std::fprintf(stderr,
                   "lantern-render: %sleft out %lld bonds whose atoms are not in the frame\n",
                   where.c_str(), static_cast<long long>(share.skipped));
  } else {
    if (auto e = agree(source.read(index, begin, end, &frame)); !e.empty()) return e;
    if (spatial)
      if (auto e = lantern::split_spatially(MPI_COMM_WORLD, &frame, split); !e.empty())
        return where + e;
  }
  const lantern::ParticleFrame &published = topology ? share.frame : frame;
  lantern_particles particles = lantern::to_c(published.view());
  if (topology) particles.count = share.owned;  // the ghosts follow, uncounted
  lantern_status st = lantern_publish(ctx, &particles);
  if (st == LANTERN_OK && topology) {
    const lantern_bonds bonds = bonds_of(share);
    st = lantern_publish_bonds(ctx, &bonds);
  }
  std::string local = st == LANTERN_OK ? "" : where + lantern_error_message(ctx);
  if (local.empty() && published.box) {
    const lantern::Box &box = *published.box;
    const int periodic[3] = {box.periodic[0], box.periodic[1], box.periodic[2]};
    const lantern_status set =
        box.triclinic ? lantern_set_triclinic_box(ctx, box.low.data(), box.high.data(),
                                                  box.tilt.data(), periodic)
                      : lantern_set_box(ctx, box.low.data(), box.high.data(), periodic);
    if (set != LANTERN_OK) local = where + lantern_error_message(ctx);
  }
  if (auto e = agree(local); !e.empty()) return e;
  // Collective; the same status on every rank.
  st = lantern_execute(ctx, published.step, published.time);
  if (st != LANTERN_OK)
    return "step " + std::to_string(published.step) + ": " + lantern_error_message(ctx);
  return {};
}

int run(const Options &opt, int rank, int size) {
  auto fail = [&](const std::string &message) {
    if (rank == 0) std::fprintf(stderr, "lantern-render: error: %s\n", message.c_str());
    return 1;
  };
  std::unique_ptr<lantern::FrameSource> source;
  if (auto e = agree(lantern::open_frame_source(opt.input, MPI_COMM_WORLD, &source)); !e.empty())
    return fail(e);
  std::vector<size_t> selected;
  if (auto e = lantern::select_frames(opt.steps, source->frames(), &selected); !e.empty())
    return fail(e);
  lantern::BondSource bonds;
  if (!opt.bonds.empty())
    if (auto e = agree(lantern::read_bond_source(opt.bonds, &bonds)); !e.empty()) return fail(e);

  lantern_context *raw = nullptr;
  const lantern_status opened =
      lantern_open(opt.config.c_str(), MPI_Comm_c2f(MPI_COMM_WORLD), &raw);
  const Context ctx(raw);
  if (opened != LANTERN_OK) return fail(lantern_error_message(ctx.get()));

  // The spatial split reorders particles between ranks: a conversion (a configuration with a
  // dump) keeps the file's order unless asked otherwise. The configuration loaded fine above.
  lantern::Config config;
  const bool loaded = lantern::load_config(opt.config, &config).ok();
  const bool dumps = loaded && config.dump.enabled;
  const bool spatial = opt.split == "space" || (opt.split.empty() && !dumps);
  // The input's own bonds (an H5MD file's connectivity) where a scene draws bonds and --bonds
  // gives none.
  const bool draws_bonds = loaded && std::any_of(config.scenes.begin(), config.scenes.end(),
                                                 [](const auto &s) { return s.bonds.enabled; });
  const bool file_bonds = opt.bonds.empty() && draws_bonds && source->has_bonds();
  const auto start = std::chrono::steady_clock::now();
  for (size_t k = 0; k < selected.size(); ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    lantern::SplitStats split;
    const int64_t step = source->frames()[selected[k]].step;
    const lantern::BondTopology *topology = nullptr;
    lantern::BondTopology from_file;
    if (!opt.bonds.empty()) {
      topology = bonds.at(step);
      if (!topology) return fail("the bond file has no bonds for step " + std::to_string(step));
    } else if (file_bonds) {
      if (auto e = agree(source->read_bonds(selected[k], &from_file)); !e.empty()) return fail(e);
      topology = &from_file;
    }
    if (auto e = render_frame(ctx.get(), *source, selected[k], opt.input, topology, rank, size,
                              spatial, &split);
        !e.empty())
      return fail(e);
    if (rank == 0) {
      char spread[96] = "";
      if (spatial && size > 1)
        std::snprintf(spread, sizeof spread, ", spatial split %lld..%lld per rank (imbalance %.2f)",
                      static_cast<long long>(split.least), static_cast<long long>(split.most),
                      split.imbalance());
      std::fprintf(stderr, "[%zu/%zu] step %lld: %lld particles%s, %.2f s (total %.1f s)\n", k + 1,
                   selected.size(), static_cast<long long>(source->frames()[selected[k]].step),
                   static_cast<long long>(source->frames()[selected[k]].count), spread,
                   seconds_since(t0), seconds_since(start));
    }
  }
  // Rank 0, when the configuration writes stats: how the last frame's work spread over the ranks.
  if (const std::string load = lantern_load_summary(ctx.get()); !load.empty())
    std::fprintf(stderr, "lantern-render: per-rank load, %s", load.c_str());
  return 0;
}

}  // namespace

int main(int argc, char **argv) {
  Options opt;
  const std::string usage_error = parse_options(argc, argv, &opt);
  // --help and --version answer on stdout without starting MPI; a usage error goes to stderr.
  if (const std::optional<int> code =
          lantern_tools::reply_to_usage("lantern-render", usage_error, kUsage))
    return *code;
  // Offline, nothing waits on the encoder but this tool: every frame goes into a movie (unless
  // the caller's environment says otherwise).
  setenv("LANTERN_MOVIE_WHEN_BEHIND", "wait", /*overwrite=*/0);
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const int code = run(opt, rank, size);
  MPI_Finalize();
  return code;
}
