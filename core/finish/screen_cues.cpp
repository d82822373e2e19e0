#include "core/finish/screen_cues.h"

#include <algorithm>
#include <cmath>

#include "core/color/colormap.h"
#include "core/composite/row_bands.h"
#include "core/finish/depth_cue.h"
#include "core/finish/outline.h"
#include "core/finish/screen_ambient_occlusion.h"
#include "core/finish/view_positions.h"

namespace lantern {

namespace {

bool screen_ao(const ScreenCueSettings &cues) {
  return cues.ambient_occlusion.enabled &&
         cues.ambient_occlusion.method == AmbientOcclusionMethod::kScreen;
}

void copy_rgb(const std::array<double, 3> &rgb, uint8_t out[3]) {
  const Rgb8 c = to_rgb8(rgb);
  std::copy(c.begin(), c.end(), out);
}

// The nearest and farthest drawn distance of the whole image (owned rows of every rank): the
// automatic range of depth_cue. Min and max are exact, so any banding gives the same two values.
Status drawn_depth_range(MPI_Comm comm, const ViewPositions &v, const RowBand &owned,
                         float *nearest, float *farthest) {
  const std::array<float, 2> local = v.drawn_minima(owned);  // min, -max
  float global[2];
  if (MPI_Allreduce(local.data(), global, 2, MPI_FLOAT, MPI_MIN, comm) != MPI_SUCCESS)
    return {StatusCode::kMpi, "depth_cue: MPI_Allreduce of the drawn depth range failed"};
  *nearest = global[0];
  *farthest = -global[1];
  return {};
}

// The screen ambient occlusion of a scene, `sphere_radius` the unit of its default radius.
AmbientOcclusionStyle ao_style(const ScreenCueSettings &cues, double sphere_radius) {
  AmbientOcclusionStyle style;
  style.radius =
      float(cues.ambient_occlusion.radius.value_or(kDefaultAoRadiusInSphereRadii * sphere_radius));
  style.samples = cues.ambient_occlusion.samples;
  style.strength = float(cues.ambient_occlusion.strength);
  style.half_resolution = cues.ambient_occlusion.resolution == AoResolution::kHalf;
  return style;
}

}  // namespace

bool wants_screen_cues(const ScreenCueSettings &cues) {
  return screen_ao(cues) || cues.outline.enabled || cues.depth_cue.enabled;
}

int screen_cue_halo(const ScreenCueSettings &cues) {
  int halo = 0;
  if (screen_ao(cues)) halo = screen_ambient_occlusion_halo(ao_style(cues, 1.0));
  if (cues.outline.enabled) halo = std::max(halo, cues.outline.width);
  return halo;
}

Status apply_screen_cues(MPI_Comm comm, int root, const ScreenCueSettings &cues, int width,
                         int height, const Camera &camera, double sphere_radius, Frame *frame) {
  if (!wants_screen_cues(cues)) return {};
  BandFrame band;
  if (Status s =
          scatter_row_bands(comm, root, *frame, width, height, 1, screen_cue_halo(cues), &band);
      !s.ok())
    return s;
  if (Status s = cue_band(comm, cues, camera, sphere_radius, &band); !s.ok()) return s;
  return gather_row_bands(comm, root, band, width, height, frame);
}

Status cue_band(MPI_Comm comm, const ScreenCueSettings &cues, const Camera &camera,
                double sphere_radius, BandFrame *band_in, CueScratch *scratch) {
  BandFrame &band = *band_in;
  CueScratch own;
  if (scratch == nullptr) scratch = &own;
  ViewPositions &positions = scratch->positions;
  if (screen_ao(cues))
    build_positions_and_apply_screen_ambient_occlusion(
        &positions, camera, ao_style(cues, sphere_radius), &band, AoVectorPath::kAuto, &scratch->ao,
        cues.threads);
  else
    positions.build(band, camera, true, cues.threads);
  if (cues.outline.enabled) {
    OutlineStyle style;
    style.width = cues.outline.width;
    style.jump = float(cues.outline.depth_threshold * sphere_radius);
    copy_rgb(cues.outline.color, style.color);
    draw_outlines(positions, style, &band, true, cues.threads);
  }
  if (cues.depth_cue.enabled) {
    DepthCueStyle style;
    float nearest = 0, farthest = 0;
    if (!cues.depth_cue.start || !cues.depth_cue.end)
      if (Status s = drawn_depth_range(comm, positions, band.owned, &nearest, &farthest); !s.ok())
        return s;
    style.start = float(cues.depth_cue.start.value_or(nearest));
    style.end = float(cues.depth_cue.end.value_or(farthest));
    copy_rgb(cues.depth_cue.color.value_or(cues.background), style.color);
    style.fade_alpha = cues.transparent_background && !cues.depth_cue.color;
    apply_depth_cue(positions, style, &band, true, cues.threads);
  }
  return {};
}

}  // namespace lantern
