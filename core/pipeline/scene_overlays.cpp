#include "core/pipeline/scene_overlays.h"

#include <chrono>
#include <new>
#include <utility>

#include "core/common/collective_status.h"
#include "core/common/guarded_status.h"
#include "core/common/injected_fault.h"
#include "core/common/ms_since.h"

namespace lantern {

Status check_scene_overlays(const std::vector<SceneConfig> &scenes) {
  for (const SceneConfig &scene : scenes)
    if (Status s = check_overlay_font(overlay_settings(scene)); !s.ok())
      return with_context("scenes '" + scene.name + "': ", std::move(s));
  return {};
}

Status draw_scene_overlays(const ScenePassInputs &in, const SceneSettings &settings,
                           const Camera &camera, const SceneConfig &scene, SceneBuffers *buffers,
                           SceneStats *stats) {
  const OverlaySettings &overlays = settings.finish.overlays;
  if (!overlays.any()) {
    buffers->overlays.reset();
    return {};
  }
  int rank = 0;
  MPI_Comm_rank(in.comm, &rank);
  Status drawn;
  if (rank == 0)
    drawn = guarded_status("overlays", [&]() -> Status {
      Status opened;
      const auto t0 = std::chrono::steady_clock::now();
      if (!buffers->overlays || !buffers->overlays->serves(overlays))
        opened = OverlayPainter::open(overlays, &buffers->overlays);
      if (opened.ok()) {
        OverlayFrame frame;
        frame.step = in.step;
        frame.time = in.time;
        frame.range = settings.shading.color.range;
        frame.scalar_name = in.scalar_name;
        frame.camera = &camera;
        if (in.box != nullptr) {
          frame.box = {in.box->low, in.box->high, in.box->tilt};
        } else {  // as the dumps do without a box: the particles' bounds
          frame.box = {in.global.lo, in.global.hi};
        }
        // Tests: memory running out on rank 0 alone (injected_fault.h).
        if (take_injected_fault("overlays: draw")) throw std::bad_alloc();
        buffers->overlays->draw(overlays, frame, &buffers->frame);
      }
      stats->overlays_ms = ms_since(t0);
      return opened;
    });
  return broadcast_status(in.comm, with_context("scenes '" + scene.name + "': ", std::move(drawn)),
                          0);
}

}  // namespace lantern
