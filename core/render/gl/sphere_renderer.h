// Draws spheres, and bonds' cylinders, as ray-cast impostors with OpenGL into a Frame (color +
// window depth).
//
// Ownership: the renderer owns its GL program, buffers and framebuffer; it must be created and
// used while the process's GlContext is current (one thread). Units: positions and radii in the
// simulation's length unit, relative to the scene origin chosen by the camera (float precision is
// spent near the scene, not near the world origin).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "core/camera/render_view.h"
#include "core/common/status.h"
#include "core/view/frame.h"

namespace lantern {

// One sphere as the GPU sees it: 20 bytes.
struct SphereInstance {
  float x, y, z;  // centre, relative to the scene origin
  float radius;
  uint8_t rgba[4];
};
static_assert(sizeof(SphereInstance) == 20, "SphereInstance is uploaded as raw bytes");

// One half-bond as the GPU sees it: a closed cylinder from `start` (its atom's centre) to `end`
// (the bond's midpoint), both relative to the scene origin; 32 bytes.
struct BondInstance {
  float start[3];
  float end[3];
  float radius;
  uint8_t rgba[4];
};
static_assert(sizeof(BondInstance) == 32, "BondInstance is uploaded as raw bytes");

struct RenderTimings {
  double draw_ms = 0;      // upload + both passes (GL finished)
  double readback_ms = 0;  // glReadPixels of color and depth into the Frame
  int tiles = 0;
};

class SphereRenderer {
 public:
  // Compiles the shaders and allocates buffers, into *out. On failure returns kGl and leaves *out
  // alone.
  static Status create(std::unique_ptr<SphereRenderer> *out);
  ~SphereRenderer();
  SphereRenderer(const SphereRenderer &) = delete;
  SphereRenderer &operator=(const SphereRenderer &) = delete;

  // Clears `frame` to the view's background and size, then draws `count` spheres: the nearest
  // wins a pixel, and at exactly equal depth the smaller color (R, then G, B; the background
  // competes at background depth), so the order of `spheres` changes no pixel. That takes two
  // passes over the spheres (depth, then color at that depth; sphere_shaders.h). Images larger
  // than the GL limit (or than kMaxTileSize) are drawn tile by tile; tiling changes no pixel.
  // Returns OK or kGl.
  Status render(const RenderView &view, const SphereInstance *spheres, size_t count, Frame *frame,
                RenderTimings *timings);
  // The same with `bond_count` half-bonds as ray-cast cylinders (bond_shaders.h) among the
  // spheres, under the same rules: nearest wins, ties to the smaller color, in both passes.
  Status render(const RenderView &view, const SphereInstance *spheres, size_t count,
                const BondInstance *bonds, size_t bond_count, Frame *frame, RenderTimings *timings);

  // Largest tile side the renderer uses (GL limit, capped to bound the FBO's memory).
  int max_tile_size() const;
  // Lowers (or restores) the tile side, e.g. to bound memory; clamped to [16, GL limit].
  void set_max_tile_size(int pixels);

 private:
  struct Impl;
  explicit SphereRenderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Largest tile edge, in pixels, even if the GL limit is higher: an 4096^2 tile holds 128 MiB.
inline constexpr int kMaxTileSize = 4096;

}  // namespace lantern
