#include "core/output/png/png_bands.h"

#include "core/output/png/checksums.h"
#include "core/output/png/run_deflate.h"

#include <zlib.h>

#include <algorithm>
#include <exception>
#include <limits>
#include <new>
#include <optional>
#include <stdexcept>
#include <thread>

namespace lantern {

namespace {

// Filtered scanlines are handed to zlib in chunks of about this many bytes: small enough to stay
// in cache between filtering, adler32 and deflate, large enough that per-call costs vanish.
constexpr size_t kChunkBytes = 64 * 1024;

int zlib_strategy(PngStrategy s) {
  switch (s) {
    case PngStrategy::kFiltered:
      return Z_FILTERED;
    case PngStrategy::kRle:
      return Z_RLE;
    case PngStrategy::kHuffmanOnly:
      return Z_HUFFMAN_ONLY;
    case PngStrategy::kDefault:
    case PngStrategy::kRuns:  // not zlib's: never asked for
    default:
      return Z_DEFAULT_STRATEGY;
  }
}

class Deflater {
 public:
  Deflater(int level, PngStrategy strategy) {
    // Raw deflate (windowBits -15): no zlib header or trailer, the root writes them once.
    if (deflateInit2(&z_, level, Z_DEFLATED, -15, 9, zlib_strategy(strategy)) != Z_OK)
      throw std::runtime_error("zlib deflateInit2 failed");
  }
  ~Deflater() { deflateEnd(&z_); }
  Deflater(const Deflater &) = delete;
  Deflater &operator=(const Deflater &) = delete;

  void reserve(size_t raw_len) { out_.reserve(deflateBound(&z_, uLong(raw_len)) + 64); }

  // Compresses `n` bytes with `flush` (Z_NO_FLUSH, Z_SYNC_FLUSH or Z_FINISH).
  void add(const uint8_t *data, size_t n, int flush) {
    z_.next_in = const_cast<Bytef *>(data);
    z_.avail_in = static_cast<uInt>(n);
    for (;;) {
      if (out_.size() - used_ < 64) out_.resize(std::max<size_t>(2 * out_.size(), used_ + 4096));
      z_.next_out = out_.data() + used_;
      z_.avail_out = static_cast<uInt>(
          std::min<size_t>(out_.size() - used_, std::numeric_limits<uInt>::max()));
      const uInt avail = z_.avail_out;
      const int rc = deflate(&z_, flush);
      used_ += avail - z_.avail_out;
      if (rc == Z_STREAM_END) break;
      if (rc != Z_OK && rc != Z_BUF_ERROR) throw std::runtime_error("zlib deflate failed");
      // Done when all input is consumed and, for a flush, zlib had output space left over.
      if (z_.avail_in == 0 && (flush == Z_NO_FLUSH || z_.avail_out != 0)) break;
    }
  }

  PageVector<uint8_t> take() {
    out_.resize(used_);
    return std::move(out_);
  }

