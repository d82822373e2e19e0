// Ray-cast spheres (and bonds' cylinders, draw_bond) on the CPU, straight into a Frame, with the
// hierarchical depth test that lets hidden spheres be skipped before any pixel work: the renderer
// for dense scenes of small spheres, where llvmpipe spends most of its time on per-primitive setup
// and on fragments it cannot reject early (the impostor shader writes depth).
//
// Each pixel centre gets the same ray as the OpenGL impostor shader (gl/sphere_shaders.h), the hit
// depth as window depth in float, and the same headlight shading. Pixels are cast in tiles of
// 8 x 8 (4 x 4, or one by one, for small spheres) by loops the compiler vectorises (an AVX2
// clone is picked at load time where the CPU has it). Spheres wholly in front of the eye are
// cast in float relative to the ray through their centre, with the window depth of the centre
// added in double, so depths stay within about a float ulp of a double computation; spheres
// reaching behind the eye plane take a double path. A pixel's result depends only on the pixel
// and the sphere - not on the rectangle passed, the tile it fell in, or the CPU - so a pixel can
// differ from OpenGL's float result by one color level or where a silhouette passes within
// float rounding of a pixel centre. Equal depths resolve to the smaller color (R, then G, B, A;
// the background counts, at background depth) - compositing's rule - so the image depends neither
// on the order spheres are drawn in nor on how they are split between ranks, and a sphere skipped
// because `covered` said so would not have changed a bit: skipping is exact.
//
// One raster owns a column strip [x0, x1] of a shared Frame and a max-depth pyramid over it;
// two rasters on disjoint strips of one Frame may draw from two threads at once.
// Ownership: borrows the Frame given to begin_strip() until the next begin_strip().
// Units: view space of ViewGeometry (camera looks down -z); depths stored as window depth.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "core/config/lighting.h"
#include "core/render/shading.h"
#include "core/view/frame.h"
#include "core/view/max_depth_pyramid.h"
#include "core/view/pixel_rays.h"
#include "core/view/view_geometry.h"

namespace lantern {

class CpuSphereRaster {
 public:
  // Clears `frame` (width x height of g) to `background` at background depth. Call once per
  // frame, before any begin_strip on it, from one thread.
  static void clear_target(const ViewGeometry &g, const uint8_t background[4], Frame *frame);

  // Draw into columns [x0, x1] of the cleared `frame`.
  void begin_strip(const ViewGeometry &g, Frame *frame, int x0, int x1);
  // Done drawing the strip: frees the depth pyramid (begin_strip makes it again), so that no
  // pyramid stays in use between frames (its pages are lazily freed, for the next frame's:
  // core/common/page_allocator.h). Nothing may be drawn or asked until begin_strip.
  void end_strip() { pyramid_.release(); }
  // Every pixel this raster has written since begin_strip lies within this rectangle (inclusive;
  // empty when it wrote none): the rest of its strip holds what the frame held before.
  const PixelRect &touched() const { return touched_; }

  // True if every pixel of `rect` (within the strip) already holds something strictly nearer
  // than view depth z: a sphere whose nearest point is at z would change none of them.
  // Inline: asked once per candidate particle.
  bool covered(PixelRect rect, double z) const {
    rect.x0 = std::max(rect.x0, x0_), rect.x1 = std::min(rect.x1, x1_);
    if (rect.empty()) return true;
    if (!(z > g_.near_plane)) return false;
    const float zw = float(g_.window_depth(z) - kQueryMargin);
    // A rectangle of at most 8 x 8 pixels (a sphere of a few pixels, as dense scenes and gases
    // draw) is read on the frame's depth straight away, a row at a time: the pyramid would probe
    // its centre and rim, pick a level and mostly refine there to the same pixels. The same
    // answer, and about 1 ms less of the 1 M-atom LJ frame's 19 ms of culling and drawing
    // (tests/bench/culling/results/base_rows_ab.txt).
    if (rect.x1 - rect.x0 < 8 && rect.y1 - rect.y0 < 8) return pyramid_.covered_on_base(rect, zw);
    return pyramid_.covered(rect, zw);
  }

