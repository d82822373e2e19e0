// write_png_across_ranks under mpiexec (2, 3 and 9 ranks): the root's file is byte for byte the
// file assemble_png makes of the same bands in memory (and write_png's on one process),
// whichever rank is the root, for frames
// whose file takes one IDAT chunk or several, RGB and RGBA, and more ranks than bands; a path
// that cannot be written fails on the root, every rank returns, and no temporary file is left;
// so does a band whose compression fails on a rank other than the root.
// (The root writes each band as it arrives, so the first IDAT chunk's length is set last.)
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "core/common/injected_fault.h"
#include "core/output/png/png_across_ranks.h"
#include "core/output/png/png_bands.h"
#include "tests/output/scratch_dir.h"
#include "tests/support/hash_noise.h"
#include "tests/support/mpi_world.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::hash;
using testing::world_rank;
using testing::world_size;

std::vector<uint8_t> read_file(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// Noise compresses to about its own size (several 1 MiB IDAT chunks at 1024 x 700); the other
// pattern, flat rows with a few changes, compresses to a few KiB (one chunk). `opaque`: alpha
// 255 everywhere (an RGB file), else a few translucent pixels (RGBA).
Frame test_frame(int width, int height, bool noise, bool opaque, uint32_t seed) {
  Frame f(width, height);
  for (size_t i = 0; i < f.rgba.size(); ++i) {
    const uint32_t k = hash(seed * 2654435761u + uint32_t(i));
    f.rgba[i] = noise ? uint8_t(k) : uint8_t((i / 4 / size_t(width)) * 7 + (k % 97 == 0 ? k : 0));
  }
  for (size_t p = 0; p < f.pixel_count(); ++p)
    f.rgba[4 * p + 3] = opaque || hash(seed + uint32_t(p)) % 50 ? 255 : uint8_t(p % 200);
  return f;
}

struct Case {
  int width, height;
  bool noise, opaque;
};

TEST(PngAcrossRanks, FileIsTheOneProcessFileOnEveryRoot) {
  const ScratchDir dir;                            // per rank; the root's is the one written
  const Case cases[] = {{1024, 700, true, true},   // RGB, three IDAT chunks
                        {1024, 700, true, false},  // RGBA, four chunks
                        {333, 257, false, true},   // 8 bands of uneven rows, one chunk
                        {40, 40, false, false}};   // one band: every rank but one has none
  for (const Case &c : cases)
    for (int root = 0; root < world_size(); root += world_size() - 1)
      for (const int threads : {1, 3}) {
        SCOPED_TRACE(std::to_string(c.width) + "x" + std::to_string(c.height) + " root " +
                     std::to_string(root) + ", " + std::to_string(threads) + " threads");
        // Only the root's frame is read; the others pass an empty one, as the pipeline may.
        const Frame frame =
            world_rank() == root ? test_frame(c.width, c.height, c.noise, c.opaque, 3) : Frame();
        const std::string across = dir.file("across.png"), alone = dir.file("alone.png");
        const Status s = write_png_across_ranks(MPI_COMM_WORLD, root, frame, c.width, c.height, 1,
                                                across, threads);
        EXPECT_OK(s);
        if (world_rank() != root) continue;
        // The reference: the same bands assembled in memory (encode_png cuts png_band_count
        // bands as the writers do; Sub needs no row above a band), through assemble_png, which
        // knows every IDAT chunk's length before writing it.
        std::vector<uint8_t> expected;
        ASSERT_OK(encode_png(frame.rgba.data(), c.width, c.height, c.opaque ? 3 : 4, 1,
                             png_band_count(c.height), &expected, png_options_for_level(1)));
        ASSERT_GT(expected.size(), 100u);
        EXPECT_EQ(read_file(across), expected);
        ASSERT_OK(write_png(frame, 1, alone, threads + 1));
        EXPECT_EQ(read_file(alone), expected);
        EXPECT_EQ(dir.entry_count(), 2u);  // no temporary file left
        if (root == world_size() - 1 && threads == 3) break;
      }
}

// Rows [y0, y1) of `height` a rank holds when the ranks split the PNG's bands in rank order,
// `skip` of them (from rank 0 on) holding none.
std::pair<int, int> band_rows_of(int rank, int ranks, int height, int width, int skip) {
  const int n = png_band_count(height), per = png_band_rows(height, width);
  const int holders = std::max(1, ranks - skip);
  const int k = std::max(0, rank - skip);
  const int b0 = rank < skip ? 0 : n * k / holders, b1 = rank < skip ? 0 : n * (k + 1) / holders;
  return {b0 * per, b1 * per};
}

TEST(PngAcrossRanks, FromRowBandsIsTheOneProcessFile) {
  const ScratchDir dir;
  // 1024 x 704: 8 bands of 88 rows; 200 x 64: 2 bands of 32 rows (more ranks than bands); 40 x
  // 40: one band. Translucent pixels on one rank only still make the file RGBA everywhere.
  const Case cases[] = {{1024, 704, true, true},
                        {1024, 704, true, false},
                        {200, 64, false, true},
                        {40, 40, false, false}};
  for (const Case &c : cases)
    for (int skip = 0; skip < std::min(2, world_size()); ++skip)
      for (const int threads : {1, 2, 5}) {
        SCOPED_TRACE(std::to_string(c.width) + "x" + std::to_string(c.height) + " skip " +
                     std::to_string(skip) + ", " + std::to_string(threads) + " threads");
        ASSERT_GT(png_band_rows(c.height, c.width), 0);
        // Every rank has the whole frame, but hands over only its rows; the others are scribbled
        // on so that a band read from the wrong place would show.
        Frame frame = test_frame(c.width, c.height, c.noise, c.opaque, 5);
        const Frame reference = frame;
        const auto [y0, y1] = band_rows_of(world_rank(), world_size(), c.height, c.width, skip);
        for (size_t p = 0; p < frame.pixel_count(); ++p) {
          const int y = int(p / size_t(c.width));
          if (y < y0 || y >= y1) frame.rgba[4 * p] ^= 0x5a, frame.rgba[4 * p + 3] = 7;
        }
        const std::string path = dir.file("bands.png");
        const uint8_t *rows = frame.rgba.data() + size_t(y0) * size_t(c.width) * 4;
        EXPECT_OK(write_png_from_row_bands(MPI_COMM_WORLD, 0, rows, y0, y1, c.width, c.height, 1,
                                           path, threads));
        if (world_rank() != 0) continue;
        std::vector<uint8_t> expected;
        ASSERT_OK(encode_png(reference.rgba.data(), c.width, c.height, c.opaque ? 3 : 4, 1,
                             png_band_count(c.height), &expected, png_options_for_level(1)));
        EXPECT_EQ(read_file(path), expected);
        EXPECT_EQ(dir.entry_count(), 1u);  // no temporary file left
      }
}

TEST(PngAcrossRanks, FromRowBandsRefusesRowsThatAreNotBandsOnEveryRank) {
  const ScratchDir dir;
  const Frame frame = test_frame(256, 256, false, true, 6);  // 8 bands of 32 rows
  EXPECT_EQ(png_band_rows(256, 256), 32);
  EXPECT_EQ(png_band_rows(257, 256), 0);  // 8 bands of uneven rows
  auto [y0, y1] = band_rows_of(world_rank(), world_size(), 256, 256, 0);
  // One rank's rows are off by one: every rank refuses, and no file is written.
  if (world_rank() == world_size() - 1) y0 = std::max(0, y0 - 1);
  const Status s =
      write_png_from_row_bands(MPI_COMM_WORLD, 0, frame.rgba.data() + size_t(y0) * 256 * 4, y0, y1,
                               256, 256, 1, dir.file("bad.png"));
  if (world_size() == 1 && y0 == 0) {
    EXPECT_OK(s);  // one rank holding every row: nothing is off
    return;
  }
  EXPECT_EQ(s.code, StatusCode::kInvalidArgument);
  EXPECT_NE(s.message.find("bad.png"), std::string::npos) << s.message;
  EXPECT_EQ(dir.entry_count(), 0u);
}

TEST(PngAcrossRanks, UnwritablePathFailsOnTheRootAndEveryRankReturns) {
  const ScratchDir dir;
  const Frame frame = world_rank() == 0 ? test_frame(1024, 700, true, true, 4) : Frame();
  // A directory where the file's parent directory would be: nothing can be created under it.
  const std::string blocker = dir.file("not_a_dir");
  if (world_rank() == 0) std::ofstream(blocker) << "x";
  const Status s =
      write_png_across_ranks(MPI_COMM_WORLD, 0, frame, 1024, 700, 1, blocker + "/image.png");
  if (world_rank() == 0) {
    EXPECT_EQ(s.code, StatusCode::kIo);
    EXPECT_NE(s.message.find("image.png"), std::string::npos) << s.message;
    EXPECT_EQ(dir.entry_count(), 1u);
  } else {
    EXPECT_OK(s);
  }
  // The communicator is still usable: nothing of the failed call is left in flight.
  int sum = 0, one = 1;
  MPI_Allreduce(&one, &sum, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(sum, world_size());
  const Status again =
      write_png_across_ranks(MPI_COMM_WORLD, 0, frame, 1024, 700, 1, dir.file("ok.png"));
  EXPECT_OK(again);
}

// A rank other than the root fails to compress its first band (as running out of memory there
// would): it and the root report the failure, no file is left, and no rank waits for ever - the
// root has already sent that rank the rows of its later bands, which it must still receive.
TEST(PngAcrossRanks, CompressionFailingOnAnotherRankFailsOnItAndTheRootAndEveryRankReturns) {
  if (world_size() < 2) GTEST_SKIP() << "needs a rank other than the root";
  const ScratchDir dir;
  const int root = 0, faulty = 1;  // at 2 and 3 ranks the owner of several bands
  const Frame frame = world_rank() == root ? test_frame(1024, 700, true, true, 5) : Frame();
  if (world_rank() == faulty) inject_fault("png: deflate band");
  const std::string path = dir.file("failed.png");
  const Status s = write_png_across_ranks(MPI_COMM_WORLD, root, frame, 1024, 700, 1, path);
  inject_fault("");
  if (world_rank() == root || world_rank() == faulty) {
    EXPECT_EQ(s.code, StatusCode::kIo);
    EXPECT_NE(s.message.find("failed.png"), std::string::npos) << s.message;
  } else {
    EXPECT_OK(s);
  }
  if (world_rank() == root) EXPECT_EQ(dir.entry_count(), 0u);
  // The communicator is still usable: nothing of the failed call is left in flight.
  int sum = 0, one = 1;
  MPI_Allreduce(&one, &sum, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(sum, world_size());
  const Status again = write_png_across_ranks(MPI_COMM_WORLD, root, frame, 1024, 700, 1, path);
  EXPECT_OK(again);
  if (world_rank() == root) {
    const Frame one_process = frame;
    const std::string alone = dir.file("alone.png");
    ASSERT_OK(write_png(one_process, 1, alone, 1));
    EXPECT_EQ(read_file(path), read_file(alone));
  }
}

}  // namespace
}  // namespace lantern
