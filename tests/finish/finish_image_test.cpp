// finish_image_to_bands (core/finish/finish_image.h) under mpiexec: every rank's band holds exactly
// the rows of the image finish_image puts on root - composited, down-sampled with samples, and
// with the screen-space cues - its bands start on multiples of the rows asked for and cover the
// image in rank order; bands that do not divide the image are refused on every rank.
#include <gtest/gtest.h>

#include <mpi.h>

#include <cstring>
#include <string>
#include <vector>

#include "core/camera/camera.h"
#include "core/finish/finish_image.h"
#include "tests/composite/synthetic_frames.h"
#include "tests/support/mpi_world.h"
#include "tests/support/orthographic_camera.h"

namespace lantern::testing {
namespace {

// Rank k's frame at s samples a pixel axis: two spheres of its own over a width x height image.
Frame rank_frame(int k, int width, int height, int s) {
  Frame f = blank_frame(width * s, height * s);
  const int ranks = world_size();
  draw_sphere(sphere_for_rank(k, 11, width * s, height * s, false), f);
  draw_sphere(sphere_for_rank(k + ranks, 11, width * s, height * s, false), f);
  return f;
}

FinishSettings settings(int width, int height, int s) {
  FinishSettings f;
  f.width = width, f.height = height, f.samples_per_axis = s;
  return f;
}

// Every screen-space cue at once: ambient occlusion at half resolution (halo 39 rows, more than
// a band holds), outlines and depth cueing.
FinishSettings cued(int width, int height, int s) {
  FinishSettings f = settings(width, height, s);
  f.cues.ambient_occlusion.enabled = true;
  f.cues.ambient_occlusion.method = AmbientOcclusionMethod::kScreen;
  f.cues.outline.enabled = true;
  f.cues.depth_cue.enabled = true;
  return f;
}

// Orthographic along -z over a 12 x 12 box, near 10 and far 90: the synthetic frames' window
// depths are distances 10 to 90, and a sphere radius of 2 is a few pixels (the cues' unit).
Camera cue_camera(int width, int height) {
  return orthographic_down_z(6.0, 1.0, width, height);
}
constexpr double kCueRadius = 2.0;

TEST(FinishImage, BandsHoldTheRowsOfTheImageOnRoot) {
  const int ranks = world_size(), rank = world_rank();
  const int width = 37, height = 48;
  const Camera camera = cue_camera(width, height);
  for (const bool cues : {false, true})
    for (const int s : {1, 2})
      for (const int band_rows : {1, 6, 16}) {
        SCOPED_TRACE(std::string(cues ? "cues, " : "") + "samples " + std::to_string(s * s) +
                     ", bands of " + std::to_string(band_rows));
        const FinishSettings finish = cues ? cued(width, height, s) : settings(width, height, s);
        // The reference: the image on root, handed to every rank.
        // (With one sample root's image is its frame, composited in place, as the pipeline has it.)
        Frame frame = rank_frame(rank, width, height, s);
        Frame image;
        FinishStats stats;
        ASSERT_TRUE(finish_image(MPI_COMM_WORLD, frame, finish, camera, kCueRadius, nullptr,
                                 s == 1 ? &frame : &image, &stats)
                        .ok());
        if (s == 1) image = frame;
        if (rank != 0) image = Frame(width, height);
        if (image.rgba.size() != size_t(4 * width * height)) {  // no rank may skip the broadcast
          ADD_FAILURE() << "rank " << rank << ": the image is not " << width << " x " << height;
          image = Frame(width, height);
        }
        MPI_Bcast(image.rgba.data(), int(image.rgba.size()), MPI_UINT8_T, 0, MPI_COMM_WORLD);

        Frame mine = rank_frame(rank, width, height, s), band;
        ImageBand owned;
        ASSERT_TRUE(finish_image_to_bands(MPI_COMM_WORLD, mine, finish, camera, kCueRadius, nullptr,
                                          band_rows, &band, &owned, &stats)
                        .ok());
        EXPECT_EQ(owned.rows.y0 % band_rows, 0);
        EXPECT_EQ(owned.rows.y1 % band_rows, 0);
        // The ranks' bands follow one another from row 0 to the last.
        std::vector<int> all(size_t(2 * ranks));
        const int rows[2] = {owned.rows.y0, owned.rows.y1};
        MPI_Allgather(rows, 2, MPI_INT, all.data(), 2, MPI_INT, MPI_COMM_WORLD);
        EXPECT_EQ(all.front(), 0);
        EXPECT_EQ(all.back(), height);
        for (int k = 1; k < ranks; ++k) EXPECT_EQ(all[size_t(2 * k)], all[size_t(2 * k - 1)]);
        // Their pixels are the image's, where finish_image_to_bands says they are.
        const Frame &held = s == 1 && !cues ? mine : band;
        EXPECT_EQ(owned.held, &held);
        if (!cues) EXPECT_EQ(owned.first, s == 1 ? 0 : owned.rows.y0);
        EXPECT_LE(owned.first, owned.rows.y0);
        int differing = 0;
        for (int y = owned.rows.y0; y < owned.rows.y1; ++y)
          differing +=
              std::memcmp(&held.rgba[4 * size_t(y - owned.first) * size_t(width)],
                          &image.rgba[4 * size_t(y) * size_t(width)], 4 * size_t(width)) != 0;
        EXPECT_EQ(differing, 0) << "rank " << rank << " rows " << owned.rows.y0 << ".."
                                << owned.rows.y1;
      }
}

// The cues change the image (so the comparison above is not of two uncued images).
TEST(FinishImage, TheCuesChangeTheImage) {
  const int width = 37, height = 48;
  const Camera camera = cue_camera(width, height);
  Frame plain = rank_frame(world_rank(), width, height, 1), shaded = plain;
  FinishStats stats;
  ASSERT_TRUE(finish_image(MPI_COMM_WORLD, plain, settings(width, height, 1), camera, kCueRadius,
                           nullptr, &plain, &stats)
                  .ok());
  ASSERT_TRUE(finish_image(MPI_COMM_WORLD, shaded, cued(width, height, 1), camera, kCueRadius,
                           nullptr, &shaded, &stats)
                  .ok());
  if (world_rank() == 0) EXPECT_NE(plain.rgba, shaded.rgba);
}

// A band's buffers kept from one frame to the next (and the cues' scratch) give the next frame the
// image of fresh ones, with one sample and with four, after a frame of other spheres.
TEST(FinishImage, KeptBuffersGiveTheImageOfFreshOnes) {
  const int width = 37, height = 48, rank = world_rank();
  const Camera camera = cue_camera(width, height);
  for (const int s : {1, 2}) {
    Frame kept_band;
    CueScratch scratch;
    FinishStats stats;
    Frame before = rank_frame(rank + 1, width, height, s), image;
    ASSERT_TRUE(finish_image(MPI_COMM_WORLD, before, cued(width, height, s), camera, kCueRadius,
                             nullptr, &image, &stats, &scratch, &kept_band)
                    .ok());
    Frame fresh = rank_frame(rank, width, height, s), kept = fresh, fresh_image, kept_image;
    ASSERT_TRUE(finish_image(MPI_COMM_WORLD, fresh, cued(width, height, s), camera, kCueRadius,
                             nullptr, &fresh_image, &stats)
                    .ok());
    ASSERT_TRUE(finish_image(MPI_COMM_WORLD, kept, cued(width, height, s), camera, kCueRadius,
                             nullptr, &kept_image, &stats, &scratch, &kept_band)
                    .ok());
    if (rank == 0) EXPECT_EQ(kept_image.rgba, fresh_image.rgba) << "samples " << s * s;
  }
}

TEST(FinishImage, BandsThatDoNotDivideTheImageAreRefusedOnEveryRank) {
  Frame frame = rank_frame(world_rank(), 20, 12, 1), band;
  ImageBand owned;
  FinishStats stats;
  for (const FinishSettings &finish : {settings(20, 12, 1), cued(20, 12, 1)})
    EXPECT_EQ(finish_image_to_bands(MPI_COMM_WORLD, frame, finish, Camera(), 1.0, nullptr, 5, &band,
                                    &owned, &stats)
                  .code,
              StatusCode::kInvalidArgument);
  // Nothing was left in flight: the communicator still works.
  int sum = 0, one = 1;
  MPI_Allreduce(&one, &sum, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  EXPECT_EQ(sum, world_size());
}

}  // namespace
}  // namespace lantern::testing
