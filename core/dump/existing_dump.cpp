#include "core/dump/existing_dump.h"

#include <vector>

#include "core/dump/h5md_layout.h"
#include "core/dump/hdf5_handle.h"

namespace lantern {
namespace {

std::vector<hsize_t> dims_of(hid_t file, const std::string &path) {
  const H5Handle dataset = own_dataset(H5Dopen2(file, path.c_str(), H5P_DEFAULT), path);
  const H5Handle space = own_space(H5Dget_space(dataset.get()), path + ": dataspace");
  const int rank = h5_check(H5Sget_simple_extent_ndims(space.get()), path + ": rank");
  std::vector<hsize_t> dims(static_cast<size_t>(rank));
  if (rank > 0) H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

bool exists(hid_t file, const std::string &path) {
  size_t pos = 0;  // every component: H5Lexists fails on a missing parent
  while ((pos = path.find('/', pos + 1)) != std::string::npos)
    if (H5Lexists(file, path.substr(0, pos).c_str(), H5P_DEFAULT) <= 0) return false;
  return H5Lexists(file, path.c_str(), H5P_DEFAULT) > 0;
}

template <typename T>
T read_element(hid_t file, const std::string &path, hid_t mem_type, hsize_t index) {
  const H5Handle dataset = own_dataset(H5Dopen2(file, path.c_str(), H5P_DEFAULT), path);
  const H5Handle space = own_space(H5Dget_space(dataset.get()), path + ": dataspace");
  const hsize_t one = 1;
  h5_check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, &index, nullptr, &one, nullptr),
           path + ": select");
  const H5Handle memory = own_space(H5Screate_simple(1, &one, nullptr), path + ": memspace");
  T value{};
  h5_check(H5Dread(dataset.get(), mem_type, memory.get(), space.get(), H5P_DEFAULT, &value),
           path + ": read");
  return value;
}

}  // namespace

std::string fields_text(const DumpFields &f) {
  std::string text = h5md::kPosition;
  if (f.species) text += std::string(", ") + h5md::kSpecies;
  if (f.id) text += std::string(", ") + h5md::kId;
  if (f.scalar) text += std::string(", ") + h5md::kScalar;
  if (f.radius) text += std::string(", ") + h5md::kRadius;
  if (f.bonds) text += std::string(", bonds (") + h5md::kBonds + ")";
  return text;
}

ExistingDump inspect_dump_file(const std::string &path) {
  silence_hdf5_errors();
  ExistingDump out;
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    H5Eclear2(H5E_DEFAULT);
    out.problem = "is not an HDF5 file";
    return out;
  }
  try {
    const H5Handle file =
        own_file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "cannot open it");
    const std::string group = std::string(h5md::kParticles) + "/" + h5md::kGroupName + "/";
    const std::string count = h5md::kParticleCount;
    if (!exists(file.get(), "/h5md") || !exists(file.get(), group + h5md::kPosition + "/value") ||
        !exists(file.get(), count + "/time"))
      throw Hdf5Error("is not an H5MD file of Lantern's layout (" + group + h5md::kPosition +
                      " and " + count + ")");
    // The complete frames: particle_count is extended last in every frame.
    const auto frames = dims_of(file.get(), count + "/time");
    if (frames.size() != 1) throw Hdf5Error(count + "/time is not one-dimensional");
    out.frames = int64_t(frames[0]);
    const auto position = dims_of(file.get(), group + h5md::kPosition + "/value");
    if (position.size() != 3 || position[2] != 3)
      throw Hdf5Error(group + h5md::kPosition + "/value is not [frames][N][3]");
    out.rows = int64_t(position[1]);
    out.triclinic = dims_of(file.get(), group + h5md::kBox + "/edges/value").size() == 3;
    out.fields.species = exists(file.get(), group + h5md::kSpecies + "/value");
    out.fields.id = exists(file.get(), group + h5md::kId + "/value");
    out.fields.scalar = exists(file.get(), group + h5md::kScalar + "/value");
    out.fields.radius = exists(file.get(), group + h5md::kRadius + "/value");
    out.fields.bonds = exists(file.get(), std::string(h5md::kBonds) + "/value");
    // Every time series holds the complete frames (a failed frame may have left more).
    std::vector<std::string> series = {group + h5md::kPosition, count,
                                       group + h5md::kBox + "/edges",
                                       group + h5md::kBox + "/offset"};
    for (const char *name : {h5md::kSpecies, h5md::kId, h5md::kScalar, h5md::kRadius})
      if (exists(file.get(), group + name + "/value")) series.push_back(group + name);
    if (out.fields.bonds) series.push_back(h5md::kBonds);
    for (const std::string &element : series)
      for (const char *part : {"/value", "/step", "/time"}) {
        if (!exists(file.get(), element + part))
          throw Hdf5Error("is not an H5MD file of Lantern's layout (no " + element + part + ")");
        const auto dims = dims_of(file.get(), element + part);
        if (dims.empty() || int64_t(dims[0]) < out.frames)
          throw Hdf5Error(element + part + " has fewer frames than " + count);
      }
    {
      const H5Handle dataset = own_dataset(
          H5Dopen2(file.get(), (group + h5md::kPosition + "/value").c_str(), H5P_DEFAULT),
          "position/value");
      const H5Handle type = own_type(H5Dget_type(dataset.get()), "position/value: type");
      if (H5Tget_class(type.get()) != H5T_FLOAT)
        throw Hdf5Error(group + h5md::kPosition + "/value is not floating point");
      out.single_precision = H5Tget_size(type.get()) == 4;
    }
    if (out.frames > 0) {
      out.last_step = read_element<int64_t>(file.get(), count + "/step", H5T_NATIVE_INT64,
                                            hsize_t(out.frames - 1));
      out.last_count = read_element<int64_t>(file.get(), count + "/value", H5T_NATIVE_INT64,
                                             hsize_t(out.frames - 1));
    }
    const std::string box =
        std::string(h5md::kParticles) + "/" + h5md::kGroupName + "/" + h5md::kBox;
    if (H5Aexists_by_name(file.get(), box.c_str(), "boundary", H5P_DEFAULT) > 0) {
      const H5Handle attr =
          own_attr(H5Aopen_by_name(file.get(), box.c_str(), "boundary", H5P_DEFAULT, H5P_DEFAULT),
                   "box boundary");
      const H5Handle type = own_type(H5Aget_type(attr.get()), "box boundary: type");
      const size_t width = H5Tget_size(type.get());
      const H5Handle space = own_space(H5Aget_space(attr.get()), "box boundary: dataspace");
      if (H5Tget_class(type.get()) == H5T_STRING && !H5Tis_variable_str(type.get()) &&
          H5Sget_simple_extent_npoints(space.get()) == 3) {
        std::vector<char> text(3 * width, '\0');
        h5_check(H5Aread(attr.get(), type.get(), text.data()), "box boundary: read");
        for (int a = 0; a < 3; ++a)
          out.periodic[size_t(a)] =
              std::string(text.data() + a * width, width).rfind("periodic", 0) == 0;
      }
    }
  } catch (const Hdf5Error &e) {
    H5Eclear2(H5E_DEFAULT);
    out.problem = e.what();
  }
  return out;
}

}  // namespace lantern
