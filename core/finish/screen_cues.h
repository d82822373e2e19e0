// The screen-space depth cues of a scene, applied to the composited frame before it
// is written: screen ambient occlusion, then outlines, then depth cueing.
//
// They run on the final-resolution composited frame, in parallel: root's frame is handed out in
// row bands with the halo the cues read (row_bands.h), every rank shades its own rows, and the
// bands are gathered back on root. Each cue depends only on the composited colour and depth and
// the camera, so the image is the same bytes at any rank count and split. With no screen cue on
// nothing runs and nothing is exchanged.
//
// Collective over comm: every rank calls with the same cues, camera and radius. `frame` is
// read and rewritten on root only. Returns OK or kMpi, the same on every rank. Never throws.
#pragma once

#include <mpi.h>

#include <array>

#include "core/camera/camera.h"
#include "core/common/status.h"
#include "core/composite/row_bands.h"
#include "core/config/config.h"
#include "core/finish/screen_ambient_occlusion.h"
#include "core/finish/view_positions.h"
#include "core/view/frame.h"

namespace lantern {

// The screen-space cues of one scene, resolved once by the pipeline from its configuration
// (core/pipeline/scene_settings.h). Each is off unless enabled; ambient occlusion here is the
// screen method's (the object method darkens particles as they are drawn, not the image).
struct ScreenCueSettings {
  AmbientOcclusionConfig ambient_occlusion;         // ambient_occlusion (method: screen)
  OutlineConfig outline;                            // outline
  DepthCueConfig depth_cue;                         // depth_cue
  std::array<double, 3> background{1.0, 1.0, 1.0};  // depth_cue's color when it names none
  // background: transparent - depth_cue without a color fades alpha towards 0 instead (depth_cue.h)
  bool transparent_background = false;
  // The threads this rank's cues may use (the run-wide `threads:`, resolved): their rows are cut
  // into that many parts, with the same bytes at any count.
  int threads = 1;
};

// True if any cue computed on the composited frame is on.
bool wants_screen_cues(const ScreenCueSettings &cues);

// The cues on root's width x height `frame`, spread over the ranks in row bands.
// `sphere_radius`: the scene's largest drawn radius (simulation units, the same on every rank),
// the unit of outline.depth_threshold and of the default ambient_occlusion.radius.
Status apply_screen_cues(MPI_Comm comm, int root, const ScreenCueSettings &cues, int width,
                         int height, const Camera &camera, double sphere_radius, Frame *frame);

// The rows of halo `cues` read above and below a band (0 without a screen cue).
int screen_cue_halo(const ScreenCueSettings &cues);

// What the cues of a band keep from frame to frame so that it is neither allocated nor written
// again: screen ambient occlusion's estimate grids, and the distances (whose border stays
// background while the band's size does not change). Ownership: the caller's; one per call in
// flight.
struct CueScratch {
  AoScratch ao;
  ViewPositions positions;
};

// The cues on one rank's band, for a pipeline whose bands are already spread over the ranks:
// `band` must hold its owned rows plus screen_cue_halo(cues) rows each side (clamped), e.g.
// from exchange_halo_rows; its owned rows are rewritten. `scratch`: buffers kept from frame to
// frame, or null. Collective (the automatic depth-cue range is reduced
// over comm). OK or kMpi, the same on every rank.
Status cue_band(MPI_Comm comm, const ScreenCueSettings &cues, const Camera &camera,
                double sphere_radius, BandFrame *band, CueScratch *scratch = nullptr);

}  // namespace lantern
