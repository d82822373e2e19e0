#include "core/output/png/png_across_ranks.h"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <thread>
#include <vector>

#include "core/output/atomic_file.h"
#include "core/output/png/png_bands.h"
#include "core/output/png/png_container.h"

namespace lantern {
namespace {

constexpr int kChannels = 4;  // the frame's RGBA8 pixels
constexpr int kHeaderWords = 4;
constexpr int kBandTag = 0x4c70;  // + band: that band's compressed bytes, to the root
constexpr int kRowsTag = 0x4c80;  // + band: that band's pixel rows, from the root

// First row of band k of n over `height` rows (k == n gives height).
int first_row(int k, int n, int height) {
  return int(int64_t(height) * k / n);
}

// First band of worker w of `workers` sharing n bands.
int first_band(int w, int workers, int n) {
  return int(int64_t(n) * w / workers);
}

// Deflates bands [b0, b1) of n; `rows` points at the first row of band b0. Returns OK or kIo
// saying why not (the file cannot be produced).
Status deflate_bands(const uint8_t *rows, int width, int height, int n, int b0, int b1, int level,
                     int channels, std::vector<PngBand> *out) {
  const size_t row_bytes = size_t(width) * kChannels;
  const PngBandOptions options = png_options_for_level(level);
  for (int b = b0; b < b1; ++b) {
    const int first = first_row(b, n, height), count = first_row(b + 1, n, height) - first;
    const uint8_t *p = rows + size_t(first - first_row(b0, n, height)) * row_bytes;
    if (Status s = deflate_png_band(p, width, count, channels, b == n - 1, level,
                                    &(*out)[size_t(b)], nullptr, options);
        !s.ok())
      return {StatusCode::kIo, s.message};
  }
  return {};
}

// RGB when every pixel is opaque (every frame but those of background: transparent): a quarter
// less to compress.
// Blocks of kOpaqueBlock pixels are checked with no exit inside, as the AND of their 4-byte words
// (a loop the compiler vectorises): its alpha byte is 255 exactly when every pixel's is.
int file_channels(const Frame &frame) {
  constexpr size_t kOpaqueBlock = 1024;
  const uint8_t *rgba = frame.rgba.data();
  const size_t n = frame.pixel_count();
  for (size_t i = 0; i < n; i += kOpaqueBlock) {
    uint32_t all = ~uint32_t(0);
    for (size_t k = i; k < std::min(n, i + kOpaqueBlock); ++k) {
      uint32_t word;
      std::memcpy(&word, rgba + 4 * k, sizeof word);
      all &= word;
    }
    uint8_t bytes[4];
    std::memcpy(bytes, &all, sizeof bytes);
    if (bytes[3] != 255) return 4;
  }
  return 3;
}

// The file straight from the bands' pieces (stream_png): no buffer of the whole file.
Status write_file(const std::vector<PngBand> &bands, int width, int height, int channels,
                  const std::string &path) {
  Status encoded;
  const std::string extension = std::filesystem::path(path).extension().string();
  const Status written = write_atomically(path, extension, [&](const std::string &temp) -> Status {
    std::FILE *f = std::fopen(temp.c_str(), "wb");
    if (!f) return {StatusCode::kIo, std::strerror(errno)};
    encoded = stream_png(bands, width, height, channels,
                         [f](const uint8_t *p, size_t n) { return std::fwrite(p, 1, n, f) == n; });
    const int error = std::ferror(f) ? errno : 0;
    if (std::fclose(f) != 0 && encoded.ok()) return {StatusCode::kIo, std::strerror(errno)};
    if (!encoded.ok() && encoded.code == StatusCode::kIo)
      return {StatusCode::kIo, std::strerror(error != 0 ? error : EIO)};
    return encoded;
  });
  if (!encoded.ok() && encoded.code != StatusCode::kIo)
    return {StatusCode::kIo, "cannot encode " + path + ": " + encoded.message};
  return written;
}

}  // namespace

int png_band_count(int height) {
  return std::clamp(height / 32, 1, 8);  // bands of >= 32 rows: flushes cost next to nothing
}

Status write_png(const Frame &frame, int level, const std::string &path, int threads) {
  const int n = png_band_count(frame.height);
  const int workers = std::clamp(threads, 1, n);
  const int channels = file_channels(frame);
  std::vector<PngBand> bands(static_cast<size_t>(n));
  std::vector<Status> failure(static_cast<size_t>(workers));
  const auto work = [&](int w) {
    const int b0 = first_band(w, workers, n), b1 = first_band(w + 1, workers, n);
    const size_t offset = size_t(first_row(b0, n, frame.height)) * frame.width * kChannels;
    failure[size_t(w)] = deflate_bands(frame.rgba.data() + offset, frame.width, frame.height, n, b0,
                                       b1, level, channels, &bands);
  };
  std::vector<std::thread> helpers;
  try {
    for (int w = 1; w < workers; ++w) helpers.emplace_back(work, w);
  } catch (const std::exception &) {  // no thread to be had: the caller's thread does the rest
    for (int w = int(helpers.size()) + 1; w < workers; ++w) work(w);
  }
  work(0);
  for (std::thread &t : helpers) t.join();
  for (const Status &f : failure)
    if (!f.ok()) return with_context("cannot encode " + path + ": ", f);
  return write_file(bands, frame.width, frame.height, channels, path);
}

Status write_png_across_ranks(MPI_Comm comm, int root, const Frame &frame, int width, int height,
                              int level, const std::string &path) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int n = png_band_count(height);
  if (size == 1) return write_png(frame, level, path, 2);

