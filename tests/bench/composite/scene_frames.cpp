#include "scene_frames.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/bricks/brick_set.h"
#include "core/camera/camera.h"
#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"
#include "core/particles/particle_scan.h"
#include "core/particles/radius_rule.h"
#include "core/pipeline/rank_draw.h"

namespace lantern::bench {
namespace {

constexpr double kLattice = 1.122462048309373 * 1.4142135623730951;  // nn 2^(1/6), fcc

}  // namespace

SceneFrame draw_fcc_share(MPI_Comm comm, int cells, int width, int height, int samples_per_axis) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  int dims[3] = {0, 0, 0};
  MPI_Dims_create(ranks, 3, dims);
  const int cx = rank % dims[0], cy = rank / dims[0] % dims[1], cz = rank / (dims[0] * dims[1]);
  // This rank's box of the crystal: lattice cells [lo, hi) along each axis.
  const auto range = [cells](int index, int parts) {
    return std::array<int, 2>{cells * index / parts, cells * (index + 1) / parts};
  };
  const std::array<int, 2> rx = range(cx, dims[0]), ry = range(cy, dims[1]),
                           rz = range(cz, dims[2]);
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::vector<double> xyz;
  std::vector<int32_t> type;
  for (int z = rz[0]; z < rz[1]; ++z)
    for (int y = ry[0]; y < ry[1]; ++y)
      for (int x = rx[0]; x < rx[1]; ++x)
        for (const auto &b : basis) {
          xyz.insert(xyz.end(),
                     {(x + b[0]) * kLattice, (y + b[1]) * kLattice, (z + b[2]) * kLattice});
          type.push_back(int32_t((x / 8 + y / 8 + z / 8) % 4));  // coloured domains
        }
  SceneFrame out;
  out.atoms = (long long)type.size();
  out.note = "fcc " + std::to_string(cells) + "^3 cells (" +
             std::to_string(4LL * cells * cells * cells) + " atoms), split " +
             std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
             std::to_string(dims[2]) + ", " + std::to_string(width) + "x" + std::to_string(height) +
             (samples_per_axis > 1
                  ? " at " + std::to_string(samples_per_axis * samples_per_axis) + " samples"
                  : std::string());

  ParticleDescription d{};
  d.count = int64_t(type.size());
  d.position = {xyz.data(), DataType::kFloat64, 0};
  d.type = {type.data(), DataType::kInt32, 0};
  ParticleArrays arrays;
  if (Status s = ParticleArrays::validate(d, &arrays); !s.ok()) {
    out.error = s.message;
    return out;
  }
  SceneConfig scene;
  scene.width = width;
  scene.height = height;
  scene.radius = 0.5;
  scene.color.by = ColorBy::kType;
  scene.culling.occlusion = OcclusionMode::kHzb;  // exact: the split never shows in the image
  const Extent global = reduce_extent(comm, scan_particles(arrays, false, scene.radius));
  const RadiusRule radius = radius_rule(scene, arrays);
  Camera camera;
  const glm::dvec3 lo{global.lo[0], global.lo[1], global.lo[2]};
  const glm::dvec3 hi{global.hi[0], global.hi[1], global.hi[2]};
  if (Status s = make_camera(scene.camera, lo, hi, radius.max_radius(global),
                             width * samples_per_axis, height * samples_per_axis, &camera);
      !s.ok()) {
    out.error = s.message;
    return out;
  }
  const BrickSet bricks = build_bricks(arrays, BrickOptions{});
  RankScene rank_scene(arrays, bricks, camera, scene);
  rank_scene.global = global;
  RankDrawScratch scratch;
  RankDraw drawn;
  if (Status s = draw_scene_on_rank(rank_scene, &scratch, &out.frame, &drawn); !s.ok())
    out.error = s.message;
  return out;
}

}  // namespace lantern::bench
