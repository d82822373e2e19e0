#include "core/output/png/png_container.h"

#include <zlib.h>

#include <algorithm>
#include <exception>

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
  put_be32(out, static_cast<uint32_t>(crc32(0, out->data() + start, uInt(out->size() - start))));
}

// Hands IDAT chunks of at most kIdatBytes, holding `total` bytes of one stream given in pieces, to
// `put`: each chunk's length is known up front and its CRC is computed as its bytes pass, so the
// pieces go straight through (the same bytes as appending every chunk whole).
class IdatStream {
 public:
  IdatStream(const PngSink &put, uint64_t total) : put_(put), left_(total) {}
  bool write(const uint8_t *data, size_t n) {
    while (n > 0) {
      if (in_chunk_ == chunk_ && !begin()) return false;
      const size_t take = std::min<size_t>(n, chunk_ - in_chunk_);
      if (!put_(data, take)) return false;
      crc_ = crc32(crc_, data, uInt(take));
      in_chunk_ += take;
      data += take;
      n -= take;
      if (in_chunk_ == chunk_ && !end()) return false;
    }
    return true;
  }

 private:
  bool begin() {
    chunk_ = size_t(std::min<uint64_t>(left_, kIdatBytes));
    left_ -= chunk_;
    in_chunk_ = 0;
    uint8_t head[8];
    be32(head, static_cast<uint32_t>(chunk_));
    const char type[4] = {'I', 'D', 'A', 'T'};
    std::copy(type, type + 4, head + 4);
    crc_ = crc32(0, head + 4, 4);
    return put_(head, 8);
  }
  bool end() {
    uint8_t crc[4];
    be32(crc, static_cast<uint32_t>(crc_));
    return put_(crc, 4);
  }

  const PngSink &put_;
  uint64_t left_;
  size_t chunk_ = 0, in_chunk_ = 0;
  uLong crc_ = 0;
};

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
    const PngBand &b = bands[i];
    if (b.rows < 0 || b.raw_len != uint64_t(b.rows) * line_bytes)
      return invalid("band " + std::to_string(i) +
                     " was compressed for a different width or channel count");
    if (b.last != (i + 1 == bands.size()))
      return invalid("only the last band may finish the deflate stream (band " + std::to_string(i) +
                     ")");
    rows += uint64_t(b.rows);
  }
  if (rows != uint64_t(height))
    return invalid("the bands hold " + std::to_string(rows) + " rows, not " +
                   std::to_string(height));

  const Status stopped(StatusCode::kIo, "assemble_png: the file could not be written");
  try {
    static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    std::vector<uint8_t> head(kSignature, kSignature + 8), ihdr;
    put_be32(&ihdr, static_cast<uint32_t>(width));
    put_be32(&ihdr, static_cast<uint32_t>(height));
    // Bit depth 8; color type 2 (RGB) or 6 (RGBA); deflate; adaptive filtering; no interlace.
    const uint8_t rest[5] = {8, uint8_t(channels_out == 3 ? 2 : 6), 0, 0, 0};
    ihdr.insert(ihdr.end(), rest, rest + 5);
    put_chunk(&head, "IHDR", ihdr.data(), ihdr.size());
    if (!put(head.data(), head.size())) return stopped;

    // zlib header: deflate with a 32 KiB window, "fastest" level hint, no dictionary
    // (0x7801 is a multiple of 31, as the FCHECK bits require); the pieces; the adler32 trailer.
    uint64_t total = 2 + 4;
    for (const PngBand &b : bands) total += b.bytes.size();
    IdatStream idat(put, total);
    const uint8_t zlib_header[2] = {0x78, 0x01};
    if (!idat.write(zlib_header, 2)) return stopped;
    uLong adler = adler32(0, nullptr, 0);
    for (const PngBand &b : bands) {
      if (!idat.write(b.bytes.data(), b.bytes.size())) return stopped;
      adler = adler32_combine(adler, b.adler, static_cast<z_off_t>(b.raw_len));
    }
    const uint8_t trailer[4] = {uint8_t(adler >> 24), uint8_t(adler >> 16), uint8_t(adler >> 8),
                                uint8_t(adler)};
    if (!idat.write(trailer, 4)) return stopped;
    std::vector<uint8_t> iend;
    put_chunk(&iend, "IEND", nullptr, 0);
    if (!put(iend.data(), iend.size())) return stopped;
    return {};
  } catch (const std::exception &e) {  // only allocation can throw here
    return {StatusCode::kOutOfMemory, std::string("assemble_png: ") + e.what()};
  }
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
