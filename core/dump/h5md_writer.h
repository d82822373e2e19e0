// Writes particle frames into one H5MD 1.1 file (layout: h5md_layout.h) with parallel HDF5.
//
// Collective: every rank of the communicator constructs the writer, appends every frame and
// destroys it together. Each rank writes its particles as one hyperslab at its offset (the
// exclusive prefix sum of the counts), so a frame is one collective MPI-IO write per field.
//
// The particle count may change from frame to frame (atoms evaporate, are deposited, leave an
// open box). Per-particle values are [frames][N_max](...): N_max, the largest count so far,
// grows with the file; a frame's particles fill rows [0, count) in rank order and the rows
// after them hold the fill value (NaN for real fields, -1 for `species` and `id`; -1 in `id` is
// H5MD's "no particle"). /observables/particle_count records each frame's count. With
// layout.fields.bonds, /connectivity/all_bonds records each frame's bonds (pairs of particle ids,
// [frames][B_max][2], padded with -1) the same way, each rank's pairs at its offset.
//
// Failures: every HDF5 call is sequenced by CollectiveCalls, so a failure on one rank is agreed
// before the next collective call and every rank returns the same kIo status with HDF5's
// message (the Hdf5Error of hdf5_handle.h stays inside the writer). After a failed frame the
// caller should destroy the writer (collective close) and write no more: the file keeps every
// completed frame, and the failed one may have left some datasets one frame longer than their
// `step`, which the caller then cuts back on one rank (frame_cut_back.h: shrinking chunked
// datasets in parallel HDF5 can itself leave ranks in different collective calls). After every
// frame the file is flushed, so a failed later step leaves a valid file with every completed
// frame, and so does a process killed part-way through a later frame in the common case (its
// datasets one frame longer, cut back on append). Without HDF5's single-writer mode, though, the
// library may write part of that frame's metadata before its flush, so a kill at the wrong moment
// can leave a file HDF5 cannot open; H5MD over parallel HDF5 offers no stronger guarantee.
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
#include "core/dump/collective_calls.h"
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
  bool bonds = false;  // /connectivity/all_bonds: the bonds, as pairs of particle ids
  bool operator==(const DumpFields &o) const {
    return species == o.species && id == o.id && scalar == o.scalar && radius == o.radius &&
           bonds == o.bonds;
  }
  bool operator!=(const DumpFields &o) const { return !(*this == o); }
};

// What is fixed when the file is created.
struct DumpLayout {
  int64_t first_count = 0;  // particles of the first frame over all ranks (sizes the chunks)
  int64_t first_bonds = 0;  // bonds of the first frame over all ranks (sizes their chunks)
  bool single_precision = false;
  DumpFields fields;
  std::array<bool, 3> periodic{false, false, false};
  // The box's edges as H5MD's matrix of edge vectors ([3][3] a frame) rather than lengths ([3]):
  // set when the first frame's box was triclinic (lantern_set_triclinic_box).
  bool triclinic = false;
};

// One rank's part of one frame.
struct DumpFrame {
  const ParticleArrays *particles = nullptr;
  // The particles written, by index, in order; null: all of them (with a group, its members).
  const std::vector<int64_t> *rows = nullptr;
  int64_t offset = 0;  // global index of this rank's first particle
  int64_t total = 0;   // particles of the frame over all ranks
  int64_t step = 0;
  double time = 0.0;
  Box box;  // rank 0's box is the one recorded
  // With fields.bonds: this rank's bonds as pairs of particle ids (first, second, first, ...),
  // the global index of its first bond and the frame's bonds over all ranks.
  const std::vector<int64_t> *bond_ids = nullptr;
  int64_t bond_offset = 0, bond_total = 0;
};

class H5mdWriter {
 public:
  // Collective. Creates `path` (replacing an existing file) and its H5MD structure, into *out.
  // On failure returns kIo and leaves *out alone.
  // With `replace` false an existing file is an error (dump.mode: create) instead of replaced.
  static Status create(MPI_Comm comm, const std::string &path, const DumpLayout &layout,
                       std::unique_ptr<H5mdWriter> *out, bool replace = true);
  // Collective. Opens `path`, one of Lantern's files with `frames` complete frames of at most
  // `rows` particles in `layout` (existing_dump.h says so; a failed frame cut back first), to
  // append after them (dump.mode: append). On failure returns kIo and leaves *out alone.
  static Status open_existing(MPI_Comm comm, const std::string &path, const DumpLayout &layout,
                              int64_t frames, int64_t rows, std::unique_ptr<H5mdWriter> *out);
  H5mdWriter(const H5mdWriter &) = delete;
  H5mdWriter &operator=(const H5mdWriter &) = delete;

  // Collective. Appends one frame and flushes the file. OK or kIo (the same on every rank).
  Status append(const DumpFrame &frame);

  const DumpLayout &layout() const { return layout_; }
  const std::string &path() const { return path_; }
  int64_t frames() const { return static_cast<int64_t>(frames_); }
  // N_max of the complete frames: the rows of the per-particle datasets before a failed frame.
  int64_t rows() const { return static_cast<int64_t>(particles_); }
  // B_max of the complete frames: the rows of /connectivity/all_bonds/value (0 without bonds).
  int64_t bond_rows() const { return static_cast<int64_t>(bond_rows_); }

 private:
  H5mdWriter(MPI_Comm comm, const std::string &path, const DumpLayout &layout)
      : path_(path), layout_(layout), calls_(comm) {}
  // The steps of create() and append(); they throw Hdf5Error (the same on every rank).
  void create_file(MPI_Comm comm, bool replace);
  void open_file(MPI_Comm comm);
  H5Handle file_access(MPI_Comm comm);  // MPI-IO, collective metadata writes; collective
  void write_frame(const DumpFrame &frame);
  void write_metadata(const std::string &author_name);
  void create_elements();
  void create_bond_list();

  std::string path_;
  DumpLayout layout_;
  CollectiveCalls calls_;
  int rank_ = 0, size_ = 1;
  hsize_t frames_ = 0;     // complete frames in the file
  hsize_t particles_ = 0;  // N_max: rows of the per-particle datasets
  hsize_t bond_rows_ = 0;  // B_max: rows of the bond list
  H5Handle file_;          // declared first: closed after every dataset below
  H5Handle dxpl_;          // collective transfers
  H5Handle particles_group_;
  std::optional<TimeSeries> position_, species_, id_, scalar_, radius_, edges_, offset_, count_,
      bonds_;
};

}  // namespace lantern
