// What an existing dump file holds, for `dump: {mode: append}`: read on one rank with serial HDF5
// before the run's collective open, so that a restarted run continues the same time series only
// when the file is one of Lantern's H5MD files (h5md_layout.h) with the fields and precision the
// run writes.
//
// Not thread-safe (HDF5 is not, here); never throws.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "core/dump/h5md_writer.h"

namespace lantern {

struct ExistingDump {
  std::string problem;  // "" when appendable, else why not (to follow "dump.file: <path> ")
  int64_t frames = 0;   // complete frames (the length of particle_count/time)
  int64_t rows = 0;     // N_max: rows of the per-particle datasets
  int64_t last_step = 0, last_count = 0;  // of the last complete frame (frames > 0)
  bool single_precision = false;
  DumpFields fields;
  std::array<bool, 3> periodic{false, false, false};
  bool triclinic = false;  // box/edges holds edge vectors ([frames][3][3]), not lengths
};

// Inspects `path`, which exists. Checks that it is Lantern's H5MD layout and that every time
// series has at least `frames` frames in value, step and time (longer ones hold a frame that
// failed part-way: the caller cuts it back before appending).
ExistingDump inspect_dump_file(const std::string &path);

// "position, species, id" (the datasets' names in the file).
std::string fields_text(const DumpFields &fields);

}  // namespace lantern
