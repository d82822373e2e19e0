#include "core/output/png/run_deflate.h"

#include <algorithm>
#include <array>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lantern {
namespace {

constexpr int kLitLenSymbols = 286;  // 0..255 literals, 256 end of block, 257..285 lengths
constexpr int kEndOfBlock = 256;
constexpr int kMinRun = 3, kMaxRun = 258;
constexpr int kMaxCodeBits = 15, kMaxCodeLengthBits = 7;

// RFC 1951 3.2.5: length codes 257.. by base length and extra bits.
constexpr std::array<uint16_t, 29> kLengthBase = {3,  4,  5,  6,   7,   8,   9,   10,  11, 13,
                                                  15, 17, 19, 23,  27,  31,  35,  43,  51, 59,
                                                  67, 83, 99, 115, 131, 163, 195, 227, 258};
constexpr std::array<uint8_t, 29> kLengthExtra = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                                  2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
// The order in which the code-length code's lengths are sent.
constexpr std::array<uint8_t, 19> kCodeLengthOrder = {16, 17, 18, 0, 8,  7, 9,  6, 10, 5,
                                                      11, 4,  12, 3, 13, 2, 14, 1, 15};

// For each run length 0..258: its length code (index into kLengthBase).
struct LengthCodes {
  std::array<uint8_t, kMaxRun + 1> code{};
  LengthCodes() {
    int c = 0;
    for (int len = kMinRun; len <= kMaxRun; ++len) {
      while (c + 1 < int(kLengthBase.size()) && kLengthBase[size_t(c + 1)] <= len) ++c;
      code[size_t(len)] = uint8_t(c);
    }
  }
};
const LengthCodes kLengthCodes;

// Huffman code lengths of at most `limit` bits for `n` symbols of the given frequencies. Unused
// symbols get 0. At least two symbols always get a code (a lone used symbol is paired with
// another), so every code is complete, as strict inflaters want.
void huffman_lengths(const uint32_t *freq, int n, int limit, uint8_t *lengths) {
  std::fill(lengths, lengths + n, uint8_t(0));
  std::vector<int> used;
  for (int s = 0; s < n; ++s)
    if (freq[s]) used.push_back(s);
  if (used.size() < 2) {
    const int a = used.empty() ? 0 : used[0];
    lengths[a] = 1;
    lengths[a == 0 ? 1 : 0] = 1;
    return;
  }
  // Two-queue Huffman: leaves by ascending frequency, internal nodes in creation order.
  std::stable_sort(used.begin(), used.end(), [&](int a, int b) { return freq[a] < freq[b]; });
  const size_t m = used.size();
  std::vector<uint64_t> weight(2 * m - 1);
  std::vector<int> parent(2 * m - 1, -1);
  for (size_t i = 0; i < m; ++i) weight[i] = freq[used[i]];
  size_t leaf = 0, inner = m, next = m;
  const auto pop = [&]() {
    if (leaf < m && (inner >= next || weight[leaf] <= weight[inner])) return leaf++;
    return inner++;
  };
  while (next < 2 * m - 1) {
    const size_t a = pop(), b = pop();
    weight[next] = weight[a] + weight[b];
    parent[a] = parent[b] = int(next);
    ++next;
  }
  // Depths (root is the last node), counted per length.
  std::vector<int> depth(2 * m - 1, 0);
  std::vector<int> count(m + 1, 0);
  for (size_t i = 2 * m - 1; i-- > 0;)
    if (parent[i] >= 0) depth[i] = depth[size_t(parent[i])] + 1;
  int longest = 0;
  for (size_t i = 0; i < m; ++i) ++count[size_t(depth[i])], longest = std::max(longest, depth[i]);
  // Too long: move leaves up while keeping the code complete (JPEG, ITU T.81 Annex K.3).
  for (int i = longest; i > limit; --i)
    while (count[size_t(i)] > 0) {
      int j = i - 2;
      while (count[size_t(j)] == 0) --j;
      count[size_t(i)] -= 2;
      count[size_t(i - 1)] += 1;
      count[size_t(j + 1)] += 2;
      count[size_t(j)] -= 1;
    }
  // Shortest codes to the most frequent symbols (the end of `used`).
  size_t k = m;
  for (int len = 1; len <= std::min(longest, limit); ++len)
    for (int c = 0; c < count[size_t(len)]; ++c) lengths[used[--k]] = uint8_t(len);
}

// Canonical codes for the lengths (RFC 1951 3.2.2), bit-reversed: deflate sends Huffman codes
// most significant bit first into a least-significant-first bit stream.
void canonical_codes(const uint8_t *lengths, int n, uint16_t *codes) {
  std::array<int, kMaxCodeBits + 2> count{}, next{};
  for (int s = 0; s < n; ++s) ++count[lengths[s]];
  count[0] = 0;
  int code = 0;
  for (int bits = 1; bits <= kMaxCodeBits; ++bits) {
    code = (code + count[size_t(bits - 1)]) << 1;
    // cppcheck-suppress containerOutOfBounds ; next holds kMaxCodeBits + 2 entries
    next[size_t(bits)] = code;
  }
  for (int s = 0; s < n; ++s) {
    const int len = lengths[s];
    if (!len) continue;
    int c = next[size_t(len)]++, reversed = 0;
    for (int b = 0; b < len; ++b, c >>= 1) reversed = (reversed << 1) | (c & 1);
    codes[s] = uint16_t(reversed);
  }
}

// The code lengths of both trees, run-length coded with symbols 16 (repeat the previous length
// 3..6 times), 17 (3..10 zeros) and 18 (11..138 zeros): pairs of symbol and extra-bits value.
std::vector<std::pair<uint8_t, uint8_t>> code_length_symbols(const uint8_t *lengths, int n) {
  std::vector<std::pair<uint8_t, uint8_t>> out;
  for (int i = 0; i < n;) {
    const uint8_t len = lengths[i];
    int run = 1;
    while (i + run < n && lengths[i + run] == len) ++run;
    i += run;
    if (len == 0) {
      for (; run >= 11; run -= std::min(run, 138))
        out.push_back({18, uint8_t(std::min(run, 138) - 11)});
      if (run >= 3) out.push_back({17, uint8_t(run - 3)}), run = 0;
      for (; run > 0; --run) out.push_back({0, 0});
    } else {
      out.push_back({len, 0}), --run;
      for (; run >= 3; run -= std::min(run, 6)) out.push_back({16, uint8_t(std::min(run, 6) - 3)});
      for (; run > 0; --run) out.push_back({len, 0});
    }
  }
  return out;
}

}  // namespace

