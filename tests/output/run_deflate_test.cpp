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

}  // namespace
}  // namespace lantern
