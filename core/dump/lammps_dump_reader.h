// Reads LAMMPS text dumps (`dump atom`, `dump custom`): the format LAMMPS users already have.
//
// A frame is (ITEM: UNITS and ITEM: TIME may come first, as LAMMPS writes them):
//   ITEM: TIMESTEP / <step>            (ITEM: TIME / <time> optional; else time = step)
//   ITEM: NUMBER OF ATOMS / <N>
//   ITEM: BOX BOUNDS [xy xz yz] pp pp pp / 3 lines "lo hi [tilt]"
//   ITEM: ATOMS <column names> / N lines
// Positions come from the first complete set of x y z, xu yu zu, xs ys zs or xsu ysu zsu
// (scaled ones are unscaled with the box, triclinic included; a triclinic frame's box is the box
// itself - origin, edge lengths and tilts - not the bounds LAMMPS writes around it); `type`, `id`
// and `radius` (or `diameter`) are used when present; other columns are ignored. Other ITEM
// sections before ATOMS are skipped.
//
// open() indexes the file once (headers checked, atom lines counted); read() then parses only the
// requested rows of one frame, so each MPI rank converts its own share. Every error names the
// file and line: "dump.lammpstrj:12: expected 5 columns ...".
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/common/status.h"
#include "core/dump/particle_frame.h"

namespace lantern {

class LammpsDumpReader {
 public:
  // Returns OK and sets *out, or kIo with an error naming the file (and line, for a malformed
  // dump).
  static Status open(const std::string &path, std::unique_ptr<LammpsDumpReader> *out);

  const std::vector<FrameInfo> &frames() const { return infos_; }
  // Parses atoms [begin, end) of frame `index` into *out. OK, kIo naming file and line, or
  // kInvalidArgument for a frame that does not exist.
  Status read(size_t index, int64_t begin, int64_t end, ParticleFrame *out) const;

  // Where a frame's atoms are and how to read them (filled by open()).
  struct Columns {
    std::array<int, 3> position{-1, -1, -1};
    bool scaled = false;
    int type = -1, id = -1, radius = -1;
    bool diameter = false;  // `diameter` column: radius = value / 2
    int needed = 0;         // tokens a line must have: 1 + the largest index used
    std::vector<std::string> names;
  };
  struct Frame {
    FrameInfo info;
    Box box;
    bool has_box = false;
    std::array<double, 3> tilt{0, 0, 0};    // xy, xz, yz (triclinic)
    std::array<double, 3> origin{0, 0, 0};  // xlo, ylo, zlo of the (unbounded) box
    std::array<double, 3> length{0, 0, 0};  // lx, ly, lz
    Columns columns;
    std::streamoff atoms_offset = 0;  // byte offset of the first atom line
    int64_t atoms_line = 0;           // its 1-based line number
  };

 private:
  std::string path_;
  std::vector<Frame> frames_;
  std::vector<FrameInfo> infos_;
};

}  // namespace lantern
