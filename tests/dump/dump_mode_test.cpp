// dump.mode (create | append | overwrite) at 1 and 2 ranks: an existing file at dump.file is
// never truncated without a word (a text file, a link's target, or a previous run's dump of 3
// frames that became 1 after a restart); append continues a compatible H5MD file, refusing an
// incompatible one by the key at fault and cutting back a frame a killed run left part-way.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/dump/h5md_reader.h"
#include "h5md_series_frames.h"
#include "lantern/lantern.h"
#include "mpi_scratch_dir.h"
#include "tests/support/mpi_world.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::world_rank;
using testing::world_size;

struct ContextCloser {
  void operator()(lantern_context *c) const { lantern_close(c); }
};
using Context = std::unique_ptr<lantern_context, ContextCloser>;

// 20 + 3 * rank particles per rank with global ids; positions follow (id, step).
struct Particles {
  std::vector<double> xyz;
  std::vector<int64_t> id;
  std::vector<float> xyz32;
  explicit Particles(int64_t step) {
    int64_t first = 0;
    for (int r = 0; r < world_rank(); ++r) first += 20 + 3 * r;
    for (int64_t i = 0; i < 20 + 3 * world_rank(); ++i) {
      const int64_t g = first + i;
      xyz.insert(xyz.end(), {double(g), 0.5 * double(step), 1.0});
      id.push_back(g);
    }
  }
  lantern_particles view(bool with_id = true) const {
    lantern_particles p{};
    p.count = int64_t(id.size());
    p.position = {xyz.data(), LANTERN_FLOAT64, 0};
    if (with_id) p.id = {id.data(), LANTERN_INT64, 0};
    return p;
  }
};

lantern_status open_dump(const std::string &file, const std::string &extra, Context *ctx) {
  const std::string yaml = "dump:\n  file: '" + file + "'\n" + extra;
  lantern_context *raw = nullptr;
  const lantern_status st = lantern_open(yaml.c_str(), MPI_Comm_c2f(MPI_COMM_WORLD), &raw);
  ctx->reset(raw);
  return st;
}

// Opens `file` with `extra` dump keys and dumps `steps` (OK expected for each).
void run(const std::string &file, const std::string &extra, const std::vector<int64_t> &steps) {
  Context ctx;
  ASSERT_EQ(open_dump(file, extra, &ctx), LANTERN_OK) << lantern_error_message(ctx.get());
  for (const int64_t s : steps) {
    const Particles p(s);
    const lantern_particles v = p.view();
    ASSERT_EQ(lantern_publish(ctx.get(), &v), LANTERN_OK);
    ASSERT_EQ(lantern_execute(ctx.get(), s, double(s)), LANTERN_OK)
        << lantern_error_message(ctx.get());
  }
}

std::vector<int64_t> steps_in(const std::string &file) {
  std::unique_ptr<H5mdReader> reader;
  EXPECT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  std::vector<int64_t> steps;
  if (reader)
    for (const FrameInfo &f : reader->frames()) steps.push_back(f.step);
  return steps;
}

