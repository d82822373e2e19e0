#include "core/dump/time_series.h"

#include <algorithm>
#include <limits>
#include <numeric>

namespace lantern {
namespace {

constexpr hsize_t kStepChunk = 256;   // step/time: one small chunk holds many frames
constexpr int64_t kIntegerFill = -1;  // H5MD: an `id` equal to the fill value is no particle
const double kRealFill = std::numeric_limits<double>::quiet_NaN();

// An extensible dataset with first axis 0 frames (unlimited) and the inner dimensions; with
// `per_particle` the first inner axis is unlimited too and the dataset declares its fill value.
H5Handle create_extensible(hid_t group, const char *name, const std::vector<hsize_t> &inner,
                           hid_t type, const std::vector<hsize_t> &chunk, bool per_particle,
                           bool integer, const std::string &what) {
  std::vector<hsize_t> dims{0}, max{H5S_UNLIMITED};
  dims.insert(dims.end(), inner.begin(), inner.end());
  max.insert(max.end(), inner.begin(), inner.end());
  if (per_particle) max[1] = H5S_UNLIMITED;
  const H5Handle space =
      own_space(H5Screate_simple(int(dims.size()), dims.data(), max.data()), what + ": dataspace");
  const H5Handle dcpl = own_plist(H5Pcreate(H5P_DATASET_CREATE), what + ": property list");
  h5_check(H5Pset_chunk(dcpl.get(), int(chunk.size()), chunk.data()), what + ": chunking");
  if (per_particle) {
    // Declared for readers (h5py's Dataset.fillvalue, H5MD's "no particle" id); written by
    // Lantern itself where a frame has fewer particles than the dataset has rows.
    h5_check(integer ? H5Pset_fill_value(dcpl.get(), H5T_NATIVE_INT64, &kIntegerFill)
                     : H5Pset_fill_value(dcpl.get(), H5T_NATIVE_DOUBLE, &kRealFill),
             what + ": fill value");
  }
  // Every element of a frame is written before it is read; skipping fills saves a full pass.
  h5_check(H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER), what + ": fill time");
  return own_dataset(
      H5Dcreate2(group, name, type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
      what + ": create");
}

void set_extent(CollectiveCalls &calls, hid_t dataset, const std::vector<hsize_t> &dims,
                const std::string &what) {
  calls.collective(what + ": extend to " + std::to_string(dims[0]) + " frames", [&] {
    h5_check(H5Dset_extent(dataset, dims.data()),
             what + ": extend to " + std::to_string(dims[0]) + " frames");
  });
}

// Writes one block of `dataset` (start/count over all axes; an empty count selects nothing, and
// the rank still takes part in the collective write). The selection is local, the write
// collective.
void write_block(CollectiveCalls &calls, hid_t dataset, const std::vector<hsize_t> &start,
                 const std::vector<hsize_t> &count, hid_t mem_type, const void *data, hid_t dxpl,
                 const std::string &what) {
  H5Handle file_space, mem_space;
  const hsize_t elements =
      std::accumulate(count.begin(), count.end(), hsize_t{1}, std::multiplies<hsize_t>());
  calls.local(what + ": select", [&] {
    file_space = own_space(H5Dget_space(dataset), what + ": dataspace");
    const hsize_t one = 1;
    mem_space =
        own_space(H5Screate_simple(1, elements ? &elements : &one, nullptr), what + ": memspace");
    if (elements == 0) {
      H5Sselect_none(file_space.get());
      H5Sselect_none(mem_space.get());
    } else {
      h5_check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                                   count.data(), nullptr),
               what + ": select");
    }
  });
  static const char kDummy = 0;
  calls.collective(what + ": write", [&] {
    h5_check(H5Dwrite(dataset, mem_type, mem_space.get(), file_space.get(), dxpl,
                      elements ? data : &kDummy),
             what + ": write");
  });
}

}  // namespace

TimeSeries::TimeSeries(CollectiveCalls &calls, hid_t parent, const std::string &name,
                       std::vector<hsize_t> inner, hid_t file_type, hsize_t chunk_rows,
                       bool per_particle)
    : name_(name),
      inner_(std::move(inner)),
      per_particle_(per_particle),
      integer_(H5Tget_class(file_type) == H5T_INTEGER) {
  // One frame per chunk, except for one number per frame (the particle count), which is chunked
  // like step and time.
  std::vector<hsize_t> chunk{inner_.empty() ? kStepChunk : 1};
  chunk.insert(chunk.end(), inner_.begin(), inner_.end());
  if (chunk.size() > 1)
    chunk[1] = std::max<hsize_t>(1, per_particle_ ? chunk_rows : std::min(chunk[1], chunk_rows));
  calls.collective(name + ": create", [&] {
    group_ = own_group(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                       name + ": create group");
    value_ = create_extensible(group_.get(), "value", inner_, file_type, chunk, per_particle_,
                               integer_, name + "/value");
    step_ = create_extensible(group_.get(), "step", {}, H5T_STD_I64LE, {kStepChunk}, false, false,
                              name + "/step");
    time_ = create_extensible(group_.get(), "time", {}, H5T_IEEE_F64LE, {kStepChunk}, false, false,
                              name + "/time");
  });
}

