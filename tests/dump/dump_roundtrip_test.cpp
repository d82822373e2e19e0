// Write -> read round trip of H5MD dumps through the C API, run at 1, 2 and 4 ranks: every rank
// publishes a different number of particles, Lantern writes them collectively, and H5mdReader
// (each rank reading its own share) finds every value where the global id says it belongs.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/dump/h5md_reader.h"
#include "lantern/lantern.h"
#include "mpi_scratch_dir.h"
#include "tests/support/mpi_world.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::world_rank;
using testing::world_size;

// Particle with global id g at a step: values anyone can recompute from (g, step).
double coord(int64_t g, int c, int64_t step) {
  return 0.25 * g + c + 0.001 * step + 1.0 / 3.0;
}
int64_t type_of(int64_t g) {
  return g % 5;
}
double scalar_of(int64_t g, int64_t step) {
  return std::sin(0.1 * g) + step;
}

// This rank's particles: 50 + 17 * rank of them, global ids after the lower ranks' ones.
struct RankParticles {
  std::vector<double> xyz, scalar;
  std::vector<int32_t> type;
  std::vector<int64_t> id;
  int64_t first = 0, count = 0, total = 0;

  RankParticles(int64_t step, int extra = 0) {
    const int rank = world_rank(), size = world_size();
    for (int r = 0; r < size; ++r) {
      const int64_t n = 50 + 17 * r + extra;
      if (r < rank) first += n;
      if (r == rank) count = n;
      total += n;
    }
    for (int64_t i = 0; i < count; ++i) {
      const int64_t g = first + i;
      for (int c = 0; c < 3; ++c) xyz.push_back(coord(g, c, step));
      type.push_back(static_cast<int32_t>(type_of(g)));
      id.push_back(g);
      scalar.push_back(scalar_of(g, step));
    }
  }
  lantern_particles view() const {
    lantern_particles p{};
    p.count = count;
    p.position = {xyz.data(), LANTERN_FLOAT64, 0};
    p.type = {type.data(), LANTERN_INT32, 0};
    p.id = {id.data(), LANTERN_INT64, 0};
    p.scalar = {scalar.data(), LANTERN_FLOAT64, 0};
    return p;
  }
};

struct ContextCloser {
  void operator()(lantern_context *c) const { lantern_close(c); }
};
using Context = std::unique_ptr<lantern_context, ContextCloser>;

Context open_dump(const std::string &file, const std::string &extra) {
  const std::string yaml = "dump:\n  file: " + file + "\n" + extra;
  lantern_context *raw = nullptr;
  const lantern_status st = lantern_open(yaml.c_str(), MPI_Comm_c2f(MPI_COMM_WORLD), &raw);
  Context ctx(raw);
  EXPECT_EQ(st, LANTERN_OK) << lantern_error_message(ctx.get());
  return ctx;
}

void write_steps(lantern_context *ctx, const std::vector<int64_t> &steps) {
  const double low[3] = {-1, -2, -3}, high[3] = {100, 50, 25};
  const int periodic[3] = {1, 1, 0};
  for (const int64_t step : steps) {
    const RankParticles p(step);
    const lantern_particles v = p.view();
    ASSERT_EQ(lantern_publish(ctx, &v), LANTERN_OK) << lantern_error_message(ctx);
    ASSERT_EQ(lantern_set_box(ctx, low, high, periodic), LANTERN_OK);
    ASSERT_EQ(lantern_execute(ctx, step, 0.5 * step), LANTERN_OK) << lantern_error_message(ctx);
  }
}

