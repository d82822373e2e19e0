// Bonds in H5MD dumps: written in situ through the C API (each rank's bonds as local indices
// with ghost particles, listed once or by both atoms' ranks), read back by H5mdReader as pairs of
// particle ids: every bond exactly once over all ranks, at any rank count. Then bad bond lists
// in a file (edited with serial HDF5): a clear error naming the dataset and the pair.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <algorithm>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "bond_topology.h"
#include "core/common/injected_fault.h"
#include "core/dump/h5md_reader.h"
#include "lantern/lantern.h"
#include "mpi_scratch_dir.h"
#include "tests/support/mpi_world.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

using testing::world_rank;
using testing::world_size;
using Pairs = std::set<std::pair<int64_t, int64_t>>;

struct ContextCloser {
  void operator()(lantern_context *c) const { lantern_close(c); }
};
using Context = std::unique_ptr<lantern_context, ContextCloser>;

Context open_config(const std::string &yaml) {
  lantern_context *raw = nullptr;
  const lantern_status st = lantern_open(yaml.c_str(), MPI_Comm_c2f(MPI_COMM_WORLD), &raw);
  Context ctx(raw);
  EXPECT_EQ(st, LANTERN_OK) << lantern_error_message(ctx.get());
  return ctx;
}

// Rank r owns the particles with ids [first, first + count): 40 + 7 r of them. The bonds: a chain
// through every id (g, g + 1), across the ranks' boundaries, and a cross-link (g, g + 13) for
// every g divisible by 10.
int64_t count_of(int r) {
  return 40 + 7 * r;
}
int64_t total_particles() {
  int64_t total = 0;
  for (int r = 0; r < world_size(); ++r) total += count_of(r);
  return total;
}
Pairs all_bonds(int64_t total) {
  Pairs out;
  for (int64_t g = 0; g + 1 < total; ++g) out.insert({g, g + 1});
  for (int64_t g = 0; g + 13 < total; g += 10) out.insert({g, g + 13});
  return out;
}

// One rank's publication: owned particles, then the ghosts its bonds need.
struct RankBonds {
  std::vector<double> xyz;
  std::vector<int64_t> id, first, second;
  int64_t count = 0, ghosts = 0;
  lantern_bond_listing listing;

  explicit RankBonds(lantern_bond_listing how) : listing(how) {
    int64_t begin = 0;
    for (int r = 0; r < world_rank(); ++r) begin += count_of(r);
    count = count_of(world_rank());
    const int64_t end = begin + count;
    for (int64_t g = begin; g < end; ++g) add(g);
    std::vector<int64_t> ghost_ids;
    const auto index_of = [&](int64_t g) {
      if (g >= begin && g < end) return g - begin;
      const auto at = std::find(ghost_ids.begin(), ghost_ids.end(), g);
      if (at != ghost_ids.end()) return count + (at - ghost_ids.begin());
      ghost_ids.push_back(g);
      add(g);
      return count + int64_t(ghost_ids.size()) - 1;
    };
    for (const auto &[a, b] : all_bonds(total_particles())) {
      const bool owns_a = a >= begin && a < end, owns_b = b >= begin && b < end;
      // Listed once: by the rank of the first atom. By both: by each rank owning an atom, the
      // bond's own atom first.
      const bool listed = how == LANTERN_BONDS_LISTED_ONCE ? owns_a : owns_a || owns_b;
      if (!listed) continue;
      const bool flip = how == LANTERN_BONDS_LISTED_BY_BOTH && !owns_a;
      first.push_back(index_of(flip ? b : a));
      second.push_back(index_of(flip ? a : b));
    }
    ghosts = int64_t(ghost_ids.size());
  }
  void add(int64_t g) {
    xyz.insert(xyz.end(), {0.3 * double(g % 17), 0.5 * double(g / 17), 0.1 * double(g % 5)});
    id.push_back(g);
  }
  void publish(lantern_context *ctx) const {
    lantern_particles p{};
    p.count = count;
    p.position = {xyz.data(), LANTERN_FLOAT64, 0};
    p.id = {id.data(), LANTERN_INT64, 0};
    ASSERT_EQ(lantern_publish(ctx, &p), LANTERN_OK) << lantern_error_message(ctx);
    lantern_bonds b{};
    b.count = int64_t(first.size());
    b.first = {first.data(), LANTERN_INT64, 0};
    b.second = {second.data(), LANTERN_INT64, 0};
    b.ghost_count = ghosts;
    b.listing = listing;
    ASSERT_EQ(lantern_publish_bonds(ctx, &b), LANTERN_OK) << lantern_error_message(ctx);
  }
};

