// Writes a rendered Frame to an image file, atomically (atomic_file.h): PNG with zlib in row
// bands (png_across_ranks.h), the other formats through OpenImageIO.
//
// Formats: PNG (RGB8 for opaque frames, else RGBA8 with straight alpha, as PNG specifies;
// out.compression_level), JPEG (RGB8, out.jpeg_quality), TIFF (RGBA8, unassociated alpha), EXR
// (R,G,B,A as half or float per out.exr_half, converted from sRGB to linear and premultiplied by
// alpha as OpenEXR specifies, plus a float `Z` channel with the camera distance). A Frame's alpha
// is straight (background: transparent leaves alpha 0 where nothing is drawn). Files carry no
// timestamps, so identical frames give byte-identical files. Thread-safe for different paths; never
// throws.
#pragma once

#include <functional>
#include <string>

#include "core/common/status.h"
#include "core/config/config.h"
#include "core/view/frame.h"

namespace lantern {

// Maps a window depth in [0, 1) to the camera distance in simulation units (for EXR `Z`).
// Background pixels (depth == kBackgroundDepth) are written as +inf without calling it.
using DepthToDistance = std::function<float(float)>;

// Writes `frame` to `path` in `out.format` (the file name's extension does not matter; the
// format is set explicitly). Creates parent directories. Returns OK, or a message naming the path
// and the reason: kIo when the file cannot be written, kInvalidArgument for a frame whose buffers
// do not match its size. On failure no file exists at `path` (an older file there stays
// untouched). `depth_to_distance` is only used for EXR; if empty, `Z` holds the raw window depth.
Status write_image(const Frame &frame, const OutputConfig &out, const std::string &path,
                   const DepthToDistance &depth_to_distance);

// The usual file extension of a format, with the dot: ".png", ".jpg", ".tif", ".exr".
const char *image_format_extension(ImageFormat format);

}  // namespace lantern