 private:
  z_stream z_{};
  PageVector<uint8_t> out_;
  size_t used_ = 0;
};

}  // namespace

PngBandOptions png_options_for_level(int level) {
  return PngBandOptions{PngFilter::kSub, level == 1 ? PngStrategy::kRuns : PngStrategy::kRle};
}

namespace {

// deflate_png_band after its argument checks. Throws std::bad_alloc, or std::runtime_error when
// zlib fails.
PngBand deflate_checked_band(const uint8_t *rgba, int width, int rows, int channels_out,
                             bool last_band, int level, const uint8_t *previous_row,
                             const PngBandOptions &options) {
  const size_t src_stride = size_t(width) * 4;
  const size_t row_bytes = size_t(width) * size_t(channels_out);
  const size_t line_bytes = row_bytes + 1;

  PngBand band;
  band.rows = rows;
  band.last = last_band;
  band.raw_len = uint64_t(rows) * line_bytes;

  const bool runs = options.strategy == PngStrategy::kRuns;
  std::optional<Deflater> z;
  RunDeflater run_deflater;
  if (!runs) {
    z.emplace(level, options.strategy);
    z->reserve(band.raw_len);
  } else {
    run_deflater.expect(band.raw_len);
  }
  const size_t chunk_rows = std::max<size_t>(1, kChunkBytes / line_bytes);
  std::vector<uint8_t> chunk(std::min<size_t>(chunk_rows, std::max(rows, 1)) * line_bytes);
  // RGB rows filtered with Sub (Lantern's default) come straight from the RGBA rows in one pass.
  const bool sub_of_rgba = channels_out == 3 && options.filter == PngFilter::kSub;
  // RGB copies of the current and previous rows (channels_out == 3 with another filter only).
  std::vector<uint8_t> rgb_cur, rgb_prev;
  if (channels_out == 3 && !sub_of_rgba) {
    rgb_cur.resize(row_bytes);
    rgb_prev.resize(row_bytes);
    if (previous_row) drop_alpha(previous_row, width, rgb_prev.data());
  }
  const uint8_t *prev = channels_out == 3 && previous_row ? rgb_prev.data() : previous_row;

  uint32_t adler = adler32(0, nullptr, 0);
  int row = 0;
  do {
    const int n = static_cast<int>(std::min<size_t>(chunk_rows, size_t(rows - row)));
    uint8_t *out = chunk.data();
    for (int r = 0; r < n; ++r, ++row, out += line_bytes) {
      const uint8_t *src = rgba + size_t(row) * src_stride;
      if (sub_of_rgba) {
        sub_filter_rgb_of_rgba(src, width, out);
        continue;
      }
      const uint8_t *cur = src;
      if (channels_out == 3) {
        drop_alpha(src, width, rgb_cur.data());
        cur = rgb_cur.data();
      }
      PngFilter f = options.filter;
      if (!prev && f != PngFilter::kNone) f = PngFilter::kSub;  // nothing above this row
      if (channels_out == 3)
        filter_row<3>(f, cur, prev, row_bytes, out);
      else
        filter_row<4>(f, cur, prev, row_bytes, out);
      if (channels_out == 3) {
        rgb_cur.swap(rgb_prev);
        prev = rgb_prev.data();
      } else {
        prev = src;
      }
    }
    const size_t bytes = size_t(n) * line_bytes;
    adler = adler32_extend(adler, chunk.data(), bytes);
    if (runs) {
      run_deflater.add_block(chunk.data(), bytes, last_band && row >= rows);
    } else {
      const int flush = row < rows ? Z_NO_FLUSH : last_band ? Z_FINISH : Z_SYNC_FLUSH;
      z->add(chunk.data(), bytes, flush);
    }
  } while (row < rows);
  band.adler = adler;
  if (runs) {
    run_deflater.finish(last_band);
    band.bytes = run_deflater.take();
  } else {
    band.bytes = z->take();
  }
  return band;
}

}  // namespace

Status deflate_png_band(const uint8_t *rgba, int width, int rows, int channels_out, bool last_band,
                        int level, PngBand *band, const uint8_t *previous_row,
                        const PngBandOptions &options) {
  if (!band) return {StatusCode::kInvalidArgument, "deflate_png_band: no output band"};
  *band = PngBand();
  if (width < 1 || rows < 0 || (channels_out != 3 && channels_out != 4) || level < 0 || level > 9 ||
      (!rgba && rows > 0))
    return {StatusCode::kInvalidArgument, "deflate_png_band: bad arguments"};
  try {
    *band = deflate_checked_band(rgba, width, rows, channels_out, last_band, level, previous_row,
                                 options);
    return {};
  } catch (const std::bad_alloc &e) {
    return {StatusCode::kOutOfMemory, std::string("deflate_png_band: ") + e.what()};
  } catch (const std::exception &e) {  // zlib failed
    return {StatusCode::kInternal, std::string("deflate_png_band: ") + e.what()};
  }
}

Status encode_png(const uint8_t *rgba, int width, int height, int channels_out, int level,
                  int threads, std::vector<uint8_t> *file, const PngBandOptions &options) {
  if (!file) return {StatusCode::kInvalidArgument, "encode_png: no output buffer"};
  file->clear();
  if (!rgba || width < 1 || height < 1)
    return {StatusCode::kInvalidArgument, "encode_png: the image is empty"};
  if ((channels_out != 3 && channels_out != 4) || level < 0 || level > 9)
    return {StatusCode::kInvalidArgument, "encode_png: channels_out must be 3 or 4 and level 0..9"};
  const int n = std::clamp(threads, 1, height);
  std::vector<PngBand> bands(static_cast<size_t>(n));
  std::vector<Status> failures(static_cast<size_t>(n));
  const size_t stride = size_t(width) * 4;
  const auto compress = [&](int b) {
    const int y0 = int(int64_t(height) * b / n), y1 = int(int64_t(height) * (b + 1) / n);
    const uint8_t *first = rgba + size_t(y0) * stride;
    failures[size_t(b)] =
        deflate_png_band(first, width, y1 - y0, channels_out, b + 1 == n, level, &bands[size_t(b)],
                         y0 > 0 ? first - stride : nullptr, options);
  };
  std::vector<std::thread> workers;
  Status started;
  try {
    workers.reserve(size_t(n - 1));
    for (int b = 1; b < n; ++b) workers.emplace_back(compress, b);
  } catch (const std::exception &e) {  // a thread could not be started: out of resources
    started = {StatusCode::kOutOfMemory,
               std::string("encode_png: cannot start a thread: ") + e.what()};
  }
  if (started.ok()) compress(0);
  for (std::thread &t : workers) t.join();
  if (!started.ok()) return started;
  for (const Status &f : failures)
    if (!f.ok()) return with_context("encode_png: ", f);
  return assemble_png(bands, width, height, channels_out, file);
}

}  // namespace lantern