// The bonds of frame f as a set of (smaller id, larger id); a pair written twice fails the test.
Pairs read_pairs(const H5mdReader &reader, size_t f) {
  std::vector<int64_t> a, b;
  EXPECT_OK(reader.read_bonds(f, &a, &b));
  Pairs out;
  for (size_t k = 0; k < a.size(); ++k)
    EXPECT_TRUE(out.insert(std::minmax(a[k], b[k])).second)
        << "bond " << a[k] << "-" << b[k] << " written twice";
  return out;
}

void write_and_check(lantern_bond_listing listing) {
  MpiScratchDir dir;
  const std::string file = dir.file("bonds.h5");
  {
    Context ctx = open_config("dump:\n  file: " + file + "\n");
    const RankBonds rank(listing);
    for (const int64_t step : {0, 5}) {
      rank.publish(ctx.get());
      ASSERT_EQ(lantern_execute(ctx.get(), step, 0.1 * double(step)), LANTERN_OK)
          << lantern_error_message(ctx.get());
    }
  }
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  ASSERT_TRUE(reader->has_bonds());
  ASSERT_EQ(reader->frames().size(), 2u);
  const Pairs expected = all_bonds(total_particles());
  for (size_t f = 0; f < 2; ++f) EXPECT_EQ(read_pairs(*reader, f), expected) << "frame " << f;
  EXPECT_EQ(reader->bonds_dataset(1), file + ": /connectivity/all_bonds/value[1]");
}

TEST(DumpBonds, ListedOnceWritesEveryBondOnce) {
  write_and_check(LANTERN_BONDS_LISTED_ONCE);
}

TEST(DumpBonds, ListedByBothWritesEveryBondOnce) {
  write_and_check(LANTERN_BONDS_LISTED_BY_BOTH);
}

// A run whose bonds change (formed, broken): each frame records its own list; a frame with fewer
// bonds than an earlier one fills the rest with H5MD's "no bond" pairs, which read back as none.
TEST(DumpBonds, EachFrameRecordsItsOwnBonds) {
  MpiScratchDir dir;
  const std::string file = dir.file("changing.h5");
  {
    Context ctx = open_config("dump:\n  file: " + file + "\n");
    RankBonds rank(LANTERN_BONDS_LISTED_ONCE);
    rank.publish(ctx.get());
    ASSERT_EQ(lantern_execute(ctx.get(), 0, 0.0), LANTERN_OK);
    if (world_rank() == 0) {  // rank 0 breaks its first 5 bonds
      rank.first.erase(rank.first.begin(), rank.first.begin() + 5);
      rank.second.erase(rank.second.begin(), rank.second.begin() + 5);
    }
    rank.publish(ctx.get());
    ASSERT_EQ(lantern_execute(ctx.get(), 1, 1.0), LANTERN_OK);
  }
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  Pairs expected = all_bonds(total_particles());
  EXPECT_EQ(read_pairs(*reader, 0), expected);
  // Rank 0 lists its bonds in order: (0, 1), (0, 13), (1, 2), (2, 3), (3, 4) are the five broken.
  for (const auto &broken : Pairs{{0, 1}, {0, 13}, {1, 2}, {2, 3}, {3, 4}}) expected.erase(broken);
  EXPECT_EQ(read_pairs(*reader, 1), expected);
}

// Without bonds the file has no /connectivity (and is the file it always was).
TEST(DumpBonds, NoBondsNoConnectivity) {
  MpiScratchDir dir;
  const std::string file = dir.file("plain.h5");
  {
    Context ctx = open_config("dump:\n  file: " + file + "\n");
    RankBonds rank(LANTERN_BONDS_LISTED_ONCE);
    lantern_particles p{};
    p.count = rank.count;
    p.position = {rank.xyz.data(), LANTERN_FLOAT64, 0};
    p.id = {rank.id.data(), LANTERN_INT64, 0};
    ASSERT_EQ(lantern_publish(ctx.get(), &p), LANTERN_OK);
    ASSERT_EQ(lantern_execute(ctx.get(), 0, 0.0), LANTERN_OK);
  }
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  EXPECT_FALSE(reader->has_bonds());
  if (world_rank() == 0) {
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    EXPECT_EQ(H5Lexists(f, "/connectivity", H5P_DEFAULT), 0);
    H5Fclose(f);
  }
}

