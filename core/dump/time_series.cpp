#include "core/dump/time_series.h"

#include <algorithm>
#include <numeric>

namespace lantern {
namespace {

constexpr hsize_t kStepChunk = 256;  // step/time: one small chunk holds many frames

// An extensible dataset with first axis 0 frames (unlimited) and fixed inner dimensions.
H5Handle create_extensible(hid_t group, const char *name, const std::vector<hsize_t> &inner,
                           hid_t type, const std::vector<hsize_t> &chunk, const std::string &what) {
  std::vector<hsize_t> dims{0}, max{H5S_UNLIMITED};
  dims.insert(dims.end(), inner.begin(), inner.end());
  max.insert(max.end(), inner.begin(), inner.end());
  const H5Handle space =
      own_space(H5Screate_simple(int(dims.size()), dims.data(), max.data()), what + ": dataspace");
  const H5Handle dcpl = own_plist(H5Pcreate(H5P_DATASET_CREATE), what + ": property list");
  h5_check(H5Pset_chunk(dcpl.get(), int(chunk.size()), chunk.data()), what + ": chunking");
  // Every element of a frame is written before it is read; skipping fills saves a full pass.
  h5_check(H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER), what + ": fill time");
  return own_dataset(
      H5Dcreate2(group, name, type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
      what + ": create");
}

// Grows `dataset` to frame + 1 frames and writes one block of it: start/count over all axes.
void write_block(hid_t dataset, hsize_t frame, const std::vector<hsize_t> &inner,
                 const std::vector<hsize_t> &start, const std::vector<hsize_t> &count,
                 hid_t mem_type, const void *data, hid_t dxpl, const std::string &what) {
  std::vector<hsize_t> dims{frame + 1};
  dims.insert(dims.end(), inner.begin(), inner.end());
  h5_check(H5Dset_extent(dataset, dims.data()),
           what + ": extend to " + std::to_string(frame + 1) + " frames");
  const H5Handle file_space = own_space(H5Dget_space(dataset), what + ": dataspace");
  const hsize_t elements =
      std::accumulate(count.begin(), count.end(), hsize_t{1}, std::multiplies<hsize_t>());
  const hsize_t one = 1;
  // A rank with nothing to write still takes part in the collective write, selecting nothing.
  const H5Handle mem_space =
      own_space(H5Screate_simple(1, elements ? &elements : &one, nullptr), what + ": memspace");
  if (elements == 0) {
    H5Sselect_none(file_space.get());
    H5Sselect_none(mem_space.get());
  } else {
    h5_check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                                 count.data(), nullptr),
             what + ": select");
  }
  static const char kDummy = 0;
  h5_check(H5Dwrite(dataset, mem_type, mem_space.get(), file_space.get(), dxpl,
                    elements ? data : &kDummy),
           what + ": write");
}

}  // namespace

TimeSeries::TimeSeries(hid_t parent, const std::string &name, std::vector<hsize_t> inner,
                       hid_t file_type, hsize_t chunk_rows)
    : name_(name), inner_(std::move(inner)) {
  group_ = own_group(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                     name + ": create group");
  std::vector<hsize_t> chunk{1};
  chunk.insert(chunk.end(), inner_.begin(), inner_.end());
  chunk[1] = std::max<hsize_t>(1, std::min(chunk[1], chunk_rows));
  value_ = create_extensible(group_.get(), "value", inner_, file_type, chunk, name + "/value");
  step_ = create_extensible(group_.get(), "step", {}, H5T_STD_I64LE, {kStepChunk}, name + "/step");
  time_ = create_extensible(group_.get(), "time", {}, H5T_IEEE_F64LE, {kStepChunk}, name + "/time");
}

void TimeSeries::append(hsize_t frame, hsize_t row_offset, hsize_t rows, hid_t mem_type,
                        const void *data, hid_t dxpl, bool write_step_time, int64_t step,
                        double time) {
  std::vector<hsize_t> start{frame, row_offset}, count{1, rows};
  for (size_t i = 1; i < inner_.size(); ++i) {
    start.push_back(0);
    count.push_back(inner_[i]);
  }
  write_block(value_.get(), frame, inner_, start, count, mem_type, data, dxpl, name_ + "/value");
  const std::vector<hsize_t> at{frame}, n{write_step_time ? hsize_t{1} : hsize_t{0}};
  write_block(step_.get(), frame, {}, at, n, H5T_NATIVE_INT64, &step, dxpl, name_ + "/step");
  write_block(time_.get(), frame, {}, at, n, H5T_NATIVE_DOUBLE, &time, dxpl, name_ + "/time");
}

void write_string_attribute(hid_t object, const std::string &name,
                            const std::vector<std::string> &values, bool scalar) {
  size_t width = 1;
  for (const auto &v : values) width = std::max(width, v.size() + 1);
  const H5Handle type = own_type(H5Tcopy(H5T_C_S1), name + ": string type");
  h5_check(H5Tset_size(type.get(), width), name + ": string size");
  h5_check(H5Tset_strpad(type.get(), H5T_STR_NULLTERM), name + ": string padding");
  std::vector<char> packed(width * values.size(), '\0');
  for (size_t i = 0; i < values.size(); ++i)
    std::copy(values[i].begin(), values[i].end(), packed.begin() + i * width);
  const hsize_t n = values.size();
  const H5Handle space = own_space(
      scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), name + ": dataspace");
  const H5Handle attr =
      own_attr(H5Acreate2(object, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
               name + ": create attribute");
  h5_check(H5Awrite(attr.get(), type.get(), packed.data()), name + ": write attribute");
}

void write_int_attribute(hid_t object, const std::string &name, const std::vector<int32_t> &values,
                         bool scalar) {
  const hsize_t n = values.size();
  const H5Handle space = own_space(
      scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), name + ": dataspace");
  const H5Handle attr = own_attr(
      H5Acreate2(object, name.c_str(), H5T_STD_I32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
      name + ": create attribute");
  h5_check(H5Awrite(attr.get(), H5T_NATIVE_INT32, values.data()), name + ": write attribute");
}

}  // namespace lantern
