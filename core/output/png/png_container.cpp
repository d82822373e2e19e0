#include "core/output/png/png_container.h"

#include <zlib.h>

#include <algorithm>
#include <exception>

namespace lantern {

namespace {

// IDAT chunks carry at most this much data (the PNG limit is 2^31 - 1).
constexpr size_t kIdatBytes = 1 << 20;

void put_be32(std::vector<uint8_t> *out, uint32_t v) {
  const uint8_t b[4] = {uint8_t(v >> 24), uint8_t(v >> 16), uint8_t(v >> 8), uint8_t(v)};
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

// Appends IDAT chunks of at most kIdatBytes from a sequence of byte ranges (one stream).
class IdatWriter {
 public:
  explicit IdatWriter(std::vector<uint8_t> *out) : out_(out) {}
  void write(const uint8_t *data, size_t n) {
    while (n > 0) {
      if (!open_) begin();
      const size_t take = std::min(n, kIdatBytes - in_chunk_);
      out_->insert(out_->end(), data, data + take);
      in_chunk_ += take;
      data += take;
      n -= take;
      if (in_chunk_ == kIdatBytes) end();
    }
  }
  void finish() {
    if (open_) end();
  }

 private:
  void begin() {
    start_ = out_->size();
    put_be32(out_, 0);  // patched in end()
    const char type[4] = {'I', 'D', 'A', 'T'};
    out_->insert(out_->end(), type, type + 4);
    in_chunk_ = 0;
    open_ = true;
  }
  void end() {
    uint8_t *p = out_->data() + start_;
    const uint32_t n = static_cast<uint32_t>(in_chunk_);
    p[0] = uint8_t(n >> 24), p[1] = uint8_t(n >> 16), p[2] = uint8_t(n >> 8), p[3] = uint8_t(n);
    put_be32(out_, static_cast<uint32_t>(crc32(0, p + 4, uInt(in_chunk_ + 4))));
    open_ = false;
  }

  std::vector<uint8_t> *out_;
  size_t start_ = 0, in_chunk_ = 0;
  bool open_ = false;
};

}  // namespace

Status assemble_png(const std::vector<PngBand> &bands, int width, int height, int channels_out,
                    std::vector<uint8_t> *file) {
  const auto invalid = [](const std::string &what) {
    return Status(StatusCode::kInvalidArgument, "assemble_png: " + what);
  };
  if (!file) return invalid("no output buffer");
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

  try {
    size_t compressed = 0;
    for (const PngBand &b : bands) compressed += b.bytes.size();
    file->clear();
    file->reserve(compressed + compressed / kIdatBytes * 12 + 128);
    static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    file->insert(file->end(), kSignature, kSignature + 8);

    std::vector<uint8_t> ihdr;
    put_be32(&ihdr, static_cast<uint32_t>(width));
    put_be32(&ihdr, static_cast<uint32_t>(height));
    // Bit depth 8; color type 2 (RGB) or 6 (RGBA); deflate; adaptive filtering; no interlace.
    const uint8_t rest[5] = {8, uint8_t(channels_out == 3 ? 2 : 6), 0, 0, 0};
    ihdr.insert(ihdr.end(), rest, rest + 5);
    put_chunk(file, "IHDR", ihdr.data(), ihdr.size());

    IdatWriter idat(file);
    // zlib header: deflate with a 32 KiB window, "fastest" level hint, no dictionary
    // (0x7801 is a multiple of 31, as the FCHECK bits require).
    const uint8_t zlib_header[2] = {0x78, 0x01};
    idat.write(zlib_header, 2);
    uLong adler = adler32(0, nullptr, 0);
    for (const PngBand &b : bands) {
      idat.write(b.bytes.data(), b.bytes.size());
      adler = adler32_combine(adler, b.adler, static_cast<z_off_t>(b.raw_len));
    }
    const uint8_t trailer[4] = {uint8_t(adler >> 24), uint8_t(adler >> 16), uint8_t(adler >> 8),
                                uint8_t(adler)};
    idat.write(trailer, 4);
    idat.finish();
    put_chunk(file, "IEND", nullptr, 0);
    return {};
  } catch (const std::exception &e) {  // only allocation can throw here
    file->clear();
    return {StatusCode::kOutOfMemory, std::string("assemble_png: ") + e.what()};
  }
}

}  // namespace lantern
