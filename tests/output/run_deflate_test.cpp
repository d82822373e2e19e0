// RunDeflater: its pieces, alone or concatenated, inflate (zlib, raw deflate) to the input.
#include "core/output/png/run_deflate.h"

#include <zlib.h>

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace lantern {
namespace {

// Inflates raw deflate data; fails the test unless it is one complete stream.
std::vector<uint8_t> inflate_raw(const std::vector<uint8_t> &in, size_t expected) {
  std::vector<uint8_t> out(expected + 16);
  z_stream z{};
  EXPECT_EQ(inflateInit2(&z, -15), Z_OK);
  z.next_in = const_cast<Bytef *>(in.data());
  z.avail_in = uInt(in.size());
  z.next_out = out.data();
  z.avail_out = uInt(out.size());
  EXPECT_EQ(inflate(&z, Z_FINISH), Z_STREAM_END) << (z.msg ? z.msg : "");
  EXPECT_EQ(z.avail_in, 0u) << "bytes after the end of the stream";
  out.resize(z.total_out);
  inflateEnd(&z);
  return out;
}

std::vector<uint8_t> one_piece(const std::vector<uint8_t> &data, size_t block) {
  RunDeflater d;
  for (size_t i = 0; i < data.size(); i += block) {
    const size_t n = std::min(block, data.size() - i);
    d.add_block(data.data() + i, n, i + n == data.size());
  }
  d.finish(true);
  const PageVector<uint8_t> bytes = d.take();
  return std::vector<uint8_t>(bytes.begin(), bytes.end());
}

TEST(RunDeflater, RoundTripsRunsLiteralsAndEdgeCases) {
  std::mt19937 rng(3);
  std::vector<std::vector<uint8_t>> inputs;
  inputs.push_back({});                               // nothing: an empty final block
  inputs.push_back({42});                             // one literal
  inputs.push_back(std::vector<uint8_t>(100000, 0));  // runs of 258 and a remainder
  inputs.push_back({7, 7, 7, 7, 9, 9, 1, 1, 1});      // runs of 3, too short runs
  std::vector<uint8_t> random(70000);
  for (auto &b : random) b = uint8_t(rng());
  inputs.push_back(random);  // every literal, no runs: the distance tree unused
  // Fibonacci frequencies make unlimited Huffman codes about 25 bits long: the 15-bit limit.
  std::vector<uint8_t> skewed;
  uint64_t f0 = 1, f1 = 1;
  for (int s = 0; s < 26; ++s, std::swap(f0, f1), f1 += f0)
    for (uint64_t k = 0; k < f0; ++k) skewed.push_back(uint8_t(s * 9 + (k & 1)));
  std::shuffle(skewed.begin(), skewed.end(), rng);
  inputs.push_back(skewed);
  std::vector<uint8_t> image_like;  // Sub-filtered rows: background zeros and shaded spans
  for (int row = 0; row < 300; ++row) {
    image_like.push_back(1);
    for (int x = 0; x < 900; ++x) image_like.push_back(x % 97 < 30 ? uint8_t(rng() % 5) : 0);
  }
  inputs.push_back(image_like);
  for (size_t i = 0; i < inputs.size(); ++i)
    for (size_t block : {size_t(1000), size_t(1) << 16}) {
      const std::vector<uint8_t> z = one_piece(inputs[i], block);
      EXPECT_EQ(inflate_raw(z, inputs[i].size()), inputs[i]) << "input " << i;
      if (i == 2 || i == 6)  // runs compress
        EXPECT_LT(z.size(), inputs[i].size() / (i == 2 ? 50 : 5)) << "input " << i;
    }
}

TEST(RunDeflater, PiecesConcatenateIntoOneStream) {
  // As bands: non-final pieces end byte-aligned with an empty stored block, the last finishes.
  std::mt19937 rng(9);
  std::vector<uint8_t> all, stream;
  for (int piece = 0; piece < 5; ++piece) {
    std::vector<uint8_t> data(piece == 2 ? 0 : 5000 + 3000 * piece);
    for (auto &b : data) b = rng() % 3 ? 0 : uint8_t(rng() % 16);
    RunDeflater d;
    d.add_block(data.data(), data.size(), piece == 4);
    d.finish(piece == 4);
    const PageVector<uint8_t> bytes = d.take();
    if (piece < 4) ASSERT_GE(bytes.size(), 4u);
    if (piece < 4)  // the sync marker: LEN 0, NLEN 0xffff
      EXPECT_EQ(std::vector<uint8_t>(bytes.end() - 4, bytes.end()),
                (std::vector<uint8_t>{0, 0, 0xff, 0xff}));
    all.insert(all.end(), data.begin(), data.end());
    stream.insert(stream.end(), bytes.begin(), bytes.end());
  }
  EXPECT_EQ(inflate_raw(stream, all.size()), all);
}

// FNV-1a over a piece's bytes.
uint64_t fnv1a(const std::vector<uint8_t> &bytes) {
  uint64_t h = 1469598103934665603ull;
  for (const uint8_t b : bytes) h = (h ^ b) * 1099511628211ull;
  return h;
}

TEST(RunDeflater, BytesAreThoseOfTheFirstEncoder) {
  // PNG files must stay byte-identical, so the encoder's choices (which bytes are literals and
  // which are runs, the trees, the bit packing) must not change: the pieces of these inputs hash
  // as the first version of the encoder made them. Runs of every length from 1 to 600 (258 and
  // its neighbours, the limit), stretches without runs of every length, at every offset in the
  // vector widths and in blocks of several sizes.
  std::mt19937 rng(21);
  std::vector<uint8_t> data;
  for (int k = 0; k < 3000; ++k) {
    const uint32_t kind = rng() % 4;
    if (kind == 0) {  // a run of 1..600 bytes, often of the byte before
      const size_t len = 1 + rng() % (k % 5 == 0 ? 600 : 12);
      const uint8_t b = data.empty() || rng() % 2 ? uint8_t(rng()) : data.back();
      data.insert(data.end(), len, b);
    } else if (kind == 1) {  // literals, no two equal in a row
      for (size_t len = rng() % 70; len > 0; --len) {
        uint8_t b = uint8_t(rng());
        if (!data.empty() && b == data.back()) ++b;
        data.push_back(b);
      }
    } else {  // a Sub-filtered shaded span: small differences, short runs
      for (size_t len = rng() % 200; len > 0; --len) data.push_back(uint8_t(rng() % 4));
    }
  }
  ASSERT_EQ(data.size(), 226213u);
  const uint64_t expected[] = {0x9aac60c8c3935991ull, 0xd90338173bbe092bull, 0x44a268afca3f2e75ull,
                               0xfc7e30c4ff8f5fc5ull, 0xf09c9d1cdcc17053ull, 0x745bcec4c592491full,
                               0x625d90634c6190c4ull, 0x0cdb0c196c357f46ull, 0xd89122857e2678c5ull};
  int e = 0;
  for (const size_t block : {size_t(7), size_t(17), size_t(1000), size_t(65536), data.size()}) {
    const uint64_t h = fnv1a(one_piece(data, block));
    EXPECT_EQ(h, expected[e++]) << "block " << block;
  }
  // Non-final pieces (the sync flush), as bands are.
  for (const size_t len : {size_t(0), size_t(5), size_t(300), size_t(70001)}) {
    RunDeflater d;
    d.add_block(data.data() + 11, len, false);
    d.finish(false);
    const PageVector<uint8_t> bytes = d.take();
    const uint64_t h = fnv1a(std::vector<uint8_t>(bytes.begin(), bytes.end()));
    EXPECT_EQ(h, expected[e++]) << "piece " << len;
  }
}

}  // namespace
}  // namespace lantern
