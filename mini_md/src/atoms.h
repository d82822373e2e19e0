// Atoms: this rank's atoms, owned ones first, then ghosts (periodic images and copies of
// neighbouring ranks' atoms). Interleaved x[N][3] layout; ghosts only carry x, f and id because
// that is all the pair loop reads or writes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "vec3.h"

namespace mini_md {

struct Atoms {
  std::vector<Vec3> x;         // positions, owned + ghosts
  std::vector<Vec3> f;         // forces, owned + ghosts (ghost forces go back to their owners)
  std::vector<Vec3> v;         // velocities, owned only
  std::vector<int64_t> id;     // global ids (1-based), owned + ghosts
  std::vector<int32_t> type;   // atom types, owned only
  std::vector<double> scalar;  // per-atom kinetic energy for rendering, owned only
  std::vector<Vec3> x_build;   // positions at the last neighbour build, owned only
  int nlocal = 0;
  int nghost = 0;

  int ntotal() const { return nlocal + nghost; }
  // Appends one owned atom; only valid while there are no ghosts.
  void add_owned(const Vec3 &pos, const Vec3 &vel, int64_t gid, int32_t t);
  // Drops all ghosts and trims the ghost-carrying arrays to the owned atoms.
  void clear_ghosts();
  // Resizes the ghost-carrying arrays for `n` ghosts appended after the owned atoms.
  void resize_ghosts(int n);
  // Removes owned atom i by moving the last owned atom into its slot (no ghosts present).
  void remove_owned(int i);
  // Reorders owned atoms: new slot k takes old atom order[k] (no ghosts present).
  void permute_owned(const std::vector<int> &order);
};

}  // namespace mini_md