  // Each rank's rows: those of its bands (none when there are more ranks than bands). Bands
  // are far below 2 GiB (16384 x 16384 RGBA is 1 GiB in all), so MPI's int counts suffice.
  const int64_t row_bytes = int64_t(width) * kChannels;
  std::vector<int64_t> offsets(static_cast<size_t>(size));
  for (int r = 0; r < size; ++r) {
    const int b0 = first_band(r, size, n), b1 = first_band(r + 1, size, n);
    const int64_t first = first_row(b0, n, height), last = first_row(b1, n, height);
    if ((last - first) * row_bytes > INT_MAX || first * row_bytes > INT_MAX)
      return rank == root ? write_png(frame, level, path, 2) : Status();  // same on every rank
    offsets[size_t(r)] = first * row_bytes;
  }
  int channels = rank == root ? file_channels(frame) : 4;
  MPI_Bcast(&channels, 1, MPI_INT, root, comm);
  // The root sends every other rank its bands' rows straight from the frame, a band per message,
  // and compresses its own rows where they are; the others receive and compress a band at a
  // time, so no rank holds a copy of its whole share.
  const int b0 = first_band(rank, size, n), b1 = first_band(rank + 1, size, n);
  std::vector<PngBand> bands(static_cast<size_t>(n));
  std::vector<MPI_Request> requests;
  Status failure;
  if (rank == root) {
    for (int r = 0; r < size; ++r) {
      if (r == root) continue;
      for (int b = first_band(r, size, n); b < first_band(r + 1, size, n); ++b) {
        const int64_t first = first_row(b, n, height), count = first_row(b + 1, n, height) - first;
        if (count == 0) continue;
        requests.emplace_back();
        MPI_Isend(frame.rgba.data() + first * row_bytes, int(count * row_bytes), MPI_UINT8_T, r,
                  kRowsTag + b, comm, &requests.back());
      }
    }
    failure = deflate_bands(frame.rgba.data() + offsets[size_t(rank)], width, height, n, b0, b1,
                            level, channels, &bands);
    MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
    requests.clear();
  } else {
    int64_t most = 0;
    for (int b = b0; b < b1; ++b)
      most = std::max<int64_t>(most, first_row(b + 1, n, height) - first_row(b, n, height));
    std::vector<uint8_t> rows(static_cast<size_t>(most * row_bytes));
    for (int b = b0; b < b1; ++b) {
      const int64_t count = first_row(b + 1, n, height) - first_row(b, n, height);
      if (count == 0) continue;
      MPI_Recv(rows.data(), int(count * row_bytes), MPI_UINT8_T, root, kRowsTag + b, comm,
               MPI_STATUS_IGNORE);
      if (failure.ok())
        failure = deflate_bands(rows.data(), width, height, n, b, b + 1, level, channels, &bands);
    }
  }

  // Every rank sends a header per band (zeros for bands it does not own) plus a failure flag,
  // then each of its non-empty bands' bytes as one message, which the root receives straight
  // into that band (no gathered copy, no second copy into the bands).
  std::vector<int64_t> header(size_t(n) * kHeaderWords + 1, 0);
  for (int b = b0; b < b1; ++b) {
    const PngBand &p = bands[size_t(b)];
    int64_t *h = &header[size_t(b) * kHeaderWords];
    h[0] = int64_t(p.bytes.size()), h[1] = p.adler, h[2] = int64_t(p.raw_len), h[3] = p.rows;
  }
  header.back() = failure.ok() ? 0 : 1;
  const int words = int(header.size());
  std::vector<int64_t> headers(rank == root ? size_t(size) * words : 0);
  MPI_Gather(header.data(), words, MPI_INT64_T, headers.data(), words, MPI_INT64_T, root, comm);
  if (rank != root) {
    for (int b = b0; b < b1; ++b) {
      const PageVector<uint8_t> &bytes = bands[size_t(b)].bytes;
      if (bytes.empty()) continue;
      requests.emplace_back();
      MPI_Isend(bytes.data(), int(bytes.size()), MPI_UINT8_T, root, kBandTag + b, comm,
                &requests.back());
    }
    MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
    return with_context("cannot encode a band of " + path + ": ", failure);
  }
  bool failed = false;
  for (int r = 0; r < size; ++r) failed |= headers[size_t(r) * words + size_t(words - 1)] != 0;
  for (int r = 0; r < size; ++r) {
    if (r == root) continue;
    for (int b = first_band(r, size, n); b < first_band(r + 1, size, n); ++b) {
      const int64_t *h = &headers[size_t(r) * words + size_t(b) * kHeaderWords];
      PngBand &p = bands[size_t(b)];
      p.bytes.resize(size_t(h[0]));
      p.adler = uint32_t(h[1]);
      p.raw_len = uint64_t(h[2]);
      p.rows = int(h[3]);
      p.last = b == n - 1;
      if (p.bytes.empty()) continue;
      requests.emplace_back();
      MPI_Irecv(p.bytes.data(), int(p.bytes.size()), MPI_UINT8_T, r, kBandTag + b, comm,
                &requests.back());
    }
  }
  MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  if (failed)
    return {StatusCode::kIo, "cannot encode " + path + ": a rank failed to compress its band"};
  return write_file(bands, width, height, channels, path);
}

}  // namespace lantern