// dump.mode: append continues the bond list of a restarted run.
TEST(DumpBonds, AppendContinuesTheBondList) {
  MpiScratchDir dir;
  const std::string file = dir.file("restart.h5");
  const RankBonds rank(LANTERN_BONDS_LISTED_BY_BOTH);
  for (const int64_t step : {0, 10}) {
    Context ctx = open_config("dump:\n  file: " + file + "\n  mode: append\n");
    rank.publish(ctx.get());
    ASSERT_EQ(lantern_execute(ctx.get(), step, 0.0), LANTERN_OK)
        << lantern_error_message(ctx.get());
  }
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  ASSERT_EQ(reader->frames().size(), 2u);
  for (size_t f = 0; f < 2; ++f) EXPECT_EQ(read_pairs(*reader, f), all_bonds(total_particles()));
}

// A frame that fails while its bonds are written (on one rank of several): every rank returns
// the error, the dump stops, and the file keeps the earlier frame with its bonds, readable.
TEST(DumpBonds, AFailedBondWriteLeavesAValidFile) {
  MpiScratchDir dir;
  const std::string file = dir.file("failed.h5");
  const RankBonds rank(LANTERN_BONDS_LISTED_ONCE);
  {
    Context ctx = open_config("dump:\n  file: " + file + "\n");
    rank.publish(ctx.get());
    ASSERT_EQ(lantern_execute(ctx.get(), 0, 0.0), LANTERN_OK) << lantern_error_message(ctx.get());
    if (world_rank() == world_size() - 1) inject_fault("all_bonds/value: write");
    EXPECT_EQ(lantern_execute(ctx.get(), 1, 1.0), LANTERN_ERR_IO);
    const std::string message = lantern_error_message(ctx.get());
    EXPECT_NE(message.find("all_bonds/value: write"), std::string::npos) << message;
    EXPECT_NE(message.find("keeps its 1 earlier frame"), std::string::npos) << message;
  }
  inject_fault("");
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file, MPI_COMM_WORLD, &reader));
  ASSERT_EQ(reader->frames().size(), 1u);
  EXPECT_EQ(read_pairs(*reader, 0), all_bonds(total_particles()));
  if (world_rank() == 0) {  // cut back to the complete frame
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    for (const char *name : {"/connectivity/all_bonds/value", "/connectivity/all_bonds/step"}) {
      const hid_t set = H5Dopen2(f, name, H5P_DEFAULT);
      const hid_t space = H5Dget_space(set);
      hsize_t dims[3] = {0, 0, 0};
      H5Sget_simple_extent_dims(space, dims, nullptr);
      EXPECT_EQ(dims[0], 1u) << name;
      H5Sclose(space);
      H5Dclose(set);
    }
    H5Fclose(f);
  }
}

// --- Bad bond lists (one rank; the file edited with serial HDF5 after the dump) ---

class H5mdBondsBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    file_ = dir_.file("bad.h5");
    Context ctx = open_config("dump:\n  file: " + file_ + "\n");
    const RankBonds rank(LANTERN_BONDS_LISTED_ONCE);
    rank.publish(ctx.get());
    ASSERT_EQ(lantern_execute(ctx.get(), 0, 0.0), LANTERN_OK);
  }
  // Opens the file for editing; closed by the returned guard's destructor.
  struct File {
    hid_t id;
    ~File() { H5Fclose(id); }
  };
  File edit() const { return {H5Fopen(file_.c_str(), H5F_ACC_RDWR, H5P_DEFAULT)}; }
  std::string error() const {
    std::unique_ptr<H5mdReader> reader;
    const Status opened = H5mdReader::open(file_, MPI_COMM_WORLD, &reader);
    EXPECT_OK(opened) << "a bad bond list must not stop the particles from being read";
    if (!opened.ok()) return opened.message;
    EXPECT_TRUE(reader->has_bonds());
    std::vector<int64_t> a, b;
    const Status s = reader->read_bonds(0, &a, &b);
    EXPECT_FALSE(s.ok());
    return s.message;
  }
  void write_pair(int64_t k, int64_t a, int64_t b) const {
    const File f = edit();
    const hid_t value = H5Dopen2(f.id, "/connectivity/all_bonds/value", H5P_DEFAULT);
    const hid_t space = H5Dget_space(value);
    const hsize_t start[3] = {0, hsize_t(k), 0}, count[3] = {1, 1, 2};
    H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, count, nullptr);
    const hsize_t two = 2;
    const hid_t memory = H5Screate_simple(1, &two, nullptr);
    const int64_t pair[2] = {a, b};
    EXPECT_GE(H5Dwrite(value, H5T_NATIVE_INT64, memory, space, H5P_DEFAULT, pair), 0);
    H5Sclose(memory);
    H5Sclose(space);
    H5Dclose(value);
  }
  // Replaces the bond list by a fixed dataset of `type` and shape `dims`, referring to `target`.
  void replace_list(hid_t type, std::vector<hsize_t> dims, const char *target) const {
    const File f = edit();
    H5Ldelete(f.id, "/connectivity/all_bonds", H5P_DEFAULT);
    const hid_t space = H5Screate_simple(int(dims.size()), dims.data(), nullptr);
    const hid_t set = H5Dcreate2(f.id, "/connectivity/all_bonds", type, space, H5P_DEFAULT,
                                 H5P_DEFAULT, H5P_DEFAULT);
    hobj_ref_t ref{};
    H5Rcreate(&ref, f.id, target, H5R_OBJECT, -1);
    const hid_t scalar = H5Screate(H5S_SCALAR);
    const hid_t attr =
        H5Acreate2(set, "particles_group", H5T_STD_REF_OBJ, scalar, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(attr, H5T_STD_REF_OBJ, &ref);
    H5Aclose(attr);
    H5Sclose(scalar);
    H5Dclose(set);
    H5Sclose(space);
  }

  MpiScratchDir dir_;
  std::string file_;
};

