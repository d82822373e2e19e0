#include "core/output/png/png_bands.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/output/atomic_file.h"
#include "tests/output/scratch_dir.h"
#include "tests/support/hash_noise.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::hash;

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4, top row first
};

// Every byte random, alpha included: nothing to compress, every filter path exercised.
Image noise_image(int w, int h, uint32_t seed) {
  Image img{w, h, std::vector<uint8_t>(size_t(w) * h * 4)};
  for (size_t i = 0; i < img.rgba.size(); ++i) img.rgba[i] = uint8_t(hash(seed * 2654435761u + i));
  return img;
}

// What Lantern renders: a flat opaque background with shaded discs, some partly transparent
// (so RGB and RGBA files differ), discs overlapping band boundaries.
Image rendered_image(int w, int h, uint32_t seed) {
  Image img{w, h, std::vector<uint8_t>(size_t(w) * h * 4)};
  for (size_t i = 0; i < img.rgba.size(); i += 4) {
    img.rgba[i + 0] = 250, img.rgba[i + 1] = 250, img.rgba[i + 2] = 255, img.rgba[i + 3] = 255;
  }
  const int discs = std::max(1, w * h / 40);
  for (int d = 0; d < discs; ++d) {
    const uint32_t k = hash(seed + uint32_t(d) * 7919u);
    const float cx = float(testing::unit(k) * w), cy = float(testing::unit(hash(k)) * h);
    const float r = 1.5f + 3.0f * float(testing::unit(hash(k + 1)));
    const uint8_t alpha = d % 5 == 0 ? uint8_t(128 + d % 100) : 255;
    for (int y = std::max(0, int(cy - r)); y <= std::min(h - 1, int(cy + r)); ++y)
      for (int x = std::max(0, int(cx - r)); x <= std::min(w - 1, int(cx + r)); ++x) {
        const float dx = (x + 0.5f - cx) / r, dy = (y + 0.5f - cy) / r;
        const float d2 = dx * dx + dy * dy;
        if (d2 > 1.0f) continue;
        const float shade = 0.3f + 0.7f * std::sqrt(1.0f - d2);
        uint8_t *p = &img.rgba[(size_t(y) * w + x) * 4];
        p[0] = uint8_t(shade * (k & 0xff)), p[1] = uint8_t(shade * ((k >> 8) & 0xff));
        p[2] = uint8_t(shade * 200), p[3] = alpha;
      }
  }
  return img;
}

// The first `channels` bytes of every RGBA pixel.
std::vector<uint8_t> expected(const Image &img, int channels) {
  if (channels == 4) return img.rgba;
  std::vector<uint8_t> rgb;
  rgb.reserve(img.rgba.size() / 4 * 3);
  for (size_t i = 0; i < img.rgba.size(); i += 4)
    rgb.insert(rgb.end(), &img.rgba[i], &img.rgba[i + 3]);
  return rgb;
}

struct Decoded {
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> pixels;
  std::string error;
};

// Writes the PNG bytes to a file and reads them back with OpenImageIO (raw bytes: no
// premultiplication by alpha on read).
Decoded decode(const ScratchDir &dir, const std::vector<uint8_t> &png) {
  Decoded d;
  const std::string path = dir.file("decode.png");
  d.error = write_bytes_atomically(path, png.data(), png.size()).message;
  if (!d.error.empty()) return d;
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) {
    d.error = "cannot open: " + OIIO::geterror();
    return d;
  }
  const OIIO::ImageSpec &spec = in->spec();
  d.width = spec.width, d.height = spec.height, d.channels = spec.nchannels;
  if (spec.format != OIIO::TypeDesc::UINT8) d.error = "not 8-bit";
  d.pixels.resize(size_t(d.width) * d.height * d.channels);
  if (!in->read_image(0, 0, 0, d.channels, OIIO::TypeDesc::UINT8, d.pixels.data()))
    d.error = "cannot read: " + in->geterror();
  return d;
}

