// One H5MD time-dependent element being written: a group with `value` (first axis = frame,
// extensible), `step` and `time`. Used by H5mdWriter for every particle field and the box.
//
// All calls are collective over the file's communicator (parallel HDF5 changes dataset extents
// collectively); each rank writes its own rows of a frame. Throws Hdf5Error on failure.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/dump/hdf5_handle.h"

namespace lantern {

class TimeSeries {
 public:
  // Creates `name` under `parent`. `inner` are the dimensions of one frame (e.g. {N, 3}); the
  // first inner axis is split across ranks. `chunk_rows` bounds the rows of one chunk.
  TimeSeries(hid_t parent, const std::string &name, std::vector<hsize_t> inner, hid_t file_type,
             hsize_t chunk_rows);

  // Grows the element to frame + 1 frames and writes rows [row_offset, row_offset + rows) of
  // that frame from `data` (rows * the other inner dims elements of mem_type, contiguous).
  // `write_step_time` is true on exactly one rank, which records step and time.
  void append(hsize_t frame, hsize_t row_offset, hsize_t rows, hid_t mem_type, const void *data,
              hid_t dxpl, bool write_step_time, int64_t step, double time);

 private:
  std::string name_;
  std::vector<hsize_t> inner_;
  H5Handle group_, value_, step_, time_;
};

// Writes a scalar or 1-D attribute on an object. `values` of a string attribute are fixed-length.
void write_string_attribute(hid_t object, const std::string &name,
                            const std::vector<std::string> &values, bool scalar);
void write_int_attribute(hid_t object, const std::string &name, const std::vector<int32_t> &values,
                         bool scalar);

}  // namespace lantern