TEST_F(H5mdBondsBadInput, NegativeIdNamesTheDatasetAndPair) {
  write_pair(3, 7, -4);
  EXPECT_EQ(error(), file_ + ": /connectivity/all_bonds/value[0][3]: negative particle id -4");
}

TEST_F(H5mdBondsBadInput, BondToItselfNamesThePair) {
  write_pair(2, 9, 9);
  EXPECT_EQ(error(), file_ +
                         ": /connectivity/all_bonds/value[0][2]: a bond from particle 9 to "
                         "itself");
}

TEST_F(H5mdBondsBadInput, IdNotInTheFrameNamesThePair) {
  write_pair(4, 5, 100000);
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file_, MPI_COMM_WORLD, &reader));
  BondTopology topology;
  ASSERT_OK(reader->read_bonds(0, &topology.first_id, &topology.second_id, &topology.pair));
  topology.type.assign(topology.first_id.size(), 0);
  topology.origin = reader->bonds_dataset(0);
  ParticleFrame all;
  ASSERT_OK(reader->read(0, 0, reader->frames()[0].count, &all));
  std::vector<int64_t> rows(size_t(all.count()));
  for (size_t r = 0; r < rows.size(); ++r) rows[r] = int64_t(r);
  BondedShare share;
  EXPECT_EQ(
      share_with_bonds(all, rows, topology, &share),
      file_ + ": /connectivity/all_bonds/value[0][4]: particle id 100000 is not in the frame");
}

TEST_F(H5mdBondsBadInput, DanglingReferenceIsNamed) {
  {
    const File f = edit();
    H5Gclose(H5Gcreate2(f.id, "/gone", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  }
  replace_list(H5T_STD_I64LE, {4, 2}, "/gone");
  {
    const File f = edit();
    H5Ldelete(f.id, "/gone", H5P_DEFAULT);
  }
  EXPECT_EQ(error(), file_ +
                         ": /connectivity/all_bonds: particles_group: a dangling object "
                         "reference");
}

TEST_F(H5mdBondsBadInput, WrongShapeIsNamed) {
  replace_list(H5T_STD_I64LE, {6}, "/particles/all");
  EXPECT_EQ(error(), file_ +
                         ": /connectivity/all_bonds has shape [6], expected [bonds][2] (pairs "
                         "of particle ids)");
}

TEST_F(H5mdBondsBadInput, RealTypeIsNamed) {
  replace_list(H5T_IEEE_F64LE, {5, 2}, "/particles/all");
  EXPECT_EQ(error(), file_ + ": /connectivity/all_bonds is not of an integer type (particle ids)");
}

TEST_F(H5mdBondsBadInput, FixedListIsRead) {  // a time-independent [B][2] list (H5MD allows it)
  replace_list(H5T_STD_I32LE, {2, 2}, "/particles/all");
  {
    const File f = edit();
    const hid_t set = H5Dopen2(f.id, "/connectivity/all_bonds", H5P_DEFAULT);
    const int32_t pairs[4] = {1, 2, 3, 7};
    H5Dwrite(set, H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, pairs);
    H5Dclose(set);
  }
  std::unique_ptr<H5mdReader> reader;
  ASSERT_OK(H5mdReader::open(file_, MPI_COMM_WORLD, &reader));
  EXPECT_EQ(read_pairs(*reader, 0), (Pairs{{1, 2}, {3, 7}}));
}

}  // namespace
}  // namespace lantern
