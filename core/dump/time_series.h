// One H5MD time-dependent element being written: a group with `value` (first axis = frame,
// extensible), `step` and `time`. Used by H5mdWriter for every particle field, the box and the
// particle count.
//
// A per-particle element's `value` has a second axis, the particle, that is extensible too: a
// frame with more particles than any before grows it, and the rows a frame does not use hold the
// dataset's fill value (declared in the file: NaN for real fields, -1 for integer ones; the
// H5MD convention for a time-dependent particle number). Fills are written explicitly (the
// datasets never pre-fill, so a run whose count never changes writes each byte once).
//
// Every call is made by every rank of the file's communicator in the same order, through
// CollectiveCalls (a failure on one rank is agreed before the next collective call); each rank
// writes its own rows of a frame. Throws Hdf5Error (the same on every rank) on failure.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

#include "core/dump/collective_calls.h"
#include "core/dump/hdf5_handle.h"

namespace lantern {

class TimeSeries {
 public:
  // Creates `name` under `parent` (collective). `inner` are the dimensions of one frame (e.g.
  // {N, 3}); with `per_particle` the first inner axis is the particle axis: split across ranks,
  // extensible, filled where unused. `chunk_rows` is the chunk size along that axis.
  TimeSeries(CollectiveCalls &calls, hid_t parent, const std::string &name,
             std::vector<hsize_t> inner, hid_t file_type, hsize_t chunk_rows, bool per_particle);

  // Opens the element `name` under `parent` as an earlier run wrote it (dump.mode: append), to
  // append after its frames; the inner dimensions and the fill (integer or real) come from the
  // file. Collective.
  struct Existing {};
  TimeSeries(Existing, CollectiveCalls &calls, hid_t parent, const std::string &name,
             bool per_particle);

  // Grows the element to frame + 1 frames (and a per-particle element to `particles` rows, when
  // that is more than it has: earlier frames get fill rows) and writes rows [row_offset,
  // row_offset + rows) of that frame from `data` (rows * the other inner dims elements of
  // mem_type, contiguous). `write_step_time` is true on exactly one rank, which records step and
  // time. The caller writes every row of the frame up to `particles`, fills included.
  void append(CollectiveCalls &calls, hsize_t frame, hsize_t particles, hsize_t row_offset,
              hsize_t rows, hid_t mem_type, const void *data, hid_t dxpl, bool write_step_time,
              int64_t step, double time);

  // Rows of a per-particle element's `value` (its second axis); 0 for other elements.
  hsize_t rows() const { return per_particle_ && !inner_.empty() ? inner_[0] : 0; }
  // Elements per row of `value` (3 for a vector field, 1 for a scalar one).
  hsize_t row_size() const;

 private:
  std::string name_;
  std::vector<hsize_t> inner_;
  bool per_particle_ = false;
  bool integer_ = false;  // fill -1 (integer file type) or NaN (real)
  H5Handle group_, value_, step_, time_;
};

// Writes a scalar or 1-D attribute on an object. `values` of a string attribute are fixed-length.
void write_string_attribute(hid_t object, const std::string &name,
                            const std::vector<std::string> &values, bool scalar);
void write_int_attribute(hid_t object, const std::string &name, const std::vector<int32_t> &values,
                         bool scalar);

}  // namespace lantern