void RunDeflater::expect(size_t input_bytes) {
  // A dynamic block's codes average at most about 9.2 bits a token (Huffman codes are within a
  // bit of the entropy, at most log2(286) bits), so 5/4 of the input holds any piece but a tiny
  // one.
  out_.reserve(used_ + input_bytes + input_bytes / 4 + 4096);
}

void RunDeflater::reserve(size_t bytes) {
  if (out_.size() >= used_ + bytes) return;
  // Within the capacity (expect()): exactly what is asked, in place. Past it: a quarter more
  // than asked, a few growths per piece and at most a quarter of it unused (blocks come exactly
  // sized, so doubling would leave up to half of the buffer idle).
  if (out_.capacity() >= used_ + bytes)
    out_.resize(used_ + bytes);
  else
    out_.resize(used_ + bytes + used_ / 4);
}

void RunDeflater::put(uint64_t bits, int count) {
  acc_ |= bits << pending_;
  pending_ += count;
  if (pending_ >= 32) {  // room reserved by the caller
    uint8_t *p = out_.data() + used_;
    p[0] = uint8_t(acc_), p[1] = uint8_t(acc_ >> 8), p[2] = uint8_t(acc_ >> 16);
    p[3] = uint8_t(acc_ >> 24);
    used_ += 4;
    acc_ >>= 32;
    pending_ -= 32;
  }
}

void RunDeflater::align() {
  reserve(8);
  for (; pending_ > 0; pending_ -= 8, acc_ >>= 8) out_[used_++] = uint8_t(acc_);
  pending_ = 0, acc_ = 0;
}

