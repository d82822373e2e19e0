#include "core/output/image_writer.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/half.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/output/atomic_file.h"
#include "core/output/png/png_across_ranks.h"

namespace lantern {

namespace {

float srgb_to_linear(uint8_t code) {
  const float c = code / 255.0f;
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// The pixel data to hand to OIIO, in the layout described by `spec`: either borrowed from the
// frame (RGBA8 formats, no copy) or built here.
struct Prepared {
  OIIO::ImageSpec spec;
  OIIO::TypeDesc buffer_type;  // UNKNOWN = native per-channel formats (EXR with half color)
  const uint8_t *borrowed = nullptr;
  std::vector<uint8_t> storage;
  const void *data() const { return borrowed ? borrowed : storage.data(); }
};

Prepared prepare_8bit(const Frame &frame, int channels) {
  Prepared p;
  p.spec = OIIO::ImageSpec(frame.width, frame.height, channels, OIIO::TypeDesc::UINT8);
  p.buffer_type = OIIO::TypeDesc::UINT8;
  // Store the bytes as they are: a frame's colour is straight (unassociated) alpha, and without
  // this OIIO treats RGBA input as premultiplied and divides by alpha when writing, so the file
  // would not match the frame (TIFF then marks its alpha as unassociated).
  p.spec.attribute("oiio:UnassociatedAlpha", 1);
  if (channels == 4) {
    p.borrowed = frame.rgba.data();
    return p;
  }
  p.storage.resize(frame.pixel_count() * 3);
  for (size_t i = 0; i < frame.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c) p.storage[3 * i + c] = frame.rgba[4 * i + c];
  return p;
}

// Copies `value` into the byte buffer at `out` (unaligned-safe) and returns the next position.
template <typename T>
uint8_t *put(uint8_t *out, T value) {
  std::memcpy(out, &value, sizeof value);
  return out + sizeof value;
}

// The EXR pixels in their native per-channel types, so OIIO does no per-channel conversion
// (which costs more than the compression itself).
template <typename Color>
void fill_exr(const Frame &frame, const DepthToDistance &to_distance, uint8_t *out) {
  Color lut[256];  // sRGB decode of every 8-bit code
  for (int i = 0; i < 256; ++i) lut[i] = Color(srgb_to_linear(static_cast<uint8_t>(i)));
  for (size_t i = 0; i < frame.pixel_count(); ++i) {
    const uint8_t *rgba = &frame.rgba[4 * i];
    if (rgba[3] == 255) {
      for (int c = 0; c < 3; ++c) out = put(out, lut[rgba[c]]);
    } else {
      // A frame holds straight (unassociated) alpha, as PNG stores it; OpenEXR's colour is
      // associated (premultiplied) with alpha, and OpenImageIO hands EXR pixels through as they
      // are (it converts only for formats that store unassociated alpha). So the colour is
      // multiplied by alpha here, in linear light: composited over any background B, the EXR
      // (C + (1 - A) B) and the PNG (c A + (1 - A) B, c decoded from sRGB) show the same pixel.
      const float a = rgba[3] / 255.0f;
      for (int c = 0; c < 3; ++c) out = put(out, Color(srgb_to_linear(rgba[c]) * a));
    }
    out = put(out, Color(rgba[3] / 255.0f));
    const float depth = frame.depth[i];
    const float z = depth >= kBackgroundDepth ? std::numeric_limits<float>::infinity()
                    : to_distance             ? to_distance(depth)
                                              : depth;
    out = put(out, z);
  }
}

Prepared prepare_exr(const Frame &frame, bool half_color, const DepthToDistance &to_distance) {
  Prepared p;
  p.spec = OIIO::ImageSpec(frame.width, frame.height, 5, OIIO::TypeDesc::FLOAT);
  p.spec.channelnames = {"R", "G", "B", "A", "Z"};
  p.spec.alpha_channel = 3;
  p.spec.z_channel = 4;
  p.spec.attribute("compression", "zip");
  if (half_color) {
    const OIIO::TypeDesc h = OIIO::TypeDesc::HALF;
    p.spec.channelformats = {h, h, h, h, OIIO::TypeDesc::FLOAT};
    p.buffer_type = OIIO::TypeDesc::UNKNOWN;
    p.storage.resize(frame.pixel_count() * (4 * sizeof(half) + sizeof(float)));
    fill_exr<half>(frame, to_distance, p.storage.data());
  } else {
    p.buffer_type = OIIO::TypeDesc::FLOAT;
    p.storage.resize(frame.pixel_count() * 5 * sizeof(float));
    fill_exr<float>(frame, to_distance, p.storage.data());
  }
  return p;
}

Prepared prepare(const Frame &frame, const OutputConfig &out, const DepthToDistance &to_distance) {
  switch (out.format) {
    case ImageFormat::kJpeg: {
      Prepared p = prepare_8bit(frame, 3);
      p.spec.attribute("Compression", "jpeg:" + std::to_string(out.jpeg_quality));
      return p;
    }
    case ImageFormat::kTiff: {
      Prepared p = prepare_8bit(frame, 4);
      p.spec.attribute("compression", "zip:" + std::to_string(out.compression_level));
      return p;
    }
    case ImageFormat::kExr:
      return prepare_exr(frame, out.exr_half, to_distance);
    case ImageFormat::kPng:
    default: {
      Prepared p = prepare_8bit(frame, 4);
      p.spec.attribute("png:compressionLevel", out.compression_level);
      return p;
    }
  }
}

// Writes the prepared pixels to `file` (format from `file`'s extension), or, given `memory`,
// into that proxy (`file` then only names the format). OK or kIo with OIIO's message.
Status write_with_oiio(const Prepared &p, const std::string &file,
                       OIIO::Filesystem::IOProxy *memory = nullptr) {
  std::unique_ptr<OIIO::ImageOutput> output = OIIO::ImageOutput::create(file);
  if (!output) return {StatusCode::kIo, "OpenImageIO cannot create a writer: " + OIIO::geterror()};
  if (memory && !(output->supports("ioproxy") && output->set_ioproxy(memory)))
    return {StatusCode::kIo, std::string("OpenImageIO's ") + output->format_name() +
                                 " writer cannot write to memory"};
  OIIO::ImageSpec spec = p.spec;
  // Deterministic files: no wall-clock or host metadata, whatever a plugin would add.
  // TIFF and OpenEXR writers stamp the current time when DateTime is absent; an empty value
  // keeps them from doing so.
  spec.attribute("DateTime", "");
  spec.attribute("Software", "Lantern");
  if (!output->open(file, spec)) return {StatusCode::kIo, output->geterror()};
  const bool written = output->write_image(p.buffer_type, p.data());
  const bool closed = output->close();
  if (!written || !closed) {
    const std::string message = output->geterror();
    return {StatusCode::kIo, message.empty() ? "OpenImageIO write failed" : message};
  }
  return {};
}

Status check_frame(const Frame &frame) {
  if (frame.width <= 0 || frame.height <= 0)
    return {StatusCode::kInvalidArgument, "the frame is empty"};
  if (frame.rgba.size() != frame.pixel_count() * 4 || frame.depth.size() != frame.pixel_count())
    return {StatusCode::kInvalidArgument, "the frame's buffers do not match its size"};
  return {};
}

}  // namespace

const char *image_format_extension(ImageFormat format) {
  switch (format) {
    case ImageFormat::kJpeg:
      return ".jpg";
    case ImageFormat::kTiff:
      return ".tif";
    case ImageFormat::kExr:
      return ".exr";
    case ImageFormat::kPng:
    default:
      return ".png";
  }
}

Status write_image(const Frame &frame, const OutputConfig &out, const std::string &path,
                   const DepthToDistance &depth_to_distance) {
  try {
    if (Status s = check_frame(frame); !s.ok())
      return with_context("cannot write '" + path + "': ", std::move(s));
    // PNG: zlib in row bands (png_across_ranks.h), ~2.6x faster than libpng's single stream.
    if (out.format == ImageFormat::kPng) return write_png(frame, out.compression_level, path, 1);
    const Prepared prepared = prepare(frame, out, depth_to_distance);
    if (out.format == ImageFormat::kJpeg) {
      // libjpeg's default error handler, which OpenImageIO's JPEG writer keeps, calls exit() when
      // a write fails (a full disk): the whole simulation would end. Encoded into memory, where
      // no write fails, the file is then written by write_bytes_atomically, which reports the
      // OS error like any other format.
      std::vector<unsigned char> encoded;
      OIIO::Filesystem::IOVecOutput memory(encoded);
      if (Status s = write_with_oiio(prepared, "memory.jpg", &memory); !s.ok())
        return with_context("cannot write '" + path + "': ", std::move(s));
      return write_bytes_atomically(path, encoded.data(), encoded.size());
    }
    // The temporary file carries the format's extension, so OIIO picks the right writer.
    return write_atomically(path, image_format_extension(out.format), [&](const std::string &temp) {
      return write_with_oiio(prepared, temp);
    });
  } catch (const std::exception &e) {
    return {StatusCode::kIo, "cannot write '" + path + "': " + e.what()};
  } catch (...) {
    return {StatusCode::kIo, "cannot write '" + path + "': unknown error"};
  }
}

}  // namespace lantern
