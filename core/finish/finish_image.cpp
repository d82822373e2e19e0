#include "core/finish/finish_image.h"

#include <algorithm>
#include <chrono>
#include <string>
#include <utility>

#include "core/common/ms_since.h"
#include "core/composite/band_compositing.h"
#include "core/composite/row_bands.h"
#include "core/finish/sample_downsampling.h"
#include "core/finish/screen_cues.h"

namespace lantern {
namespace {

using Clock = std::chrono::steady_clock;

// How down-sampling treats alpha: straight on a transparent background (an edge pixel keeps its
// surface's colour and partial coverage), else every sample is opaque.
SampleAlpha sample_alpha(const FinishSettings &finish) {
  return finish.transparent_background ? SampleAlpha::kStraight : SampleAlpha::kOpaque;
}

// The frames composited so that every rank ends with its own row band of the merged frame
// (multiples of `multiple` image rows, i.e. of s * multiple sample rows), down-sampled (s > 1)
// into *band, which then holds the rank's row_band(height, ranks, rank, multiple) of the image:
// exactly, or, with one sample, in place among the rows of the whole merged frame, its `halo`
// rows either side held for exchange_halo_rows to fill. Fills *composite.
//
// With one sample no row is copied: `frame` and band->frame trade buffers, so the band is the
// merged frame, rows where compositing left them, and `frame` gets the band's last buffers to
// draw the next step into (the CPU raster and the readback clear or write every pixel). A copy of
// the owned rows into a band of their own took 0.6 ms of void_impact's 2-rank frame at 1024^2
// (4 MiB of colour and depth a rank), on every frame with a screen-space cue.
Status composite_into_image_band(MPI_Comm comm, Frame &frame, int s, int multiple, int halo,
                                 SampleAlpha alpha, const CompositeOptions &options,
                                 BandFrame *band, CompositeStats *composite) {
  RowBand rows;
  if (Status st = composite_to_row_bands(comm, frame, s * multiple, &rows, options, composite);
      !st.ok())
    return st;
  band->first = rows.y0 / s;
  band->owned = {rows.y0 / s, rows.y1 / s};
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  if (s > 1) {
    downsample_band(frame, s, band->first, band->owned.rows(), &band->frame, alpha);
  } else if (ranks == 1) {
    band->frame = std::move(frame);  // the band is the frame: no copy
  } else {
    std::swap(band->frame, frame);
    band->frame.drawn_within.reset();  // compositing wrote outside it
    band->first = 0;
    band->held = with_halo(rows, band->frame.height, halo);
  }
  return {};
}

// The image's bands to root's *image (on one rank the band is the image: moved, not copied).
Status assemble_image(MPI_Comm comm, BandFrame *band, int width, int height, Frame *image) {
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  if (ranks == 1) {
    *image = std::move(band->frame);
    return {};
  }
  return gather_row_bands(comm, 0, *band, width, height, image);
}

// Widens every rank's band (of row_band(height, ranks, rank, multiple)) by the halo the cues
// read and cues its own rows. Adds the time to stats->cues_ms.
Status cue_image_band(MPI_Comm comm, const FinishSettings &finish, const Camera &image_camera,
                      double sphere_radius, int multiple, BandFrame *band, FinishStats *stats,
                      CueScratch *cue_scratch) {
  const auto t0 = Clock::now();
  Status cued = exchange_halo_rows(comm, finish.width, finish.height, screen_cue_halo(finish.cues),
                                   band, multiple);
  if (cued.ok()) cued = cue_band(comm, finish.cues, image_camera, sphere_radius, band, cue_scratch);
  if (!cued.ok()) return with_context("screen cues: ", std::move(cued));
  stats->cues_ms += ms_since(t0);
  return {};
}

}  // namespace

Status finish_image(MPI_Comm comm, Frame &frame, const FinishSettings &finish,
                    const Camera &image_camera, double sphere_radius,
                    const CompositeCostModel *model, Frame *image, FinishStats *stats,
                    CueScratch *cue_scratch, Frame *kept_band) {
  const int s = finish.samples_per_axis;
  const bool cues = wants_screen_cues(finish.cues);
  CompositeOptions options;
  options.model = model;
  if (s == 1 && !cues) {  // nothing after compositing: straight to root's frame
    if (Status st = composite_frames(comm, frame, 0, options, &stats->composite); !st.ok())
      return with_context("compositing: ", std::move(st));
    return {};
  }
  auto t0 = Clock::now();
  BandFrame band;
  if (kept_band != nullptr) band.frame = std::move(*kept_band);  // the last frame's buffers
  const SampleAlpha alpha = sample_alpha(finish);
  if (Status st =
          composite_into_image_band(comm, frame, s, 1, cues ? screen_cue_halo(finish.cues) : 0,
                                    alpha, options, &band, &stats->composite);
      !st.ok())
    return with_context("compositing: ", std::move(st));
  stats->downsample_ms = ms_since(t0) - stats->composite.milliseconds;
  // Each rank cues its band plus the halo rows its neighbours own.
  if (cues)
    if (Status st =
            cue_image_band(comm, finish, image_camera, sphere_radius, 1, &band, stats, cue_scratch);
        !st.ok())
      return st;
  t0 = Clock::now();
  if (Status st = assemble_image(comm, &band, finish.width, finish.height, image); !st.ok())
    return with_context("gathering the image: ", std::move(st));
  if (s > 1) stats->downsample_ms += ms_since(t0);
  if (kept_band != nullptr) *kept_band = std::move(band.frame);
  return {};
}

Status finish_image_to_bands(MPI_Comm comm, Frame &frame, const FinishSettings &finish,
                             const Camera &image_camera, double sphere_radius,
                             const CompositeCostModel *model, int band_rows, Frame *band,
                             ImageBand *owned, FinishStats *stats, CueScratch *cue_scratch) {
  const int s = finish.samples_per_axis;
  if (band_rows < 1 || finish.height % band_rows != 0)
    return {StatusCode::kInvalidArgument,
            "finish_image_to_bands: bands of " + std::to_string(band_rows) +
                " rows do not divide the image's " + std::to_string(finish.height)};
  CompositeOptions options;
  options.model = model;
  if (wants_screen_cues(finish.cues)) {
    // As finish_image up to the gathering, with bands of whole `band_rows`: the cued rows stay
    // in *band (the halo rows above them first).
    const auto t0 = Clock::now();
    BandFrame cued;
    cued.frame = std::move(*band);  // its buffers, kept from the last frame
    if (Status st =
            composite_into_image_band(comm, frame, s, band_rows, screen_cue_halo(finish.cues),
                                      sample_alpha(finish), options, &cued, &stats->composite);
        !st.ok())
      return with_context("compositing: ", std::move(st));
    stats->downsample_ms = ms_since(t0) - stats->composite.milliseconds;
    if (Status st = cue_image_band(comm, finish, image_camera, sphere_radius, band_rows, &cued,
                                   stats, cue_scratch);
        !st.ok())
      return st;
    owned->rows = cued.owned;
    owned->first = cued.first;
    *band = std::move(cued.frame);
    owned->held = band;
    return {};
  }
  RowBand rows;  // sample rows
  if (Status st =
          composite_to_row_bands(comm, frame, s * band_rows, &rows, options, &stats->composite);
      !st.ok())
    return with_context("compositing: ", std::move(st));
  owned->rows = {rows.y0 / s, rows.y1 / s};
  // Unlike composite_into_image_band, no copy of the rows with one sample: the writer reads them
  // where compositing left them.
  if (s == 1) {
    owned->first = 0;
    owned->held = &frame;
    return {};
  }
  const auto t0 = Clock::now();
  const SampleAlpha alpha = sample_alpha(finish);
  downsample_band(frame, s, owned->rows.y0, owned->rows.rows(), band, alpha);
  owned->first = owned->rows.y0;
  owned->held = band;
  stats->downsample_ms = ms_since(t0);
  return {};
}

}  // namespace lantern
