// Reads H5MD files (Lantern's own dumps, and other H5MD writers' files of the same shape) frame
// by frame, each rank reading only its share of the particles with a hyperslab.
//
// Accepted: /h5md with a version attribute; one group under /particles ("all" if present, else
// the first); position as a time-dependent element with value [frames][N][3] and step[frames]
// (time[frames] optional); optional species / id / scalar / radius elements with value
// [frames][N] (or time-independent [N]); an optional box (edges, offset, boundary; edges as
// lengths [3], or as a triclinic box's edge vectors [3][3] in LAMMPS's restricted form).
// Particle counts that vary in time: N is the number of rows; Lantern's
// /observables/particle_count gives each frame's count (its particles are rows [0, count)), and
// rows that hold no particle are skipped: an `id` equal to the id dataset's fill value (the
// H5MD convention), or, without ids, a position of three NaNs where NaN is the declared fill
// value (files padded with NaN).
// Bonds (H5MD 1.1 connectivity): the first pair list under /connectivity whose particles_group
// attribute (an object reference, or the group's name) is the particle group read - a
// time-dependent element {value [frames][B][2], step} or a fixed [B][2] dataset of integer
// particle ids; a pair holding the dataset's fill value is no bond. Lists of other tuples
// (angles) and of other particle groups are ignored. A bond list that cannot be used (wrong shape
// or type, a dangling reference, no id element to match the ids with) does not stop the
// particles from being read: read_bonds() reports it.
// Every problem is reported as "<file>: <what is wrong>".
#pragma once

#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/dump/particle_frame.h"

namespace lantern {

class H5mdReader {
 public:
  // Opens `path` on `comm` (collective: MPI-IO) and checks its structure. Returns OK and sets
  // *out, or kIo with an error message naming the file; a file that some rank cannot read fails
  // on every rank, with the lowest such rank's message.
  static Status open(const std::string &path, MPI_Comm comm, std::unique_ptr<H5mdReader> *out);
  ~H5mdReader();
  H5mdReader(const H5mdReader &) = delete;
  H5mdReader &operator=(const H5mdReader &) = delete;

  // count of each frame: its particles (Lantern's files), or else the rows it may use.
  const std::vector<FrameInfo> &frames() const;
  // Reads rows [begin, end) of frame `index` into *out, without the rows that hold no particle
  // (independent I/O). OK, kIo naming the file, or kInvalidArgument for a frame that does not
  // exist.
  Status read(size_t index, int64_t begin, int64_t end, ParticleFrame *out) const;

  // Whether the file has a bond list for the particle group (usable or not).
  bool has_bonds() const;
  // The bonds of frame `index` as particle ids (first[k], second[k]), pairs of fill values left
  // out. OK; kIo naming the file, the dataset and the pair at fault ("<file>:
  // /connectivity/all_bonds/value[2][17]: negative particle id -4"), or for an unusable list;
  // kInvalidArgument for a frame that does not exist or whose step the list does not record.
  // `pair`, if given, receives each bond's index in the dataset (for messages).
  Status read_bonds(size_t index, std::vector<int64_t> *first, std::vector<int64_t> *second,
                    std::vector<int64_t> *pair = nullptr) const;
  // The file and bond list's dataset with the row of frame `index` ("dump.h5:
  // /connectivity/all_bonds/value[2]"); "" without a usable list.
  std::string bonds_dataset(size_t index) const;

 private:
  struct Impl;
  explicit H5mdReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// True when the file starts with the HDF5 signature (used to tell H5MD from text dumps).
bool has_hdf5_signature(const std::string &path);

}  // namespace lantern