// Asserts that `png` decodes to exactly the image's RGB or RGBA bytes.
void expect_decodes_to(const ScratchDir &dir, const std::vector<uint8_t> &png, const Image &img,
                       int channels, const std::string &what) {
  SCOPED_TRACE(what);
  ASSERT_FALSE(png.empty());
  const Decoded d = decode(dir, png);
  ASSERT_EQ(d.error, "");
  EXPECT_EQ(d.width, img.width);
  EXPECT_EQ(d.height, img.height);
  ASSERT_EQ(d.channels, channels);
  EXPECT_TRUE(d.pixels == expected(img, channels)) << "decoded pixels differ";
}

// encode_png's file; a failure fails the test (and gives an empty file).
std::vector<uint8_t> encoded(const uint8_t *rgba, int width, int height, int channels, int level,
                             int threads) {
  std::vector<uint8_t> png;
  EXPECT_OK(encode_png(rgba, width, height, channels, level, threads, &png));
  return png;
}

std::string describe(const Image &img, int channels, int bands) {
  return std::to_string(img.width) + "x" + std::to_string(img.height) + " " +
         (channels == 3 ? "RGB" : "RGBA") + ", " + std::to_string(bands) + " bands";
}

TEST(PngBands, RoundTripsAtEverySizeAndBandCount) {
  const ScratchDir dir;
  const std::pair<int, int> sizes[] = {{1, 1}, {3, 7}, {37, 23}, {101, 5}, {2, 64}, {255, 130}};
  for (const auto &[w, h] : sizes) {
    for (const Image &img : {noise_image(w, h, 1), rendered_image(w, h, 2)}) {
      for (int channels : {3, 4}) {
        for (int bands : {1, 2, 3, 4, 7}) {
          std::vector<uint8_t> png;
          EXPECT_OK(encode_png(img.rgba.data(), w, h, channels, 1, bands, &png));
          expect_decodes_to(dir, png, img, channels, describe(img, channels, bands));
        }
      }
    }
  }
}

TEST(PngBands, FullFrameRoundTripsAndBandCountsDecodeIdentically) {
  const ScratchDir dir;
  for (const Image &img : {rendered_image(1024, 1024, 3), noise_image(1024, 1024, 4)}) {
    for (int channels : {3, 4}) {
      std::vector<uint8_t> first;
      for (int bands : {1, 2, 3, 4, 7}) {
        const std::vector<uint8_t> png =
            encoded(img.rgba.data(), img.width, img.height, channels, 1, bands);
        expect_decodes_to(dir, png, img, channels, describe(img, channels, bands));
        const Decoded d = decode(dir, png);
        if (first.empty()) first = d.pixels;
        EXPECT_TRUE(d.pixels == first) << describe(img, channels, bands);
      }
    }
  }
}

TEST(PngBands, MoreBandsThanRowsGiveOneRowBands) {
  const ScratchDir dir;
  const Image img = rendered_image(29, 5, 5);
  for (int bands : {5, 6, 64, 1000}) {
    const std::vector<uint8_t> png = encoded(img.rgba.data(), 29, 5, 4, 1, bands);
    expect_decodes_to(dir, png, img, 4, describe(img, 4, bands));
  }
  // Zero or negative counts run on the calling thread as one band.
  for (int bands : {0, -3})
    expect_decodes_to(dir, encoded(img.rgba.data(), 29, 5, 4, 1, bands), img, 4, "bands <= 0");
}

