// libFuzzer: the H5MD reader (H5mdReader) on files built from the input, structure-aware: the
// bytes choose which groups, datasets and attributes exist, their shapes, types, fill values and
// contents (an H5MD file of Lantern's layout, or of another writer, or neither), the file is
// written with serial HDF5 to /dev/shm, and the reader opens it and reads every frame in two
// halves, as two ranks would, and the bonds of every frame (H5MD's connectivity). Raw byte soup
// would mostly exercise HDF5's own parser, which is not Lantern's code; the reader's logic is in
// what it makes of valid HDF5 objects.
#include <fuzzer/FuzzedDataProvider.h>
#include <hdf5.h>
#include <mpi.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/dump/h5md_reader.h"

namespace {

std::string path;

hid_t pick_type(FuzzedDataProvider &in) {
  switch (in.ConsumeIntegralInRange(0, 4)) {
    case 0:
      return H5T_NATIVE_DOUBLE;
    case 1:
      return H5T_NATIVE_FLOAT;
    case 2:
      return H5T_NATIVE_INT32;
    case 3:
      return H5T_NATIVE_INT64;
    default:
      return H5T_NATIVE_UINT8;
  }
}

// A dataset `name` in `group` of the given rank, small dimensions, any type, contents and
// (sometimes) a fill value, written from the input.
void make_dataset(FuzzedDataProvider &in, hid_t group, const char *name, int rank, bool frames,
                  hsize_t n_frames, hsize_t n_rows) {
  if (in.ConsumeIntegralInRange(0, 15) == 0) return;  // sometimes missing
  if (in.ConsumeIntegralInRange(0, 15) == 0) rank = in.ConsumeIntegralInRange(0, 4);
  std::vector<hsize_t> dims;
  for (int d = 0; d < rank; ++d) {
    hsize_t v = d == 0 && frames ? n_frames : d <= 1 ? n_rows : 3;
    if (in.ConsumeIntegralInRange(0, 7) == 0) v = in.ConsumeIntegralInRange<hsize_t>(0, 9);
    dims.push_back(v);
  }
  const hid_t type = pick_type(in);
  const hid_t space =
      rank == 0 ? H5Screate(H5S_SCALAR) : H5Screate_simple(rank, dims.data(), nullptr);
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  if (in.ConsumeBool()) {
    const double fill = in.ConsumeBool() ? -1.0 : in.ConsumeFloatingPoint<double>();
    const int64_t ifill = in.ConsumeBool() ? -1 : in.ConsumeIntegral<int64_t>();
    if (type == H5T_NATIVE_DOUBLE || type == H5T_NATIVE_FLOAT)
      H5Pset_fill_value(dcpl, H5T_NATIVE_DOUBLE, &fill);
    else
      H5Pset_fill_value(dcpl, H5T_NATIVE_INT64, &ifill);
  }
  const hid_t dataset = H5Dcreate2(group, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  if (dataset >= 0) {
    hsize_t elements = 1;
    for (hsize_t d : dims) elements *= d;
    std::vector<double> values(elements);
    for (double &v : values) {
      switch (in.ConsumeIntegralInRange(0, 3)) {
        case 0:
          v = in.ConsumeFloatingPoint<double>();
          break;
        case 1:
          v = double(in.ConsumeIntegralInRange<int64_t>(-3, 12));
          break;
        default:
          v = in.ConsumeFloatingPointInRange<double>(-10.0, 10.0);
      }
    }
    if (elements > 0)
      H5Dwrite(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
    H5Dclose(dataset);
  }
  H5Pclose(dcpl);
  H5Sclose(space);
}

// A time-dependent element (value, step, time) at `where`.
void make_element(FuzzedDataProvider &in, hid_t parent, const char *where, int value_rank,
                  hsize_t n_frames, hsize_t n_rows) {
  if (in.ConsumeIntegralInRange(0, 7) == 0) return;
  const hid_t group = H5Gcreate2(parent, where, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (group < 0) return;
  const bool fixed = in.ConsumeIntegralInRange(0, 5) == 0;  // a time-independent [N] element
  if (fixed) {
    make_dataset(in, parent, (std::string(where) + "_fixed").c_str(), value_rank - 1, false, 0,
                 n_rows);
  }
  make_dataset(in, group, "value", value_rank, true, n_frames, n_rows);
  make_dataset(in, group, "step", 1, true, n_frames, n_rows);
  if (in.ConsumeBool()) make_dataset(in, group, "time", 1, true, n_frames, n_rows);
  H5Gclose(group);
}

void string_attribute(hid_t object, const char *name, const std::vector<std::string> &values) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, 16);
  std::vector<char> packed(16 * values.size(), '\0');
  for (size_t i = 0; i < values.size(); ++i) values[i].copy(packed.data() + 16 * i, 15);
  const hsize_t n = values.size();
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const hid_t attr = H5Acreate2(object, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  if (attr >= 0) {
    H5Awrite(attr, type, packed.data());
    H5Aclose(attr);
  }
  H5Sclose(space);
  H5Tclose(type);
}

// A pair list under /connectivity (H5MD's bonds): [frames][B][2] with steps, or [B][2], of any
// type and mostly small ids, and a particles_group attribute that is an object reference to the
// particle group, to another group or to nothing (dangling), a name, or something else.
void make_connectivity(FuzzedDataProvider &in, hid_t file, hsize_t n_frames, hsize_t n_rows) {
  const hid_t connectivity =
      H5Gcreate2(file, "/connectivity", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (connectivity < 0) return;
  const bool per_frame = in.ConsumeBool();
  const hid_t holder =
      per_frame ? H5Gcreate2(connectivity, "all_bonds", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)
                : connectivity;
  std::vector<hsize_t> dims;
  if (per_frame) dims.push_back(n_frames);
  dims.push_back(in.ConsumeIntegralInRange<hsize_t>(0, 6));
  dims.push_back(2);
  if (in.ConsumeIntegralInRange(0, 7) == 0) dims.back() = in.ConsumeIntegralInRange<hsize_t>(0, 4);
  if (in.ConsumeIntegralInRange(0, 7) == 0) dims.pop_back();
  const hid_t type = pick_type(in);
  const hid_t space = H5Screate_simple(int(dims.size()), dims.data(), nullptr);
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  if (in.ConsumeBool()) {
    const int64_t fill = -1;
    H5Pset_fill_value(dcpl, H5T_NATIVE_INT64, &fill);
  }
  const hid_t value = H5Dcreate2(holder, per_frame ? "value" : "all_bonds", type, space,
                                 H5P_DEFAULT, dcpl, H5P_DEFAULT);
  if (value >= 0) {
    hsize_t elements = 1;
    for (hsize_t d : dims) elements *= d;
    std::vector<double> ids(elements);
    for (double &v : ids) v = double(in.ConsumeIntegralInRange<int64_t>(-2, int64_t(n_rows) + 2));
    if (elements > 0) H5Dwrite(value, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, ids.data());
    H5Dclose(value);
  }
  H5Pclose(dcpl);
  H5Sclose(space);
  if (per_frame) make_dataset(in, holder, "step", 1, true, n_frames, 0);
  const char *owner = "/connectivity/all_bonds";  // the group, or the fixed dataset
  const hid_t scalar = H5Screate(H5S_SCALAR);
  switch (in.ConsumeIntegralInRange(0, 4)) {
    case 0:
    case 1: {  // a reference: to the particle group, another group, or one deleted after
      const int which = in.ConsumeIntegralInRange(0, 2);
      if (which == 2) H5Gclose(H5Gcreate2(file, "/gone", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
      hobj_ref_t ref{};
      const char *target = which == 0 ? "/particles/all" : which == 1 ? "/h5md" : "/gone";
      if (H5Rcreate(&ref, file, target, H5R_OBJECT, -1) >= 0) {
        const hid_t attr = H5Acreate_by_name(file, owner, "particles_group", H5T_STD_REF_OBJ,
                                             scalar, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        if (attr >= 0) {
          H5Awrite(attr, H5T_STD_REF_OBJ, &ref);
          H5Aclose(attr);
        }
      }
      if (which == 2) H5Ldelete(file, "/gone", H5P_DEFAULT);
      break;
    }
    case 2: {
      const hid_t object = H5Oopen(file, owner, H5P_DEFAULT);
      if (object >= 0) {
        string_attribute(object, "particles_group", {in.ConsumeBool() ? "all" : "/particles/x"});
        H5Oclose(object);
      }
      break;
    }
    case 3: {
      const int32_t number = 7;
      const hid_t attr = H5Acreate_by_name(file, owner, "particles_group", H5T_STD_I32LE, scalar,
                                           H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
      if (attr >= 0) {
        H5Awrite(attr, H5T_NATIVE_INT32, &number);
        H5Aclose(attr);
      }
      break;
    }
    default:
      break;  // none
  }
  H5Sclose(scalar);
  if (per_frame) H5Gclose(holder);
  H5Gclose(connectivity);
}

bool build_file(FuzzedDataProvider &in) {
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file < 0) return false;
  if (in.ConsumeIntegralInRange(0, 15) != 0) {
    const hid_t h5md = H5Gcreate2(file, "/h5md", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (in.ConsumeIntegralInRange(0, 15) != 0) {
      const int version[2] = {1, 1};
      const hsize_t two = 2;
      const hid_t space = H5Screate_simple(1, &two, nullptr);
      const hid_t attr =
          H5Acreate2(h5md, "version", H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT);
      H5Awrite(attr, H5T_NATIVE_INT, version);
      H5Aclose(attr);
      H5Sclose(space);
    }
    H5Gclose(h5md);
  }
  const hsize_t n_frames = in.ConsumeIntegralInRange<hsize_t>(0, 4);
  const hsize_t n_rows = in.ConsumeIntegralInRange<hsize_t>(0, 8);
  if (in.ConsumeIntegralInRange(0, 15) != 0) {
    const hid_t particles = H5Gcreate2(file, "/particles", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    const std::string name = in.ConsumeBool() ? "all" : in.ConsumeRandomLengthString(12);
    const hid_t group = H5Gcreate2(particles, name.empty() ? "x" : name.c_str(), H5P_DEFAULT,
                                   H5P_DEFAULT, H5P_DEFAULT);
    if (group >= 0) {
      make_element(in, group, "position", 3, n_frames, n_rows);
      for (const char *field : {"species", "id", "scalar", "radius"})
        if (in.ConsumeBool()) make_element(in, group, field, 2, n_frames, n_rows);
      if (in.ConsumeBool()) {
        const hid_t box = H5Gcreate2(group, "box", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        if (in.ConsumeBool()) {
          std::vector<std::string> boundary;
          for (int a = 0, n = in.ConsumeIntegralInRange(0, 4); a < n; ++a)
            boundary.push_back(in.ConsumeBool() ? "periodic" : in.ConsumeRandomLengthString(15));
          if (!boundary.empty()) string_attribute(box, "boundary", boundary);
        }
        make_element(in, box, "edges", 2, n_frames, 3);
        make_element(in, box, "offset", 2, n_frames, 3);
        H5Gclose(box);
      }
      H5Gclose(group);
    }
    H5Gclose(particles);
  }
  if (in.ConsumeBool()) {
    const hid_t observables =
        H5Gcreate2(file, "/observables", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    make_element(in, observables, "particle_count", 1, n_frames, 0);
    H5Gclose(observables);
  }
  if (in.ConsumeBool()) make_connectivity(in, file, n_frames, n_rows);
  H5Fclose(file);
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
  MPI_Init(nullptr, nullptr);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  path = "/dev/shm/lantern_fuzz_h5md_" + std::to_string(getpid()) + ".h5";
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  FuzzedDataProvider in(data, size);
  if (!build_file(in)) return 0;
  std::unique_ptr<lantern::H5mdReader> reader;
  if (lantern::H5mdReader::open(path, MPI_COMM_WORLD, &reader).ok()) {
    const auto &frames = reader->frames();
    for (size_t f = 0; f < frames.size() && f < 6; ++f) {
      const int64_t count = frames[f].count, half = count / 2;
      lantern::ParticleFrame frame;
      if (reader->read(f, 0, half, &frame).ok() && frame.count() > half) __builtin_trap();
      if (reader->read(f, half, count, &frame).ok() && frame.count() > count - half)
        __builtin_trap();
      // Bonds read back are pairs of two different, non-negative ids.
      std::vector<int64_t> first, second, pair;
      if (reader->read_bonds(f, &first, &second, &pair).ok()) {
        if (first.size() != second.size() || pair.size() != first.size()) __builtin_trap();
        for (size_t k = 0; k < first.size(); ++k)
          if (first[k] < 0 || second[k] < 0 || first[k] == second[k]) __builtin_trap();
      }
    }
  }
  reader.reset();
  unlink(path.c_str());
  return 0;
}
