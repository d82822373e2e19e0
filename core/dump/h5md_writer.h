// Writes particle frames into one H5MD 1.1 file (layout: h5md_layout.h) with parallel HDF5.
//
// Collective: every rank of the communicator constructs the writer, appends every frame and
// destroys it together. Each rank writes its particles as one hyperslab at its offset (the
// exclusive prefix sum of the counts), so a frame is one collective MPI-IO write per field.
// The particle count N is fixed per file (set by the first frame): H5MD stores fixed-size frames
// and Lantern does not pad. After every frame the file is flushed, so a crash later leaves a
// valid file with every completed frame. HDF5 failures are returned as kIo with HDF5's message
// (the Hdf5Error of hdf5_handle.h stays inside the writer).
#pragma once

#include <mpi.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/dump/box.h"
#include "core/dump/hdf5_handle.h"
#include "core/dump/time_series.h"
#include "core/particles/particle_arrays.h"

namespace lantern {

// The optional per-particle fields a file holds (position is always there).
struct DumpFields {
  bool species = false;  // the published `type`
  bool id = false;
  bool scalar = false;
  bool radius = false;
};

// What is fixed when the file is created.
struct DumpLayout {
  int64_t global_count = 0;  // N, particles per frame over all ranks
  bool single_precision = false;
  DumpFields fields;
  std::array<bool, 3> periodic{false, false, false};
};

// One rank's part of one frame.
struct DumpFrame {
  const ParticleArrays *particles = nullptr;
  // The particles written, by index, in order; null: all of them (with a group, its members).
  const std::vector<int64_t> *rows = nullptr;
  int64_t offset = 0;  // global index of this rank's first particle
  int64_t step = 0;
  double time = 0.0;
  Box box;  // rank 0's box is the one recorded
};

class H5mdWriter {
 public:
  // Collective. Creates `path` (replacing an existing file) and its H5MD structure, into *out.
  // On failure returns kIo and leaves *out alone.
  static Status create(MPI_Comm comm, const std::string &path, const DumpLayout &layout,
                       std::unique_ptr<H5mdWriter> *out);
  H5mdWriter(const H5mdWriter &) = delete;
  H5mdWriter &operator=(const H5mdWriter &) = delete;

  // Collective. Appends one frame and flushes the file. OK or kIo.
  Status append(const DumpFrame &frame);

  const DumpLayout &layout() const { return layout_; }
  const std::string &path() const { return path_; }
  int64_t frames() const { return static_cast<int64_t>(frames_); }

 private:
  H5mdWriter(const std::string &path, const DumpLayout &layout) : path_(path), layout_(layout) {}
  // The steps of create() and append(); they throw Hdf5Error.
  void create_file(MPI_Comm comm);
  void write_frame(const DumpFrame &frame);
  void write_metadata();
  void create_elements();

  std::string path_;
  DumpLayout layout_;
  int rank_ = 0;
  hsize_t frames_ = 0;
  H5Handle file_;  // declared first: closed after every dataset below
  H5Handle dxpl_;  // collective transfers
  H5Handle particles_;
  std::optional<TimeSeries> position_, species_, id_, scalar_, radius_, edges_, offset_;
};

}  // namespace lantern
