#include "core/output/png/png_container.h"

#include <zlib.h>

#include <algorithm>
#include <exception>
#include <memory>
#include <string>
#include <utility>

#include "core/output/png/checksums.h"

namespace lantern {

namespace {

// IDAT chunks carry at most this much data (the PNG limit is 2^31 - 1).
constexpr size_t kIdatBytes = 1 << 20;

void be32(uint8_t *b, uint32_t v) {
  b[0] = uint8_t(v >> 24), b[1] = uint8_t(v >> 16), b[2] = uint8_t(v >> 8), b[3] = uint8_t(v);
}

void put_be32(std::vector<uint8_t> *out, uint32_t v) {
  uint8_t b[4];
  be32(b, v);
  out->insert(out->end(), b, b + 4);
}

// Appends one chunk: length, type, data, CRC of type + data.
void put_chunk(std::vector<uint8_t> *out, const char type[4], const uint8_t *data, size_t n) {
  put_be32(out, static_cast<uint32_t>(n));
  const size_t start = out->size();
  out->insert(out->end(), type, type + 4);
  if (n) out->insert(out->end(), data, data + n);
  put_be32(out, crc32_extend(0, out->data() + start, out->size() - start));
}

// Hands IDAT chunks of at most kIdatBytes, holding one stream given in pieces, to `put`: each
// chunk's CRC is computed as its bytes pass, so the pieces go straight through (the same bytes as
// appending every chunk whole). With the stream's `total` known, each chunk's length is too when
// its header goes out; without it (PngBandStream), a chunk is announced as kIdatBytes, which all
// but the last are, and close() corrects the last one's length through `patch`.
class IdatStream {
 public:
  IdatStream(const PngSink &put, uint64_t total) : put_(put), left_(total) {}
  IdatStream(const PngSink &put, const PngPatch &patch, uint64_t offset)
      : put_(put), patch_(&patch), left_(UINT64_MAX), offset_(offset) {}
  bool write(const uint8_t *data, size_t n) {
    while (n > 0) {
      if (in_chunk_ == chunk_ && !begin()) return false;
      const size_t take = std::min<size_t>(n, chunk_ - in_chunk_);
      if (!put_(data, take)) return false;
      crc_ = crc32_extend(crc_, data, take);
      in_chunk_ += take;
      offset_ += take;
      data += take;
      n -= take;
      if (in_chunk_ == chunk_ && !end()) return false;
    }
    return true;
  }
  // Ends an unfinished last chunk (only without a known total: otherwise it ends itself).
  bool close() {
    if (in_chunk_ == chunk_) return true;
    uint8_t length[4];
    be32(length, static_cast<uint32_t>(in_chunk_));
    if (!(*patch_)(chunk_offset_, length, 4)) return false;
    chunk_ = in_chunk_;
    return end();
  }

 private:
  bool begin() {
    chunk_ = size_t(std::min<uint64_t>(left_, kIdatBytes));
    if (left_ != UINT64_MAX) left_ -= chunk_;
    in_chunk_ = 0;
    uint8_t head[8];
    be32(head, static_cast<uint32_t>(chunk_));
    const char type[4] = {'I', 'D', 'A', 'T'};
    std::copy(type, type + 4, head + 4);
    crc_ = crc32_extend(0, head + 4, 4);
    chunk_offset_ = offset_;
    offset_ += 8;
    return put_(head, 8);
  }
  bool end() {
    uint8_t crc[4];
    be32(crc, static_cast<uint32_t>(crc_));
    offset_ += 4;
    return put_(crc, 4);
  }