TimeSeries::TimeSeries(Existing, CollectiveCalls &calls, hid_t parent, const std::string &name,
                       bool per_particle)
    : name_(name), per_particle_(per_particle) {
  calls.collective(name + ": open", [&] {
    group_ = own_group(H5Gopen2(parent, name.c_str(), H5P_DEFAULT), name + ": open group");
    value_ = own_dataset(H5Dopen2(group_.get(), "value", H5P_DEFAULT), name + "/value: open");
    step_ = own_dataset(H5Dopen2(group_.get(), "step", H5P_DEFAULT), name + "/step: open");
    time_ = own_dataset(H5Dopen2(group_.get(), "time", H5P_DEFAULT), name + "/time: open");
    const H5Handle space = own_space(H5Dget_space(value_.get()), name + "/value: dataspace");
    const int rank = h5_check(H5Sget_simple_extent_ndims(space.get()), name + "/value: rank");
    std::vector<hsize_t> dims(static_cast<size_t>(std::max(rank, 1)), 0);
    H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
    inner_.assign(dims.begin() + 1, dims.end());
    const H5Handle type = own_type(H5Dget_type(value_.get()), name + "/value: type");
    integer_ = H5Tget_class(type.get()) == H5T_INTEGER;
  });
}

hsize_t TimeSeries::row_size() const {
  // cppcheck-suppress containerOutOfBounds ; begin() + 1 only where inner_ is not empty
  return std::accumulate(inner_.begin() + (inner_.empty() ? 0 : 1), inner_.end(), hsize_t{1},
                         std::multiplies<hsize_t>());
}

void TimeSeries::append(CollectiveCalls &calls, hsize_t frame, hsize_t particles,
                        hsize_t row_offset, hsize_t rows, hid_t mem_type, const void *data,
                        hid_t dxpl, bool write_step_time, int64_t step, double time) {
  const std::string what = name_ + "/value";
  const hsize_t had = per_particle_ ? inner_[0] : 0;
  if (per_particle_) inner_[0] = std::max(had, particles);
  std::vector<hsize_t> dims{frame + 1};
  dims.insert(dims.end(), inner_.begin(), inner_.end());
  set_extent(calls, value_.get(), dims, what);

  std::vector<hsize_t> start(dims.size(), 0), count = dims;
  if (per_particle_ && inner_[0] > had && frame > 0) {
    // The particle axis grew: the new rows of the earlier frames hold no particle. One rank
    // writes them; the others select nothing.
    const hsize_t added = inner_[0] - had;
    std::vector<int64_t> int_fill;
    std::vector<double> real_fill;
    count[0] = write_step_time ? frame : 0;
    count[1] = added;
    start[1] = had;
    const size_t n = static_cast<size_t>(count[0] * added * row_size());
    calls.local(what + ": fill buffer", [&] {
      if (integer_)
        int_fill.assign(n, kIntegerFill);
      else
        real_fill.assign(n, kRealFill);
    });
    write_block(calls, value_.get(), start, count, integer_ ? H5T_NATIVE_INT64 : H5T_NATIVE_DOUBLE,
                integer_ ? static_cast<const void *>(int_fill.data()) : real_fill.data(), dxpl,
                what + " (fill of earlier frames)");
  }

  // The frame's block: this rank's rows of a per-particle element, or the whole frame of
  // another one (box, count) from the rank that passes rows > 0.
  start.assign(dims.size(), 0);
  count = dims;
  start[0] = frame;
  count[0] = 1;
  if (per_particle_) {
    start[1] = row_offset;
    count[1] = rows;
  }
  if (rows == 0) count.assign(count.size(), 0);  // this rank writes nothing of the frame
  write_block(calls, value_.get(), start, count, mem_type, data, dxpl, what);

  const std::vector<hsize_t> frames{frame + 1}, at{frame},
      n{write_step_time ? hsize_t{1} : hsize_t{0}};
  set_extent(calls, step_.get(), frames, name_ + "/step");
  write_block(calls, step_.get(), at, n, H5T_NATIVE_INT64, &step, dxpl, name_ + "/step");
  set_extent(calls, time_.get(), frames, name_ + "/time");
  write_block(calls, time_.get(), at, n, H5T_NATIVE_DOUBLE, &time, dxpl, name_ + "/time");
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