// Reads every frame back, this rank's share only, and checks it against (id, step).
void check_file(const std::string &file, const std::vector<int64_t> &steps, double tolerance) {
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  ASSERT_EQ(reader->frames().size(), steps.size());
  const RankParticles expected_layout(0);
  for (size_t f = 0; f < steps.size(); ++f) {
    const FrameInfo &info = reader->frames()[f];
    EXPECT_EQ(info.step, steps[f]);
    EXPECT_DOUBLE_EQ(info.time, 0.5 * steps[f]);
    ASSERT_EQ(info.count, expected_layout.total);
    const auto [begin, end] = rank_share(info.count, world_rank(), world_size());
    ParticleFrame frame;
    ASSERT_OK(reader->read(f, begin, end, &frame));
    ASSERT_EQ(frame.count(), end - begin);
    ASSERT_EQ(frame.id.size(), size_t(end - begin));
    ASSERT_EQ(frame.type.size(), size_t(end - begin));
    ASSERT_EQ(frame.scalar.size(), size_t(end - begin));
    EXPECT_TRUE(frame.radius.empty());
    for (int64_t i = 0; i < frame.count(); ++i) {
      const int64_t g = frame.id[i];
      EXPECT_EQ(g, begin + i) << "particles are stored in rank order";
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(frame.position[3 * i + c], coord(g, c, steps[f]),
                    tolerance * std::abs(coord(g, c, steps[f])));
      EXPECT_EQ(frame.type[i], type_of(g));
      EXPECT_NEAR(frame.scalar[i], scalar_of(g, steps[f]),
                  tolerance * (1 + std::abs(scalar_of(g, steps[f]))));
    }
    ASSERT_TRUE(frame.box.has_value());
    EXPECT_EQ(frame.box->low, (std::array<double, 3>{-1, -2, -3}));
    EXPECT_EQ(frame.box->high, (std::array<double, 3>{100, 50, 25}));
    EXPECT_EQ(frame.box->periodic, (std::array<bool, 3>{true, true, false}));
  }
}

TEST(DumpRoundTrip, Float64IsExact) {
  const MpiScratchDir dir;
  const std::string file = dir.file("exact.h5");
  {
    const Context ctx = open_dump(file, "  schedule: {every: 10}\n");
    write_steps(ctx.get(), {0, 5, 10, 20});  // step 5 is not scheduled: no frame
  }
  check_file(file, {0, 10, 20}, 0.0);
}

TEST(DumpRoundTrip, Float32WithinSinglePrecision) {
  const MpiScratchDir dir;
  const std::string file = dir.file("single.h5");
  {
    const Context ctx = open_dump(file, "  precision: float32\n");
    write_steps(ctx.get(), {3, 4});
  }
  check_file(file, {3, 4}, 1e-6);
}

TEST(DumpRoundTrip, FileIsValidAfterEveryFrameWithoutClose) {
  const MpiScratchDir dir;
  const std::string file = dir.file("open.h5");
  const Context ctx = open_dump(file, "");
  write_steps(ctx.get(), {1, 2});
  // Still open for writing: the flushed file already holds both frames.
  check_file(file, {1, 2}, 0.0);
}

