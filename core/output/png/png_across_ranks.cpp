#include "core/output/png/png_across_ranks.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <new>
#include <string>
#include <vector>

#include "core/common/injected_fault.h"
#include "core/common/rank_threads.h"
#include "core/output/atomic_file.h"
#include "core/output/png/png_bands.h"
#include "core/output/png/png_container.h"

namespace lantern {
namespace {

constexpr int kChannels = 4;  // the frame's RGBA8 pixels
// A band's header, to the root: compressed size, adler32, raw length, rows, failed (1: no bytes
// follow, for this band and every later one of its rank).
constexpr int kHeaderWords = 5;
constexpr int kBandTag = 0x4c70;  // + band: that band's compressed bytes, to the root
constexpr int kRowsTag = 0x4c80;  // + band: that band's pixel rows, from the root
constexpr int kHeadTag = 0x4c90;  // + band: that band's header, to the root

// First row of band k of n over `height` rows (k == n gives height).
int first_row(int k, int n, int height) {
  return int(int64_t(height) * k / n);
}

// First band of worker w of `workers` sharing n bands.
int first_band(int w, int workers, int n) {
  return int(int64_t(n) * w / workers);
}

// The rank that compresses band b.
int band_owner(int b, int workers, int n) {
  int w = 0;
  while (w + 1 < workers && first_band(w + 1, workers, n) <= b) ++w;
  return w;
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

// deflate_bands() of bands [b0, b1) on up to `threads` threads of this process, each a
// contiguous share of them; rows_of(b) is band b's first row (read on the threads: no MPI in
// it). The bands do not depend on who compresses them: the same bytes on any count. Returns the
// first share's failure in band order, or OK; an allocation that fails on a thread is such a
// failure (kIo, as every failure to produce the file), never an exception out of the thread.
Status deflate_bands_on_threads(const std::function<const uint8_t *(int)> &rows_of, int width,
                                int height, int n, int b0, int b1, int level, int channels,
                                int threads, std::vector<PngBand> *out) {
  const int count = std::max(0, b1 - b0);
  const int parts = std::clamp(threads, 1, std::max(1, count));
  std::vector<Status> failure(static_cast<size_t>(parts));
  run_in_parts(parts, count, [&](int part, int64_t first, int64_t last) {
    Status &f = failure[size_t(part)];
    try {
      for (int b = b0 + int(first); b < b0 + int(last) && f.ok(); ++b)
        f = deflate_bands(rows_of(b), width, height, n, b, b + 1, level, channels, out);
    } catch (const std::bad_alloc &) {
      f = {StatusCode::kIo, "out of memory compressing a band"};
    }
  });
  for (const Status &f : failure)
    if (!f.ok()) return f;
  return {};
}

// RGB when every pixel is opaque (every frame but those of background: transparent): a quarter
// less to compress.
// Blocks of kOpaqueBlock pixels are checked with no exit inside, as the AND of their 4-byte words
// (a loop the compiler vectorises): its alpha byte is 255 exactly when every pixel's is.
int file_channels(const uint8_t *rgba, size_t n) {
  constexpr size_t kOpaqueBlock = 1024;
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

// The file's bytes to one descriptor: the small pieces (chunk headers and CRCs) gathered, the
// bands' bytes written straight from where they are; patch() rewrites bytes already written.
class FileSink {
 public:
  // cppcheck-suppress uninitMemberVar ; small_ is written before it is read (used_)
  explicit FileSink(int fd) : fd_(fd) {}
  bool put(const uint8_t *p, size_t n) {
    if (used_ + n > sizeof small_ && !flush()) return false;
    if (n >= sizeof small_) return keep(write_all(fd_, p, n));
    std::memcpy(small_ + used_, p, n);
    used_ += n;
    return true;
  }
  bool patch(uint64_t offset, const uint8_t *p, size_t n) {
    if (!flush()) return false;
    while (n > 0) {
      const ssize_t w = ::pwrite(fd_, p, n, off_t(offset));
      if (w < 0 && errno == EINTR) continue;
      if (w < 0) return keep(errno);
      p += w, n -= size_t(w), offset += uint64_t(w);
    }
    return true;
  }
  bool flush() {
    const size_t n = used_;
    used_ = 0;
    return keep(write_all(fd_, small_, n));
  }
  int error() const { return error_; }

 private:
  bool keep(int error) {
    if (error != 0 && error_ == 0) error_ = error;
    return error == 0;
  }
  int fd_;
  int error_ = 0;
  size_t used_ = 0;
  uint8_t small_[4096];  // only its first used_ bytes are ever read
};

// The file from its n bands, asking `band` for each in turn (top first; nullptr: a band cannot
// be had, and no file is written) and writing it at once (PngBandStream): the root writes while
// other ranks still compress later bands.
Status write_file(int n, int width, int height, int channels, const std::string &path,
                  const std::function<PngBand *(int)> &band) {
  Status encoded;
  const std::string extension = std::filesystem::path(path).extension().string();
  const Status written = write_atomically(path, extension, [&](const std::string &temp) -> Status {
    // No O_TRUNC: write_atomically has just created the file, empty and ours alone, and on ext4
    // a truncating open makes close() start writing the file back (auto_da_alloc): 0.1 to 2.5 ms
    // of a 1.5 MB PNG's close on the write stage's critical path, for no guarantee the temporary
    // name and rename do not already give (atomic_file.h: no fsync, by design).
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) return {StatusCode::kIo, std::strerror(errno)};
    FileSink file(fd);
    PngBandStream png(
        width, height, channels, n, [&file](const uint8_t *p, size_t k) { return file.put(p, k); },
        [&file](uint64_t at, const uint8_t *p, size_t k) { return file.patch(at, p, k); });
    for (int b = 0; b < n && encoded.ok(); ++b) {
      PngBand *p = band(b);
      if (!p) {
        encoded = {StatusCode::kInternal, "a band is missing"};
        break;
      }
      encoded = png.add(*p);
    }
    if (encoded.ok()) encoded = png.finish();
    if (encoded.ok() && !file.flush()) encoded = {StatusCode::kIo, "the file could not be written"};
    const int error = file.error();
    if (::close(fd) != 0 && encoded.ok()) return {StatusCode::kIo, std::strerror(errno)};
    if (!encoded.ok() && encoded.code == StatusCode::kIo)
      return {StatusCode::kIo, std::strerror(error != 0 ? error : EIO)};
    return encoded;
  });
  if (!encoded.ok() && encoded.code != StatusCode::kIo)
    return {StatusCode::kIo, "cannot encode " + path + ": " + encoded.message};
  return written;
}

// A rank other than the root: compresses bands [b0, b1) of n, the rows of band b at rows_of(b)
// (asked in band order), and sends each to the root as soon as it is compressed, header then
// bytes, so that the root writes the file as the bands come while later ones are still being
// compressed here. After a failure the rest are sent as failed headers (no bytes): the root
// receives every band whatever fails, so every send completes.
//
// `threads` > 1 (rows_of then only points into memory this rank holds, no MPI): the bands are
// first all compressed on that many threads, then sent in band order.
Status send_bands(MPI_Comm comm, int root, int width, int height, int n, int b0, int b1, int level,
                  int channels, const std::string &path,
                  const std::function<const uint8_t *(int)> &rows_of, int threads = 1) {
  std::vector<PngBand> bands(static_cast<size_t>(n));
  std::vector<int64_t> headers(size_t(std::max(b1 - b0, 0)) * kHeaderWords);
  std::vector<MPI_Request> requests;
  requests.reserve(size_t(std::max(b1 - b0, 0)) * 2);
  Status failure;
  const bool compressed = threads > 1 && b1 - b0 > 1;
  if (compressed)
    failure = deflate_bands_on_threads(rows_of, width, height, n, b0, b1, level, channels, threads,
                                       &bands);
  for (int b = b0; b < b1; ++b) {
    if (!compressed) {
      // Every band's rows are taken, also after a failure: they may be a message from the root,
      // whose send completes only once it is received here (a band of a 1024-pixel-wide frame is
      // far beyond MPI's eager limit), so skipping them would leave the root waiting for ever.
      const uint8_t *rows = rows_of(b);
      if (failure.ok() && take_injected_fault("png: deflate band " + std::to_string(b)))
        failure = {StatusCode::kIo, "band " + std::to_string(b) + ": injected fault"};
      if (failure.ok())
        failure = deflate_bands(rows, width, height, n, b, b + 1, level, channels, &bands);
    }
    const PngBand &p = bands[size_t(b)];
    int64_t *h = &headers[size_t(b - b0) * kHeaderWords];
    const bool failed = !failure.ok();  // this band and every later one: none sent
    h[0] = failed ? 0 : int64_t(p.bytes.size()), h[1] = p.adler, h[2] = int64_t(p.raw_len),
    h[3] = p.rows, h[4] = failed ? 1 : 0;
    requests.emplace_back();
    MPI_Isend(h, kHeaderWords, MPI_INT64_T, root, kHeadTag + b, comm, &requests.back());
    if (h[0] == 0) continue;
    requests.emplace_back();
    MPI_Isend(p.bytes.data(), int(p.bytes.size()), MPI_UINT8_T, root, kBandTag + b, comm,
              &requests.back());
  }
  MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  return with_context("cannot encode a band of " + path + ": ", failure);
}

// The root: compresses its own bands [b0, b1) of n from `rows` (the first row of band b0), then
// writes the file band by band, receiving each other rank's band (from owner(b)) when its turn
// comes - the header, then the bytes straight into the band - so the file's first bands are
// written while the others are still being compressed. Every band is received whatever fails, so
// that every rank's sends complete.
Status write_with_ranks(MPI_Comm comm, int root, const uint8_t *rows, int width, int height, int n,
                        int b0, int b1, int level, int channels, const std::string &path,
                        const std::function<int(int)> &owner, int threads) {
  std::vector<PngBand> bands(static_cast<size_t>(n));
  const size_t row_bytes = size_t(width) * kChannels;
  const Status failure = deflate_bands_on_threads(
      [&](int b) {
        return rows + size_t(first_row(b, n, height) - first_row(b0, n, height)) * row_bytes;
      },
      width, height, n, b0, b1, level, channels, threads, &bands);
  int received = 0;  // bands [0, received) are here
  bool remote_failed = false;
  // The buffers of bands already written, to receive later bands into (the smallest that holds
  // one): their pages are mapped and faulted in already, where a fresh buffer costs ~0.2 ms a
  // band of a 1 M-atom frame (mmap, zero fill, page faults) on the root's critical path.
  std::vector<PageVector<uint8_t>> spare;
  const auto receive_through = [&](int last) {
    for (; received <= last; ++received) {
      const int b = received;
      const int r = owner(b);
      if (r == root) continue;
      int64_t h[kHeaderWords];
      MPI_Recv(h, kHeaderWords, MPI_INT64_T, r, kHeadTag + b, comm, MPI_STATUS_IGNORE);
      PngBand &p = bands[size_t(b)];
      const size_t bytes = size_t(h[0]);
      auto fit = spare.end();
      for (auto it = spare.begin(); it != spare.end(); ++it)
        if (it->size() >= bytes && (fit == spare.end() || it->size() < fit->size())) fit = it;
      if (fit != spare.end()) {
        p.bytes = std::move(*fit);
        spare.erase(fit);
      }
      p.bytes.resize(bytes);  // a spare's contents past `bytes` are dropped, nothing is filled
      p.adler = uint32_t(h[1]);
      p.raw_len = uint64_t(h[2]);
      p.rows = int(h[3]);
      p.last = b == n - 1;
      remote_failed |= h[4] != 0;
      if (!p.bytes.empty())
        MPI_Recv(p.bytes.data(), int(p.bytes.size()), MPI_UINT8_T, r, kBandTag + b, comm,
                 MPI_STATUS_IGNORE);
    }
  };
  Status written = failure;
  if (failure.ok())
    written = write_file(n, width, height, channels, path, [&](int b) -> PngBand * {
      if (b > 0) spare.push_back(std::move(bands[size_t(b) - 1].bytes));  // written by now
      receive_through(b);
      return remote_failed ? nullptr : &bands[size_t(b)];
    });
  receive_through(n - 1);
  if (remote_failed || !failure.ok())
    return {StatusCode::kIo, "cannot encode " + path + ": a rank failed to compress its band"};
  return written;
}
}  // namespace

int png_band_count(int height) {
  return std::clamp(height / 32, 1, 8);  // bands of >= 32 rows: flushes cost next to nothing
}

Status write_png(const Frame &frame, int level, const std::string &path, int threads) {
  const int n = png_band_count(frame.height);
  const int channels = file_channels(frame.rgba.data(), frame.pixel_count());
  const size_t row_bytes = size_t(frame.width) * kChannels;
  std::vector<PngBand> bands(static_cast<size_t>(n));
  const Status failure = deflate_bands_on_threads(
      [&](int b) { return frame.rgba.data() + size_t(first_row(b, n, frame.height)) * row_bytes; },
      frame.width, frame.height, n, 0, n, level, channels, threads, &bands);
  if (!failure.ok()) return with_context("cannot encode " + path + ": ", failure);
  return write_file(n, frame.width, frame.height, channels, path,
                    [&bands](int b) { return &bands[size_t(b)]; });
}

Status write_png_across_ranks(MPI_Comm comm, int root, const Frame &frame, int width, int height,
                              int level, const std::string &path, int threads) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int n = png_band_count(height);
  if (size == 1) return write_png(frame, level, path, threads);