// As MPI ranks would: every band compressed on its own, without the row above it, in uneven
// sizes including 1-row and 0-row bands, then assembled by the root.
TEST(PngBands, IndependentBandsWithEveryFilterAndStrategy) {
  const ScratchDir dir;
  const Image img = rendered_image(53, 17, 6);
  const int split[] = {1, 0, 5, 1, 1, 9};  // rows per band, sum 17
  const PngFilter filters[] = {PngFilter::kNone, PngFilter::kSub, PngFilter::kUp,
                               PngFilter::kAverage, PngFilter::kPaeth};
  const PngStrategy strategies[] = {PngStrategy::kRuns, PngStrategy::kDefault,
                                    PngStrategy::kFiltered, PngStrategy::kRle,
                                    PngStrategy::kHuffmanOnly};
  for (PngFilter filter : filters) {
    for (PngStrategy strategy : strategies) {
      for (bool with_previous_row : {false, true}) {
        for (int channels : {3, 4}) {
          const PngBandOptions options{filter, strategy};
          std::vector<PngBand> bands;
          int y = 0;
          for (size_t b = 0; b < std::size(split); ++b) {
            const uint8_t *first = img.rgba.data() + size_t(y) * img.width * 4;
            const uint8_t *previous = with_previous_row && y > 0 ? first - img.width * 4 : nullptr;
            bands.emplace_back();
            ASSERT_OK(deflate_png_band(first, img.width, split[b], channels,
                                       b + 1 == std::size(split), 6, &bands.back(), previous,
                                       options));
            EXPECT_EQ(bands.back().raw_len, uint64_t(split[b]) * (1 + img.width * channels));
            y += split[b];
          }
          std::vector<uint8_t> png;
          ASSERT_OK(assemble_png(bands, img.width, img.height, channels, &png));
          expect_decodes_to(dir, png, img, channels,
                            "filter " + std::to_string(int(filter)) + " strategy " +
                                std::to_string(int(strategy)) +
                                (with_previous_row ? " with" : " without") + " previous row, " +
                                std::to_string(channels) + " channels");
        }
      }
    }
  }
}

TEST(PngBands, EveryLevelRoundTrips) {
  const ScratchDir dir;
  const Image img = rendered_image(64, 48, 7);
  for (int level = 0; level <= 9; ++level)
    expect_decodes_to(dir, encoded(img.rgba.data(), 64, 48, 4, level, 3), img, 4,
                      "level " + std::to_string(level));
}

