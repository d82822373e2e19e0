// One movie file encoded through FFmpeg's libraries (libavcodec, libavformat, libswscale), frame
// by frame, so that the file is playable at every moment: MPEG-4 (.mp4, .mov) is written
// fragmented (an empty moov, then one moof + mdat per frame), Matroska (.mkv, .webm) one cluster
// per frame, and every frame is flushed to the file as soon as its packet leaves the encoder. A
// process killed at any point (kill -9) leaves a movie holding every frame written so far.
// Encoders run without look-ahead or reordered frames where they have the option (x264, x265
// zerolatency; VP9 and AV1 with no lag), so a frame reaches the file when it is encoded.
//
// Pixels: RGBA8 frames (alpha ignored) become yuv420p in BT.709 (limited range, tagged with the
// sRGB transfer), what players expect. yuv420p has one chroma sample per 2 x 2 pixels, so an odd
// width or height is padded by one column or row repeating the image's edge (the movie is then
// one pixel wider or taller than the images). lossless: true keeps RGB without subsampling (any
// size, bit-exact): libx264rgb at qp 0 (h264), x265 lossless in GBR (hevc), VP9 lossless in GBR;
// ffv1 (Matroska only) is always lossless. Many players cannot show RGB H.264/HEVC; it is for
// archives and tests.
//
// Without FFmpeg's libraries (LANTERN_WITH_MOVIE=OFF, or AUTO without them) every entry point
// returns a kConfig status saying that this build lacks movies.
//
// Thread-safety: a MovieEncoder is used by one thread at a time; different encoders are
// independent. The free functions are thread-safe.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "core/common/status.h"
#include "core/config/config.h"

namespace lantern {

// False when this build has no movie support.
bool movie_support_built();

// The codecs this build encodes, with the encoder each uses, e.g.
// "h264 (libx264), hevc (libx265), vp9 (libvpx-vp9), av1 (libaom-av1), ffv1 (ffv1)".
std::string movie_codecs_available();

// Checks `movie` for `path` (the expanded file name) against this build: the codec is known and
// present, fits the container, takes `quality` in its range or `lossless`. OK or kConfig naming
// the key (output.movie.codec, ...) and what this build has.
Status check_movie_config(const MovieConfig &movie, const std::string &path);

class MovieEncoder {
 public:
  // Checks the settings (check_movie_config), creates the parent directories, opens `path`
  // (truncating an existing file) and writes the header: an empty but playable movie of
  // width x height frames. kConfig for settings this build cannot encode; kIo naming the path
  // when the file cannot be written.
  static Status open(const MovieConfig &movie, const std::string &path, int width, int height,
                     std::unique_ptr<MovieEncoder> *out);
  ~MovieEncoder();  // closes the file; without finish() the last fragments stay as written
  MovieEncoder(const MovieEncoder &) = delete;
  MovieEncoder &operator=(const MovieEncoder &) = delete;

  // Encodes one frame: width x height RGBA8 pixels, rows from the top, 4 * width bytes apart
  // (read during the call), shown at `index` / fps seconds (indices increase; gaps hold the
  // previous frame). Packets the encoder releases are written and flushed to the file before
  // this returns. OK or kIo naming the path.
  Status encode(const uint8_t *rgba, int64_t index);
  // Frames whose packets are in the file so far.
  int64_t frames_written() const;
  // Drains the encoder and writes the trailer (the index). Idempotent. OK or kIo.
  Status finish();
  // The libavcodec encoder, e.g. "libx264".
  const std::string &encoder_name() const;
  // The coded frame size (the padded size for odd yuv420p sizes).
  int coded_width() const;
  int coded_height() const;

 private:
  struct Impl;
  explicit MovieEncoder(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace lantern
