// adler32_extend and crc32_extend: zlib's adler32_z and crc32_z, value for value, on every length
// around the vector loops' steps and blocks, at any alignment, from any starting checksum, and
// (Adler-32) on all-0xFF bytes, the largest sums, where a lane or a block too long would overflow.
#include "core/output/png/checksums.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "tests/support/hash_noise.h"

namespace lantern {
namespace {

std::vector<uint8_t> noise_bytes(size_t n, uint64_t seed) {
  std::vector<uint8_t> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = uint8_t(testing::hash(uint32_t(seed * 1000003u + i)) >> 24);
  return v;
}

uint32_t zlib_adler(uint32_t adler, const std::vector<uint8_t> &v, size_t from, size_t n) {
  return uint32_t(adler32_z(adler, v.data() + from, n));
}

// Extends `start` by the bytes of v in pieces of growing, uneven lengths (as chunks of rows come)
// with both functions, expecting the same value after every piece.
template <typename Mine, typename Theirs>
void expect_same_over_pieces(const std::vector<uint8_t> &v, uint32_t start, size_t growth,
                             const Mine &mine, const Theirs &theirs) {
  uint32_t a = start, b = start;
  for (size_t at = 0, n = 1; at < v.size(); at += n, n = n * growth + 7) {
    const size_t take = std::min(n, v.size() - at);
    a = mine(a, v.data() + at, take);
    b = theirs(b, v.data() + at, take);
    ASSERT_EQ(a, b) << "after " << at + take << " bytes";
  }
}

TEST(Adler32, IsZlibsAtEveryLengthAndOffset) {
  const std::vector<uint8_t> v = noise_bytes(3 * 5552 + 200, 7);
  for (size_t n = 0; n <= 200; ++n)
    for (size_t from : {size_t(0), size_t(1), size_t(13)})
      ASSERT_EQ(adler32_extend(1, v.data() + from, n), zlib_adler(1, v, from, n))
          << n << " bytes from " << from;
  // Around the block of 5536 bytes the vector loop sums before reducing, and zlib's NMAX 5552.
  for (size_t n : {5503, 5535, 5536, 5537, 5551, 5552, 5553, 5568, 11072, 11103, 3 * 5552 + 200})
    EXPECT_EQ(adler32_extend(1, v.data(), n), zlib_adler(1, v, 0, n)) << n << " bytes";
}

TEST(Adler32, ContinuesAnyChecksumAsZlibDoes) {
  const std::vector<uint8_t> v = noise_bytes(100000, 11);
  expect_same_over_pieces(v, 1, 3, adler32_extend, [](uint32_t a, const uint8_t *p, size_t n) {
    return uint32_t(adler32_z(a, p, n));
  });
  // Starting checksums with both halves near the modulus.
  for (uint32_t start : {0u, 0xFFF0FFF0u, 0xFFF00001u, 0x0001FFF0u})
    EXPECT_EQ(adler32_extend(start, v.data(), 9000), zlib_adler(start, v, 0, 9000)) << start;
}

TEST(Adler32, LargestBytesDoNotOverflow) {
  const std::vector<uint8_t> v(3 << 20, 0xFF);
  for (size_t n : {size_t(5536), size_t(5552), size_t(65536), v.size()})
    EXPECT_EQ(adler32_extend(0xFFF0FFF0u, v.data(), n), zlib_adler(0xFFF0FFF0u, v, 0, n)) << n;
}

uint32_t zlib_crc(uint32_t crc, const std::vector<uint8_t> &v, size_t from, size_t n) {
  return uint32_t(crc32_z(crc, v.data() + from, n));
}

TEST(Crc32, IsZlibsAtEveryLengthAndOffset) {
  const std::vector<uint8_t> v = noise_bytes(70000, 5);
  for (size_t n = 0; n <= 300; ++n)
    for (size_t from : {size_t(0), size_t(1), size_t(7)})
      ASSERT_EQ(crc32_extend(0, v.data() + from, n), zlib_crc(0, v, from, n))
          << n << " bytes from " << from;
  for (size_t n : {1023, 1024, 1025, 4096 + 15, 65536, 69999})
    EXPECT_EQ(crc32_extend(0, v.data(), n), zlib_crc(0, v, 0, n)) << n << " bytes";
  // All zeros and all ones (the folds see no carries to hide behind).
  for (const uint8_t b : {uint8_t(0), uint8_t(0xFF)}) {
    const std::vector<uint8_t> flat(5000, b);
    EXPECT_EQ(crc32_extend(0, flat.data(), flat.size()), zlib_crc(0, flat, 0, flat.size()));
  }
}

TEST(Crc32, ContinuesAnyCrcAsZlibDoes) {
  const std::vector<uint8_t> v = noise_bytes(200000, 13);
  expect_same_over_pieces(v, 0, 2, crc32_extend, [](uint32_t c, const uint8_t *p, size_t n) {
    return uint32_t(crc32_z(c, p, n));
  });
  for (uint32_t start : {0xFFFFFFFFu, 0x12345678u, 0x80000001u})
    EXPECT_EQ(crc32_extend(start, v.data(), 777), zlib_crc(start, v, 0, 777)) << start;
}

}  // namespace
}  // namespace lantern
