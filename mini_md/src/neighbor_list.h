// Binned half neighbour list (Verlet list with skin) for Newton's third law.
//
// Atoms (owned and ghost) are counting-sorted into bins of about half the list cutoff; each
// owned atom scans the rows of a 5x5x5 bin stencil that can hold atoms within cutoff + skin. A pair
// is stored once, by the atom with the smaller global id (equal ids: a periodic image of the atom
// itself, ordered by coordinates). Because the rule compares integers, the two ranks that share a
// pair across a subdomain face always agree on which one computes it; the other receives its half
// of the force through the reverse ghost exchange.
//
// Layout: compressed rows (offsets + int32 neighbour indices), one contiguous array, so the force
// loop streams through it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "atoms.h"
#include "vec3.h"

namespace mini_md {

// A regular grid of bins over [lo - pad, hi + pad], with a ring of always-empty bins around it
// so that stencil offsets never leave the grid.
class BinGrid {
 public:
  BinGrid(const Vec3 &lo, const Vec3 &hi, double pad, double target_size, int ring);
  int bin_of(const Vec3 &p) const;
  int bin_count() const { return n_[0] * n_[1] * n_[2]; }
  const std::array<int, 3> &dims() const { return n_; }
  const Vec3 &bin_size() const { return size_; }

 private:
  Vec3 origin_{0, 0, 0};
  Vec3 size_{1, 1, 1};
  Vec3 inv_size_{1, 1, 1};
  std::array<int, 3> n_{1, 1, 1};      // including the ring
  std::array<int, 3> inner_{1, 1, 1};  // without the ring
  int ring_ = 0;
};

class NeighborList {
 public:
  // Rebuilds the list for the owned atoms of `atoms` against owned + ghost atoms within
  // `list_cut` (cutoff + skin). `lo`, `hi`: this rank's subdomain.
  void build(const Atoms &atoms, const Vec3 &lo, const Vec3 &hi, double list_cut);

  int atom_count() const { return static_cast<int>(offsets_.size()) - 1; }
  const int64_t *offsets() const { return offsets_.data(); }
  const int *neighbors() const { return neighbors_.data(); }
  size_t pair_count() const { return neighbors_.size(); }

 private:
  std::vector<int64_t> offsets_{0};
  std::vector<int> neighbors_;
  // Atoms copied in bin order, so each stencil row (five adjacent bins along x) is one
  // contiguous run of positions that the candidate loop streams through.
  std::vector<int> bin_start_;
  std::vector<int> atom_bin_;
  std::vector<Vec3> binned_x_;
  std::vector<int64_t> binned_id_;
  std::vector<int> binned_index_;
};

// A permutation that orders the owned atoms by bin of `list_cut`-sized cells, so that atoms that
// are neighbours in space are neighbours in memory (the pair loop then hits cache). Requires no
// ghosts.
std::vector<int> spatial_sort_order(const Atoms &atoms, const Vec3 &lo, const Vec3 &hi,
                                    double list_cut);

}  // namespace mini_md