// The file's author (/h5md/author name, from $USER) is rank 0's even where the ranks' environments
// differ: an attribute written collectively must be the same on every rank (names of different
// lengths left the ranks waiting for ever in HDF5's metadata writes).
TEST(DumpRoundTrip, AuthorIsRankZerosUserWhateverTheRanksEnvironments) {
  const MpiScratchDir dir;
  const std::string file = dir.file("author.h5");
  const char *user = std::getenv("USER");
  const std::string kept = user ? user : "";
  setenv("USER",
         world_rank() == 0 ? "user_of_rank_0"
                           : std::string(size_t(5 + 40 * world_rank()), 'x').c_str(),
         1);
  {
    const Context ctx = open_dump(file, "");
    write_steps(ctx.get(), {1});
  }
  if (user)
    setenv("USER", kept.c_str(), 1);
  else
    unsetenv("USER");
  if (world_rank() != 0) return;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const hid_t a = H5Aopen_by_name(f, "/h5md/author", "name", H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(a, 0);
  const hid_t t = H5Aget_type(a);
  std::vector<char> text(H5Tget_size(t) + 1, '\0');
  EXPECT_GE(H5Aread(a, t, text.data()), 0);
  EXPECT_STREQ(text.data(), "user_of_rank_0");
  H5Tclose(t), H5Aclose(a), H5Fclose(f);
}

TEST(DumpRoundTrip, EmptyRanksStillTakePart) {
  // Odd ranks own nothing: they still join every collective write, selecting nothing.
  const MpiScratchDir dir;
  const std::string file = dir.file("holes.h5");
  const RankParticles all(7);
  const bool empty = world_rank() % 2 == 1;
  {
    const Context ctx = open_dump(file, "");
    lantern_particles v = all.view();
    if (empty) v = lantern_particles{};
    ASSERT_EQ(lantern_publish(ctx.get(), &v), LANTERN_OK);
    ASSERT_EQ(lantern_execute(ctx.get(), 7, 1.0), LANTERN_OK) << lantern_error_message(ctx.get());
  }
  int64_t mine = empty ? 0 : all.count, total = 0;
  MPI_Allreduce(&mine, &total, 1, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  ASSERT_EQ(reader->frames().size(), 1u);
  EXPECT_EQ(reader->frames()[0].count, total);
  ParticleFrame frame;
  ASSERT_OK(reader->read(0, 0, total, &frame));
  for (int64_t i = 0; i < total; ++i) EXPECT_EQ(frame.position[3 * i], coord(frame.id[i], 0, 7));
}

// Atoms lost and gained between dumps (fix evaporate, fix deposit): every frame keeps its own
// count, the particle axis grows to the largest, and each rank reads back exactly the
// particles of the frame (the fill rows after them are not particles).
TEST(DumpRoundTrip, ParticleCountChangesFromFrameToFrame) {
  const MpiScratchDir dir;
  const std::string file = dir.file("count.h5");
  const std::vector<int64_t> steps{0, 1, 2, 3};
  const std::vector<int> extra{0, -20, 30, -45};  // per rank: lose, gain beyond, lose again
  std::vector<int64_t> totals;
  {
    const Context ctx = open_dump(file, "");
    for (size_t k = 0; k < steps.size(); ++k) {
      const RankParticles p(steps[k], extra[k]);
      totals.push_back(p.total);
      const lantern_particles v = p.view();
      ASSERT_EQ(lantern_publish(ctx.get(), &v), LANTERN_OK);
      ASSERT_EQ(lantern_execute(ctx.get(), steps[k], 0.5 * steps[k]), LANTERN_OK)
          << lantern_error_message(ctx.get());
    }
  }
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  ASSERT_EQ(reader->frames().size(), steps.size());
  for (size_t k = 0; k < steps.size(); ++k) {
    ASSERT_EQ(reader->frames()[k].count, totals[k]) << "frame " << k;
    // Rank r of this frame holds 50 + 17 r + extra particles with consecutive global ids.
    const auto [begin, end] = rank_share(totals[k], world_rank(), world_size());
    ParticleFrame frame;
    ASSERT_OK(reader->read(k, begin, end, &frame));
    ASSERT_EQ(frame.count(), end - begin);
    ASSERT_EQ(frame.global_count, totals[k]);
    for (int64_t i = 0; i < frame.count(); ++i) {
      const int64_t g = frame.id[i];
      ASSERT_EQ(g, begin + i);
      for (int c = 0; c < 3; ++c) EXPECT_EQ(frame.position[3 * i + c], coord(g, c, steps[k]));
      EXPECT_EQ(frame.type[i], type_of(g));
    }
  }
  // Reading past a frame's count reaches only fill rows: none of them is a particle.
  const int64_t rows = *std::max_element(totals.begin(), totals.end());
  ParticleFrame tail;
  ASSERT_OK(reader->read(1, totals[1], rows, &tail));
  EXPECT_EQ(tail.count(), 0);
}

TEST(DumpErrors, ListedFieldNotPublished) {
  const MpiScratchDir dir;
  const Context ctx = open_dump(dir.file("fields.h5"), "  fields: [position, radius]\n");
  const RankParticles p(0);
  const lantern_particles v = p.view();
  ASSERT_EQ(lantern_publish(ctx.get(), &v), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx.get(), 0, 0.0), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(lantern_error_message(ctx.get())).find("dump.fields: 'radius'"),
            std::string::npos)
      << lantern_error_message(ctx.get());
}

TEST(DumpErrors, NoParticlesAnywhere) {
  const MpiScratchDir dir;
  const Context ctx = open_dump(dir.file("empty.h5"), "");
  const lantern_particles none{};
  ASSERT_EQ(lantern_publish(ctx.get(), &none), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx.get(), 0, 0.0), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(lantern_error_message(ctx.get())).find("no rank has particles"),
            std::string::npos);
}

