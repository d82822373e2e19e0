// Rank-count invariance of the whole pipeline through the C API: the same particles, rendered on
// one rank (rank 0 alone, MPI_COMM_SELF) and on every rank of MPI_COMM_WORLD under several
// splits (all on one rank, round robin, blocks, slabs, hashed), give pixel-identical images in
// both projections and every coloring, with a camera that moves with the step, and with bonds
// too, in both listings, with ghosts and periodic images. Run under mpiexec with 1, 2, 3, 4 and 8
// ranks.
#include <gtest/gtest.h>

#include <mpi.h>

#include <unistd.h>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "lantern/lantern.h"
#include "tests/support/bonded_molecules.h"
#include "tests/support/hash_noise.h"
#include "tests/support/image_file.h"
#include "tests/support/mpi_world.h"
#if LANTERN_TEST_MOVIES
#include "tests/support/movie_file.h"
#endif

namespace lantern::testing {
namespace {

// Structure-of-arrays particles, as a simulation would own them.
struct Particles {
  std::vector<double> x, y, z, radius, scalar;
  std::vector<int32_t> type;
  std::vector<int64_t> id;
  size_t size() const { return x.size(); }
  void push(const Particles &from, size_t i) {
    x.push_back(from.x[i]);
    y.push_back(from.y[i]);
    z.push_back(from.z[i]);
    radius.push_back(from.radius[i]);
    scalar.push_back(from.scalar[i]);
    type.push_back(from.type[i]);
    id.push_back(from.id[i]);
  }
};

// A clustered cloud in [0, 10]^3 with varied radii, types and scalars.
Particles make_particles(int count) {
  Particles p;
  for (int i = 0; i < count; ++i) {
    const uint32_t h = hash(uint32_t(i) * 2654435761U + 17U);
    const double cluster = double(h % 3);
    p.x.push_back(2.0 + 3.0 * cluster + 2.5 * unit(hash(h + 1)));
    p.y.push_back(10.0 * unit(hash(h + 2)));
    p.z.push_back(10.0 * unit(hash(h + 3)) * (0.5 + 0.2 * cluster));
    p.radius.push_back(0.15 + 0.35 * unit(hash(h + 4)));
    p.scalar.push_back(std::sin(0.7 * p.x.back()) * p.y.back());
    p.type.push_back(int32_t(hash(h + 5) % 5));
    p.id.push_back(i);
  }
  return p;
}

enum class Split { kAllOnFirst, kAllOnLast, kRoundRobin, kBlocks, kSlabsByX, kHashed };
const Split kSplits[] = {Split::kAllOnFirst, Split::kAllOnLast, Split::kRoundRobin,
                         Split::kBlocks,     Split::kSlabsByX,  Split::kHashed};
const char *split_name(Split s) {
  switch (s) {
    case Split::kAllOnFirst:
      return "all_on_first";
    case Split::kAllOnLast:
      return "all_on_last";
    case Split::kRoundRobin:
      return "round_robin";
    case Split::kBlocks:
      return "blocks";
    case Split::kSlabsByX:
      return "slabs_by_x";
    case Split::kHashed:
      return "hashed";
  }
  return "?";
}

int owner(Split s, const Particles &p, size_t i, int ranks) {
  switch (s) {
    case Split::kAllOnFirst:
      return 0;
    case Split::kAllOnLast:
      return ranks - 1;
    case Split::kRoundRobin:
      return int(i % size_t(ranks));
    case Split::kBlocks:
      return int(i * size_t(ranks) / p.size());
    case Split::kSlabsByX:
      return std::min(ranks - 1, std::max(0, int(p.x[i] / 10.0 * ranks)));
    case Split::kHashed:
      return int(hash(uint32_t(i) + 99U) % uint32_t(ranks));
  }
  return 0;
}

Particles owned_by(Split s, const Particles &all, int rank, int ranks) {
  Particles mine;
  for (size_t i = 0; i < all.size(); ++i)
    if (owner(s, all, i, ranks) == rank) mine.push(all, i);
  return mine;
}

lantern_particles describe(const Particles &p) {
  lantern_particles d{};
  d.count = int64_t(p.size());
  d.position_x = {p.x.data(), LANTERN_FLOAT64, 0};
  d.position_y = {p.y.data(), LANTERN_FLOAT64, 0};
  d.position_z = {p.z.data(), LANTERN_FLOAT64, 0};
  d.radius = {p.radius.data(), LANTERN_FLOAT64, 0};
  d.scalar = {p.scalar.data(), LANTERN_FLOAT64, 0};
  d.type = {p.type.data(), LANTERN_INT32, 0};
  d.id = {p.id.data(), LANTERN_INT64, 0};
  return d;
}

// Both projections times every coloring (and a per-particle radius), small images.
// persp_zoom looks at the middle only, so on slab splits some ranks have no pixel in view.
const char *const kSceneNames[] = {"persp_type",   "persp_scalar", "persp_solid", "ortho_type",
                                   "ortho_scalar", "ortho_solid",  "persp_zoom"};

std::string scene_yaml(const std::string &name, const std::string &projection,
                       const std::string &color, const std::string &radius,
                       const std::string &pattern, double zoom = 1.3, int height = 90) {
  return "  - name: " + name + "\n    width: 120\n    height: " + std::to_string(height) +
         "\n    background: [0.1, 0.2, 0.3]\n" + "    radius: " + radius +
         "\n    camera: {projection: " + projection +
         ", azimuth: 35, elevation: 25, zoom: " + std::to_string(zoom) + "}\n    color: " + color +
         "\n    output: {pattern: \"" + pattern + "\"}\n";
}

// `top`: extra top-level keys; `each`: extra keys for every scene (indented by four spaces);
// `colored`: extra keys for the scenes colored by type or scalar (not solid).
std::string config_yaml(const std::string &directory, const std::string &prefix,
                        const std::string &top = "", const std::string &each = "",
                        const std::string &colored = "", int height = 90) {
  const std::string pattern = directory + "/" + prefix + "_{scene}_{step:06d}.png";
  const auto scene_yaml = [&each, height](const std::string &name, const std::string &projection,
                                          const std::string &color, const std::string &radius,
                                          const std::string &pattern, double zoom = 1.3) {
    return ::lantern::testing::scene_yaml(name, projection, color, radius, pattern, zoom, height) +
           each;
  };
  return top + "scenes:\n" + scene_yaml("persp_type", "perspective", "{by: type}", "0.4", pattern) +
         colored +
         scene_yaml("persp_scalar", "perspective", "{by: scalar, colormap: viridis}",
                    "per_particle", pattern) +
         colored +
         scene_yaml("persp_solid", "perspective", "{by: solid, solid: [0.9, 0.5, 0.1]}", "0.4",
                    pattern) +
         scene_yaml("ortho_type", "orthographic", "{by: type}", "per_particle", pattern) + colored +
         scene_yaml("ortho_scalar", "orthographic",
                    "{by: scalar, colormap: coolwarm, range: [-5, 5]}", "0.4", pattern) +
         colored +
         scene_yaml("ortho_solid", "orthographic", "{by: solid}", "per_particle", pattern) +
         scene_yaml("persp_zoom", "perspective", "{by: type}", "0.4", pattern, 6.0) + colored;
}

std::string file_of(const std::string &directory, const std::string &prefix,
                    const std::string &scene, int step) {
  char name[64];
  std::snprintf(name, sizeof name, "_%s_%06d.png", scene.c_str(), step);
  return directory + "/" + prefix + name;
}

// "" if identical, else how many pixels differ.
std::string compare_images(const std::string &expected_path, const std::string &actual_path) {
  const ImagePixels e = read_image(expected_path), a = read_image(actual_path);
  if (!e.error.empty()) return e.error;
  if (!a.error.empty()) return a.error;
  if (e.width != a.width || e.height != a.height || e.channels != a.channels)
    return "image shapes differ";
  size_t differing = 0;
  const size_t pixels = size_t(e.width) * e.height, c = size_t(e.channels);
  for (size_t i = 0; i < pixels; ++i)
    for (size_t k = 0; k < c; ++k)
      if (e.pixels[i * c + k] != a.pixels[i * c + k]) {
        ++differing;
        break;
      }
  if (differing == 0) {
    // PNG bands do not depend on who compressed them: the files are the same bytes too.
    return read_bytes(expected_path) == read_bytes(actual_path)
               ? std::string()
               : "same pixels but different file bytes (" + actual_path + ")";
  }
  return std::to_string(differing) + " of " + std::to_string(pixels) + " pixels differ (" +
         expected_path + " vs " + actual_path + ")";
}

// A scratch directory made by rank 0 and known to every rank.
std::string shared_directory() {
  char path[256] = "/tmp/lantern_rank_invariance_XXXXXX";
  if (world_rank() == 0 && mkdtemp(path) == nullptr) path[0] = '\0';
  MPI_Bcast(path, sizeof path, MPI_CHAR, 0, MPI_COMM_WORLD);
  return path;
}

struct Render {
  lantern_status status = LANTERN_OK;
  std::string error;
};

// Opens a context on comm, publishes `mine`, and renders step `step` once. Collective on comm.
Render render_once(MPI_Comm comm, const std::string &config, const Particles &mine, int step) {
  Render r;
  lantern_context *ctx = nullptr;
  r.status = lantern_open(config.c_str(), MPI_Comm_c2f(comm), &ctx);
  if (r.status == LANTERN_OK) {
    // The simulation box (the overlays' box: rank 0's is drawn), the same on every rank.
    const double low[3] = {-0.5, -0.5, -0.5}, high[3] = {10.5, 10.5, 10.5};
    const int periodic[3] = {1, 1, 0};
    r.status = lantern_set_box(ctx, low, high, periodic);
  }
  if (r.status == LANTERN_OK) {
    const lantern_particles d = describe(mine);
    r.status = lantern_publish(ctx, &d);
    // Publishing is local: every rank must still enter the collective execute.
    const lantern_status executed = lantern_execute(ctx, step, double(step));
    if (r.status == LANTERN_OK) r.status = executed;
  }
  r.error = lantern_error_message(ctx);
  lantern_close(ctx);
  return r;
}

// `config` with every scene's background replaced by `background` ("" keeps the colour).
std::string with_background(std::string config, const std::string &background) {
  if (background.empty()) return config;
  const std::string colour = "background: [0.1, 0.2, 0.3]";
  for (size_t at = config.find(colour); at != std::string::npos; at = config.find(colour, at))
    config.replace(at, colour.size(), "background: " + background);
  return config;
}

// Renders `all` on rank 0 alone, then under every split on all ranks; compares on rank 0.
void expect_rank_invariant(const Particles &all, const std::string &label,
                           const std::string &top = "", const std::string &each = "",
                           const std::string &colored = "", const std::string &background = "",
                           int height = 90) {
  const std::string dir = shared_directory();
  ASSERT_FALSE(dir.empty());
  const int rank = world_rank(), ranks = world_size();
  if (rank == 0) {
    const Render ref = render_once(
        MPI_COMM_SELF,
        with_background(config_yaml(dir, label + "_ref", top, each, colored, height), background),
        all, 0);
    EXPECT_EQ(ref.status, LANTERN_OK) << ref.error;
  }
  const std::string config =
      with_background(config_yaml(dir, label, top, each, colored, height), background);
  for (size_t s = 0; s < std::size(kSplits); ++s) {
    const Render r =
        render_once(MPI_COMM_WORLD, config, owned_by(kSplits[s], all, rank, ranks), int(s));
    EXPECT_EQ(r.status, LANTERN_OK) << split_name(kSplits[s]) << ": " << r.error;
  }
  if (rank != 0) return;
  bool all_same = true;
  for (size_t s = 0; s < std::size(kSplits); ++s) {
    for (const char *scene : kSceneNames) {
      const std::string difference = compare_images(file_of(dir, label + "_ref", scene, 0),
                                                    file_of(dir, label, scene, int(s)));
      EXPECT_EQ(difference, "") << "split " << split_name(kSplits[s]) << ", scene " << scene << ", "
                                << ranks << " ranks";
      all_same = all_same && difference.empty();
    }
  }
  // A transparent background shows as alpha: the images are RGBA, not flattened.
  if (background == "transparent")
    EXPECT_EQ(read_image(file_of(dir, label + "_ref", "persp_type", 0)).channels, 4);
  // The images stay for inspection only when asked (LANTERN_KEEP_TEST_IMAGES=1).
  if (all_same || std::getenv("LANTERN_KEEP_TEST_IMAGES") == nullptr)
    std::system(("rm -rf '" + dir + "'").c_str());
  else
    std::printf("images kept in %s\n", dir.c_str());
}

TEST(RankInvariance, SameImagesForEveryRankCountAndSplit) {
  expect_rank_invariant(make_particles(1500), "cloud");
}

// Without OpenGL every scene goes to the CPU raster, nine-spheres culling becoming hzb there.
TEST(RankInvariance, SameImagesWithoutOpenGl) {
  expect_rank_invariant(make_particles(1500), "nogl", "gl: none\n",
                        "    culling: {occlusion: nine_spheres}\n");
}

// 256 rows make a PNG of 8 bands of 32 rows: the image is composited into whole bands, one run
// of them per rank, which each rank compresses where it is (the merged frame
// never on one rank), with one sample and with four; the stats say so.
void expect_rank_invariant_in_bands(const std::string &label, const std::string &each,
                                    int height = 256) {
  const std::string stats_dir = shared_directory();
  ASSERT_FALSE(stats_dir.empty());
  const std::string stats = stats_dir + "/stats.jsonl";
  expect_rank_invariant(make_particles(1500), label, "stats: \"" + stats + "\"\n", each, "", "",
                        height);
  if (world_rank() != 0) return;
  std::ifstream in(stats);
  std::string line, all;
  int lines = 0;
  while (std::getline(in, line)) all += line, ++lines;
  EXPECT_EQ(lines, 1 + int(std::size(kSplits)));  // the one-rank reference, then every split
  const std::string bands = "\"composite_method\":\"active_pixels_bands\"";
  size_t found = 0;
  for (size_t at = all.find(bands); at != std::string::npos; at = all.find(bands, at + 1)) ++found;
  EXPECT_EQ(found, world_size() > 1 ? std::size(kSplits) * std::size(kSceneNames) : 0u) << all;
  std::system(("rm -rf '" + stats_dir + "'").c_str());
}

TEST(RankInvariance, SameImagesWrittenFromRowBands) {
  expect_rank_invariant_in_bands("bands", "");
}

TEST(RankInvariance, SameImagesWrittenFromRowBandsWithFourSamples) {
  expect_rank_invariant_in_bands("bands_ssaa4", "    samples: 4\n");
}

// 64 rows make 2 bands of 32: from 3 ranks on, the first two hold a band each, the others none.
TEST(RankInvariance, SameImagesWrittenFromRowBandsOnMoreRanksThanBands) {
  expect_rank_invariant_in_bands("bands_few", "", 64);
}

// Super-sampling: compositing at sample resolution and down-sampling each rank's band of rows give
// the same bytes at any rank count and split (bands of 90 rows need not divide evenly).
TEST(RankInvariance, SameImagesWithFourSamples) {
  expect_rank_invariant(make_particles(1500), "ssaa4", "", "    samples: 4\n");
}

TEST(RankInvariance, SameImagesWithSixteenSamples) {
  expect_rank_invariant(make_particles(1500), "ssaa16", "", "    samples: 16\n");
}

// Every depth cue at once: screen ambient occlusion, outlines and depth cueing run on
// row bands of the composited frame, which must not show in the image; see-through types are
// dithered on the image's pixel grid, whoever draws them.
TEST(RankInvariance, SameImagesWithEveryDepthCue) {
  expect_rank_invariant(make_particles(1500), "cues", "",
                        "    ambient_occlusion: {method: screen, samples: 12}\n"
                        "    outline: {width: 2, color: [0.1, 0, 0]}\n"
                        "    depth_cue: {color: [0.5, 0.5, 0.5]}\n"
                        "    opacity: [0.5, 1, 0.25]\n"
                        "    lighting: {direction: [-0.5, 0.7, 0.5], ambient: 0.3, "
                        "specular: 0.5, shininess: 30}\n");
}

// Screen ambient occlusion at full resolution (the default, half, is in the test above), and at
// half resolution on a super-sampled frame's down-sampled bands.
TEST(RankInvariance, SameImagesWithFullResolutionAmbientOcclusion) {
  expect_rank_invariant(make_particles(1500), "ao_full", "",
                        "    ambient_occlusion: {method: screen, resolution: full}\n");
}

TEST(RankInvariance, SameImagesWithAmbientOcclusionOnFourSamples) {
  expect_rank_invariant(make_particles(1500), "ao_ssaa4", "",
                        "    samples: 4\n    ambient_occlusion: {method: screen, radius: 1.2}\n");
}

// Overlays, drawn on rank 0 over the finished image: labels in two corners, the simulation box
// (depth-tested against the composited depth, which every split must give alike), the axis
// triad, and a legend (colour bar or type key) in every coloured scene; with four samples too
// (the overlays go over the down-sampled image).
TEST(RankInvariance, SameImagesWithOverlays) {
  const std::string box = "    box: {color: [0.9, 0.9, 0.9], width: 1.5}\n";
#if LANTERN_TEST_TEXT
  const std::string overlays =
      box +
      "    labels: [{text: 'scene {scene}', size: 14}, {text: 'Lantern', position: top_right, "
      "size: 12, color: [1, 1, 0]}]\n"
      "    axes: {size: 40, font_size: 10}\n";
  const std::string legend =
      "    legend: {font_size: 10, length: 60, width: 8, color: [1, 1, 1], "
      "type_names: [a, b, c, d, e]}\n";
#else
  const std::string overlays = box, legend;
#endif
  expect_rank_invariant(make_particles(1500), "overlays", "", overlays, legend);
  expect_rank_invariant(make_particles(1500), "overlays_ssaa4", "", overlays + "    samples: 4\n",
                        legend);
}

// background: transparent - alpha 0 where no rank drew, partial alpha on super-sampled edges
// (alpha-weighted down-sampling of each rank's band), every cue (the depth cue fading alpha) and
// the overlays over it; and density images, whose transfer becomes alpha.
TEST(RankInvariance, SameImagesOnATransparentBackground) {
  const std::string box = "    box: {color: [0.9, 0.9, 0.9], width: 1.5}\n";
#if LANTERN_TEST_TEXT
  const std::string overlays =
      box +
      "    labels: [{text: 'scene {scene}', size: 14}]\n    axes: {size: 40, font_size: 10}\n";
#else
  const std::string overlays = box;
#endif
  expect_rank_invariant(make_particles(1500), "transparent", "",
                        overlays +
                            "    samples: 4\n"
                            "    ambient_occlusion: {method: screen, samples: 12}\n"
                            "    outline: {width: 2, color: [0.1, 0, 0]}\n"
                            "    depth_cue: {}\n",
                        "", "transparent");
  expect_rank_invariant(make_particles(1500), "transparent_nogl", "gl: none\n",
                        "    samples: 4\n    depth_cue: {color: [0.5, 0.5, 0.5]}\n", "",
                        "transparent");
  expect_rank_invariant(make_particles(1500), "transparent_density", "",
                        "    style: density\n    density: {transfer: asinh}\n", "", "transparent");
}

// Object-space ambient occlusion: a density volume summed over ranks, per-particle colours.
TEST(RankInvariance, SameImagesWithObjectAmbientOcclusion) {
  expect_rank_invariant(make_particles(1500), "object_ao", "",
                        "    ambient_occlusion: {method: object, radius: 1.5, strength: 0.8}\n");
  // Nodes farther apart than radius / 2 (about 2200 at it).
  expect_rank_invariant(make_particles(1500), "object_ao_max_nodes", "",
                        "    ambient_occlusion: {method: object, radius: 1.5, strength: 0.8, "
                        "max_nodes: 256}\n");
}

// style: density sums fixed-point footprints over the ranks: every coloring, both projections,
// each transfer, and level of detail off (a LOD prefix depends on the bricks, so on the split).
TEST(RankInvariance, SameDensityImagesForEveryRankCountAndSplit) {
  expect_rank_invariant(make_particles(1500), "density_asinh", "",
                        "    style: density\n    density: {transfer: asinh}\n");
  expect_rank_invariant(make_particles(1500), "density_log", "",
                        "    style: density\n    density: {transfer: log, colormap: plasma}\n");
}

// Coincident pairs: two particles at exactly the same position with the same radius, one of type
// 0 (red) and one of type 1 (blue), with different ids; in every other pair the red one comes
// first. Every pixel of a pair is a depth tie, settled by the smaller color: blue.
Particles make_coincident_pairs() {
  Particles p;
  int64_t id = 1000;
  for (int k = 0; k < 36; ++k) {
    const double x = 1.5 * (k % 6), y = 1.5 * ((k / 6) % 3), z = 2.0 * (k / 18);
    for (int m = 0; m < 2; ++m) {
      p.x.push_back(x), p.y.push_back(y), p.z.push_back(z);
      p.radius.push_back(0.7), p.scalar.push_back(0.0);
      p.type.push_back(int32_t((m + k) % 2));
      p.id.push_back(id += 7);
    }
  }
  return p;
}

Particles of_type(const Particles &all, int32_t type) {
  Particles some;
  for (size_t i = 0; i < all.size(); ++i)
    if (all.type[i] == type) some.push(all, i);
  return some;
}

Particles reversed(const Particles &all) {
  Particles r;
  for (size_t i = all.size(); i-- > 0;) r.push(all, i);
  return r;
}

// Perspective and orthographic, spheres of a few pixels (the CPU raster under `auto`) and of
// tens of pixels (OpenGL, when the build has it).
const char *const kPairScenes[] = {"small_persp", "large_persp", "small_ortho", "large_ortho"};

std::string pair_config(const std::string &directory, const std::string &prefix) {
  const std::string pattern = directory + "/" + prefix + "_{scene}_{step:06d}.png";
  const std::string color = "{by: type, palette: [[0.9, 0.1, 0.1], [0.1, 0.2, 0.9]]}";
  // No occlusion culling: auto might pick an approximate mode for the denser pair scenes.
  const std::string exact = "    culling: {occlusion: none}\n";
  return "scenes:\n" +
         scene_yaml("small_persp", "perspective", color, "per_particle", pattern, 1.0) + exact +
         scene_yaml("large_persp", "perspective", color, "per_particle", pattern, 4.0) + exact +
         scene_yaml("small_ortho", "orthographic", color, "per_particle", pattern, 1.0) + exact +
         scene_yaml("large_ortho", "orthographic", color, "per_particle", pattern, 4.0) + exact;
}

TEST(RankInvariance, CoincidentParticlesShowTheSmallerColorForEveryRankCountSplitAndOrder) {
  const Particles pairs = make_coincident_pairs(), blue = of_type(pairs, 1);
  const std::string dir = shared_directory();
  ASSERT_FALSE(dir.empty());
  const int rank = world_rank(), ranks = world_size();
  // References on rank 0 alone: the blue particles only, and the pairs in both published orders.
  if (rank == 0) {
    for (const auto &[prefix, particles] : {std::pair<std::string, Particles>{"blue", blue},
                                            {"pairs", pairs},
                                            {"pairs_reversed", reversed(pairs)}}) {
      const Render r = render_once(MPI_COMM_SELF, pair_config(dir, prefix), particles, 0);
      EXPECT_EQ(r.status, LANTERN_OK) << prefix << ": " << r.error;
    }
  }
  // Every split, plus the two members of each pair on different ranks in both orders (red on the
  // first rank and blue on the last, then the other way round).
  const auto split_pairs = [&](int32_t first_type) {
    Particles mine;
    for (size_t i = 0; i < pairs.size(); ++i)
      if ((pairs.type[i] == first_type ? 0 : ranks - 1) == rank) mine.push(pairs, i);
    return mine;
  };
  std::vector<std::string> labels;
  for (size_t s = 0; s < std::size(kSplits); ++s) labels.push_back(split_name(kSplits[s]));
  labels.push_back("red_first_rank");
  labels.push_back("blue_first_rank");
  for (size_t s = 0; s < labels.size(); ++s) {
    const Particles mine = s < std::size(kSplits) ? owned_by(kSplits[s], pairs, rank, ranks)
                                                  : split_pairs(int32_t(s - std::size(kSplits)));
    const Render r = render_once(MPI_COMM_WORLD, pair_config(dir, "split"), mine, int(s));
    EXPECT_EQ(r.status, LANTERN_OK) << labels[s] << ": " << r.error;
  }
  if (rank != 0) return;
  for (const char *scene : kPairScenes) {
    const std::string blue_image = file_of(dir, "blue", scene, 0);
    EXPECT_EQ(compare_images(blue_image, file_of(dir, "pairs", scene, 0)), "") << scene;
    EXPECT_EQ(compare_images(blue_image, file_of(dir, "pairs_reversed", scene, 0)), "") << scene;
    for (size_t s = 0; s < labels.size(); ++s)
      EXPECT_EQ(compare_images(blue_image, file_of(dir, "split", scene, int(s))), "")
          << "split " << labels[s] << ", scene " << scene << ", " << ranks << " ranks";
  }
  std::system(("rm -rf '" + dir + "'").c_str());
}

// Several steps in one context, with scalars that grow with the step so that remembered colour
// ranges ({auto: first}, {auto: running}) differ from each frame's own; the newer colormaps
// (turbo, RdBu reversed, a custom list); and, in builds with movies, a lossless movie of every
// scene, whose decoded frames must be equal at every rank count too.
const char *const kSequenceScenes[] = {"first_turbo", "frame_turbo", "running_rdbu", "custom"};

std::string sequence_config(const std::string &directory, const std::string &prefix) {
  const std::string pattern = directory + "/" + prefix + "_{scene}_{step:06d}.png";
  const std::string movie = LANTERN_TEST_MOVIES
                                ? ", movie: {file: '" + directory + "/" + prefix +
                                      "_{scene}.mkv', codec: ffv1, when_behind: wait}"
                                : "";
  const auto scene = [&](const std::string &name, const std::string &color) {
    return "  - name: " + name +
           "\n    width: 121\n    height: 91\n    radius: per_particle\n    camera: {azimuth: 35, "
           "elevation: 25, zoom: 1.3}\n    color: " +
           color + "\n    output: {pattern: '" + pattern + "'" + movie + "}\n";
  };
  return "scenes:\n" + scene("first_turbo", "{by: scalar, colormap: turbo, range: {auto: first}}") +
         scene("frame_turbo", "{by: scalar, colormap: turbo, range: auto}") +
         scene("running_rdbu",
               "{by: scalar, colormap: RdBu, reverse: true, range: {auto: running}}") +
         scene("custom", "{by: scalar, colormap: [[0, 0, 0.5], [1, 1, 0], [1, 0, 0]]}");
}

// Renders `steps` in order in one context on comm; with `grow_scalars`, the scalars at step k
// are scaled by 1 + k.
Render render_steps(MPI_Comm comm, const std::string &config, Particles mine,
                    const std::vector<int> &steps, bool grow_scalars = false) {
  Render r;
  lantern_context *ctx = nullptr;
  r.status = lantern_open(config.c_str(), MPI_Comm_c2f(comm), &ctx);
  const std::vector<double> scalar = mine.scalar;
  for (size_t k = 0; k < steps.size() && r.status == LANTERN_OK; ++k) {
    if (grow_scalars)
      for (size_t i = 0; i < scalar.size(); ++i) mine.scalar[i] = scalar[i] * (1.0 + steps[k]);
    const lantern_particles d = describe(mine);
    r.status = lantern_publish(ctx, &d);
    const lantern_status executed = lantern_execute(ctx, steps[k], double(steps[k]));
    if (r.status == LANTERN_OK) r.status = executed;
  }
  r.error = lantern_error_message(ctx);
  const lantern_status closed = lantern_close(ctx);
  if (r.status == LANTERN_OK) r.status = closed;
  return r;
}

// Renders steps 0..steps-1 in one context on comm: at step k the scalars are scaled by 1 + k.
Render render_sequence(MPI_Comm comm, const std::string &config, const Particles &mine, int steps) {
  std::vector<int> all(size_t(steps), 0);
  for (int k = 0; k < steps; ++k) all[size_t(k)] = k;
  return render_steps(comm, config, mine, all, true);
}

TEST(RankInvariance, RememberedColorRangesColormapsAndMoviesAreTheSameForEveryRankCount) {
  constexpr int kSteps = 3;
  const Particles all = make_particles(1200);
  const std::string dir = shared_directory();
  ASSERT_FALSE(dir.empty());
  const int rank = world_rank(), ranks = world_size();
  if (rank == 0) {
    const Render ref = render_sequence(MPI_COMM_SELF, sequence_config(dir, "ref"), all, kSteps);
    EXPECT_EQ(ref.status, LANTERN_OK) << ref.error;
  }
  const Split splits[] = {Split::kRoundRobin, Split::kSlabsByX};
  for (const Split split : splits) {
    const Render r = render_sequence(MPI_COMM_WORLD, sequence_config(dir, split_name(split)),
                                     owned_by(split, all, rank, ranks), kSteps);
    EXPECT_EQ(r.status, LANTERN_OK) << split_name(split) << ": " << r.error;
  }
  if (rank == 0) {
    for (const Split split : splits)
      for (const char *scene : kSequenceScenes) {
        for (int step = 0; step < kSteps; ++step)
          EXPECT_EQ(compare_images(file_of(dir, "ref", scene, step),
                                   file_of(dir, split_name(split), scene, step)),
                    "")
              << split_name(split) << ", scene " << scene << ", step " << step << ", " << ranks
              << " ranks";
#if LANTERN_TEST_MOVIES
        const MovieFrames ref = read_movie(dir + "/ref_" + scene + ".mkv");
        const MovieFrames got = read_movie(dir + "/" + split_name(split) + "_" + scene + ".mkv");
        EXPECT_EQ(ref.error, "");
        EXPECT_EQ(got.error, "");
        EXPECT_EQ(ref.rgb.size(), size_t(kSteps));
        EXPECT_TRUE(ref.rgb == got.rgb) << "decoded movie frames differ: " << split_name(split)
                                        << ", scene " << scene << ", " << ranks << " ranks";
#endif
      }
    // The remembered range is the frame's own at the first step only.
    EXPECT_EQ(compare_images(file_of(dir, "ref", "first_turbo", 0),
                             file_of(dir, "ref", "frame_turbo", 0)),
              "");
    EXPECT_NE(compare_images(file_of(dir, "ref", "first_turbo", kSteps - 1),
                             file_of(dir, "ref", "frame_turbo", kSteps - 1)),
              "");
    std::system(("rm -rf '" + dir + "'").c_str());
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// A camera that moves with the step (camera.path, camera.orbit): resolved from the configuration
// and the step alone, so the same on every rank. A keyframed path in perspective, the orbit in
// orthographic, and a path with four samples and outlines (the final image's camera is built a
// second time there). Steps between keyframes, at one, at the last and after it.
const char *const kMovingScenes[] = {"path_persp", "orbit_ortho", "path_cues"};
const int kMovingSteps[] = {0, 25, 40, 70, 100, 130};

std::string moving_camera_config(const std::string &directory, const std::string &prefix) {
  const std::string pattern = directory + "/" + prefix + "_{scene}_{step:06d}.png";
  const std::string path =
      "{path: [{step: 0, azimuth: 10, elevation: 10, zoom: 1}, "
      "{step: 40, azimuth: 150, elevation: 45, zoom: 1.8}, {step: 100, azimuth: 260, "
      "elevation: -20, zoom: 1.2}]}";
  const auto scene = [&](const std::string &name, const std::string &camera,
                         const std::string &extra) {
    return "  - name: " + name +
           "\n    width: 120\n    height: 90\n    background: [0.1, 0.2, 0.3]\n"
           "    radius: per_particle\n    camera: " +
           camera + "\n    color: {by: type}\n    output: {pattern: '" + pattern + "'}\n" + extra;
  };
  return "scenes:\n" + scene("path_persp", path, "") +
         scene("orbit_ortho",
               "{projection: orthographic, azimuth: 35, elevation: 25, zoom: 1.3, orbit: "
               "{degrees_per_step: 3}}",
               "") +
         scene("path_cues", path, "    samples: 4\n    outline: {width: 2}\n");
}

TEST(RankInvariance, MovingCameraIsTheSameForEveryRankCountAndSplitAndMovesWithTheStep) {
  const Particles all = make_particles(1200);
  const std::vector<int> steps(std::begin(kMovingSteps), std::end(kMovingSteps));
  const std::string dir = shared_directory();
  ASSERT_FALSE(dir.empty());
  const int rank = world_rank(), ranks = world_size();
  if (rank == 0) {
    const Render ref = render_steps(MPI_COMM_SELF, moving_camera_config(dir, "ref"), all, steps);
    EXPECT_EQ(ref.status, LANTERN_OK) << ref.error;
  }
  const Split splits[] = {Split::kRoundRobin, Split::kSlabsByX, Split::kAllOnLast};
  for (const Split split : splits) {
    const Render r = render_steps(MPI_COMM_WORLD, moving_camera_config(dir, split_name(split)),
                                  owned_by(split, all, rank, ranks), steps);
    EXPECT_EQ(r.status, LANTERN_OK) << split_name(split) << ": " << r.error;
  }
  if (rank == 0) {
    for (const Split split : splits)
      for (const char *scene : kMovingScenes)
        for (const int step : steps)
          EXPECT_EQ(compare_images(file_of(dir, "ref", scene, step),
                                   file_of(dir, split_name(split), scene, step)),
                    "")
              << split_name(split) << ", scene " << scene << ", step " << step << ", " << ranks
              << " ranks";
    // The camera moves: every frame up to the path's last keyframe differs from the one before;
    // after it the path holds its end (the orbit goes on turning).
    for (const char *scene : kMovingScenes)
      for (size_t k = 1; k + 1 < steps.size(); ++k)
        EXPECT_NE(compare_images(file_of(dir, "ref", scene, steps[k - 1]),
                                 file_of(dir, "ref", scene, steps[k])),
                  "")
            << "scene " << scene << ": steps " << steps[k - 1] << " and " << steps[k];
    EXPECT_EQ(compare_images(file_of(dir, "ref", "path_persp", 100),
                             file_of(dir, "ref", "path_persp", 130)),
              "");
    EXPECT_NE(compare_images(file_of(dir, "ref", "orbit_ortho", 100),
                             file_of(dir, "ref", "orbit_ortho", 130)),
              "");
    std::system(("rm -rf '" + dir + "'").c_str());
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(RankInvariance, NoParticlesAnywhereGivesTheBackgroundEverywhere) {
  expect_rank_invariant(Particles{}, "empty");
}

// --- Bonds ----------------------------------------------------------------------------------

// One rank's share of a bonded system, as a domain-decomposed code holds it: its own atoms, then
// the ghosts its bonds reach (copies of other ranks' atoms, or periodic images), and its bond
// list as local indices.
struct RankMolecule {
  Particles atoms;  // owned, then ghosts
  int64_t owned = 0;
  std::vector<int64_t> first, second;
  std::vector<int32_t> type;
};

// Who lists which bond, and what its atoms' indices are on that rank. As LAMMPS does, a bond's
// other atom is the image closest to the listing rank's own atom (along periodic axes of edge
// `box`; 0: none; a triclinic box where `tilt`, LAMMPS's {xy, xz, yz}, is not zero): that rank's
// atom itself when it owns it there, else a ghost - also on one rank, for a bond across a periodic
// face. `core_wraps`: no image is made here - the atom itself, or a ghost at its own position -
// and Lantern's minimum image along the box's axes joins the bond across the face. LISTED_ONCE: the
// rank owning the bond's first atom lists it (LAMMPS with newton_bond on); LISTED_BY_BOTH: every
// own atom's bonds with its own index (newton_bond off).
RankMolecule rank_share(Split split, const Particles &all, const BondedSystem &system,
                        lantern_bond_listing listing, double box, int rank, int ranks,
                        const std::array<double, 3> &tilt = {0, 0, 0}, bool core_wraps = false) {
  RankMolecule m;
  std::vector<int> owner_rank(all.size());
  std::vector<int64_t> local(all.size(), -1);
  for (size_t i = 0; i < all.size(); ++i) {
    owner_rank[i] = owner(split, all, i, ranks);
    if (owner_rank[i] == rank) local[i] = int64_t(m.atoms.size()), m.atoms.push(all, i);
  }
  m.owned = int64_t(m.atoms.size());
  std::map<std::tuple<size_t, int, int, int>, int64_t> ghost;  // (atom, image shift) -> index
  // An atom's coordinates along the edge vectors a, b, c (LAMMPS's lamda coordinates).
  const auto fractional = [&](size_t i, double *f) {
    f[2] = all.z[i] / box;
    f[1] = (all.y[i] - tilt[2] * f[2]) / box;
    f[0] = (all.x[i] - tilt[0] * f[1] - tilt[1] * f[2]) / box;
  };
  const auto index_near = [&](size_t e, size_t anchor) {
    int shift[3] = {0, 0, 0};
    if (box > 0 && !core_wraps) {
      double fe[3], fa[3];
      fractional(e, fe), fractional(anchor, fa);
      for (int k = 0; k < 3; ++k) shift[k] = int(std::nearbyint(fe[k] - fa[k]));
    }
    if (shift[0] == 0 && shift[1] == 0 && shift[2] == 0 && local[e] >= 0) return local[e];
    const auto key = std::make_tuple(e, shift[0], shift[1], shift[2]);
    if (const auto found = ghost.find(key); found != ghost.end()) return found->second;
    const int64_t g = int64_t(m.atoms.size());
    m.atoms.push(all, e);
    m.atoms.x.back() -= shift[0] * box + shift[1] * tilt[0] + shift[2] * tilt[1];
    m.atoms.y.back() -= shift[1] * box + shift[2] * tilt[2];
    m.atoms.z.back() -= shift[2] * box;
    ghost.emplace(key, g);
    return g;
  };
  const auto list = [&](size_t k, size_t a, size_t b, size_t anchor) {
    m.first.push_back(index_near(a, anchor));
    m.second.push_back(index_near(b, anchor));
    m.type.push_back(system.bond_type[k]);
  };
  for (size_t k = 0; k < system.bond_count(); ++k) {
    const size_t a = size_t(system.bonds[2 * k]), b = size_t(system.bonds[2 * k + 1]);
    const bool own_a = owner_rank[a] == rank, own_b = owner_rank[b] == rank;
    if (listing == LANTERN_BONDS_LISTED_ONCE) {
      if (own_a) list(k, a, b, a);
      continue;
    }
    // Listed by both: each own atom's bond with that atom's own index - one entry when both
    // atoms are here and the closest image of b is b itself, else one per own atom (as LAMMPS's
    // newton_bond off bondlist has it).
    if (own_a && own_b && index_near(b, a) == local[b]) {
      list(k, a, b, a);
      continue;
    }
    if (own_a) list(k, a, b, a);
    if (own_b) list(k, a, b, b);
  }
  return m;
}

// Renders `mine` with its bonds (and the periodic box of edge `box`, if any) once on comm.
Render render_bonded_once(MPI_Comm comm, const std::string &config, const RankMolecule &mine,
                          lantern_bond_listing listing, double box, int step,
                          const std::array<double, 3> &tilt = {0, 0, 0}) {
  Render r;
  lantern_context *ctx = nullptr;
  r.status = lantern_open(config.c_str(), MPI_Comm_c2f(comm), &ctx);
  if (r.status == LANTERN_OK) {
    lantern_particles d = describe(mine.atoms);
    d.count = mine.owned;
    lantern_bonds b{};
    b.count = int64_t(mine.first.size());
    b.first = {mine.first.data(), LANTERN_INT64, 0};
    b.second = {mine.second.data(), LANTERN_INT64, 0};
    b.type = {mine.type.data(), LANTERN_INT32, 0};
    b.ghost_count = int64_t(mine.atoms.size()) - mine.owned;
    b.listing = listing;
    const double low[3] = {0, 0, 0}, high[3] = {box, box, box};
    const int periodic[3] = {1, 1, 1};
    r.status = lantern_publish(ctx, &d);
    if (r.status == LANTERN_OK) r.status = lantern_publish_bonds(ctx, &b);
    const bool tilted = tilt[0] != 0 || tilt[1] != 0 || tilt[2] != 0;
    if (r.status == LANTERN_OK && box > 0)
      r.status = tilted ? lantern_set_triclinic_box(ctx, low, high, tilt.data(), periodic)
                        : lantern_set_box(ctx, low, high, periodic);
    const lantern_status executed = lantern_execute(ctx, step, double(step));
    if (r.status == LANTERN_OK) r.status = executed;
  }
  r.error = lantern_error_message(ctx);
  lantern_close(ctx);
  return r;
}

// A polymer melt in a periodic cube of edge 12 (chains cross its faces), its coordinates on a
// grid of 2^-12 so that a periodic image x +- 12 is exact and the minimum image is the same bits
// from a copy or an image; radii, scalars and types as make_particles gives them.
BondedSystem melt_on_grid() {
  BondedSystem s = polymer_melt(16, 32, 12.0);
  for (double &v : s.xyz) v = std::min(std::nearbyint(v * 4096.0) / 4096.0, 12.0 - 1.0 / 4096.0);
  return s;
}

Particles atoms_of(const BondedSystem &s) {
  Particles p;
  for (size_t i = 0; i < s.atoms(); ++i) {
    const uint32_t h = hash(uint32_t(i) * 2246822519U + 3U);
    p.x.push_back(s.xyz[3 * i]), p.y.push_back(s.xyz[3 * i + 1]), p.z.push_back(s.xyz[3 * i + 2]);
    p.radius.push_back(0.25 + 0.15 * unit(h));
    p.scalar.push_back(std::sin(0.5 * p.x.back()) * p.y.back());
    p.type.push_back(s.type[i] + int32_t(i % 3));
    p.id.push_back(s.id[i]);
  }
  return p;
}

const char *const kBondSceneNames[] = {"bond_atom", "bond_type", "bond_solid", "bond_close",
                                       "bond_ortho"};

std::string bond_config(const std::string &directory, const std::string &prefix,
                        const std::string &each) {
  const std::string pattern = directory + "/" + prefix + "_{scene}_{step:06d}.png";
  const std::string stats = "stats: " + directory + "/" + prefix + "_stats.jsonl\n";
  const auto scene = [&](const std::string &name, const std::string &projection,
                         const std::string &bonds, const std::string &radius, double zoom) {
    return scene_yaml(name, projection, "{by: type}", radius, pattern, zoom) +
           "    bonds: " + bonds + "\n" + each;
  };
  // Small spheres under auto go to the CPU raster; bond_close's camera, inside the melt, sees
  // spheres large enough for OpenGL where the build has it (its bonds cut by the near plane).
  return stats + "scenes:\n" +
         scene("bond_atom", "perspective", "{radius: 0.12}", "per_particle", 1.3) +
         scene("bond_type", "perspective", "{radius: 0.15, color: by_type}", "0.3", 1.3) +
         scene("bond_solid", "perspective", "{color: solid, solid: [0.7, 0.7, 0.2]}", "0.3", 1.3) +
         scene("bond_close", "perspective", "{radius: 0.2}", "0.45", 12.0) +
         scene("bond_ortho", "orthographic", "{radius: 0.12, color: by_type}", "per_particle", 1.3);
}

// Renders `system` on rank 0 alone, then under every split on all ranks; compares on rank 0.
void expect_bonds_rank_invariant(const BondedSystem &system, lantern_bond_listing listing,
                                 double box, const std::string &label, const std::string &each = "",
                                 const std::string &background = "",
                                 const std::array<double, 3> &tilt = {0, 0, 0},
                                 bool core_wraps = false) {
  const Particles all = atoms_of(system);
  const std::string dir = shared_directory();
  ASSERT_FALSE(dir.empty());
  const int rank = world_rank(), ranks = world_size();
  if (rank == 0) {
    const RankMolecule one =
        rank_share(Split::kAllOnFirst, all, system, listing, box, 0, 1, tilt, core_wraps);
    const Render ref = render_bonded_once(
        MPI_COMM_SELF, with_background(bond_config(dir, label + "_ref", each), background), one,
        listing, box, 0, tilt);
    EXPECT_EQ(ref.status, LANTERN_OK) << ref.error;
  }
  const std::string config = with_background(bond_config(dir, label, each), background);
  for (size_t s = 0; s < std::size(kSplits); ++s) {
    const RankMolecule mine =
        rank_share(kSplits[s], all, system, listing, box, rank, ranks, tilt, core_wraps);
    const Render r = render_bonded_once(MPI_COMM_WORLD, config, mine, listing, box, int(s), tilt);
    EXPECT_EQ(r.status, LANTERN_OK) << split_name(kSplits[s]) << ": " << r.error;
  }
  if (rank != 0) return;
  // Every half-bond was taken by exactly one rank: the stats' sums over ranks (one line per
  // split) count two halves per bond, drawn or culled.
  std::ifstream stats(dir + "/" + label + "_stats.jsonl");
  int lines = 0;
  for (std::string line; std::getline(stats, line); ++lines) {
    int scenes = 0;
    for (size_t at = line.find("\"halves\":"); at != std::string::npos;
         at = line.find("\"halves\":", at + 1), ++scenes)
      EXPECT_EQ(std::stoll(line.substr(at + 9)), int64_t(2 * system.bond_count())) << line;
    EXPECT_EQ(scenes, int(std::size(kBondSceneNames))) << line;
  }
  EXPECT_EQ(lines, int(std::size(kSplits)));
  bool all_same = true;
  for (size_t s = 0; s < std::size(kSplits); ++s)
    for (const char *scene : kBondSceneNames) {
      const std::string difference = compare_images(file_of(dir, label + "_ref", scene, 0),
                                                    file_of(dir, label, scene, int(s)));
      EXPECT_EQ(difference, "") << "split " << split_name(kSplits[s]) << ", scene " << scene << ", "
                                << ranks << " ranks";
      all_same = all_same && difference.empty();
    }
  if (all_same || std::getenv("LANTERN_KEEP_TEST_IMAGES") == nullptr)
    std::system(("rm -rf '" + dir + "'").c_str());
  else
    std::printf("images kept in %s\n", dir.c_str());
}

// Each bond listed on its first atom's rank, which draws it whole; ghosts for the atoms of other
// ranks and for periodic images.
TEST(RankInvariance, SameImagesWithBondsListedOnce) {
  expect_bonds_rank_invariant(melt_on_grid(), LANTERN_BONDS_LISTED_ONCE, 12.0, "bonds_once");
}

// Each bond listed on both atoms' ranks, each drawing its own atoms' halves; periodic, and with
// no box (bonds across the box drawn straight).
TEST(RankInvariance, SameImagesWithBondsListedByBoth) {
  expect_bonds_rank_invariant(melt_on_grid(), LANTERN_BONDS_LISTED_BY_BOTH, 12.0, "bonds_both");
  expect_bonds_rank_invariant(melt_on_grid(), LANTERN_BONDS_LISTED_BY_BOTH, 0.0, "bonds_both_open");
}

// A triclinic box (LAMMPS's tilts xy 3, xz -2, yz 1.5): the melt sheared into it (on the grid of
// 2^-12 again, so that an image is exact), its bonds across the tilted faces joined by ghosts at
// their closest images (as LAMMPS holds them) or by Lantern's triclinic minimum image of the
// atoms as stored. Each way the same bytes at every rank count and split; listed by both atoms'
// ranks (each half at its own atom) the two ways give the same bytes too.
TEST(RankInvariance, SameImagesWithBondsInATriclinicBox) {
  const std::array<double, 3> tilt = {3.0, -2.0, 1.5};
  BondedSystem sheared = melt_on_grid();
  for (size_t i = 0; i < sheared.atoms(); ++i) {
    double *x = &sheared.xyz[3 * i];
    x[0] += tilt[0] * x[1] / 12.0 + tilt[1] * x[2] / 12.0, x[1] += tilt[2] * x[2] / 12.0;
    for (int k = 0; k < 3; ++k) x[k] = std::nearbyint(x[k] * 4096.0) / 4096.0;
  }
  expect_bonds_rank_invariant(sheared, LANTERN_BONDS_LISTED_ONCE, 12.0, "bonds_triclinic_once", "",
                              "", tilt);
  expect_bonds_rank_invariant(sheared, LANTERN_BONDS_LISTED_BY_BOTH, 12.0, "bonds_triclinic_wraps",
                              "", "", tilt, true);
  const std::string dir = shared_directory();  // collective; rank 0 renders and compares
  if (world_rank() != 0) return;
  ASSERT_FALSE(dir.empty());
  const Particles all = atoms_of(sheared);
  for (const bool core_wraps : {false, true}) {
    const RankMolecule one = rank_share(Split::kAllOnFirst, all, sheared,
                                        LANTERN_BONDS_LISTED_BY_BOTH, 12.0, 0, 1, tilt, core_wraps);
    const Render r =
        render_bonded_once(MPI_COMM_SELF, bond_config(dir, core_wraps ? "wraps" : "ghosts", ""),
                           one, LANTERN_BONDS_LISTED_BY_BOTH, 12.0, 0, tilt);
    ASSERT_EQ(r.status, LANTERN_OK) << r.error;
  }
  for (const char *scene : kBondSceneNames)
    EXPECT_EQ(compare_images(file_of(dir, "ghosts", scene, 0), file_of(dir, "wraps", scene, 0)), "")
        << scene << ": ghosts at the closest images against Lantern's triclinic minimum image";
  std::system(("rm -rf '" + dir + "'").c_str());
}

// Bonds in OpenGL, and under every cue, super-sampled, see-through types and a custom light.
TEST(RankInvariance, SameImagesWithBondsInOpenGlAndUnderEveryCue) {
  expect_bonds_rank_invariant(melt_on_grid(), LANTERN_BONDS_LISTED_ONCE, 12.0, "bonds_cues",
                              "    samples: 4\n"
                              "    ambient_occlusion: {method: screen, samples: 8}\n"
                              "    outline: {width: 1, color: [0.1, 0, 0]}\n"
                              "    depth_cue: {color: [0.5, 0.5, 0.5]}\n"
                              "    opacity: [1, 0.5, 1, 0.75]\n"
                              "    lighting: {direction: [-0.5, 0.7, 0.5], specular: 0.5}\n"
                              "    culling: {occlusion: hzb}\n");
}

// Bonds on a transparent background: cylinders are opaque like spheres (alpha 1), their
// super-sampled edges partial alpha, the depth cue fading alpha.
TEST(RankInvariance, SameImagesWithBondsOnATransparentBackground) {
  expect_bonds_rank_invariant(melt_on_grid(), LANTERN_BONDS_LISTED_ONCE, 12.0, "bonds_transparent",
                              "    samples: 4\n    depth_cue: {}\n", "transparent");
}

TEST(RankInvariance, UnwritableOutputFailsTheStepOnEveryRankWithoutHanging) {
  // Rank 0 cannot create the directory (its parent is a file); every rank compressed a band and
  // must hear of the failure, with the path, and the context must render the next step.
  const std::string dir = shared_directory();
  ASSERT_FALSE(dir.empty());
  if (world_rank() == 0) std::fclose(std::fopen((dir + "/file").c_str(), "w"));
  MPI_Barrier(MPI_COMM_WORLD);
  const std::string bad = "scenes:\n" + scene_yaml("bad", "perspective", "{by: type}", "0.4",
                                                   dir + "/file/x_{step:06d}.png");
  const Particles all = make_particles(300);
  const Particles mine = owned_by(kSplits[0], all, world_rank(), world_size());
  const Render r = render_once(MPI_COMM_WORLD, bad, mine, 0);
  EXPECT_EQ(r.status, LANTERN_ERR_IO);
  EXPECT_NE(r.error.find(dir + "/file/x_000000.png"), std::string::npos) << r.error;
  const Render ok = render_once(MPI_COMM_WORLD, config_yaml(dir, "after"), mine, 1);
  EXPECT_EQ(ok.status, LANTERN_OK) << ok.error;
  MPI_Barrier(MPI_COMM_WORLD);
  if (world_rank() == 0) std::system(("rm -rf '" + dir + "'").c_str());
}

}  // namespace
}  // namespace lantern::testing
