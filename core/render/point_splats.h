// The CPU point path (opt-in with lod.point_path): a sphere whose silhouette is under a pixel
// across skips OpenGL. Its silhouette can hold at most one pixel centre, so the CPU casts the
// impostor shader's own ray through the (at most four) candidate centres, in double, and writes
// that pixel's color (same shading formula) and window depth into the rendered Frame where it is
// nearer than what OpenGL drew (at an equal depth where its color is smaller, R then G, B, A: the
// renderers' and compositing's rule, so ties do not depend on the order or the split). Nearly exact
// - the shader works in float, so a silhouette edge or a color can differ by one unit - and far
// cheaper than an impostor on llvmpipe. Thread-safety: none (writes the frame).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/color/colormap.h"
#include "core/common/page_allocator.h"
#include "core/config/lighting.h"
#include "core/particles/particle_arrays.h"
#include "core/view/frame.h"
#include "core/view/view_geometry.h"

namespace lantern {

using ColorOf = std::function<Rgb8(int64_t)>;
using AlphaOf = std::function<uint8_t(int64_t)>;

// `entries` as in DrawList::points. Radius: the published array when per_particle, else radius.
// `alpha` (empty: all opaque) gives each particle's 8-bit opacity for screen_door.h's test.
void splat_points(const ParticleArrays &particles, bool per_particle, double radius,
                  const PageVector<uint64_t> &entries, const ViewGeometry &g, const ColorOf &color,
                  Frame *frame, const AlphaOf &alpha = AlphaOf(),
                  const Lighting &lighting = Lighting());

}  // namespace lantern
