#include "core/pipeline/density_scene_pass.h"

#include <algorithm>
#include <chrono>
#include <string>

#include "core/color/colormap.h"
#include "core/common/collective_status.h"
#include "core/composite/density_sum.h"
#include "core/composite/density_transfer.h"
#include "core/render/density_pass.h"
#include "core/render/sphere_instances.h"

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

void sum_density_counts(MPI_Comm comm, const CullStats &local, SceneStats *stats) {
  int64_t in[4] = {local.drawn, local.frustum_culled, local.cut_culled, local.lod_dropped};
  int64_t out[4] = {0, 0, 0, 0};
  MPI_Allreduce(in, out, 4, MPI_INT64_T, MPI_SUM, comm);
  stats->drawn = out[0];
  stats->frustum_culled = out[1];
  stats->cut_culled = out[2];
  stats->lod_dropped = out[3];
}

}  // namespace

Status run_density_scene(const ScenePassInputs &in, const SceneConfig &scene, const Camera &camera,
                         const RadiusRule &radius, Status local, SceneBuffers *buffers,
                         SceneStats *stats) {
  const std::string where = "scenes '" + scene.name + "': ";
  // The same on every rank (a global count): the bound that keeps every pixel sum below 2^63.
  if (in.global.finite_count > kDensityMaxParticles)
    return {StatusCode::kInvalidArgument,
            where + "style: density sums at most 2^38 particles exactly; this step has " +
                std::to_string(in.global.finite_count)};
  stats->renderer = "density";
  stats->occlusion = "none (density)";
  CullStats cull;
  DensityImage &image = buffers->density;
  if (local.ok()) {
    auto t0 = Clock::now();
    double build_ms = 0.0;
    const BrickSet &bricks = in.scratch->bricks.for_step(*in.particles, in.step, brick_options(in),
                                                         &build_ms, &stats->bricks);
    stats->bricks_ms = build_ms;
    // A refit the runtime made ahead of the scan (BrickCache::refit_first) counts as culling too.
    const double ahead_ms = std::max(0.0, build_ms - ms_since(t0));
    BrickSelection &selection = in.scratch->selection;
    select_density_bricks(bricks, camera, scene, radius, &selection, &buffers->cut_counts);
    stats->cull_ms = ms_since(t0) + ahead_ms;
    t0 = Clock::now();
    const InstanceRecipe recipe = make_recipe(*in.particles, scene, radius, camera, in.global);
    cull = render_density(*in.particles, bricks, scene, selection, recipe, &image);
    stats->draw_ms = ms_since(t0);
  } else {
    image.reset(scene.width, scene.height, density_channels(scene.color.by));
  }
  if (Status s = agree_on_status(in.comm, local); !s.ok()) return s;
  sum_density_counts(in.comm, cull, stats);
  stats->culled = in.global.finite_count - stats->drawn;

  const auto t0 = Clock::now();
  if (Status s = sum_density_to_root(in.comm, 0, &image); !s.ok())
    return with_context(where + "compositing: ", std::move(s));
  int rank = 0;
  MPI_Comm_rank(in.comm, &rank);
  if (rank == 0) {
    const Rgb8 bg = to_rgb8(scene.background);
    const uint8_t background[4] = {bg[0], bg[1], bg[2], 255};
    // The loader accepts only known names, so the map exists.
    const Colormap map =
        Colormap::named(scene.density.colormap).value_or(*Colormap::named("grayscale"));
    map_density(image, scene.density, map, background, &buffers->frame);
  }
  stats->composite_ms = ms_since(t0);
  stats->composite_method = "sum (int64)";
  return {};
}

}  // namespace lantern
