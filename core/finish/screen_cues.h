// The screen-space depth cues of a scene (issue 13), applied to the composited frame before it
// is written: screen ambient occlusion, then outlines, then depth cueing.
//
// They run on the final-resolution composited frame, in parallel: root's frame is handed out in
// row bands with the halo the cues read (row_bands.h), every rank shades its own rows, and the
// bands are gathered back on root. Each cue depends only on the composited colour and depth and
// the camera, so the image is the same bytes at any rank count and split. With no screen cue on
// nothing runs and nothing is exchanged.
//
// Collective over comm: every rank calls with the same scene, camera and radius. `frame` is
// read and rewritten on root only. Returns OK or kMpi, the same on every rank. Never throws.
#pragma once

#include <mpi.h>

#include "core/camera/camera.h"
#include "core/common/status.h"
#include "core/composite/row_bands.h"
#include "core/config/config.h"
#include "core/view/frame.h"

namespace lantern {

// True if the scene asks for any cue computed on the composited frame.
bool wants_screen_cues(const SceneConfig &scene);

// `sphere_radius`: the scene's largest drawn radius (simulation units, the same on every rank),
// the unit of outline.depth_threshold and of the default ambient_occlusion.radius.
Status apply_screen_cues(MPI_Comm comm, int root, const SceneConfig &scene, const Camera &camera,
                         double sphere_radius, Frame *frame);

// The rows of halo the cues of `scene` read above and below a band (0 without a screen cue).
int screen_cue_halo(const SceneConfig &scene);

// The cues on one rank's band, for a pipeline whose bands are already spread over the ranks:
// `band` must hold its owned rows plus screen_cue_halo(scene) rows each side (clamped), e.g.
// from exchange_halo_rows; its owned rows are rewritten. Collective (the automatic depth-cue
// range is reduced over comm). OK or kMpi, the same on every rank.
Status cue_band(MPI_Comm comm, const SceneConfig &scene, const Camera &camera, double sphere_radius,
                BandFrame *band);

}  // namespace lantern