  // Each rank's rows: those of its bands (none when there are more ranks than bands). Bands
  // are far below 2 GiB (16384 x 16384 RGBA is 1 GiB in all), so MPI's int counts suffice.
  const int64_t row_bytes = int64_t(width) * kChannels;
  std::vector<int64_t> offsets(static_cast<size_t>(size));
  for (int r = 0; r < size; ++r) {
    const int b0 = first_band(r, size, n), b1 = first_band(r + 1, size, n);
    const int64_t first = first_row(b0, n, height), last = first_row(b1, n, height);
    if ((last - first) * row_bytes > INT_MAX || first * row_bytes > INT_MAX)
      return rank == root ? write_png(frame, level, path, threads) : Status();  // every rank alike
    offsets[size_t(r)] = first * row_bytes;
  }
  const int b0 = first_band(rank, size, n), b1 = first_band(rank + 1, size, n);
  const auto band_rows = [&](int b) {
    return int64_t(first_row(b + 1, n, height)) - first_row(b, n, height);
  };
  std::vector<MPI_Request> requests;
  if (rank != root) {
    // Receives its bands' rows a band at a time (so no rank holds a copy of its whole share),
    // compresses each and sends it on at once.
    int64_t most = 0;
    for (int b = b0; b < b1; ++b) most = std::max(most, band_rows(b));
    std::vector<uint8_t> rows(static_cast<size_t>(most * row_bytes));
    // The first band's rows arrive while the root still looks at the frame's alpha.
    MPI_Request first_rows = MPI_REQUEST_NULL;
    if (b0 < b1 && band_rows(b0) > 0)
      MPI_Irecv(rows.data(), int(band_rows(b0) * row_bytes), MPI_UINT8_T, root, kRowsTag + b0, comm,
                &first_rows);
    int channels = 4;
    MPI_Bcast(&channels, 1, MPI_INT, root, comm);
    const auto rows_of = [&](int b) -> const uint8_t * {
      if (band_rows(b) > 0) {
        if (b == b0)
          MPI_Wait(&first_rows, MPI_STATUS_IGNORE);
        else
          MPI_Recv(rows.data(), int(band_rows(b) * row_bytes), MPI_UINT8_T, root, kRowsTag + b,
                   comm, MPI_STATUS_IGNORE);
      }
      return rows.data();
    };
    // send_bands takes every band's rows through rows_of, the first through MPI_Wait above
    // (which the analyzer's MPI checker cannot follow through the std::function).
    // NOLINTNEXTLINE(clang-analyzer-optin.mpi.MPI-Checker)
    return send_bands(comm, root, width, height, n, b0, b1, level, channels, path, rows_of);
  }

