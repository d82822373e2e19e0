// Screen-space ambient occlusion of a composited band (Kozlikova et al., "Visualization of
// Biomolecular Structures: State of the Art Revisited", CGF 2017, for its use on molecular
// data): each drawn pixel is darkened by how much of the hemisphere above it the surrounding
// composited surface covers.
//
// The estimate at a pixel at view-space point P with normal n (reconstructed from the depth of
// its neighbours, on each axis the side with the smaller depth step so that normals do not bend
// over silhouettes): `samples` pixels are read on a fixed golden-angle spiral of radius `radius`
// projected to pixels (at most kMaxAoPixels), turned by an angle that depends only on the
// pixel's image position (x mod 4, y mod 4): no random state, so every rank computes the same.
// A sample at view-space point Q occludes by max(0, cos(n, Q - P) - kAoBias) x
// max(0, 1 - |Q - P|^2 / radius^2); the colour is scaled by
// 1 - strength x min(1, 2 x mean occlusion). A convex surface (one lone sphere) never occludes
// itself: every chord points below its tangent plane.
//
// Resolution (`half_resolution`):
//   - full: the estimate at every pixel.
//   - half (the default): the estimate at the pixels of even column and even row only (a
//     quarter of them, with the turn of (x/2 mod 4, y/2 mod 4)), computed 8 pixels at a time in
//     vector registers; then blurred over 5 x 5 of those estimates with the separable weights
//     1 2 2 2 1 (every one of the 4 turns of a row or column weighs the same), skipping
//     estimates whose depth differs from the centre's by more than kAoDepthTolerance x radius;
//     then brought back to every pixel from the 1, 2 or 4 nearest estimates (bilinear) whose
//     depth is within kAoDepthTolerance x radius of the pixel's own. A pixel with no such
//     estimate (a sliver of surface narrower than two pixels) gets the full-resolution estimate.
//     Measured against full: lantern-bench-cues.
//
// Reads only distances (view_positions.h); writes the colour of the band's owned rows. Needs a
// halo of screen_ambient_occlusion_halo() rows, from which every value is computed: the same
// bytes whatever the band.
#pragma once

#include <vector>

#include "core/camera/camera.h"
#include "core/composite/row_bands.h"
#include "core/finish/view_positions.h"

namespace lantern {

// The largest sampling radius in pixels: bounds the work per pixel and the rows exchanged,
// whatever radius and zoom ask for.
inline constexpr int kMaxAoPixels = 32;
// Cosine below which a neighbour does not occlude: absorbs the error of normals reconstructed
// from 8-bit-free but float depth on curved surfaces.
inline constexpr float kAoBias = 0.1f;
// Half resolution: estimates further apart in depth than this many radii are not mixed.
inline constexpr float kAoDepthTolerance = 0.25f;

struct AmbientOcclusionStyle {
  float radius = 1.0f;    // sampling radius, simulation units, > 0
  int samples = 16;       // 1..64
  float strength = 0.6f;  // [0, 1]
  bool half_resolution = true;
};

// The rows of halo above and below a band that the style reads.
int screen_ambient_occlusion_halo(const AmbientOcclusionStyle &style);

// The instruction set of the half-resolution pass. kAuto takes the fastest measured that the
// processor has: AVX2 with gathers where those are fast (cpu_prefers_gathers()), else AVX-512,
// else AVX2. The others force one, for tests and benchmarks; one the processor lacks runs the
// portable pass (the baseline: SSE2 on x86-64). All give the same bits: the same IEEE operations in
// the same order, lane by lane.
enum class AoVectorPath { kAuto, kAvx512, kAvx2Gather, kAvx2, kPortable };

// The half-resolution pass's estimate grids, kept by a caller from frame to frame so that they
// are neither allocated nor faulted in again (what a frame leaves in them is never read by the
// next). Ownership: the caller's; one per call in flight.
struct AoScratch {
  std::vector<float> raw_value, raw_z, across_value, across_z, blurred_value, blurred_z;
};

// `scratch`: kept buffers, or null for buffers of this call only. `threads`: how many threads
// (this one included) may share the rows (the run-wide `threads:`); every count gives the same
// bytes. Thread-safety: one call per band and scratch at a time.
void apply_screen_ambient_occlusion(const ViewPositions &positions,
                                    const AmbientOcclusionStyle &style, BandFrame *band,
                                    AoVectorPath path = AoVectorPath::kAuto,
                                    AoScratch *scratch = nullptr, int threads = 1);

// The same, with `positions` built here from the band's depths and `camera` (as
// positions->build(*band, camera, true, threads) builds them, which they are on return, for the
// cues after this one). At half resolution on one thread (one part of the rows), each row's
// distances are computed just before the estimates first read them and the phases run row by row,
// so the distances are read from the cache rather than from memory: the same bytes.
void build_positions_and_apply_screen_ambient_occlusion(
    ViewPositions *positions, const Camera &camera, const AmbientOcclusionStyle &style,
    BandFrame *band, AoVectorPath path = AoVectorPath::kAuto, AoScratch *scratch = nullptr,
    int threads = 1);

}  // namespace lantern
