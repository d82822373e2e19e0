// Every kind of bad input gives a clear message naming the file and what is wrong (and the line
// for text dumps), never a crash: truncated and non-H5MD files, missing datasets, mismatched
// shapes, malformed LAMMPS dumps. Also the good paths of the LAMMPS reader (scaled, triclinic).
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <fstream>
#include <memory>
#include <string>

#include "core/dump/h5md_reader.h"
#include "core/dump/hdf5_handle.h"
#include "core/dump/lammps_dump_reader.h"
#include "mpi_scratch_dir.h"
#include "tests/support/status_expect.h"

namespace lantern {
namespace {

void write_text(const std::string &path, const std::string &text) {
  std::ofstream(path, std::ios::binary) << text;
}

// The message of a failed open or read ("" when the file reads): a bad file is always kIo.
std::string io_error(const Status &s) {
  if (!s.ok()) EXPECT_EQ(s.code, StatusCode::kIo) << s.message;
  return s.message;
}

std::string h5md_error(const std::string &path) {
  std::unique_ptr<H5mdReader> reader;
  return io_error(H5mdReader::open(path, MPI_COMM_SELF, &reader));
}

std::string lammps_error(const std::string &path) {
  std::unique_ptr<LammpsDumpReader> reader;
  if (Status s = LammpsDumpReader::open(path, &reader); !s.ok()) return io_error(s);
  for (size_t f = 0; f < reader->frames().size(); ++f) {
    ParticleFrame frame;
    if (Status s = reader->read(f, 0, reader->frames()[f].count, &frame); !s.ok())
      return io_error(s);
  }
  return {};
}

#define EXPECT_HAS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

// A tiny HDF5 file built by hand: groups and datasets of given shapes.
class Hdf5Builder {
 public:
  explicit Hdf5Builder(const std::string &path)
      : file_(own_file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), path)) {}
  void group(const std::string &name) {
    own_group(H5Gcreate2(file_.get(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), name);
  }
  void dataset(const std::string &name, std::vector<hsize_t> dims, hid_t type = H5T_NATIVE_DOUBLE) {
    const H5Handle space =
        own_space(H5Screate_simple(int(dims.size()), dims.data(), nullptr), name);
    const H5Handle d = own_dataset(H5Dcreate2(file_.get(), name.c_str(), type, space.get(),
                                              H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                                   name);
    hsize_t n = 1;
    for (hsize_t x : dims) n *= x;
    std::vector<double> zeros(n, 0.0);
    H5Dwrite(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, zeros.data());
  }
  void h5md() {
    group("/h5md");
    const hsize_t two = 2;
    const H5Handle space = own_space(H5Screate_simple(1, &two, nullptr), "v");
    const H5Handle a = own_attr(
        H5Acreate2(file_.get(), "version", H5T_STD_I32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
        "version");
    (void)a;
    const H5Handle g = own_group(H5Gopen2(file_.get(), "/h5md", H5P_DEFAULT), "/h5md");
    const H5Handle b = own_attr(
        H5Acreate2(g.get(), "version", H5T_STD_I32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
        "version");
    const int v[2] = {1, 1};
    H5Awrite(b.get(), H5T_NATIVE_INT, v);
  }
  // /particles/all/position with `frames` frames of n particles.
  void particles(hsize_t frames, hsize_t n, hsize_t step_len) {
    group("/particles");
    group("/particles/all");
    group("/particles/all/position");
    dataset("/particles/all/position/value", {frames, n, 3});
    dataset("/particles/all/position/step", {step_len}, H5T_STD_I64LE);
  }

 private:
  H5Handle file_;
};

TEST(H5mdBadInput, MissingFile) {
  EXPECT_HAS(h5md_error("/nonexistent/x.h5"), "/nonexistent/x.h5: cannot open the file");
}

TEST(H5mdBadInput, NotHdf5) {
  const MpiScratchDir dir;
  write_text(dir.file("text.h5"), "hello, not hdf5\n");
  EXPECT_HAS(h5md_error(dir.file("text.h5")), "text.h5: not an HDF5 file");
}

TEST(H5mdBadInput, TruncatedFile) {
  const MpiScratchDir dir;
  {
    Hdf5Builder b(dir.file("full.h5"));
    b.h5md();
    b.particles(2, 1000, 2);
  }
  std::ifstream in(dir.file("full.h5"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  write_text(dir.file("cut.h5"), bytes.substr(0, bytes.size() / 2));
  const std::string e = h5md_error(dir.file("cut.h5"));
  EXPECT_HAS(e, "cut.h5: cannot open as HDF5");
  EXPECT_HAS(e, "truncated");
}

TEST(H5mdBadInput, HdfButNotH5md) {
  const MpiScratchDir dir;
  {
    Hdf5Builder b(dir.file("plain.h5"));
    b.group("/data");
  }
  EXPECT_HAS(h5md_error(dir.file("plain.h5")), "plain.h5: not an H5MD file: no /h5md group");
}

TEST(H5mdBadInput, MissingPositionDataset) {
  const MpiScratchDir dir;
  {
    Hdf5Builder b(dir.file("nopos.h5"));
    b.h5md();
    b.group("/particles");
    b.group("/particles/all");
  }
  EXPECT_HAS(h5md_error(dir.file("nopos.h5")), "missing dataset /particles/all/position/value");
}

TEST(H5mdBadInput, PositionNotThreeComponents) {
  const MpiScratchDir dir;
  {
    Hdf5Builder b(dir.file("shape.h5"));
    b.h5md();
    b.group("/particles");
    b.group("/particles/all");
    b.group("/particles/all/position");
    b.dataset("/particles/all/position/value", {2, 10, 2});
  }
  EXPECT_HAS(h5md_error(dir.file("shape.h5")), "has shape [2][10][2], expected [frames][N][3]");
}

TEST(H5mdBadInput, StepLengthMismatch) {
  const MpiScratchDir dir;
  {
    Hdf5Builder b(dir.file("steps.h5"));
    b.h5md();
    b.particles(3, 10, 2);
  }
  EXPECT_HAS(h5md_error(dir.file("steps.h5")), "position/step has shape [2] but");
}

TEST(H5mdBadInput, SpeciesShapeMismatch) {
  const MpiScratchDir dir;
  {
    Hdf5Builder b(dir.file("species.h5"));
    b.h5md();
    b.particles(2, 10, 2);
    b.group("/particles/all/species");
    b.dataset("/particles/all/species/value", {2, 11}, H5T_STD_I32LE);
  }
  EXPECT_HAS(h5md_error(dir.file("species.h5")), "species/value has shape [2][11]");
}

const char *kHeader =
    "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp ff\n0 10\n0 20\n0 "
    "30\n";

TEST(LammpsBadInput, NotADump) {
  const MpiScratchDir dir;
  write_text(dir.file("x.txt"), "\n# a comment\n");
  EXPECT_HAS(lammps_error(dir.file("x.txt")), "x.txt:2: expected 'ITEM: TIMESTEP'");
}

TEST(LammpsBadInput, MissingPositionColumn) {
  const MpiScratchDir dir;
  write_text(dir.file("d"), std::string(kHeader) + "ITEM: ATOMS id type x y\n1 1 0 0\n2 1 1 1\n");
  const std::string e = lammps_error(dir.file("d"));
  EXPECT_HAS(e, "d:9: ITEM: ATOMS has no complete set of position columns");
  EXPECT_HAS(e, "'z' is missing");
}

TEST(LammpsBadInput, ShortLineNamesLineAndColumn) {
  const MpiScratchDir dir;
  write_text(dir.file("d"), std::string(kHeader) + "ITEM: ATOMS id type x y z\n1 1 0 0 0\n2 1 1\n");
  const std::string e = lammps_error(dir.file("d"));
  EXPECT_HAS(e, "d:11: short line: 3 columns");
  EXPECT_HAS(e, "(y is missing)");
}

TEST(LammpsBadInput, NotANumber) {
  const MpiScratchDir dir;
  write_text(dir.file("d"),
             std::string(kHeader) + "ITEM: ATOMS id type x y z\n1 1 0 0 0\n2 1 1 zz 1\n");
  EXPECT_HAS(lammps_error(dir.file("d")), "d:11: column 'y': 'zz' is not a number");
}

TEST(LammpsBadInput, TruncatedAtoms) {
  const MpiScratchDir dir;
  write_text(dir.file("d"), std::string(kHeader) + "ITEM: ATOMS id type x y z\n1 1 0 0 0\n");
  EXPECT_HAS(lammps_error(dir.file("d")), "file ends after 1 of 2 atom lines");
}

TEST(LammpsBadInput, BadAtomCount) {
  const MpiScratchDir dir;
  write_text(dir.file("d"), "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\nmany\n");
  EXPECT_HAS(lammps_error(dir.file("d")), "d:4: ITEM: NUMBER OF ATOMS: expected one integer");
}

TEST(LammpsBadInput, ScaledWithoutBox) {
  const MpiScratchDir dir;
  write_text(dir.file("d"),
             "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: ATOMS id xs ys zs\n1 0 0 0\n");
  EXPECT_HAS(lammps_error(dir.file("d")), "d:5: scaled coordinates but no ITEM: BOX BOUNDS");
}

TEST(LammpsReader, ScaledOrthogonalAndTriclinicAreUnscaled) {
  const MpiScratchDir dir;
  write_text(
      dir.file("d"),
      std::string(kHeader) +
          "ITEM: ATOMS id type xs ys zs q\n1 2 0.5 0.5 0.5 9\n2 3 1 0 "
          "0.25 9\n"
          "ITEM: TIMESTEP\n200\nITEM: NUMBER OF ATOMS\n1\n"
          "ITEM: BOX BOUNDS xy xz yz pp pp pp\n-1 12 1\n0 10 -2\n0 10 0\n"  // xy=1 xz=-2 yz=0
          "ITEM: ATOMS xs ys zs\n1 1 1\n");
  std::unique_ptr<LammpsDumpReader> r;
  ASSERT_OK(LammpsDumpReader::open(dir.file("d"), &r));
  ASSERT_EQ(r->frames().size(), 2u);
  ParticleFrame f;
  ASSERT_OK(r->read(0, 1, 2, &f));  // the second atom only, as a second rank would
  EXPECT_EQ(f.position, (std::vector<double>{10, 0, 7.5}));
  EXPECT_EQ(f.type, (std::vector<int64_t>{3}));
  EXPECT_EQ(f.id, (std::vector<int64_t>{2}));
  EXPECT_EQ(f.box->periodic, (std::array<bool, 3>{true, true, false}));
  ASSERT_OK(r->read(1, 0, 1, &f));
  // xlo = -1 - min(0, 1, -2, -1) = 1, lx = (12 - 1) - 1 = 10: x = 1 + 10 + 1 - 2 = 10.
  EXPECT_EQ(f.position, (std::vector<double>{10, 10, 10}));
  EXPECT_EQ(f.step, 200);
}

TEST(LammpsReader, UnitsAndTimeBeforeTimestepAsLammpsWritesThem) {
  // dump_modify ... time yes units yes: ITEM: UNITS and ITEM: TIME precede ITEM: TIMESTEP.
  const MpiScratchDir dir;
  write_text(dir.file("d"),
             "ITEM: UNITS\nlj\nITEM: TIME\n0.25\nITEM: TIMESTEP\n50\nITEM: NUMBER OF ATOMS\n1\n"
             "ITEM: BOX BOUNDS pp pp pp\n0.0000000000000000e+00 3.3591923827650149e+01\n0 1\n0 "
             "1\nITEM: ATOMS id type x y z vx\n7 1 1.5e+00 2 3 0.1\n");
  std::unique_ptr<LammpsDumpReader> r;
  ASSERT_OK(LammpsDumpReader::open(dir.file("d"), &r));
  ASSERT_EQ(r->frames().size(), 1u);
  EXPECT_EQ(r->frames()[0].step, 50);
  EXPECT_EQ(r->frames()[0].time, 0.25);
  ParticleFrame f;
  ASSERT_OK(r->read(0, 0, 1, &f));
  EXPECT_EQ(f.position, (std::vector<double>{1.5, 2, 3}));
  EXPECT_DOUBLE_EQ(f.box->high[0], 33.591923827650149);
}

// A dump with Windows line ends: the header scan dropped each '\r', but the atom lines kept it in
// their last column ("3\r" is not a number), so open() succeeded and every frame failed.
TEST(LammpsReader, CrlfLineEndsReadAsLf) {
  const MpiScratchDir dir;
  std::string text =
      "ITEM: TIMESTEP\n50\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n0 "
      "10\nITEM: ATOMS id type x y z\n7 1 1.5 2 3\n8 2 4 5 6\n";
  for (size_t at = text.find('\n'); at != std::string::npos; at = text.find('\n', at + 2))
    text.insert(at, "\r");
  write_text(dir.file("d"), text);
  std::unique_ptr<LammpsDumpReader> r;
  ASSERT_OK(LammpsDumpReader::open(dir.file("d"), &r));
  ParticleFrame f;
  ASSERT_OK(r->read(0, 0, 2, &f));
  EXPECT_EQ(f.position, (std::vector<double>{1.5, 2, 3, 4, 5, 6}));
  EXPECT_EQ(f.type, (std::vector<int64_t>{1, 2}));
}

}  // namespace
}  // namespace lantern