  // The root sends every other rank its bands' rows straight from the frame, a band per
  // message, then tells them whether the file is RGB, and compresses its own rows where they are.
  for (int r = 0; r < size; ++r) {
    if (r == root) continue;
    for (int b = first_band(r, size, n); b < first_band(r + 1, size, n); ++b) {
      if (band_rows(b) == 0) continue;
      requests.emplace_back();
      MPI_Isend(frame.rgba.data() + first_row(b, n, height) * row_bytes,
                int(band_rows(b) * row_bytes), MPI_UINT8_T, r, kRowsTag + b, comm,
                &requests.back());
    }
  }
  int channels = file_channels(frame.rgba.data(), frame.pixel_count());
  MPI_Bcast(&channels, 1, MPI_INT, root, comm);
  const Status written = write_with_ranks(
      comm, root, frame.rgba.data() + offsets[size_t(rank)], width, height, n, b0, b1, level,
      channels, path, [size, n](int b) { return band_owner(b, size, n); }, threads);
  MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  return written;
}

int png_band_rows(int height, int width) {
  const int n = png_band_count(height);
  if (height % n != 0) return 0;
  // A band's compressed bytes move in one MPI message (int counts): far from it in practice.
  if (int64_t(height / n) * width * kChannels > INT_MAX / 2) return 0;
  return height / n;
}

Status write_png_from_row_bands(MPI_Comm comm, int root, const uint8_t *rows, int y0, int y1,
                                int width, int height, int level, const std::string &path,
                                int threads) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int n = png_band_count(height);
  const int per_band = png_band_rows(height, width);
  // Every rank's bands and whether its rows are opaque, in one collective: the same table on
  // every rank, so that all agree on the channels and on whether the split is one of bands.
  const bool aligned = per_band > 0 && y0 % per_band == 0 && y1 % per_band == 0 && 0 <= y0 &&
                       y0 <= y1 && y1 <= height;
  const int mine[3] = {aligned ? y0 / per_band : -1, aligned ? y1 / per_band : -1,
                       aligned ? file_channels(rows, size_t(y1 - y0) * size_t(width)) : 4};
  std::vector<int> table(size_t(size) * 3);
  MPI_Allgather(mine, 3, MPI_INT, table.data(), 3, MPI_INT, comm);
  std::vector<int> owner(size_t(std::max(n, 0)), -1);
  int channels = 3, next = 0;
  for (int r = 0; r < size; ++r) {
    const int b0 = table[size_t(r) * 3], b1 = table[size_t(r) * 3 + 1];
    channels = std::max(channels, table[size_t(r) * 3 + 2]);
    if (b0 != next || b1 < b0 || b1 > n)
      return {StatusCode::kInvalidArgument,
              "cannot write " + path + ": the ranks' rows are not whole PNG bands in rank order"};
    for (int b = b0; b < b1; ++b) owner[size_t(b)] = r;
    next = b1;
  }
  if (next != n)
    return {StatusCode::kInvalidArgument,
            "cannot write " + path + ": the ranks' rows do not cover the image"};
  const int b0 = y0 / per_band, b1 = y1 / per_band;
  // The rows of band b (b0 <= b < b1) are this rank's, where they are.
  const size_t band_bytes = size_t(per_band) * size_t(width) * kChannels;
  const auto rows_of = [&](int b) { return rows + size_t(b - b0) * band_bytes; };
  if (rank != root)
    return send_bands(comm, root, width, height, n, b0, b1, level, channels, path, rows_of,
                      threads);
  return write_with_ranks(
      comm, root, rows, width, height, n, b0, b1, level, channels, path,
      [&owner](int b) { return owner[size_t(b)]; }, threads);
}

}  // namespace lantern
