// Row bands after compositing: every rank's share of rows is a function of the image and the rank
// count only, tiles the image, keeps multiples of a super-sampling factor, and a scatter with
// halos followed by a gather gives the root back its frame bit for bit.
#include <gtest/gtest.h>

#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <string>

#include "core/composite/row_bands.h"
#include "tests/composite/synthetic_frames.h"
#include "tests/support/mpi_world.h"

namespace lantern::testing {
namespace {

TEST(RowBands, TileTheImageInRankOrderWithBoundariesOnTheMultiple) {
  for (int height : {1, 7, 64, 1000, 1024}) {
    for (int ranks = 1; ranks <= 9; ++ranks) {
      for (int multiple : {1, 2, 4, 8}) {
        if (height % multiple != 0) continue;
        int next = 0;
        for (int k = 0; k < ranks; ++k) {
          const RowBand b = row_band(height, ranks, k, multiple);
          EXPECT_EQ(b.y0, next) << height << " rows, " << ranks << " ranks, rank " << k;
          EXPECT_EQ(b.y0 % multiple, 0);
          EXPECT_LE(b.rows(), (height / multiple / ranks + 1) * multiple);
          next = b.y1;
        }
        EXPECT_EQ(next, height) << height << " rows, " << ranks << " ranks";
      }
    }
  }
}

TEST(RowBands, SuperSampledBandsDownSampleIntoTheImagesBands) {
  for (int s : {2, 4, 8})
    for (int ranks = 1; ranks <= 5; ++ranks)
      for (int k = 0; k < ranks; ++k) {
        const RowBand fine = row_band(123 * s, ranks, k, s), coarse = row_band(123, ranks, k);
        EXPECT_EQ(fine.y0, coarse.y0 * s);
        EXPECT_EQ(fine.y1, coarse.y1 * s);
      }
}

TEST(RowBands, ScatterWithHalosThenGatherRestoresTheRootsFrame) {
  const int width = 37, height = 53;
  Frame full = blank_frame(width, height);
  for (int i = 0; i < 5; ++i) draw_sphere(sphere_for_rank(i, 3, width, height, false), full);
  const int ranks = world_size(), rank = world_rank();
  for (int halo : {0, 1, 5, 100}) {
    BandFrame band;
    ASSERT_TRUE(scatter_row_bands(MPI_COMM_WORLD, 0, full, width, height, 1, halo, &band).ok());
    const RowBand owned = row_band(height, ranks, rank);
    EXPECT_EQ(band.owned.y0, owned.y0);
    EXPECT_EQ(band.owned.y1, owned.y1);
    if (owned.rows() > 0) {
      EXPECT_EQ(band.first, std::max(0, owned.y0 - halo));
      EXPECT_EQ(band.first + band.frame.height, std::min(height, owned.y1 + halo));
    }
    // Every row held, halo included, is the root's row.
    for (int y = 0; y < band.frame.height; ++y)
      for (int x = 0; x < width; ++x) {
        const size_t mine = band.frame.index(x, y), root = full.index(x, band.first + y);
        ASSERT_EQ(band.frame.depth[mine], full.depth[root]) << "row " << band.first + y;
        for (int c = 0; c < 4; ++c)
          ASSERT_EQ(band.frame.rgba[4 * mine + c], full.rgba[4 * root + c]);
      }
    Frame back;
    ASSERT_TRUE(gather_row_bands(MPI_COMM_WORLD, 0, band, width, height, &back).ok());
    if (rank == 0) EXPECT_EQ(describe_difference(full, back), "") << "halo " << halo;
  }
}

TEST(RowBands, AWrongRootFrameFailsOnEveryRankWithoutDeadlock) {
  const Frame wrong = blank_frame(10, 10);
  BandFrame band;
  const Status s = scatter_row_bands(MPI_COMM_WORLD, 0, wrong, 12, 10, 1, 0, &band);
  EXPECT_EQ(s.code, StatusCode::kMpi);
  EXPECT_NE(s.message.find("expected 12 x 10"), std::string::npos) << s.message;
}

// Halos fetched from the neighbours (no root) hold the same rows as halos handed out by the root,
// also when a halo reaches past the next rank's band (small bands at many ranks).
TEST(RowBands, HaloExchangeMatchesTheRootsRows) {
  const int width = 29, height = 23;
  Frame full = blank_frame(width, height);
  for (int i = 0; i < 4; ++i) draw_sphere(sphere_for_rank(i, 7, width, height, false), full);
  for (int halo : {0, 1, 4, 30}) {
    BandFrame expected, mine;
    ASSERT_TRUE(scatter_row_bands(MPI_COMM_WORLD, 0, full, width, height, 1, halo, &expected).ok());
    ASSERT_TRUE(scatter_row_bands(MPI_COMM_WORLD, 0, full, width, height, 1, 0, &mine).ok());
    ASSERT_TRUE(exchange_halo_rows(MPI_COMM_WORLD, width, height, halo, &mine).ok());
    EXPECT_EQ(mine.first, expected.first) << "halo " << halo;
    EXPECT_EQ(mine.owned.y0, expected.owned.y0);
    EXPECT_EQ(mine.owned.y1, expected.owned.y1);
    EXPECT_EQ(describe_difference(mine.frame, expected.frame), "") << "halo " << halo;
  }
}

// A rank that holds its owned rows in place in a frame of the whole image (as compositing left
// them) gets its halo rows in place too: the rows the root hands out, and `held` says which.
// Rows outside them are spare and keep whatever they held.
TEST(RowBands, HaloExchangeInPlaceInTheWholeImage) {
  const int width = 29, height = 23;
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  Frame full = blank_frame(width, height);
  for (int i = 0; i < 4; ++i) draw_sphere(sphere_for_rank(i, 7, width, height, false), full);
  const RowBand owned = row_band(height, ranks, rank);
  for (int halo : {0, 1, 4, 30}) {
    BandFrame expected, whole;
    ASSERT_TRUE(scatter_row_bands(MPI_COMM_WORLD, 0, full, width, height, 1, halo, &expected).ok());
    whole.frame = Frame(width, height);
    std::fill(whole.frame.rgba.begin(), whole.frame.rgba.end(), uint8_t(0x5a));
    std::fill(whole.frame.depth.begin(), whole.frame.depth.end(), -7.0f);
    for (int y = owned.y0; y < owned.y1; ++y)
      for (int x = 0; x < width; ++x) {
        const size_t i = full.index(x, y);
        whole.frame.depth[i] = full.depth[i];
        for (int c = 0; c < 4; ++c) whole.frame.rgba[4 * i + c] = full.rgba[4 * i + c];
      }
    ASSERT_TRUE(exchange_halo_rows(MPI_COMM_WORLD, width, height, halo, &whole).ok());
    EXPECT_EQ(whole.first, 0);
    ASSERT_TRUE(whole.held.has_value());
    const RowBand held = whole.held_rows();
    EXPECT_EQ(held.y0, expected.first) << "halo " << halo;
    EXPECT_EQ(held.rows(), expected.frame.height) << "halo " << halo;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const size_t i = full.index(x, y);
        const bool in = y >= held.y0 && y < held.y1;
        ASSERT_EQ(whole.frame.depth[i], in ? full.depth[i] : -7.0f) << "row " << y;
        ASSERT_EQ(whole.frame.rgba[4 * i], in ? full.rgba[4 * i] : uint8_t(0x5a)) << "row " << y;
      }
    Frame back;
    ASSERT_TRUE(gather_row_bands(MPI_COMM_WORLD, 0, whole, width, height, &back).ok());
    if (rank == 0) EXPECT_EQ(describe_difference(full, back), "") << "halo " << halo;
  }
}

TEST(RowBands, HaloExchangeRefusesABandThatIsNotExactlyTheOwnedRows) {
  BandFrame band;
  band.frame = blank_frame(5, 3);  // whatever the rank owns, 3 rows at row 0 is wrong somewhere
  const Status s = exchange_halo_rows(MPI_COMM_WORLD, 5, 1000, 2, &band);
  EXPECT_EQ(s.code, StatusCode::kMpi);
  EXPECT_NE(s.message.find("is not exactly its rows"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace lantern::testing