  const PngSink &put_;
  const PngPatch *patch_ = nullptr;
  uint64_t left_;              // stream bytes not yet in a chunk; UINT64_MAX: unknown
  uint64_t offset_ = 0;        // file offset of the next byte put
  uint64_t chunk_offset_ = 0;  // of the current chunk's header
  size_t chunk_ = 0, in_chunk_ = 0;
  uint32_t crc_ = 0;
};

// Signature and IHDR: 8-bit, color type 2 (RGB) or 6 (RGBA), deflate, adaptive filtering, no
// interlace.
std::vector<uint8_t> file_head(int width, int height, int channels_out) {
  static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<uint8_t> head(kSignature, kSignature + 8), ihdr;
  put_be32(&ihdr, static_cast<uint32_t>(width));
  put_be32(&ihdr, static_cast<uint32_t>(height));
  const uint8_t rest[5] = {8, uint8_t(channels_out == 3 ? 2 : 6), 0, 0, 0};
  ihdr.insert(ihdr.end(), rest, rest + 5);
  put_chunk(&head, "IHDR", ihdr.data(), ihdr.size());
  return head;
}

// zlib header: deflate with a 32 KiB window, "fastest" level hint, no dictionary (0x7801 is a
// multiple of 31, as the FCHECK bits require).
constexpr uint8_t kZlibHeader[2] = {0x78, 0x01};

// Why band `i` of `count` cannot be band `i` of a width x channels_out image, or "" when it can.
std::string band_mismatch(const PngBand &b, size_t i, size_t count, uint64_t line_bytes) {
  if (b.rows < 0 || b.raw_len != uint64_t(b.rows) * line_bytes)
    return "band " + std::to_string(i) + " was compressed for a different width or channel count";
  if (b.last != (i + 1 == count))
    return "only the last band may finish the deflate stream (band " + std::to_string(i) + ")";
  return "";
}

// The IEND chunk that ends every file.
std::vector<uint8_t> iend_chunk() {
  std::vector<uint8_t> iend;
  put_chunk(&iend, "IEND", nullptr, 0);
  return iend;
}

}  // namespace

Status stream_png(const std::vector<PngBand> &bands, int width, int height, int channels_out,
                  const PngSink &put) {
  const auto invalid = [](const std::string &what) {
    return Status(StatusCode::kInvalidArgument, "assemble_png: " + what);
  };
  if (width < 1 || height < 1) return invalid("the image is empty");
  if (channels_out != 3 && channels_out != 4) return invalid("channels_out must be 3 or 4");
  if (bands.empty()) return invalid("no bands");
  const uint64_t line_bytes = uint64_t(width) * uint64_t(channels_out) + 1;
  uint64_t rows = 0;
  for (size_t i = 0; i < bands.size(); ++i) {
    if (const std::string why = band_mismatch(bands[i], i, bands.size(), line_bytes); !why.empty())
      return invalid(why);
    rows += uint64_t(bands[i].rows);
  }
  if (rows != uint64_t(height))
    return invalid("the bands hold " + std::to_string(rows) + " rows, not " +
                   std::to_string(height));

  const Status stopped(StatusCode::kIo, "assemble_png: the file could not be written");
  try {
    const std::vector<uint8_t> head = file_head(width, height, channels_out);
    if (!put(head.data(), head.size())) return stopped;
    uint64_t total = 2 + 4;
    for (const PngBand &b : bands) total += b.bytes.size();
    IdatStream idat(put, total);
    if (!idat.write(kZlibHeader, 2)) return stopped;
    uLong adler = adler32(0, nullptr, 0);
    for (const PngBand &b : bands) {
      if (!idat.write(b.bytes.data(), b.bytes.size())) return stopped;
      adler = adler32_combine(adler, b.adler, static_cast<z_off_t>(b.raw_len));
    }
    uint8_t trailer[4];
    be32(trailer, static_cast<uint32_t>(adler));  // the zlib trailer
    if (!idat.write(trailer, 4)) return stopped;
    const std::vector<uint8_t> iend = iend_chunk();
    if (!put(iend.data(), iend.size())) return stopped;
    return {};
  } catch (const std::exception &e) {  // only allocation can throw here
    return {StatusCode::kOutOfMemory, std::string("assemble_png: ") + e.what()};
  }
}

struct PngBandStream::State {
  State(const PngSink &put, const PngPatch &patch, uint64_t offset) : idat(put, patch, offset) {}
  IdatStream idat;  // refers to the stream's put_ and patch_
  uLong adler = adler32(0, nullptr, 0);
  uint64_t rows = 0;
};

PngBandStream::PngBandStream(int width, int height, int channels_out, int bands, PngSink put,
                             PngPatch patch)
    : width_(width),
      height_(height),
      channels_(channels_out),
      bands_(bands),
      put_(std::move(put)),
      patch_(std::move(patch)) {}

PngBandStream::~PngBandStream() = default;

Status PngBandStream::add(const PngBand &band) {
  if (!failure_.ok()) return failure_;
  const auto fail = [this](StatusCode code, const std::string &what) {
    failure_ = {code, "assemble_png: " + what};
    return failure_;
  };
  if (width_ < 1 || height_ < 1) return fail(StatusCode::kInvalidArgument, "the image is empty");
  if (channels_ != 3 && channels_ != 4)
    return fail(StatusCode::kInvalidArgument, "channels_out must be 3 or 4");
  if (added_ >= bands_) return fail(StatusCode::kInvalidArgument, "more bands than announced");
  const uint64_t line_bytes = uint64_t(width_) * uint64_t(channels_) + 1;
  if (const std::string why = band_mismatch(band, size_t(added_), size_t(bands_), line_bytes);
      !why.empty())
    return fail(StatusCode::kInvalidArgument, why);
  try {
    if (!state_) {
      const std::vector<uint8_t> head = file_head(width_, height_, channels_);
      if (!put_(head.data(), head.size()))
        return fail(StatusCode::kIo, "the file could not be written");
      state_ = std::make_unique<State>(put_, patch_, head.size());
      if (!state_->idat.write(kZlibHeader, 2))
        return fail(StatusCode::kIo, "the file could not be written");
    }
  } catch (const std::exception &e) {
    return fail(StatusCode::kOutOfMemory, e.what());
  }
  ++added_;
  state_->rows += uint64_t(band.rows);
  if (!state_->idat.write(band.bytes.data(), band.bytes.size()))
    return fail(StatusCode::kIo, "the file could not be written");
  state_->adler = adler32_combine(state_->adler, band.adler, static_cast<z_off_t>(band.raw_len));
  return {};
}

Status PngBandStream::finish() {
  if (!failure_.ok()) return failure_;
  if (added_ != bands_ || !state_) {
    failure_ = {StatusCode::kInvalidArgument, "assemble_png: " + std::to_string(added_) +
                                                  " bands added of " + std::to_string(bands_)};
    return failure_;
  }
  if (state_->rows != uint64_t(height_)) {
    failure_ = {StatusCode::kInvalidArgument, "assemble_png: the bands hold " +
                                                  std::to_string(state_->rows) + " rows, not " +
                                                  std::to_string(height_)};
    return failure_;
  }
  uint8_t trailer[4];
  be32(trailer, static_cast<uint32_t>(state_->adler));  // the zlib trailer
  try {
    const std::vector<uint8_t> iend = iend_chunk();
    if (state_->idat.write(trailer, 4) && state_->idat.close() && put_(iend.data(), iend.size()))
      return {};
  } catch (const std::exception &e) {
    failure_ = {StatusCode::kOutOfMemory, std::string("assemble_png: ") + e.what()};
    return failure_;
  }
  failure_ = {StatusCode::kIo, "assemble_png: the file could not be written"};
  return failure_;
}

Status assemble_png(const std::vector<PngBand> &bands, int width, int height, int channels_out,
                    std::vector<uint8_t> *file) {
  if (!file) return {StatusCode::kInvalidArgument, "assemble_png: no output buffer"};
  file->clear();
  try {
    size_t compressed = 0;
    for (const PngBand &b : bands) compressed += b.bytes.size();
    file->reserve(compressed + compressed / kIdatBytes * 12 + 128);
  } catch (const std::exception &e) {
    return {StatusCode::kOutOfMemory, std::string("assemble_png: ") + e.what()};
  }
  const Status s =
      stream_png(bands, width, height, channels_out, [file](const uint8_t *p, size_t n) {
        file->insert(file->end(), p, p + n);
        return true;
      });
  if (!s.ok()) file->clear();
  return s;
}

}  // namespace lantern
