// The CPU point path (approximate, opt-in with lod.point_path): a sphere far below a pixel is
// written straight into the rendered Frame as one pixel - the pixel its centre projects into,
// coloured as the impostor shades its centre, at the window depth of its nearest point - and
// merged with what OpenGL drew by nearest depth. About a hundred times cheaper than an impostor
// on llvmpipe. Thread-safety: none (writes the frame).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/color/colormap.h"
#include "core/culling/view_geometry.h"
#include "core/particles/particle_arrays.h"
#include "core/render/frame.h"

namespace lantern {

using ColourOf = std::function<Rgb8(int64_t)>;

// `entries` as in DrawList::points. Radius: the published array when per_particle, else radius.
void splat_points(const ParticleArrays &particles, bool per_particle, double radius,
                  const std::vector<uint64_t> &entries, const ViewGeometry &g,
                  const ColourOf &colour, Frame *frame);

}  // namespace lantern