uint32_t be32(const uint8_t *p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

// The container by hand: signature, IHDR, IDAT chunks of at most 1 MiB, IEND, valid CRCs; the
// IDAT payload inflates (zlib checks the adler32) to the filtered scanlines' length.
TEST(PngBands, ContainerIsWellFormedWithMebibyteIdatChunks) {
  const Image img = noise_image(1024, 700, 8);  // ~2.8 MB that does not compress
  const std::vector<uint8_t> png = encoded(img.rgba.data(), 1024, 700, 4, 1, 3);
  ASSERT_GT(png.size(), 8u);
  const uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  ASSERT_TRUE(std::equal(signature, signature + 8, png.begin()));
  std::vector<std::string> types;
  std::vector<uint8_t> idat;
  size_t pos = 8;
  while (pos + 12 <= png.size()) {
    const uint32_t n = be32(&png[pos]);
    ASSERT_LE(pos + 12 + n, png.size());
    const std::string type(png.begin() + long(pos) + 4, png.begin() + long(pos) + 8);
    EXPECT_EQ(be32(&png[pos + 8 + n]), uint32_t(crc32(0, &png[pos + 4], n + 4))) << type;
    if (type == "IHDR") {
      ASSERT_EQ(n, 13u);
      EXPECT_EQ(be32(&png[pos + 8]), 1024u);
      EXPECT_EQ(be32(&png[pos + 12]), 700u);
      EXPECT_EQ(png[pos + 16], 8);  // bit depth
      EXPECT_EQ(png[pos + 17], 6);  // RGBA
    }
    if (type == "IDAT") {
      EXPECT_LE(n, 1u << 20);
      idat.insert(idat.end(), &png[pos + 8], &png[pos + 8] + n);
    }
    types.push_back(type);
    pos += 12 + n;
  }
  EXPECT_EQ(pos, png.size());
  ASSERT_GE(types.size(), 5u);  // IHDR, at least 3 IDAT, IEND
  EXPECT_EQ(types.front(), "IHDR");
  EXPECT_EQ(types.back(), "IEND");
  for (size_t i = 1; i + 1 < types.size(); ++i) EXPECT_EQ(types[i], "IDAT");

  const uLong raw_len = 700ul * (1 + 1024 * 4);
  std::vector<uint8_t> raw(raw_len + 16);
  uLongf out_len = uLongf(raw.size());
  EXPECT_EQ(uncompress(raw.data(), &out_len, idat.data(), uLong(idat.size())), Z_OK);
  EXPECT_EQ(out_len, raw_len);
}

// stream_png hands out the file assemble_png builds, piece by piece (the root writes it to disk
// that way, without a buffer of the whole file), and stops with kIo when the sink fails.
TEST(PngBands, StreamedFileIsTheAssembledFileAndStopsWhenTheSinkFails) {
  const Image img = noise_image(1024, 700, 5);  // several IDAT chunks
  std::vector<PngBand> bands(3);
  const int split[4] = {0, 250, 500, 700};
  for (int b = 0; b < 3; ++b)
    ASSERT_OK(deflate_png_band(img.rgba.data() + size_t(split[b]) * 1024 * 4, 1024,
                               split[b + 1] - split[b], 4, b == 2, 1, &bands[size_t(b)]));
  std::vector<uint8_t> whole, streamed;
  ASSERT_OK(assemble_png(bands, 1024, 700, 4, &whole));
  size_t calls = 0;
  ASSERT_OK(stream_png(bands, 1024, 700, 4, [&](const uint8_t *p, size_t n) {
    ++calls;
    streamed.insert(streamed.end(), p, p + n);
    return true;
  }));
  EXPECT_EQ(streamed, whole);
  EXPECT_GT(calls, 3u);  // in pieces, not one buffer
  for (const size_t stop_at : {size_t(1), size_t(3), calls - 1}) {
    size_t seen = 0;
    const Status s =
        stream_png(bands, 1024, 700, 4, [&](const uint8_t *, size_t) { return ++seen < stop_at; });
    EXPECT_EQ(s.code, StatusCode::kIo) << stop_at;
    EXPECT_EQ(seen, stop_at);  // nothing more after the failure
  }
}

// PngBandStream (bands written as they arrive, the compressed total unknown until the end) gives
// assemble_png's bytes: one IDAT chunk, several, and a stream that ends exactly on a chunk
// boundary, where no length needs correcting; put() sees each band's bytes before the next band
// is added.
TEST(PngBands, BandStreamIsTheAssembledFile) {
  const auto streamed = [](const std::vector<PngBand> &bands, int width, int height, int channels,
                           std::vector<uint8_t> *file) {
    file->clear();
    size_t patches = 0;
    PngBandStream png(
        width, height, channels, int(bands.size()),
        [&](const uint8_t *p, size_t n) {
          file->insert(file->end(), p, p + n);
          return true;
        },
        [&](uint64_t at, const uint8_t *p, size_t n) {
          EXPECT_LE(at + n, file->size());
          std::copy(p, p + n, file->begin() + long(at));
          ++patches;
          return true;
        });
    for (const PngBand &b : bands) {
      const size_t before = file->size();
      EXPECT_OK(png.add(b));
      EXPECT_GE(file->size(), before + b.bytes.size());  // written at once, not held back
    }
    EXPECT_OK(png.finish());
    return patches;
  };
  // Real bands: 2.8 MB of noise (three chunks, the last short) and a small render (one chunk).
  for (const bool noise : {true, false}) {
    const int w = noise ? 1024 : 96, h = noise ? 700 : 64;
    const Image img = noise ? noise_image(w, h, 5) : rendered_image(w, h, 5);
    std::vector<PngBand> bands(3);
    const int split[4] = {0, h / 3, 2 * h / 3, h};
    for (int b = 0; b < 3; ++b)
      ASSERT_OK(deflate_png_band(img.rgba.data() + size_t(split[b]) * w * 4, w,
                                 split[b + 1] - split[b], 4, b == 2, 1, &bands[size_t(b)]));
    std::vector<uint8_t> whole, file;
    ASSERT_OK(assemble_png(bands, w, h, 4, &whole));
    EXPECT_EQ(streamed(bands, w, h, 4, &file), 1u) << noise;
    EXPECT_EQ(file, whole) << noise;
  }
  // Pieces sized so that the stream (2 header bytes, the pieces, 4 trailer bytes) fills exactly
  // two chunks: the length announced for each is right, nothing is patched.
  const uint64_t line = 1 + 4 * 4;
  std::vector<PngBand> exact(2);
  for (size_t b = 0; b < 2; ++b) {
    exact[b].rows = 1, exact[b].raw_len = line, exact[b].last = b == 1, exact[b].adler = 7 + b;
    exact[b].bytes.assign(b == 0 ? (1u << 20) + 1000 : (1u << 20) - 1000 - 6, uint8_t(b + 1));
  }
  std::vector<uint8_t> whole, file;
  ASSERT_OK(assemble_png(exact, 4, 2, 4, &whole));
  EXPECT_EQ(streamed(exact, 4, 2, 4, &file), 0u);
  EXPECT_EQ(file, whole);
}

// A band that does not fit, too few bands at finish(), or a sink that fails: an error, and
// nothing more is put after it.
TEST(PngBands, BandStreamRejectsWhatAssemblyRejects) {
  const Image img = rendered_image(16, 8, 9);
  std::vector<PngBand> bands(2);
  ASSERT_OK(deflate_png_band(img.rgba.data(), 16, 4, 4, false, 1, &bands[0]));
  ASSERT_OK(deflate_png_band(img.rgba.data() + 16 * 4 * 4, 16, 4, 4, true, 1, &bands[1]));
  size_t puts = 0;
  const auto count = [&puts](const uint8_t *, size_t) { return ++puts, true; };
  const auto no_patch = [](uint64_t, const uint8_t *, size_t) { return true; };
  {
    PngBandStream png(16, 8, 3, 2, count, no_patch);  // compressed as RGBA, announced as RGB
    EXPECT_EQ(png.add(bands[0]).code, StatusCode::kInvalidArgument);
    EXPECT_EQ(png.finish().code, StatusCode::kInvalidArgument);
    EXPECT_EQ(puts, 0u);
  }
  {
    PngBandStream png(16, 8, 4, 2, count, no_patch);
    EXPECT_EQ(png.add(bands[1]).code, StatusCode::kInvalidArgument);  // the last band first
  }
  {
    PngBandStream png(16, 8, 4, 3, count, no_patch);  // three announced, two added
    EXPECT_OK(png.add(bands[0]));
    EXPECT_EQ(png.add(bands[1]).code, StatusCode::kInvalidArgument);  // not the last of three
  }
  {
    PngBandStream png(16, 9, 4, 2, count, no_patch);  // a row more than the bands hold
    EXPECT_OK(png.add(bands[0]));
    EXPECT_OK(png.add(bands[1]));
    EXPECT_EQ(png.finish().code, StatusCode::kInvalidArgument);
  }
  {
    size_t seen = 0;
    PngBandStream png(
        16, 8, 4, 2, [&](const uint8_t *, size_t) { return ++seen < 3; }, no_patch);
    EXPECT_EQ(png.add(bands[0]).code, StatusCode::kIo);
    EXPECT_EQ(png.add(bands[1]).code, StatusCode::kIo);
    EXPECT_EQ(png.finish().code, StatusCode::kIo);
    EXPECT_EQ(seen, 3u);
  }
  {
    PngBandStream png(16, 8, 4, 2, count, [](uint64_t, const uint8_t *, size_t) { return false; });
    EXPECT_OK(png.add(bands[0]));
    EXPECT_OK(png.add(bands[1]));
    EXPECT_EQ(png.finish().code, StatusCode::kIo);  // the last chunk's length cannot be set
  }
}

TEST(PngBands, MismatchedBandsAreRejectedWithAMessage) {
  const Image img = rendered_image(16, 8, 9);
  const auto band = [&](int y0, int rows, bool last, int channels = 4, int width = 16) {
    PngBand out;
    EXPECT_OK(deflate_png_band(img.rgba.data() + size_t(y0) * 16 * 4, width, rows, channels, last,
                               1, &out));
    return out;
  };
  std::vector<uint8_t> png = {1, 2, 3};
  const auto rejected = [](const Status &s) {
    return s.code == StatusCode::kInvalidArgument && !s.message.empty();
  };
  // Too few rows.
  Status s = assemble_png({band(0, 4, false), band(4, 3, true)}, 16, 8, 4, &png);
  EXPECT_TRUE(rejected(s)) << s.message;
  EXPECT_NE(s.message.find("7 rows"), std::string::npos) << s.message;
  // The stream finishes before the last band, or never.
  s = assemble_png({band(0, 4, true), band(4, 4, true)}, 16, 8, 4, &png);
  EXPECT_TRUE(rejected(s)) << s.message;
  EXPECT_NE(s.message.find("last band"), std::string::npos) << s.message;
  EXPECT_TRUE(rejected(assemble_png({band(0, 4, false), band(4, 4, false)}, 16, 8, 4, &png)));
  // Compressed for another channel count or width.
  s = assemble_png({band(0, 4, false, 3), band(4, 4, true)}, 16, 8, 4, &png);
  EXPECT_TRUE(rejected(s)) << s.message;
  EXPECT_NE(s.message.find("band 0"), std::string::npos) << s.message;
  EXPECT_TRUE(rejected(assemble_png({band(0, 4, false, 4, 15), band(4, 4, true)}, 16, 8, 4, &png)));
  // No bands, bad sizes, bad channels, no output.
  EXPECT_TRUE(rejected(assemble_png({}, 16, 8, 4, &png)));
  EXPECT_TRUE(rejected(assemble_png({band(0, 8, true)}, 0, 8, 4, &png)));
  EXPECT_TRUE(rejected(assemble_png({band(0, 8, true)}, 16, 8, 2, &png)));
  EXPECT_TRUE(rejected(assemble_png({band(0, 8, true)}, 16, 8, 4, nullptr)));
  // The good case still works after all that.
  EXPECT_OK(assemble_png({band(0, 4, false), band(4, 4, true)}, 16, 8, 4, &png));
}

TEST(PngBands, BadArgumentsAreRejected) {
  const Image img = rendered_image(4, 4, 10);
  PngBand band;
  const auto refused = [&band](const Status &s) {
    return s.code == StatusCode::kInvalidArgument && !s.message.empty() && band.bytes.empty() &&
           band.rows == 0;
  };
  EXPECT_TRUE(refused(deflate_png_band(img.rgba.data(), 0, 4, 4, true, 1, &band)));
  EXPECT_TRUE(refused(deflate_png_band(img.rgba.data(), 4, -1, 4, true, 1, &band)));
  EXPECT_TRUE(refused(deflate_png_band(img.rgba.data(), 4, 4, 2, true, 1, &band)));
  EXPECT_TRUE(refused(deflate_png_band(img.rgba.data(), 4, 4, 4, true, 10, &band)));
  EXPECT_TRUE(refused(deflate_png_band(nullptr, 4, 4, 4, true, 1, &band)));
  EXPECT_TRUE(refused(deflate_png_band(img.rgba.data(), 4, 4, 4, true, 1, nullptr)));
  EXPECT_OK(deflate_png_band(nullptr, 4, 0, 4, true, 1, &band));
  EXPECT_TRUE(band.last);

  const auto rejected = [](const Status &s, const std::vector<uint8_t> &png) {
    return s.code == StatusCode::kInvalidArgument && !s.message.empty() && png.empty();
  };
  std::vector<uint8_t> png = {1, 2, 3};
  EXPECT_TRUE(rejected(encode_png(nullptr, 4, 4, 4, 1, 1, &png), png));
  png = {1, 2, 3};
  EXPECT_TRUE(rejected(encode_png(img.rgba.data(), 4, 0, 4, 1, 1, &png), png));
  png = {1, 2, 3};
  EXPECT_TRUE(rejected(encode_png(img.rgba.data(), 4, 4, 1, 1, 1, &png), png));
  png = {1, 2, 3};
  EXPECT_TRUE(rejected(encode_png(img.rgba.data(), 4, 4, 4, -1, 1, &png), png));
  EXPECT_EQ(encode_png(img.rgba.data(), 4, 4, 4, 1, 1, nullptr).code,
            StatusCode::kInvalidArgument);  // no output buffer: no crash
  EXPECT_OK(encode_png(img.rgba.data(), 4, 4, 4, 1, 1, &png, {}));
  EXPECT_GT(png.size(), 0u);
}

}  // namespace
}  // namespace lantern