void RunDeflater::add_block(const uint8_t *data, size_t n, bool final) {
  if (n == 0) return;
  // Tokens: a literal, or a run of the previous byte of kMinRun..kMaxRun (distance 1), taken
  // wherever one starts: at the first byte from which kMinRun bytes equal the one before them.
  // (Taking a run wherever a byte equals the one before it, and a literal when fewer than
  // kMinRun follow, makes the same tokens.) Where a run may start is found 16 positions at a
  // time; the literals before it are copied to tokens 16 at a time, and their counts go to four
  // tables, so that a repeated byte's counts do not wait on each other, summed afterwards.
  if (tokens_.size() < n) tokens_.resize(n);  // kept between blocks: never shrunk
  uint16_t *const tokens = tokens_.data();
  size_t count = 0;
  std::array<uint32_t, kLitLenSymbols> lit_freq{};
  uint32_t literal_freq[4][256] = {};
  uint32_t runs = 0;
  const auto literals = [&](size_t from, size_t to) {
    size_t k = from;
#if defined(__SSE2__)
    const __m128i zero = _mm_setzero_si128();
    for (; k + 16 <= to; k += 16) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i *>(data + k));
      _mm_storeu_si128(reinterpret_cast<__m128i *>(tokens + count), _mm_unpacklo_epi8(v, zero));
      _mm_storeu_si128(reinterpret_cast<__m128i *>(tokens + count + 8), _mm_unpackhi_epi8(v, zero));
      count += 16;
      // The counts from the bytes in registers, four at a time into the four tables.
      for (uint64_t w :
           {uint64_t(_mm_cvtsi128_si64(v)), uint64_t(_mm_cvtsi128_si64(_mm_unpackhi_epi64(v, v)))})
        for (int half = 0; half < 2; ++half, w >>= 32) {
          ++literal_freq[0][w & 0xFF];
          ++literal_freq[1][(w >> 8) & 0xFF];
          ++literal_freq[2][(w >> 16) & 0xFF];
          ++literal_freq[3][(w >> 24) & 0xFF];
        }
    }
#endif
    for (; k < to; ++k) {
      const uint8_t b = data[k];
      tokens[count++] = b;
      ++literal_freq[k & 3][b];
    }
  };
  // The first position from `from` (>= 1) where a run can start (kMinRun bytes from it equal
  // the byte before it, all before n), or n.
  static_assert(kMinRun == 3, "run_start tests three equal bytes");
  const auto run_start = [&](size_t from) {
    size_t k = from;
#if defined(__SSE2__)
    // Bit m of `equal`: byte k + m equals the one before it, for m < 32; a run starts at k + m
    // where bits m, m + 1 and m + 2 are set. Positions k .. k + 15 are settled in each step.
    for (; k + 32 <= n; k += 16) {
      const auto eq16 = [&](size_t at) {
        const __m128i now = _mm_loadu_si128(reinterpret_cast<const __m128i *>(data + at));
        const __m128i before = _mm_loadu_si128(reinterpret_cast<const __m128i *>(data + at - 1));
        return uint32_t(_mm_movemask_epi8(_mm_cmpeq_epi8(now, before)));
      };
      const uint32_t equal = eq16(k) | eq16(k + 16) << 16;
      const uint32_t starts = equal & equal >> 1 & equal >> 2 & 0xFFFFu;
      if (starts) return k + size_t(__builtin_ctz(starts));
    }
#endif
    for (; k + 3 <= n; ++k)
      if (data[k] == data[k - 1] && data[k + 1] == data[k - 1] && data[k + 2] == data[k - 1])
        return k;
    return n;
  };
  size_t i = 0;
  while (i < n) {
    const size_t k = run_start(std::max<size_t>(i, 1));
    literals(i, k);
    if (k >= n) break;
    // A run of data[k] from k: at least kMinRun bytes, at most kMaxRun.
    const uint8_t b = data[k];
    const size_t end = std::min(n, k + kMaxRun);
    size_t j = k + kMinRun;
#if defined(__SSE2__)
    // A background's runs are long: their end found 16 bytes at a time.
    const __m128i same = _mm_set1_epi8(char(b));
    for (; j + 16 <= end; j += 16) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i *>(data + j));
      const unsigned equal = unsigned(_mm_movemask_epi8(_mm_cmpeq_epi8(v, same)));
      if (equal != 0xFFFFu) {
        j += size_t(__builtin_ctz(~equal));
        break;
      }
    }
    if (j + 16 > end)
