// adler32_extend: zlib's adler32_z, value for value, on every length around the vector loop's
// steps and blocks, from any starting checksum, and on all-0xFF bytes (the largest sums, where a
// lane or a block too long would overflow).
#include "core/output/png/adler32.h"

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
  uint32_t mine = 1, theirs = 1;
  // Pieces of uneven lengths, as chunks of rows come.
  for (size_t at = 0, n = 1; at < v.size(); at += n, n = n * 3 + 7) {
    const size_t take = std::min(n, v.size() - at);
    mine = adler32_extend(mine, v.data() + at, take);
    theirs = zlib_adler(theirs, v, at, take);
    ASSERT_EQ(mine, theirs) << "after " << at + take << " bytes";
  }
  // Starting checksums with both halves near the modulus.
  for (uint32_t start : {0u, 0xFFF0FFF0u, 0xFFF00001u, 0x0001FFF0u})
    EXPECT_EQ(adler32_extend(start, v.data(), 9000), zlib_adler(start, v, 0, 9000)) << start;
}

TEST(Adler32, LargestBytesDoNotOverflow) {
  const std::vector<uint8_t> v(3 << 20, 0xFF);
  for (size_t n : {size_t(5536), size_t(5552), size_t(65536), v.size()})
    EXPECT_EQ(adler32_extend(0xFFF0FFF0u, v.data(), n), zlib_adler(0xFFF0FFF0u, v, 0, n)) << n;
}

}  // namespace
}  // namespace lantern
