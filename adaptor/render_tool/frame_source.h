// The input of lantern-render: an H5MD file or a LAMMPS text dump, behind one interface, chosen
// by the file's first bytes (the HDF5 signature or not).
#pragma once

#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

#include "bond_topology.h"
#include "core/dump/particle_frame.h"

namespace lantern {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual const std::vector<FrameInfo> &frames() const = 0;
  // Reads particles [begin, end) of frame `index`; "" or a message naming the file.
  virtual std::string read(size_t index, int64_t begin, int64_t end, ParticleFrame *out) const = 0;
  // Whether the input records bonds (an H5MD file's connectivity), and those of frame `index`
  // (ids; no bond types): "" or a message naming the file and dataset.
  virtual bool has_bonds() const { return false; }
  virtual std::string read_bonds(size_t /*index*/, BondTopology *out) const {
    *out = BondTopology{};
    return {};
  }
};

// Collective over comm (H5MD files are opened with MPI-IO). "" and *out, or an error.
std::string open_frame_source(const std::string &path, MPI_Comm comm,
                              std::unique_ptr<FrameSource> *out);

}  // namespace lantern