#endif
      while (j < end && data[j] == b) ++j;
    tokens[count++] = uint16_t(256 + (j - k));
    ++lit_freq[size_t(257 + kLengthCodes.code[j - k])];
    ++runs;
    i = j;
  }
  for (int b = 0; b < 256; ++b)
    lit_freq[size_t(b)] =
        literal_freq[0][b] + literal_freq[1][b] + literal_freq[2][b] + literal_freq[3][b];
  lit_freq[kEndOfBlock] = 1;

  // The two trees: literal/length, and distance (only distance 1, code 0, is ever used).
  std::array<uint8_t, kLitLenSymbols + 2> lengths{};  // literal/length lengths, then distance
  huffman_lengths(lit_freq.data(), kLitLenSymbols, kMaxCodeBits, lengths.data());
  int nlit = kLitLenSymbols;
  while (nlit > 257 && lengths[size_t(nlit - 1)] == 0) --nlit;
  const uint32_t dist_freq[2] = {runs, 0};
  uint8_t dist_len[2];
  huffman_lengths(dist_freq, 2, kMaxCodeBits, dist_len);  // codes 0 and 1, one bit each
  std::array<uint8_t, kLitLenSymbols + 2> all{};
  std::copy(lengths.begin(), lengths.begin() + nlit, all.begin());
  all[size_t(nlit)] = dist_len[0], all[size_t(nlit + 1)] = dist_len[1];
  const auto symbols = code_length_symbols(all.data(), nlit + 2);
  std::array<uint32_t, 19> cl_freq{};
  for (const auto &s : symbols) ++cl_freq[s.first];
  std::array<uint8_t, 19> cl_len{};
  huffman_lengths(cl_freq.data(), 19, kMaxCodeLengthBits, cl_len.data());
  std::array<uint16_t, 19> cl_code{};
  canonical_codes(cl_len.data(), 19, cl_code.data());
  int hclen = 19;
  while (hclen > 4 && cl_len[kCodeLengthOrder[size_t(hclen - 1)]] == 0) --hclen;

  // Block header (RFC 1951 3.2.7). The block's exact size in bits, from the code lengths and
  // the symbol counts: the output grows by what the block takes, not by a bound on it.
  static constexpr int kExtraBits[3] = {2, 3, 7};  // of symbols 16, 17, 18
  uint64_t bits = 3 + 5 + 5 + 4 + 3 * uint64_t(hclen);
  for (const auto &s : symbols)
    bits += cl_len[s.first] + (s.first >= 16 ? kExtraBits[s.first - 16] : 0);
  for (size_t k = 0; k < size_t(kLitLenSymbols); ++k) bits += uint64_t(lit_freq[k]) * lengths[k];
  for (size_t c = 0; c < kLengthExtra.size(); ++c)
    bits += uint64_t(lit_freq[257 + c]) * kLengthExtra[c];
  bits += uint64_t(runs) * dist_len[0];
  reserve(size_t(bits / 8) + 16);  // put() stores 4 bytes at a time
  put(final ? 1 : 0, 1);
  put(2, 2);  // dynamic Huffman codes
  put(uint64_t(nlit - 257), 5);
  put(uint64_t(2 - 1), 5);
  put(uint64_t(hclen - 4), 4);
  for (int k = 0; k < hclen; ++k) put(cl_len[kCodeLengthOrder[size_t(k)]], 3);
  for (const auto &[sym, extra] : symbols) {
    put(cl_code[sym], cl_len[sym]);
    if (sym >= 16) put(extra, kExtraBits[sym - 16]);
  }

  // Data: each token as one put of at most 15 + 5 + 1 bits, looked up whole (its code, and for
  // a run the length's extra bits and the distance code after it) in a table by token, and
  // packed with the bit buffer in registers.
  std::array<uint16_t, kLitLenSymbols> code{};
  canonical_codes(lengths.data(), kLitLenSymbols, code.data());
  uint16_t dist_code[2];
  canonical_codes(dist_len, 2, dist_code);
  std::array<uint32_t, 256 + kMaxRun + 1> symbol{};  // bits | count << 24, by token
  for (int t = 0; t < 256; ++t)
    symbol[size_t(t)] = code[size_t(t)] | uint32_t(lengths[size_t(t)]) << 24;
  for (int len = kMinRun; len <= kMaxRun; ++len) {
    const int c = kLengthCodes.code[size_t(len)], sym = 257 + c;
    uint32_t bits = code[size_t(sym)];
    int width = lengths[size_t(sym)];
    bits |= uint32_t(len - kLengthBase[size_t(c)]) << width, width += kLengthExtra[size_t(c)];
    bits |= uint32_t(dist_code[0]) << width, width += dist_len[0];
    // cppcheck-suppress containerOutOfBounds ; symbol holds 256 + kMaxRun + 1 entries
    symbol[size_t(256 + len)] = bits | uint32_t(width) << 24;
  }
  {
    uint64_t acc = acc_;
    int pending = pending_;
    uint8_t *out = out_.data() + used_;
    size_t k = 0;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    // Three tokens a step where their bits fit, else two: their bits joined first (independent
    // of the buffer), then one shift into the buffer and its whole bytes stored, eight at a time
    // with no branch (the spare bytes are rewritten by the next store; the room reserved above
    // holds the last). One serial step per two or three tokens where each token waited on the
    // one before. At most 7 bits are pending between steps and a token is at most 21 bits: two
    // always fit (7 + 42 < 64); a third joins them when the three take at most 56 bits, so that
    // fewer than 64 are pending when the whole bytes are shifted out (literal codes are at most
    // 15 bits, so three literals always do).
    const auto flush = [&]() {
      std::memcpy(out, &acc, sizeof acc);
      const int whole = pending >> 3;
      out += whole;
      acc >>= 8 * whole;  // whole <= 7: at most 7 + 56 bits pending here (31 on entry)
      pending &= 7;
    };
    flush();  // put() leaves up to 31 bits pending
    for (; k + 3 <= count;) {
      const uint32_t e1 = symbol[tokens[k]], e2 = symbol[tokens[k + 1]], e3 = symbol[tokens[k + 2]];
      const int n1 = int(e1 >> 24), n12 = n1 + int(e2 >> 24), n3 = int(e3 >> 24);
      uint64_t joined = uint64_t(e1 & 0xFFFFFFu) | uint64_t(e2 & 0xFFFFFFu) << n1;
      int width = n12;
      if (n12 + n3 <= 56) {
        joined |= uint64_t(e3 & 0xFFFFFFu) << n12;
        width += n3;
        k += 3;
      } else {
        k += 2;
      }
      acc |= joined << pending;
      pending += width;
      flush();
    }
    for (; k + 2 <= count; k += 2) {
      const uint32_t e1 = symbol[tokens[k]], e2 = symbol[tokens[k + 1]];
      const int n1 = int(e1 >> 24);
      const uint64_t two = uint64_t(e1 & 0xFFFFFFu) | uint64_t(e2 & 0xFFFFFFu) << n1;
      acc |= two << pending;
      pending += n1 + int(e2 >> 24);
      flush();
    }
#endif
    for (; k < count; ++k) {
      const uint32_t e = symbol[tokens[k]];
      acc |= uint64_t(e & 0xFFFFFFu) << pending;
      pending += int(e >> 24);
      if (pending >= 32) {  // room reserved above
        out[0] = uint8_t(acc), out[1] = uint8_t(acc >> 8), out[2] = uint8_t(acc >> 16);
        out[3] = uint8_t(acc >> 24);
        out += 4;
        acc >>= 32;
        pending -= 32;
      }
    }
    acc_ = acc, pending_ = pending, used_ = size_t(out - out_.data());
  }
  put(code[kEndOfBlock], lengths[kEndOfBlock]);
  ended_ |= final;
}

void RunDeflater::finish(bool end_of_stream) {
  reserve(16);
  if (end_of_stream) {
    if (!ended_) {
      put(1, 1);  // an empty final block with the fixed codes: end of block is 7 zero bits
      put(1, 2);
      put(0, 7);
      ended_ = true;
    }
    align();
    return;
  }
  put(0, 3);  // an empty stored block: three header bits, alignment, LEN 0, NLEN 0xffff
  align();
  reserve(4);
  for (const uint8_t b : {0x00, 0x00, 0xff, 0xff}) out_[used_++] = b;
}

PageVector<uint8_t> RunDeflater::take() {
  out_.resize(used_);
  PageVector<uint8_t> out;
  out.swap(out_);
  acc_ = 0, pending_ = 0, used_ = 0, ended_ = false;
  return out;
}

}  // namespace lantern
