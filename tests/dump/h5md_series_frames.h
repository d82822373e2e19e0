// The frames of every H5MD time series in one of Lantern's dump files, read with serial HDF5 on
// the calling rank: for each element that exists (position, species, id, scalar, radius, the
// box's edges and offset, particle_count), the first dimension of its value, step and time. A
// valid file has the three equal in every element, and equal across the elements.
#pragma once

#include <hdf5.h>

#include <map>
#include <string>
#include <vector>

namespace lantern::testing {

inline std::map<std::string, std::vector<hsize_t>> time_series_frames(const std::string &file) {
  std::map<std::string, std::vector<hsize_t>> out;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return out;
  const auto frames_of = [f](const std::string &path) -> hsize_t {
    const hid_t d = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
    if (d < 0) return hsize_t(-1);
    const hid_t space = H5Dget_space(d);
    hsize_t dims[3] = {0, 0, 0};
    if (H5Sget_simple_extent_ndims(space) > 0) H5Sget_simple_extent_dims(space, dims, nullptr);
    H5Sclose(space);
    H5Dclose(d);
    return dims[0];
  };
  for (const char *element :
       {"/particles/all/position", "/particles/all/species", "/particles/all/id",
        "/particles/all/scalar", "/particles/all/radius", "/particles/all/box/edges",
        "/particles/all/box/offset", "/observables/particle_count"}) {
    const std::string e = element;
    if (H5Lexists(f, e.c_str(), H5P_DEFAULT) <= 0) continue;
    out[e] = {frames_of(e + "/value"), frames_of(e + "/step"), frames_of(e + "/time")};
  }
  H5Fclose(f);
  return out;
}

// "" when every element has `frames` frames in value, step and time; else what differs.
inline std::string time_series_mismatch(const std::string &file, hsize_t frames) {
  std::string problems;
  const auto series = time_series_frames(file);
  if (series.empty()) return file + ": no time series (cannot open it?)";
  for (const auto &[element, f] : series)
    if (f[0] != frames || f[1] != frames || f[2] != frames)
      problems += element + ": value " + std::to_string(f[0]) + ", step " + std::to_string(f[1]) +
                  ", time " + std::to_string(f[2]) + " frames (expected " + std::to_string(frames) +
                  "); ";
  return problems;
}

}  // namespace lantern::testing
