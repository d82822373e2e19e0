// From the ranks' frames of one scene to its finished image on root: the frames are depth-
// composited over the communicator, then finished - super-sampling's down-sampling
// (sample_downsampling.h) and the screen-space cues (screen_cues.h) - before root holds the image.
//
// Without a stage after compositing the frames are composited straight to root. With one, every
// rank composites into its own row band of the image (whole pixels: multiples of s sample rows),
// down-samples it, adds the halo rows the cues read from its neighbours and cues it, and root
// gathers the finished bands: the merged frame is never gathered on one rank. The bands depend
// only on (height, ranks) and each pixel only on its own samples and halo, so the bytes never
// depend on the rank count. finish_image_to_bands stops before the gathering, for an output that
// works band by band.
//
// Collective over comm; every rank calls with the same settings and returns the same status.
// Ownership: reads and consumes `frame` (this rank's frame); writes *image on root only.
#pragma once

#include <mpi.h>

#include "core/camera/camera.h"
#include "core/common/status.h"
#include "core/composite/depth_compositor.h"
#include "core/composite/row_bands.h"
#include "core/config/config.h"
#include "core/finish/overlays/overlays.h"
#include "core/finish/screen_cues.h"
#include "core/view/frame.h"

namespace lantern {

// What finishing needs of one scene, resolved once by the pipeline from its configuration
// (core/pipeline/scene_settings.h).
struct FinishSettings {
  int width = 0, height = 0;  // the image, pixels
  int samples_per_axis = 1;   // s: the ranks' frames are s times the image's width and height
  // background: transparent - down-sampling averages colour weighted by alpha (straight alpha,
  // sample_downsampling.h), so an edge pixel keeps its surface's colour and partial coverage.
  bool transparent_background = false;
  ScreenCueSettings cues;    // the screen-space cues on the final-resolution image
  DensityConfig density;     // style: density - the transfer to colors (density_transfer.h)
  OverlaySettings overlays;  // box, labels, legend, axes: drawn on root after finish_image
};

struct FinishStats {
  CompositeStats composite;  // the method run, this rank's milliseconds and traffic
  double downsample_ms = 0;  // samples > 1: down-sampling and gathering the bands
  double cues_ms = 0;        // the screen-space cues, halo rows included
};

// `frame`: this rank's frame at s = finish.samples_per_axis times the image's width and height.
// `image_camera`: the camera of the final-resolution image (the cues read view depths through
// it); `sphere_radius`: the scene's largest drawn radius (the cues' unit). *image (root's image,
// finish.width x finish.height) may be `frame` itself when s is 1. `model`: compositing's cost
// model (the same on every rank), or null for default_cost_model().
// `ao`: screen ambient occlusion's buffers, kept by the caller from frame to frame, or null;
// `kept_band`: a frame (not `frame` or *image) whose buffers this rank's band uses and leaves
// there for the next call, or null.
// Returns OK, or the failing step's status with "compositing: ", "screen cues: " or "gathering
// the image: " in front of its message.
Status finish_image(MPI_Comm comm, Frame &frame, const FinishSettings &finish,
                    const Camera &image_camera, double sphere_radius,
                    const CompositeCostModel *model, Frame *image, FinishStats *stats,
                    CueScratch *cue_scratch = nullptr, Frame *kept_band = nullptr);

// This rank's rows of an image left in row bands: image rows [rows.y0, rows.y1), held in the
// frame `held` (not owned: finish_image_to_bands's `frame` or *band), whose row 0 is image row
// `first`.
struct ImageBand {
  RowBand rows;
  int first = 0;
  const Frame *held = nullptr;
};

// finish_image without gathering the image on root, for an output that works band by band (the
// PNG writer, core/output/png/png_across_ranks.h): the frames are composited so that every rank
// ends with its own row band of the image, every boundary a multiple of `band_rows` image rows
// (which must divide finish.height), down-sampled when s > 1, and cued as finish_image cues
// (each band widened by the halo rows its neighbours hold). On return *owned says which rows this
// rank holds and where: in `frame` itself when s is 1 and there are no screen cues (its other
// rows are unspecified), else in *band (width x owned->rows.rows() pixels, after the halo rows
// above them with cues), which must then not be `frame`. The bands depend only on (height,
// ranks, band_rows), the pixels on nothing but their samples and halo, so the bytes do not
// depend on the rank count. kInvalidArgument, on every rank, when band_rows does not divide the
// height.
Status finish_image_to_bands(MPI_Comm comm, Frame &frame, const FinishSettings &finish,
                             const Camera &image_camera, double sphere_radius,
                             const CompositeCostModel *model, int band_rows, Frame *band,
                             ImageBand *owned, FinishStats *stats,
                             CueScratch *cue_scratch = nullptr);

}  // namespace lantern
