#include "core/dump/h5md_writer.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "core/dump/h5md_layout.h"

namespace lantern {
namespace {

// About 1.5 MB of float64 positions per chunk: large enough for efficient MPI-IO, small enough
// that a reader of a few particles does not read whole frames. Files of few particles get
// chunks of at least kMinChunkRows, so a count that grows later does not split a frame into
// many tiny chunks.
constexpr hsize_t kChunkRows = 65536;
constexpr hsize_t kMinChunkRows = 1024;

// This rank's rows of one field, in the memory type HDF5 converts from: `n` particles, then
// `tail` fill rows (the last rank pads the frame up to N_max).
struct FieldRows {
  hid_t mem_type = H5T_NATIVE_DOUBLE;
  std::vector<double> f64;
  std::vector<float> f32;
  std::vector<int32_t> i32;
  std::vector<int64_t> i64;
  const void *data() const {
    if (!f32.empty()) return f32.data();
    if (!i32.empty()) return i32.data();
    if (!i64.empty()) return i64.data();
    return f64.data();
  }
};

template <typename T, typename Get>
std::vector<T> gather(int64_t n, int64_t tail, int components, T fill, Get get) {
  std::vector<T> out(static_cast<size_t>((n + tail) * components), fill);
  for (int64_t i = 0; i < n; ++i)
    for (int c = 0; c < components; ++c) out[i * components + c] = static_cast<T>(get(i, c));
  return out;
}

// A real-valued field in the file's precision; fill rows are NaN.
template <typename Get>
FieldRows real_rows(bool single, int64_t n, int64_t tail, int components, Get get) {
  FieldRows rows;
  if (single) {
    rows.mem_type = H5T_NATIVE_FLOAT;
    rows.f32 = gather<float>(n, tail, components, std::numeric_limits<float>::quiet_NaN(), get);
  } else {
    rows.f64 = gather<double>(n, tail, components, std::numeric_limits<double>::quiet_NaN(), get);
  }
  return rows;
}

// The version lantern_version() reports: CMake reads it from the public header (the one place
// it is defined) and hands it to core as LANTERN_VERSION_STRING.
std::string version_string() {
  return LANTERN_VERSION_STRING;
}

// Rank 0's user name on every rank: an attribute written collectively must be the same on every
// rank, and a job's ranks need not share an environment.
std::string author_name(MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const char *user = rank == 0 ? std::getenv("USER") : nullptr;
  std::string name = user && *user ? user : "unknown";
  int length = int(name.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, comm);
  name.resize(size_t(length));
  MPI_Bcast(name.data(), length, MPI_CHAR, 0, comm);
  return name;
}

}  // namespace

Status H5mdWriter::create(MPI_Comm comm, const std::string &path, const DumpLayout &layout,
                          std::unique_ptr<H5mdWriter> *out, bool replace) {
  std::unique_ptr<H5mdWriter> writer(new H5mdWriter(comm, path, layout));  // private constructor
  try {
    writer->create_file(comm, replace);
  } catch (const Hdf5Error &e) {
    // The same on every rank: the writer closes collectively. A file this call created is
    // removed: half-built, it would make every later scheduled dump fail as "exists" (mode
    // create) or as not Lantern's (mode append) instead of trying again.
    const bool created = writer->file_.valid();
    writer.reset();
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    std::error_code ignored;
    if (created && rank == 0) std::filesystem::remove(path, ignored);
    return {StatusCode::kIo, e.what()};
  }
  *out = std::move(writer);
  return {};
}

Status H5mdWriter::open_existing(MPI_Comm comm, const std::string &path, const DumpLayout &layout,
                                 int64_t frames, int64_t rows, std::unique_ptr<H5mdWriter> *out) {
  std::unique_ptr<H5mdWriter> writer(new H5mdWriter(comm, path, layout));
  writer->frames_ = hsize_t(frames);
  writer->particles_ = hsize_t(rows);
  try {
    writer->open_file(comm);
  } catch (const Hdf5Error &e) {
    return {StatusCode::kIo, e.what()};
  }
  *out = std::move(writer);
  return {};
}

H5Handle H5mdWriter::file_access(MPI_Comm comm) {
  H5Handle fapl;
  calls_.collective("file access list", [&] {  // collective: the MPI-IO driver dups comm
    fapl = own_plist(H5Pcreate(H5P_FILE_ACCESS), "file access list");
    h5_check(H5Pset_fapl_mpio(fapl.get(), comm, MPI_INFO_NULL), "MPI-IO driver");
    // Metadata written collectively by all ranks instead of many small independent writes.
    h5_check(H5Pset_coll_metadata_write(fapl.get(), true), "collective metadata");
  });
  return fapl;
}

void H5mdWriter::open_file(MPI_Comm comm) {
  silence_hdf5_errors();
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
  calls_.local("transfer list", [&] {
    dxpl_ = own_plist(H5Pcreate(H5P_DATASET_XFER), "transfer list");
    h5_check(H5Pset_dxpl_mpio(dxpl_.get(), H5FD_MPIO_COLLECTIVE), "collective transfers");
  });
  const H5Handle fapl = file_access(comm);
  calls_.collective("open", [&] {
    file_ = own_file(H5Fopen(path_.c_str(), H5F_ACC_RDWR, fapl.get()), "cannot open the file");
  });
  H5Handle box, observables;
  calls_.collective("groups", [&] {
    const std::string all = std::string(h5md::kParticles) + "/" + h5md::kGroupName;
    particles_group_ = own_group(H5Gopen2(file_.get(), all.c_str(), H5P_DEFAULT), all);
    box = own_group(H5Gopen2(particles_group_.get(), h5md::kBox, H5P_DEFAULT), all + "/box");
    observables =
        own_group(H5Gopen2(file_.get(), h5md::kObservables, H5P_DEFAULT), h5md::kObservables);
  });
  const TimeSeries::Existing existing;
  const hid_t group = particles_group_.get();
  edges_.emplace(existing, calls_, box.get(), "edges", false);
  offset_.emplace(existing, calls_, box.get(), "offset", false);
  count_.emplace(existing, calls_, observables.get(), h5md::kParticleCountName, false);
  position_.emplace(existing, calls_, group, h5md::kPosition, true);
  const DumpFields &f = layout_.fields;
  if (f.species) species_.emplace(existing, calls_, group, h5md::kSpecies, true);
  if (f.id) id_.emplace(existing, calls_, group, h5md::kId, true);
  if (f.scalar) scalar_.emplace(existing, calls_, group, h5md::kScalar, true);
  if (f.radius) radius_.emplace(existing, calls_, group, h5md::kRadius, true);
  if (f.bonds) {
    H5Handle connectivity;
    calls_.collective("connectivity group", [&] {
      connectivity =
          own_group(H5Gopen2(file_.get(), h5md::kConnectivity, H5P_DEFAULT), h5md::kConnectivity);
    });
    bonds_.emplace(existing, calls_, connectivity.get(), h5md::kBondsName, true);
    bond_rows_ = bonds_->rows();
  }
  calls_.settle();
}

Status H5mdWriter::append(const DumpFrame &frame) {
  try {
    write_frame(frame);
  } catch (const Hdf5Error &e) {
    H5Eclear2(H5E_DEFAULT);
    return {StatusCode::kIo, e.what()};
  }
  return {};
}

void H5mdWriter::create_file(MPI_Comm comm, bool replace) {
  silence_hdf5_errors();
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
  H5Handle fapl;
  calls_.local("file is writable", [&] {
    // Checked on every rank before the collective create: a directory this rank cannot write
    // (another node's view, a permission change) fails here, agreed, instead of inside MPI-IO.
    const std::string dir = std::filesystem::path(path_).parent_path().string();
    if (::access(dir.empty() ? "." : dir.c_str(), W_OK | X_OK) != 0)
      throw Hdf5Error("cannot create the file: directory not writable by this process (" +
                      std::string(std::strerror(errno)) + ")");
    dxpl_ = own_plist(H5Pcreate(H5P_DATASET_XFER), "transfer list");
    h5_check(H5Pset_dxpl_mpio(dxpl_.get(), H5FD_MPIO_COLLECTIVE), "collective transfers");
  });
  fapl = file_access(comm);
  calls_.collective("create", [&] {
    file_ = own_file(
        H5Fcreate(path_.c_str(), replace ? H5F_ACC_TRUNC : H5F_ACC_EXCL, H5P_DEFAULT, fapl.get()),
        replace ? "cannot create the file" : "cannot create the file (or it exists)");
  });
  const std::string author = author_name(comm);
  calls_.collective("metadata", [&] { write_metadata(author); });
  create_elements();
  calls_.collective("flush", [&] { h5_check(H5Fflush(file_.get(), H5F_SCOPE_GLOBAL), "flush"); });
  calls_.settle();
}

void H5mdWriter::write_metadata(const std::string &author_name) {
  const H5Handle h5md =
      own_group(H5Gcreate2(file_.get(), "/h5md", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/h5md");
  write_int_attribute(h5md.get(), "version", {1, 1}, false);
  const H5Handle author = own_group(
      H5Gcreate2(h5md.get(), "author", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/h5md/author");
  write_string_attribute(author.get(), "name", {author_name}, true);
  const H5Handle creator = own_group(
      H5Gcreate2(h5md.get(), "creator", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/h5md/creator");
  write_string_attribute(creator.get(), "name", {"Lantern"}, true);
  write_string_attribute(creator.get(), "version", {version_string()}, true);
}

void H5mdWriter::create_elements() {
  H5Handle box, observables;
  calls_.collective("groups", [&] {
    const H5Handle particles =
        own_group(H5Gcreate2(file_.get(), h5md::kParticles, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                  "/particles");
    particles_group_ = own_group(
        H5Gcreate2(particles.get(), h5md::kGroupName, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        "/particles/all");
    box = own_group(
        H5Gcreate2(particles_group_.get(), h5md::kBox, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        "/particles/all/box");
    write_int_attribute(box.get(), "dimension", {3}, true);
    std::vector<std::string> boundary;
    for (const bool p : layout_.periodic) boundary.push_back(p ? "periodic" : "none");
    write_string_attribute(box.get(), "boundary", boundary, false);
    observables = own_group(
        H5Gcreate2(file_.get(), h5md::kObservables, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        "/observables");
  });
  const hid_t group = particles_group_.get();
  edges_.emplace(calls_, box.get(), "edges",
                 layout_.triclinic ? std::vector<hsize_t>{3, 3} : std::vector<hsize_t>{3},
                 H5T_IEEE_F64LE, 3, false);
  offset_.emplace(calls_, box.get(), "offset", std::vector<hsize_t>{3}, H5T_IEEE_F64LE, 3, false);
  count_.emplace(calls_, observables.get(), h5md::kParticleCountName, std::vector<hsize_t>{},
                 H5T_STD_I64LE, 1, false);

  const hsize_t chunk =
      std::clamp<hsize_t>(hsize_t(layout_.first_count), kMinChunkRows, kChunkRows);
  const hid_t real = layout_.single_precision ? H5T_IEEE_F32LE : H5T_IEEE_F64LE;
  position_.emplace(calls_, group, h5md::kPosition, std::vector<hsize_t>{0, 3}, real, chunk, true);
  const DumpFields &f = layout_.fields;
  if (f.species)
    species_.emplace(calls_, group, h5md::kSpecies, std::vector<hsize_t>{0}, H5T_STD_I32LE, chunk,
                     true);
  if (f.id)
    id_.emplace(calls_, group, h5md::kId, std::vector<hsize_t>{0}, H5T_STD_I64LE, chunk, true);
  if (f.scalar)
    scalar_.emplace(calls_, group, h5md::kScalar, std::vector<hsize_t>{0}, real, chunk, true);
  if (f.radius)
    radius_.emplace(calls_, group, h5md::kRadius, std::vector<hsize_t>{0}, real, chunk, true);
  if (f.bonds) create_bond_list();
}

// /connectivity/all_bonds: a time-dependent list of pairs of particle ids whose particles_group
// attribute refers to the particle group (H5MD 1.1, connectivity).
void H5mdWriter::create_bond_list() {
  H5Handle connectivity;
  calls_.collective("connectivity group", [&] {
    connectivity = own_group(
        H5Gcreate2(file_.get(), h5md::kConnectivity, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        h5md::kConnectivity);
  });
  const hsize_t chunk =
      std::clamp<hsize_t>(hsize_t(layout_.first_bonds), kMinChunkRows, kChunkRows);
  bonds_.emplace(calls_, connectivity.get(), h5md::kBondsName, std::vector<hsize_t>{0, 2},
                 H5T_STD_I64LE, chunk, true);
  calls_.collective("connectivity: particles_group", [&] {
    const std::string target = std::string(h5md::kParticles) + "/" + h5md::kGroupName;
    hobj_ref_t ref{};
    h5_check(H5Rcreate(&ref, file_.get(), target.c_str(), H5R_OBJECT, -1),
             "particles_group: reference");
    const H5Handle group =
        own_group(H5Gopen2(connectivity.get(), h5md::kBondsName, H5P_DEFAULT), h5md::kBonds);
    const H5Handle space = own_space(H5Screate(H5S_SCALAR), "particles_group: dataspace");
    const H5Handle attr =
        own_attr(H5Acreate2(group.get(), h5md::kParticlesGroupAttribute, H5T_STD_REF_OBJ,
                            space.get(), H5P_DEFAULT, H5P_DEFAULT),
                 "particles_group: create");
    h5_check(H5Awrite(attr.get(), H5T_STD_REF_OBJ, &ref), "particles_group: write");
  });
}

void H5mdWriter::write_frame(const DumpFrame &f) {
  const ParticleArrays &p = *f.particles;
  const int64_t n = f.rows ? int64_t(f.rows->size()) : p.count();
  const auto row = [&f](int64_t k) { return f.rows ? (*f.rows)[size_t(k)] : k; };
  const bool root = rank_ == 0;
  const bool single = layout_.single_precision;
  const hsize_t particles = std::max(particles_, hsize_t(f.total));
  // The last rank's rows end at the frame's count; it pads the frame with fill rows up to N_max.
  const int64_t tail = rank_ == size_ - 1 ? int64_t(particles) - f.total : 0;
  const hsize_t rows = hsize_t(n + tail);

  FieldRows position, species, id, scalar, radius;
  calls_.local("gather the frame", [&] {  // allocations: a failure here is agreed like HDF5's
    position =
        real_rows(single, n, tail, 3, [&](int64_t i, int c) { return p.position(row(i))[c]; });
    if (species_) {
      species.mem_type = H5T_NATIVE_INT32;
      // The species are 32-bit; an int64 type beyond that was cut to its low bits (2^32 + 2
      // stored as 2, 2^32 - 1 as -1, the fill value), silently: now the dump fails naming it.
      species.i32 = gather<int32_t>(n, tail, 1, -1, [&](int64_t i, int) {
        const int64_t t = p.type(row(i));
        if (t < std::numeric_limits<int32_t>::min() || t > std::numeric_limits<int32_t>::max())
          throw std::out_of_range("particles.type[" + std::to_string(row(i)) + "] = " +
                                  std::to_string(t) + " does not fit the dump's 32-bit species");
        return int32_t(t);
      });
    }
    if (id_) {
      id.mem_type = H5T_NATIVE_INT64;
      id.i64 = gather<int64_t>(n, tail, 1, -1, [&](int64_t i, int) { return p.id(row(i)); });
    }
    if (scalar_)
      scalar = real_rows(single, n, tail, 1, [&](int64_t i, int) { return p.scalar(row(i)); });
    if (radius_)
      radius = real_rows(single, n, tail, 1, [&](int64_t i, int) { return p.radius(row(i)); });
  });
  const auto put = [&](std::optional<TimeSeries> &series, const FieldRows &r) {
    if (series)
      series->append(calls_, frames_, particles, hsize_t(f.offset), rows, r.mem_type, r.data(),
                     dxpl_.get(), root, f.step, f.time);
  };
  put(position_, position);
  put(species_, species);
  put(id_, id);
  put(scalar_, scalar);
  put(radius_, radius);
  hsize_t bond_rows = bond_rows_;
  if (bonds_) {  // this rank's pairs at its offset; the last rank pads up to B_max with -1
    bond_rows = std::max(bond_rows_, hsize_t(f.bond_total));
    const int64_t mine = f.bond_ids ? int64_t(f.bond_ids->size() / 2) : 0;
    const int64_t bond_tail = rank_ == size_ - 1 ? int64_t(bond_rows) - f.bond_total : 0;
    std::vector<int64_t> pairs;
    calls_.local("gather the bonds", [&] {
      pairs.assign(size_t(2 * (mine + bond_tail)), -1);
      if (mine > 0) std::copy(f.bond_ids->begin(), f.bond_ids->end(), pairs.begin());
    });
    bonds_->append(calls_, frames_, bond_rows, hsize_t(f.bond_offset), hsize_t(mine + bond_tail),
                   H5T_NATIVE_INT64, pairs.data(), dxpl_.get(), root, f.step, f.time);
  }

  // The box and the count are one row each, written by rank 0 alone.
  const auto edges = f.box.edges();
  const auto vectors = f.box.edge_vectors();  // rows a, b, c: 9 doubles in a row
  const hid_t dxpl = dxpl_.get();
  edges_->append(calls_, frames_, 0, 0, root ? 1 : 0, H5T_NATIVE_DOUBLE,
                 layout_.triclinic ? vectors[0].data() : edges.data(), dxpl, root, f.step, f.time);
  offset_->append(calls_, frames_, 0, 0, root ? 1 : 0, H5T_NATIVE_DOUBLE, f.box.low.data(), dxpl,
                  root, f.step, f.time);
  count_->append(calls_, frames_, 0, 0, root ? 1 : 0, H5T_NATIVE_INT64, &f.total, dxpl, root,
                 f.step, f.time);
  const std::string flush = "flush after frame " + std::to_string(frames_ + 1);
  calls_.collective(flush, [&] { h5_check(H5Fflush(file_.get(), H5F_SCOPE_GLOBAL), flush); });
  calls_.settle();
  ++frames_;
  particles_ = particles;
  bond_rows_ = bond_rows;
}

}  // namespace lantern