TEST(DumpErrors, UnwritableFileIsAnIoErrorAndLaterStepsRetry) {
  const MpiScratchDir dir;
  const Context ctx = open_dump("/proc/lantern_cannot_write_here/d.h5", "");
  const RankParticles p(0);
  const lantern_particles v = p.view();
  ASSERT_EQ(lantern_publish(ctx.get(), &v), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx.get(), 0, 0.0), LANTERN_ERR_IO);
  EXPECT_NE(std::string(lantern_error_message(ctx.get())).find("/proc/lantern_cannot_write_here"),
            std::string::npos)
      << lantern_error_message(ctx.get());
  EXPECT_EQ(lantern_execute(ctx.get(), 1, 0.0), LANTERN_ERR_IO);
}

// The last line of a JSON-lines file, parsed (rank 0 writes the stats).
nlohmann::json last_json_line(const std::string &path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last.empty() ? nlohmann::json() : nlohmann::json::parse(last);
}

// A dump and a 16 x 16 scene on every step, with a stats file.
Context open_dump_and_scene(const MpiScratchDir &dir, const std::string &stats) {
  const std::string yaml = "stats: '" + stats + "'\nscenes:\n  - {width: 16, height: 16, " +
                           "output: {pattern: '" + dir.file("img_{step}.png") + "'}}\n" +
                           "dump:\n  file: " + dir.file("d.h5") + "\n";
  lantern_context *raw = nullptr;
  const lantern_status st = lantern_open(yaml.c_str(), MPI_Comm_c2f(MPI_COMM_WORLD), &raw);
  Context ctx(raw);
  EXPECT_EQ(st, LANTERN_OK) << lantern_error_message(ctx.get());
  return ctx;
}

// The dump failed (no particles anywhere) and the call returned 2, but the
// step's stats line said "status": 0.
TEST(DumpErrors, StatsLineReportsTheStatusTheStepReturns) {
  const MpiScratchDir dir;
  const std::string stats = dir.file("stats.jsonl");
  const Context ctx = open_dump_and_scene(dir, stats);
  const lantern_particles none{};
  ASSERT_EQ(lantern_publish(ctx.get(), &none), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx.get(), 0, 0.0), LANTERN_ERR_INVALID_ARGUMENT);
  if (world_rank() == 0) {
    const nlohmann::json line = last_json_line(stats);
    ASSERT_TRUE(line.is_object()) << "no stats line";
    EXPECT_EQ(line["step"], 0);
    EXPECT_EQ(line["status"], int(LANTERN_ERR_INVALID_ARGUMENT)) << line.dump();
  }
  // A good step after it reports 0.
  const RankParticles p(1);
  const lantern_particles v = p.view();
  ASSERT_EQ(lantern_publish(ctx.get(), &v), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx.get(), 1, 0.0), LANTERN_OK) << lantern_error_message(ctx.get());
  if (world_rank() == 0) EXPECT_EQ(last_json_line(stats)["status"], 0);
}

// An unwritable stats file was only a warning on rank 0 and the step returned
// OK. Now every rank returns LANTERN_ERR_IO naming the file (no rank left waiting), the images
// are still written, and the next step retries.
TEST(StatsFile, UnwritableIsAnIoErrorOnEveryRankAndImagesAreStillWritten) {
  const MpiScratchDir dir;
  const std::string blocker = dir.file("blocker");  // a file where the stats directory should be
  if (world_rank() == 0) std::ofstream(blocker) << "not a directory";
  MPI_Barrier(MPI_COMM_WORLD);
  const std::string stats = blocker + "/stats.jsonl";
  const Context ctx = open_dump_and_scene(dir, stats);
  const RankParticles p(0);
  const lantern_particles v = p.view();
  ASSERT_EQ(lantern_publish(ctx.get(), &v), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx.get(), 0, 0.0), LANTERN_ERR_IO);
  const std::string message = lantern_error_message(ctx.get());
  EXPECT_NE(message.find("stats"), std::string::npos) << message;
  EXPECT_NE(message.find(stats), std::string::npos) << message;
  if (world_rank() == 0) EXPECT_TRUE(std::filesystem::exists(dir.file("img_0.png")));
  // Fixed: the next step writes its stats line.
  MPI_Barrier(MPI_COMM_WORLD);
  if (world_rank() == 0) std::filesystem::remove(blocker);
  MPI_Barrier(MPI_COMM_WORLD);
  EXPECT_EQ(lantern_execute(ctx.get(), 1, 0.0), LANTERN_OK) << lantern_error_message(ctx.get());
  if (world_rank() == 0) EXPECT_EQ(last_json_line(stats)["step"], 1);
}