std::string text_of(const std::string &path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Rank 0 writes `text` to `path`; every rank waits for it.
void write_text(const std::string &path, const std::string &text) {
  if (world_rank() == 0) std::ofstream(path) << text;
  MPI_Barrier(MPI_COMM_WORLD);
}

class DumpMode : public ::testing::Test {
 protected:
  std::string file(const std::string &name) const { return scratch_.file(name); }
  MpiScratchDir scratch_;
};

TEST_F(DumpMode, CreateIsTheDefaultAndRefusesAnExistingFileNamingTheKey) {
  const std::string notes = file("notes.txt"), link = file("link.h5"), previous = file("run.h5");
  write_text(notes, "a text file\n");
  if (world_rank() == 0) std::filesystem::create_symlink(notes, link);
  MPI_Barrier(MPI_COMM_WORLD);
  run(previous, "", {0, 1, 2});
  for (const std::string &path : {notes, link, previous}) {
    Context ctx;
    EXPECT_EQ(open_dump(path, "", &ctx), LANTERN_ERR_CONFIG) << path;
    const std::string m = lantern_error_message(ctx.get());
    EXPECT_NE(m.find("dump.file: '" + path + "' exists, and dump.mode: create (the default)"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("mode: append"), std::string::npos) << m;
  }
  EXPECT_EQ(text_of(notes), "a text file\n");  // the link's target too
  EXPECT_EQ(steps_in(previous), (std::vector<int64_t>{0, 1, 2}));
}

TEST_F(DumpMode, OverwriteReplacesTheFile) {
  const std::string path = file("old.h5");
  write_text(path, "not even HDF5\n");
  run(path, "  mode: overwrite\n", {7});
  EXPECT_EQ(steps_in(path), (std::vector<int64_t>{7}));
}

TEST_F(DumpMode, AppendContinuesTheTimeSeriesOfARestartedRun) {
  const std::string path = file("run.h5");
  run(path, "  mode: append\n", {0, 1, 2});  // no file yet: created
  run(path, "  mode: append\n", {3, 4});     // the restart carries on
  EXPECT_EQ(steps_in(path), (std::vector<int64_t>{0, 1, 2, 3, 4}));
  // A restart from an earlier checkpoint: a step the file holds is refused, later ones appended.
  {
    Context ctx;
    ASSERT_EQ(open_dump(path, "  mode: append\n", &ctx), LANTERN_OK)
        << lantern_error_message(ctx.get());
    for (const int64_t s : {4, 5}) {
      const Particles p(s);
      const lantern_particles v = p.view();
      ASSERT_EQ(lantern_publish(ctx.get(), &v), LANTERN_OK);
      const lantern_status st = lantern_execute(ctx.get(), s, double(s));
      if (s == 4) {
        EXPECT_EQ(st, LANTERN_ERR_INVALID_ARGUMENT);
        EXPECT_NE(
            std::string(lantern_error_message(ctx.get())).find("already holds frames up to step 4"),
            std::string::npos)
            << lantern_error_message(ctx.get());
      } else {
        EXPECT_EQ(st, LANTERN_OK) << lantern_error_message(ctx.get());
      }
    }
  }
  EXPECT_EQ(steps_in(path), (std::vector<int64_t>{0, 1, 2, 3, 4, 5}));
  if (world_rank() == 0) EXPECT_EQ(testing::time_series_mismatch(path, 6), "");
  // Every frame's positions are the run's own (x = id, y = step / 2).
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(path, MPI_COMM_WORLD, &reader));
  ParticleFrame frame;
  ASSERT_OK(reader->read(4, 0, reader->frames()[4].count, &frame));
  for (int64_t i = 0; i < frame.count(); ++i) EXPECT_EQ(frame.position[3 * i + 1], 2.0);
}

TEST_F(DumpMode, AppendRefusesAFileItCannotContinueNamingTheKey) {
  const std::string text = file("notes.txt"), run64 = file("run64.h5");
  write_text(text, "notes\n");
  run(run64, "", {0});
  const struct {
    std::string path, extra, expected;
  } cases[] = {
      {text, "  mode: append\n", "(dump.mode: append) is not an HDF5 file"},
      {run64, "  mode: append\n  precision: float32\n",
       "dump.precision: float32, but '" + run64 + "' (dump.mode: append) holds float64"},
      {run64, "  mode: append\n  fields: [position]\n",
       "dump.fields: the run writes [position], but '" + run64 +
           "' (dump.mode: append) holds [position, id]"},
  };
  for (const auto &c : cases) {
    Context ctx;
    EXPECT_EQ(open_dump(c.path, c.extra, &ctx), LANTERN_ERR_CONFIG) << c.extra;
    EXPECT_NE(std::string(lantern_error_message(ctx.get())).find(c.expected), std::string::npos)
        << lantern_error_message(ctx.get());
  }
  // Fields chosen from what is published (no list): checked at the first dump.
  Context ctx;
  ASSERT_EQ(open_dump(run64, "  mode: append\n", &ctx), LANTERN_OK);
  const Particles p(1);
  const lantern_particles v = p.view(/*with_id=*/false);
  ASSERT_EQ(lantern_publish(ctx.get(), &v), LANTERN_OK);
  EXPECT_EQ(lantern_execute(ctx.get(), 1, 1.0), LANTERN_ERR_CONFIG);
  EXPECT_NE(std::string(lantern_error_message(ctx.get()))
                .find("dump.fields: the run writes [position], but"),
            std::string::npos)
      << lantern_error_message(ctx.get());
  ctx.reset();
  EXPECT_EQ(text_of(text), "notes\n");
  EXPECT_EQ(steps_in(run64), (std::vector<int64_t>{0}));
}

// A run killed in the middle of a frame leaves position/value one frame longer than its step:
// append cuts it back before continuing.
TEST_F(DumpMode, AppendCutsBackAFrameLeftPartWay) {
  const std::string path = file("killed.h5");
  run(path, "", {0, 1});
  if (world_rank() == 0) {
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const hid_t d = H5Dopen2(f, "/particles/all/position/value", H5P_DEFAULT);
    const hid_t space = H5Dget_space(d);
    hsize_t dims[3];
    H5Sget_simple_extent_dims(space, dims, nullptr);
    dims[0] += 1;
    EXPECT_GE(H5Dset_extent(d, dims), 0);
    H5Sclose(space);
    H5Dclose(d);
    H5Fclose(f);
    EXPECT_NE(testing::time_series_mismatch(path, 2), "");
  }
  MPI_Barrier(MPI_COMM_WORLD);
  run(path, "  mode: append\n", {2});
  EXPECT_EQ(steps_in(path), (std::vector<int64_t>{0, 1, 2}));
  if (world_rank() == 0) EXPECT_EQ(testing::time_series_mismatch(path, 3), "");
}

}  // namespace
}  // namespace lantern
