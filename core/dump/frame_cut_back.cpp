#include "core/dump/frame_cut_back.h"

#include <algorithm>
#include <vector>

#include "core/dump/h5md_layout.h"
#include "core/dump/hdf5_handle.h"

namespace lantern {
namespace {

// Shrinks `path` (a dataset) to `frames` along its first axis and, when `particle_axis`, to
// `rows` along its second; never grows an axis.
void shrink(hid_t file, const std::string &path, hsize_t frames, bool particle_axis, hsize_t rows) {
  const H5Handle dataset = own_dataset(H5Dopen2(file, path.c_str(), H5P_DEFAULT), path);
  const H5Handle space = own_space(H5Dget_space(dataset.get()), path + ": dataspace");
  const int rank = H5Sget_simple_extent_ndims(space.get());
  h5_check(rank, path + ": rank");
  if (rank == 0) return;
  std::vector<hsize_t> dims(static_cast<size_t>(rank));
  h5_check(H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr), path + ": dimensions");
  std::vector<hsize_t> cut = dims;
  cut[0] = std::min(dims[0], frames);
  if (particle_axis && rank > 1) cut[1] = std::min(dims[1], rows);
  if (cut != dims) h5_check(H5Dset_extent(dataset.get(), cut.data()), path + ": cut back");
}

}  // namespace

Status cut_back_frames(const std::string &path, int64_t frames, int64_t rows) {
  silence_hdf5_errors();
  try {
    const H5Handle file =
        own_file(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), "cannot reopen the file");
    const std::string particles = std::string(h5md::kParticles) + "/" + h5md::kGroupName + "/";
    const std::string box = particles + h5md::kBox + "/";
    const std::vector<std::pair<std::string, bool>> elements = {{particles + h5md::kPosition, true},
                                                                {particles + h5md::kSpecies, true},
                                                                {particles + h5md::kId, true},
                                                                {particles + h5md::kScalar, true},
                                                                {particles + h5md::kRadius, true},
                                                                {box + "edges", false},
                                                                {box + "offset", false},
                                                                {h5md::kBonds, false},
                                                                {h5md::kParticleCount, false}};
    // The bond list is cut back along its frame axis only: a bond axis that grew in the failed
    // frame keeps fill pairs (-1) in the earlier frames, written before that frame's pairs.
    for (const auto &[element, per_particle] : elements) {
      if (H5Lexists(file.get(), element.c_str(), H5P_DEFAULT) <= 0) continue;
      shrink(file.get(), element + "/value", hsize_t(frames), per_particle, hsize_t(rows));
      for (const char *axis : {"/step", "/time"})
        if (H5Lexists(file.get(), (element + axis).c_str(), H5P_DEFAULT) > 0)
          shrink(file.get(), element + axis, hsize_t(frames), false, 0);
    }
    h5_check(H5Fflush(file.get(), H5F_SCOPE_LOCAL), "flush");
  } catch (const Hdf5Error &e) {
    H5Eclear2(H5E_DEFAULT);
    return {StatusCode::kIo, e.what()};
  }
  return {};
}

}  // namespace lantern
