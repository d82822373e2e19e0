#include "core/pipeline/density_scene_pass.h"

#include <algorithm>
#include <chrono>
#include <new>
#include <string>

#include "core/color/colormap.h"
#include "core/common/collective_status.h"
#include "core/common/ms_since.h"
#include "core/composite/density_sum.h"
#include "core/finish/density_transfer.h"
#include "core/render/density_pass.h"
#include "core/render/shading_settings.h"
#include "core/render/sphere_instances.h"

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

Status run_density_scene(const ScenePassInputs &in, const SceneSettings &settings,
                         const std::string &where, const Camera &camera, const RadiusRule &radius,
                         Status local, SceneBuffers *buffers, SceneStats *stats) {
  // The same on every rank (a global count): the bound that keeps every pixel sum below 2^63.
  if (in.global.finite_count > kDensityMaxParticles)
    return {StatusCode::kInvalidArgument,
            where + "style: density sums at most 2^38 particles exactly; this step has " +
                std::to_string(in.global.finite_count)};
  stats->renderer = "density";
  stats->occlusion = "none (density)";
  CullStats counts;
  DensityImage &image = buffers->density;
  // Allocations of this rank's sums: running out of memory is agreed below like any failure (a
  // rank that failed returns there, so its image is never used).
  if (local.ok()) try {
      auto t0 = Clock::now();
      double build_ms = 0.0;
      const BrickSet &bricks = in.scratch->bricks.for_step(
          *in.particles, in.step, brick_options(in), &build_ms, &stats->bricks);
      stats->bricks_ms = build_ms;
      // A refit the runtime made ahead of the scan (BrickCache::refit_first) counts as culling too.
      const double ahead_ms = std::max(0.0, build_ms - ms_since(t0));
      BrickSelection &selection = in.scratch->draw.selection;
      select_density_bricks(bricks, camera, settings.cull, radius, &selection,
                            &buffers->cut_counts);
      stats->cull_ms = ms_since(t0) + ahead_ms;
      t0 = Clock::now();
      const InstanceRecipe recipe =
          make_recipe(*in.particles, settings.shading, radius, camera, in.global);
      counts = render_density(*in.particles, bricks, settings.cull, selection, recipe, &image);
      stats->draw_ms = ms_since(t0);
    } catch (const std::bad_alloc &) {
      const int64_t bytes = int64_t(settings.finish.width) * settings.finish.height *
                            density_channels(settings.shading.color.by) * int64_t(sizeof(int64_t));
      local = {StatusCode::kOutOfMemory,
               where + "out of memory summing " + std::to_string(settings.finish.width) + " x " +
                   std::to_string(settings.finish.height) + " pixels (" + std::to_string(bytes) +
                   " bytes of sums on this rank)"};
    }
  if (Status s = agree_on_status(in.comm, local); !s.ok()) return s;
  sum_counts_over_ranks(in.comm, counts, stats);  // splatted and occlusion_culled: 0 here
  stats->culled = in.global.finite_count - stats->drawn;

  const auto t0 = Clock::now();
  if (Status s = sum_density_to_root(in.comm, 0, &image); !s.ok())
    return with_context(where + "compositing: ", std::move(s));
  int rank = 0;
  MPI_Comm_rank(in.comm, &rank);
  if (rank == 0) {
    const std::array<uint8_t, 4> background = background_rgba8(settings.shading);
    // The loader accepts only known names, so the map exists.
    const DensityConfig &density = settings.finish.density;
    const Colormap map = Colormap::named(density.colormap).value_or(*Colormap::named("grayscale"));
    map_density(image, density, map, background.data(), &buffers->frame);
  }
  stats->composite_ms = ms_since(t0);
  stats->composite_method = "sum (int64)";
  int ranks = 1;
  MPI_Comm_size(in.comm, &ranks);
  if (in.per_rank_stats && ranks > 1) {
    // MPI_Reduce: what this rank hands to MPI, and root gets back (the tree's traffic is MPI's).
    CompositeStats sum;
    const uint64_t bytes = 8 * uint64_t(image.sum.size());
    (rank == 0 ? sum.traffic.bytes_received : sum.traffic.bytes_sent) = bytes;
    (rank == 0 ? sum.traffic.messages_received : sum.traffic.messages_sent) = 1;
    stats->composite = summarize_composite(in.comm, sum, nullptr);
  }
  return {};
}

}  // namespace lantern