  // Asks for the depths covered(rect, z) reads first - the rectangle's centre pixel and the
  // middles of its top and bottom edges - ahead of the call (only a hint to the cache).
  void prefetch_covered(PixelRect rect) const {
    rect.x0 = std::max(rect.x0, x0_), rect.x1 = std::min(rect.x1, x1_);
    if (rect.empty()) return;
    const float *depth = frame_->depth.data() + ((rect.x0 + rect.x1) >> 1);
    const size_t w = size_t(g_.width);
    __builtin_prefetch(depth + size_t((rect.y0 + rect.y1) >> 1) * w, 0, 3);
    __builtin_prefetch(depth + size_t(rect.y0) * w, 0, 3);
    __builtin_prefetch(depth + size_t(rect.y1) * w, 0, 3);
  }

  // The light of the spheres drawn from now on (lighting.h); the default (also before any call)
  // draws through the original headlight code, bit for bit.
  void set_lighting(const Lighting &lighting);

  // Ray-casts the sphere (view-space centre c, radius r, color rgb) over the pixels of `rect`
  // inside the strip; `rect` must hold every pixel the sphere covers
  // (ViewGeometry::sphere_rect_tight with a slack of 0.05 px does). `alpha8` below 255 makes
  // the sphere see-through: only the pixels screen_door_keeps() accepts are drawn. Returns true
  // if it won at least one pixel.
  bool draw(const glm::dvec3 &c, double r, const uint8_t rgb[3], PixelRect rect,
            uint8_t alpha8 = 255);

  // Ray-casts the closed cylinder (a half-bond) from view-space point a to b, radius r, over the
  // pixels of `rect` inside the strip (cylinder_rect, core/view/cylinder_bounds.h, holds every
  // pixel it covers), with the spheres' rules: the first surface a pixel's ray enters (the curved
  // side, or an end disc), clipped by the near and far planes as a sphere's nearest hit is; the
  // same light; depth ties to the smaller color; `alpha8` as for draw(). A cylinder wholly in
  // front of the eye (every one, orthographic) is cast in float relative to the ray through a
  // (centred_cylinder_cast.h), a row at a time in vector code, as spheres are; one reaching
  // behind the eye plane in double (CylinderCast). The cast is exact per pixel and depends only
  // on the pixel and the cylinder (not on the rows cast, the vector width or the CPU). Returns
  // true if it won at least one pixel.
  bool draw_bond(const glm::dvec3 &a, const glm::dvec3 &b, double r, const uint8_t rgb[3],
                 PixelRect rect, uint8_t alpha8 = 255);

 private:
  // Query depths are lowered by two float ulps below 1.0 before the strict comparison: the stored
  // depths are double results rounded to float, so this keeps "covered" a guarantee.
  static constexpr double kQueryMargin = 2.0 * 5.96e-8;
  // draw_bond for a cylinder wholly in front of the eye (or any, orthographic): the float cast
  // (centred_cylinder_cast.h), skipping pixels nearer than window depth `reject`.
  bool draw_centred_bond(const glm::dvec3 &a, const glm::dvec3 &u, double length, double r,
                         const uint8_t rgb[3], const PixelRect &rect, uint8_t alpha8, float reject);
  // Whether the strip is the whole frame. Then a vector read of depths may run past the strip's
  // last column into the next row; otherwise it stays in the strip, because other threads write
  // the columns beside it (a read of them, its lanes dropped, would still race with their writes).
  bool holds_every_column() const { return x0_ == 0 && x1_ == g_.width - 1; }

  ViewGeometry g_;
  Frame *frame_ = nullptr;
  int x0_ = 0, x1_ = -1;
  MaxDepthPyramid pyramid_;  // over the frame's depth (level 0), from begin_strip to end_strip
  // Pixels bond draws lowered that the pyramid's levels above 0 do not show yet, within a box of
  // less than kDeferExtent pixels a side.
  static constexpr int kDeferExtent = 16;
  PixelRect pending_;
  PixelRect touched_;  // touched()
  PixelRays rays_;
  std::optional<shading::LightModel<float>> light_;  // set for a lighting other than the default
  // The pixels of a cylinder to cast (columns and rows), the depths they hold, and their window
  // depths and squared Lambert factors (draw_bond); each list has cast_capacity_ entries.
  void grow_cast_lists(int count);
  std::vector<int> cast_x_, cast_y_;
  std::vector<float> cast_depth_, cast_wz_, cast_lambert2_;
  int cast_capacity_ = 0;
};

}  // namespace lantern