// Species are stored in 32 bits: an int64 type beyond them was cut to its low bits (2^32 + 2 as
// 2), silently. Now the step fails on every rank naming the type, and a later step with types
// that fit is dumped.
TEST(DumpRoundTrip, TypesBeyond32BitsFailTheDumpNamingThem) {
  const MpiScratchDir dir;
  const Context ctx = open_dump(dir.file("types.h5"), "");
  std::vector<double> x = {0, 0, 0, 1, 0, 0};
  // On the last rank only: the others' rows fit, and must fail with it.
  std::vector<int64_t> type = {1, world_rank() == world_size() - 1 ? (int64_t(1) << 32) + 2 : 5};
  lantern_particles p{};
  p.count = 2;
  p.position = {x.data(), LANTERN_FLOAT64, 0};
  p.type = {type.data(), LANTERN_INT64, 0};
  ASSERT_EQ(lantern_publish(ctx.get(), &p), LANTERN_OK);
  const lantern_status failed = lantern_execute(ctx.get(), 0, 0.0);
  int all_failed = failed != LANTERN_OK ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &all_failed, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  EXPECT_EQ(all_failed, 1);
  EXPECT_NE(std::string(lantern_error_message(ctx.get())).find("does not fit the dump's 32-bit"),
            std::string::npos)
      << lantern_error_message(ctx.get());
  type[1] = 7;

  EXPECT_EQ(lantern_execute(ctx.get(), 1, 0.0), LANTERN_OK) << lantern_error_message(ctx.get());
}

TEST(SetBox, RejectsInvertedAndNull) {
  const MpiScratchDir dir;
  const Context ctx = open_dump(dir.file("box.h5"), "");
  const double low[3] = {0, 5, 0}, high[3] = {1, 2, 1};
  EXPECT_EQ(lantern_set_box(ctx.get(), low, high, nullptr), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(lantern_error_message(ctx.get())).find("low[1]"), std::string::npos);
  // An edge whose length overflows: periodic bonds' ends became NaN, silently not drawn.
  const double wide_low[3] = {-1e308, 0, 0}, wide_high[3] = {1e308, 1, 1};
  EXPECT_EQ(lantern_set_box(ctx.get(), wide_low, wide_high, nullptr), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(lantern_error_message(ctx.get())).find("high[0] - low[0] overflows"),
            std::string::npos)
      << lantern_error_message(ctx.get());
  EXPECT_EQ(lantern_set_box(ctx.get(), nullptr, high, nullptr), LANTERN_ERR_NULL_ARGUMENT);
  EXPECT_EQ(lantern_set_box(nullptr, low, high, nullptr), LANTERN_ERR_NULL_ARGUMENT);
}

TEST(SetBox, TriclinicRejectsNonFiniteTiltAndNull) {
  const MpiScratchDir dir;
  const Context ctx = open_dump(dir.file("tilt.h5"), "");
  const double low[3] = {0, 0, 0}, high[3] = {1, 2, 3}, nan_tilt[3] = {0, NAN, 0};
  EXPECT_EQ(lantern_set_triclinic_box(ctx.get(), low, high, nan_tilt, nullptr),
            LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(lantern_error_message(ctx.get())).find("tilt[1] (xz) is not finite"),
            std::string::npos)
      << lantern_error_message(ctx.get());
  EXPECT_EQ(lantern_set_triclinic_box(ctx.get(), low, high, nullptr, nullptr),
            LANTERN_ERR_NULL_ARGUMENT);
  EXPECT_NE(std::string(lantern_error_message(ctx.get())).find("tilt: NULL"), std::string::npos);
}

