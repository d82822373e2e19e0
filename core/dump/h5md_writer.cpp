#include "core/dump/h5md_writer.h"

#include <cstdlib>
#include <vector>

#include "core/dump/h5md_layout.h"

namespace lantern {
namespace {

// About 1.5 MB of float64 positions per chunk: large enough for efficient MPI-IO, small enough
// that a reader of a few particles does not read whole frames.
constexpr hsize_t kChunkRows = 65536;

template <typename T, typename Get>
std::vector<T> gather(int64_t n, int components, Get get) {
  std::vector<T> out(static_cast<size_t>(n) * components);
  for (int64_t i = 0; i < n; ++i)
    for (int c = 0; c < components; ++c) out[i * components + c] = static_cast<T>(get(i, c));
  return out;
}

// Writes one real-valued field in the file's precision.
template <typename Get>
void append_real(TimeSeries &series, bool single, hsize_t frame, const DumpFrame &f, int64_t n,
                 int components, Get get, hid_t dxpl, bool root) {
  if (single) {
    const auto buf = gather<float>(n, components, get);
    series.append(frame, f.offset, n, H5T_NATIVE_FLOAT, buf.data(), dxpl, root, f.step, f.time);
  } else {
    const auto buf = gather<double>(n, components, get);
    series.append(frame, f.offset, n, H5T_NATIVE_DOUBLE, buf.data(), dxpl, root, f.step, f.time);
  }
}

// The version lantern_version() reports: CMake reads it from the public header (the one place
// it is defined) and hands it to core as LANTERN_VERSION_STRING.
std::string version_string() {
  return LANTERN_VERSION_STRING;
}

std::string author_name() {
  const char *user = std::getenv("USER");
  return user && *user ? user : "unknown";
}

}  // namespace

Status H5mdWriter::create(MPI_Comm comm, const std::string &path, const DumpLayout &layout,
                          std::unique_ptr<H5mdWriter> *out) {
  std::unique_ptr<H5mdWriter> writer(new H5mdWriter(path, layout));  // private constructor
  try {
    writer->create_file(comm);
  } catch (const Hdf5Error &e) {
    return {StatusCode::kIo, e.what()};
  }
  *out = std::move(writer);
  return {};
}

Status H5mdWriter::append(const DumpFrame &frame) {
  try {
    write_frame(frame);
  } catch (const Hdf5Error &e) {
    return {StatusCode::kIo, e.what()};
  }
  return {};
}

void H5mdWriter::create_file(MPI_Comm comm) {
  silence_hdf5_errors();
  MPI_Comm_rank(comm, &rank_);
  const H5Handle fapl = own_plist(H5Pcreate(H5P_FILE_ACCESS), "file access list");
  h5_check(H5Pset_fapl_mpio(fapl.get(), comm, MPI_INFO_NULL), "MPI-IO driver");
  // Metadata written collectively by all ranks instead of many small independent writes.
  h5_check(H5Pset_coll_metadata_write(fapl.get(), true), "collective metadata");
  file_ = own_file(H5Fcreate(path_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()),
                   "cannot create the file");
  dxpl_ = own_plist(H5Pcreate(H5P_DATASET_XFER), "transfer list");
  h5_check(H5Pset_dxpl_mpio(dxpl_.get(), H5FD_MPIO_COLLECTIVE), "collective transfers");
  write_metadata();
  create_elements();
  h5_check(H5Fflush(file_.get(), H5F_SCOPE_GLOBAL), "flush");
}

void H5mdWriter::write_metadata() {
  const H5Handle h5md =
      own_group(H5Gcreate2(file_.get(), "/h5md", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/h5md");
  write_int_attribute(h5md.get(), "version", {1, 1}, false);
  const H5Handle author = own_group(
      H5Gcreate2(h5md.get(), "author", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/h5md/author");
  write_string_attribute(author.get(), "name", {author_name()}, true);
  const H5Handle creator = own_group(
      H5Gcreate2(h5md.get(), "creator", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/h5md/creator");
  write_string_attribute(creator.get(), "name", {"Lantern"}, true);
  write_string_attribute(creator.get(), "version", {version_string()}, true);
}

void H5mdWriter::create_elements() {
  const H5Handle particles =
      own_group(H5Gcreate2(file_.get(), h5md::kParticles, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                "/particles");
  particles_ = own_group(
      H5Gcreate2(particles.get(), h5md::kGroupName, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
      "/particles/all");
  const hid_t group = particles_.get();
  const H5Handle box = own_group(
      H5Gcreate2(group, h5md::kBox, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/particles/all/box");
  write_int_attribute(box.get(), "dimension", {3}, true);
  std::vector<std::string> boundary;
  for (const bool p : layout_.periodic) boundary.push_back(p ? "periodic" : "none");
  write_string_attribute(box.get(), "boundary", boundary, false);
  edges_.emplace(box.get(), "edges", std::vector<hsize_t>{3}, H5T_IEEE_F64LE, 3);
  offset_.emplace(box.get(), "offset", std::vector<hsize_t>{3}, H5T_IEEE_F64LE, 3);

  const hsize_t n = static_cast<hsize_t>(layout_.global_count);
  const hid_t real = layout_.single_precision ? H5T_IEEE_F32LE : H5T_IEEE_F64LE;
  position_.emplace(group, h5md::kPosition, std::vector<hsize_t>{n, 3}, real, kChunkRows);
  const DumpFields &f = layout_.fields;
  if (f.species)
    species_.emplace(group, h5md::kSpecies, std::vector<hsize_t>{n}, H5T_STD_I32LE, kChunkRows);
  if (f.id) id_.emplace(group, h5md::kId, std::vector<hsize_t>{n}, H5T_STD_I64LE, kChunkRows);
  if (f.scalar) scalar_.emplace(group, h5md::kScalar, std::vector<hsize_t>{n}, real, kChunkRows);
  if (f.radius) radius_.emplace(group, h5md::kRadius, std::vector<hsize_t>{n}, real, kChunkRows);
}

void H5mdWriter::write_frame(const DumpFrame &f) {
  const ParticleArrays &p = *f.particles;
  const int64_t n = f.rows ? int64_t(f.rows->size()) : p.count();
  const auto row = [&f](int64_t k) { return f.rows ? (*f.rows)[size_t(k)] : k; };
  const bool root = rank_ == 0;
  const hid_t dxpl = dxpl_.get();
  const bool single = layout_.single_precision;

  append_real(
      *position_, single, frames_, f, n, 3, [&](int64_t i, int c) { return p.position(row(i))[c]; },
      dxpl, root);
  if (species_) {
    const auto t = gather<int32_t>(n, 1, [&](int64_t i, int) { return p.type(row(i)); });
    species_->append(frames_, f.offset, n, H5T_NATIVE_INT32, t.data(), dxpl, root, f.step, f.time);
  }
  if (id_) {
    const auto ids = gather<int64_t>(n, 1, [&](int64_t i, int) { return p.id(row(i)); });
    id_->append(frames_, f.offset, n, H5T_NATIVE_INT64, ids.data(), dxpl, root, f.step, f.time);
  }
  if (scalar_)
    append_real(
        *scalar_, single, frames_, f, n, 1, [&](int64_t i, int) { return p.scalar(row(i)); }, dxpl,
        root);
  if (radius_)
    append_real(
        *radius_, single, frames_, f, n, 1, [&](int64_t i, int) { return p.radius(row(i)); }, dxpl,
        root);

  // The box is one row of 3 values, written by rank 0 alone.
  const auto edges = f.box.edges();
  edges_->append(frames_, 0, root ? 3 : 0, H5T_NATIVE_DOUBLE, edges.data(), dxpl, root, f.step,
                 f.time);
  offset_->append(frames_, 0, root ? 3 : 0, H5T_NATIVE_DOUBLE, f.box.low.data(), dxpl, root, f.step,
                  f.time);
  ++frames_;
  h5_check(H5Fflush(file_.get(), H5F_SCOPE_GLOBAL), "flush after frame " + std::to_string(frames_));
}

}  // namespace lantern
