// Bonds for lantern-render: the bond list of a LAMMPS data file (its `Bonds` section: bond id,
// type, atom id, atom id), or per step from a LAMMPS `dump local` of the bonds' atom ids (e.g.
// `compute b all property/local batom1 batom2 btype` dumped as `c_b[1] c_b[2] c_b[3]`: the first
// two columns other than `index` are the atom ids, a third the bond type) or, per frame, from an
// H5MD file's connectivity (frame_source.h; `origin` set), and, per frame, this
// rank's share of the particles with the bonds it draws and the ghost atoms those bonds end at.
//
// Which rank draws a bond, and where: the rank that reads the bond's first atom (as the data file
// lists it) draws the whole bond, from that atom to the image of the second atom closest to it
// along the box's periodic axes (a triclinic box's along c, then b, then a, each image made as
// LAMMPS's border communication shifts a coordinate) - as LAMMPS holds a bond (newton_bond on: on
// its first atom, with the partner's closest image as a ghost) and draws it in `dump image`. A
// second atom read by another rank, or an image of it across a periodic face, is a ghost row after
// the owned ones (lantern_bonds.ghost_count). So lantern-render draws a LAMMPS dump's bonds as
// lantern-lammps drew them in the run, bit for bit, at any rank count. Bonds whose atoms are not
// both in the frame (a dump of a group) are left out and counted.
//
// Ownership: plain values. Thread-safety: none needed (one thread).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/dump/particle_frame.h"

namespace lantern {

struct BondTopology {
  std::vector<int64_t> first_id, second_id, type;  // per bond, as the data file lists it
  // Bonds read from an H5MD dump's connectivity (which names exactly the atoms of its frame):
  // the dataset ("dump.h5: /connectivity/all_bonds/value[2]") and each bond's pair index in it.
  // An atom id missing from the frame is then an error naming them, not a bond left out.
  std::string origin;
  std::vector<int64_t> pair;
};

// The bonds of a run: one list for every frame (a data file) or one per step (a dump local).
struct BondSource {
  BondTopology fixed;
  std::map<int64_t, BondTopology> by_step;
  bool per_step = false;
  // The bonds of `step`, or null when a dump local has none for it.
  const BondTopology *at(int64_t step) const;
};

// Reads the LAMMPS data file or dump local at `path` (a file starting with `ITEM: TIMESTEP` is a
// dump). "" or a message naming the file and line.
std::string read_bond_source(const std::string &path, BondSource *out);

struct BondedShare {
  ParticleFrame frame;  // the owned rows, then the ghost rows (frame.count() counts both)
  int64_t owned = 0;    // rows that are particles; the rest are ghosts
  std::vector<int64_t> first, second, type;  // this rank's bonds: local row indices, bond type
  int64_t skipped = 0;  // bonds with an atom missing from the frame (over all of it)
};

// This rank's `rows` of the whole frame `all` (each at most once; published in this order), with
// its bonds and their ghosts. Needs the frame's atom ids. "" or an error (with an `origin`, one
// naming the pair whose atom is not in the frame).
std::string share_with_bonds(const ParticleFrame &all, const std::vector<int64_t> &rows,
                             const BondTopology &topology, BondedShare *out);

// The rows of the whole frame `all` that hold the atoms `ids` (after the spatial split, this
// rank's atoms), in the order of `ids`. "" or an error naming an id the frame lacks.
std::string rows_of_ids(const ParticleFrame &all, const std::vector<int64_t> &ids,
                        std::vector<int64_t> *rows);

}  // namespace lantern