// A triclinic box: H5MD's edges are the matrix of edge vectors (rows a, b, c), and reading the
// file back gives the box, its tilt and its corner. A box that starts at zero tilt (a LAMMPS box
// before `fix deform` shears it) keeps that layout; a file made for an orthogonal box refuses a
// tilt, naming the way out, and takes the next orthogonal step.
TEST(DumpRoundTrip, TriclinicBoxIsTheEdgeVectorMatrix) {
  const MpiScratchDir dir;
  const std::string file = dir.file("triclinic.h5");
  const double low[3] = {-1, -2, -3}, high[3] = {9, 6, 2}, zero[3] = {0, 0, 0},
               tilt[3] = {2.5, -1.25, 0.5};
  const int periodic[3] = {1, 1, 1};
  {
    const Context ctx = open_dump(file, "");
    for (const int64_t step : {0, 1}) {
      const RankParticles p(step);
      const lantern_particles v = p.view();
      ASSERT_EQ(lantern_publish(ctx.get(), &v), LANTERN_OK);
      ASSERT_EQ(lantern_set_triclinic_box(ctx.get(), low, high, step == 0 ? zero : tilt, periodic),
                LANTERN_OK);
      ASSERT_EQ(lantern_execute(ctx.get(), step, 0.0), LANTERN_OK)
          << lantern_error_message(ctx.get());
    }
  }
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  ASSERT_EQ(reader->frames().size(), 2u);
  for (size_t f = 0; f < 2; ++f) {
    ParticleFrame frame;
    ASSERT_OK(reader->read(f, 0, 0, &frame));
    ASSERT_TRUE(frame.box.has_value());
    EXPECT_TRUE(frame.box->triclinic);
    EXPECT_EQ(frame.box->low, (std::array<double, 3>{-1, -2, -3}));
    EXPECT_EQ(frame.box->high, (std::array<double, 3>{9, 6, 2}));
    const std::array<double, 3> want_tilt =
        f == 0 ? std::array<double, 3>{0, 0, 0} : std::array<double, 3>{2.5, -1.25, 0.5};
    EXPECT_EQ(frame.box->tilt, want_tilt);
  }
  reader.reset();
  MPI_Barrier(MPI_COMM_WORLD);
  // The matrix itself, as any H5MD reader sees it: rows a = (10, 0, 0), b = (xy, 8, 0),
  // c = (xz, yz, 5).
  if (world_rank() == 0) {
    const hid_t h5 = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    const hid_t edges = H5Dopen2(h5, "/particles/all/box/edges/value", H5P_DEFAULT);
    double m[2][3][3];
    ASSERT_GE(H5Dread(edges, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, m), 0);
    const double want[3][3] = {{10, 0, 0}, {2.5, 8, 0}, {-1.25, 0.5, 5}};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(m[1][r][c], want[r][c]) << r << ", " << c;
    H5Dclose(edges);
    H5Fclose(h5);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  // An orthogonal box's file cannot take a tilt.
  const std::string plain = dir.file("orthogonal.h5");
  const Context ctx = open_dump(plain, "");
  const RankParticles p(0);
  const lantern_particles v = p.view();
  ASSERT_EQ(lantern_publish(ctx.get(), &v), LANTERN_OK);
  ASSERT_EQ(lantern_set_box(ctx.get(), low, high, periodic), LANTERN_OK);
  ASSERT_EQ(lantern_execute(ctx.get(), 0, 0.0), LANTERN_OK) << lantern_error_message(ctx.get());
  ASSERT_EQ(lantern_set_triclinic_box(ctx.get(), low, high, tilt, periodic), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx.get(), 1, 0.0), LANTERN_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(lantern_error_message(ctx.get())).find("lantern_set_triclinic_box"),
            std::string::npos)
      << lantern_error_message(ctx.get());
  ASSERT_EQ(lantern_set_box(ctx.get(), low, high, periodic), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx.get(), 2, 0.0), LANTERN_OK) << lantern_error_message(ctx.get());
}

}  // namespace
}  // namespace lantern
