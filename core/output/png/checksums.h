// The two checksums a PNG file carries, vectorised: the Adler-32 of its zlib stream (RFC 1950),
// over every filtered byte a band compresses, and the CRC-32 of each chunk (PNG spec 5.5), over
// every compressed byte the root writes. zlib's own are scalar; on 1.5 MiB (a 1 M-atom frame's
// PNG) on the 2-core Zen 3 build machine, Adler-32 took 0.50 ms there and 0.05-0.07 ms here (AVX2
// sums), CRC-32 0.42-0.57 ms there and 0.12-0.13 ms here (carry-less multiplication, after V.
// Gopal et al., "Fast CRC Computation for Generic Polynomials Using PCLMULQDQ Instruction",
// Intel white paper, 2009): the CRC is on the root's critical path when it writes the file.
// Same values as zlib's for every input (tests compare them); zlib's are used where the CPU
// lacks the instructions.
//
// Thread-safety: pure functions. Errors: none.
#pragma once

#include <cstddef>
#include <cstdint>

namespace lantern {

// zlib's adler32_z(adler, data, n): the checksum `adler` (1 for none yet) extended by n bytes.
uint32_t adler32_extend(uint32_t adler, const uint8_t *data, size_t n);

// zlib's crc32_z(crc, data, n): the CRC-32 `crc` (0 for none yet) extended by n bytes.
uint32_t crc32_extend(uint32_t crc, const uint8_t *data, size_t n);

}  // namespace lantern
