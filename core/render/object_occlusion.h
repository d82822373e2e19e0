// Object-space ambient occlusion (after Grottel et al., "Object-Space Ambient Occlusion for
// Molecular Dynamics", PacificVis 2012): one darkening factor per particle, from how much of the
// space around it is filled, applied to its colour before drawing, so the CPU raster and OpenGL
// both show it and it does not depend on the view.
//
// The measure is the particle's occupancy o: the density of drawn particles around it, smoothed
// over about half the ambient-occlusion radius, relative to the bulk density of the scene. A
// particle deep inside a solid has o = 1; one on a flat open face sees half-space, o = o_face
// (a little over 1/2: its own layer counts); in a crease, a step between blocks, a pit or on the
// wall of a void more of the space around it is filled, o > o_face. Its colour is scaled by
//   1 - strength x clamp((o - o_face) / (1 - o_face), 0, 1),
// so flat faces, edges and corners keep their colour, a 90-degree crease darkens by about
// o_face x strength, and buried particles by the full strength.
//
//   - The volume: nodes on the lattice of multiples of `cell` = radius / 2 (wider by factors of
//     kOcclusionCellWidening where that would exceed `max_nodes` nodes), over the global
//     particle bounds. So the nodes stay put while the bounds move a little from step to step,
//     and the deposit can share the bricks' refit's read of the positions (take_tapped()).
//     Every rank deposits its drawn particles (kept by the mask, not cut away by an enabled cut
//     plane) on the 8 nodes around each, with trilinear weights in 1/16 per axis (so a
//     crystal's lattice does not alias against the nodes); the integer deposits are summed over
//     ranks (each rank sums, smooths and bins only its own slab of planes of z, from the planes
//     the other ranks' particles reach, and the slabs' enclosures are gathered), so the volume,
//     and every factor, is the same for any split of the particles.
//   - Smoothing: the separable filter 1 4 6 4 1 along each axis (exact, in integers); a particle's
//     value is the trilinear interpolation of the smoothed nodes at its centre.
//   - The bulk density: the smoothed value below which kOcclusionBulkQuantile of the particles
//     lie (a histogram of the nodes weighted by their deposits): the density inside the solid or
//     liquid that most particles belong to, not the fullest node (which lattice aliasing and
//     compressed regions push up, leaving every visible particle below a darkening threshold).
//   - o_face: the same deposit, filter and interpolation applied in one dimension to layers of
//     particles spaced by the bulk's mean spacing (density^(-1/3)), at the outermost layer,
//     averaged over the layers' offset to the nodes: what a flat face of the bulk gives. The mean
//     spacing is at least the layer spacing of a cubic, fcc or bcc crystal's common faces, so
//     such faces come out at or below o_face: they do not darken.
//
// Units: simulation lengths. Ownership: a value; one kept from frame to frame and built again
// reuses its buffers (no allocation or page faults after the first). Thread-safety: factor() is
// const and may run on several threads at once.
#pragma once

#include <mpi.h>

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/common/status.h"
#include "core/common/uninitialized_buffer.h"
#include "core/config/config.h"
#include "core/culling/cut_planes.h"
#include "core/particles/global_extent.h"
#include "core/particles/particle_arrays.h"

namespace lantern {

namespace object_occlusion_detail {  // object_occlusion.cpp
struct NodeGrid;
struct NodeWeights;
}  // namespace object_occlusion_detail

// Node spacing, in ambient-occlusion radii (before `max_nodes` widens it).
inline constexpr double kOcclusionCellPerRadius = 0.5;
// The share of particles whose surroundings are at most as dense as the bulk.
inline constexpr double kOcclusionBulkQuantile = 0.8;
// The factor the node spacing grows by, as often as needed, to keep within `max_nodes`:
// 2^(1/16).
inline constexpr double kOcclusionCellWidening = 1.0442737824274138;

class OcclusionVolume {
 public:
  // Collective over comm: deposits this rank's drawn particles and sums the deposits over
  // ranks. `radius`: the ambient-occlusion radius (> 0). `threads`: how many threads (this one
  // included) may share the deposit, each on quads of its own that are then added up (integers:
  // the same volume at any count). `max_nodes`: the most nodes (at least 8; the spacing widens
  // past radius / 2 to keep within it). Returns OK or kMpi (the same on every rank).
  Status build(MPI_Comm comm, const ParticleArrays &particles, const Extent &global,
               const std::vector<CutPlane> &cuts, double radius, double strength, int threads = 1,
               int64_t max_nodes = kDefaultAoMaxNodes);

  // Sharing the bricks' refit's read of the positions, for one step. arm_tap(): true when the
  // last build drew its arrays' particles without a group (all of them, or all its cutting planes
  // left); then this step's deposit goes on last step's grid, a node wider on every side, as
  // take_tapped() hands it the positions: all of them, in stripes of consecutive indices from 0
  // (BrickOptions::tap, which calls it while the refit has them in cache), of which it deposits
  // those the last build's planes leave. The refit's threads hand their stripes at once,
  // each as a part (begin_tapped_parts(), then take_tapped() of each part on its thread, part
  // p's stripes after part p - 1's) onto quads of its own. build() uses that deposit when this
  // step's grid lies inside that grid, its cutting planes are the last build's and every
  // particle came, finite (the same sums: the same volume), and deposits on its own otherwise. An
  // armed tap lives until the next build() or arm_tap(). Thread-safety: take_tapped() of different
  // parts may run at once.
  bool arm_tap();
  void begin_tapped_parts(int parts);
  void take_tapped(int part, const double *xyz, int64_t first, int64_t end);
  // Whether the last build() used a tapped deposit, and the time take_tapped() spent for it (ms;
  // part of the ambient-occlusion stage's cost, though spent within the refit).
  bool last_build_tapped() const { return last_tapped_; }
  double last_tap_ms() const { return last_tap_ms_; }

  // The colour factor in [1 - strength, 1] of a particle at x (a drawn one: inside the bounds).
  float factor(const glm::dvec3 &x) const;

  // The occupancy o of a particle at x, and the terms of the factor (tests, diagnostics).
  double occupancy(const glm::dvec3 &x) const;
  double face_occupancy() const { return face_; }
  double node_spacing() const { return cell_; }
  // The bulk density, in particles per node cell (cell^3).
  double bulk_per_cell() const { return bulk_; }
  // The node grid (x, y, z counts; its first node at node_origin() cells from the coordinates'
  // zero along each axis, an integer) and a copy of the enclosure per node, x fastest (empty
  // where nothing darkens): tests.
  std::array<int, 3> node_counts() const { return n_; }
  std::array<double, 3> node_origin() const { return {origin_[0], origin_[1], origin_[2]}; }
  std::vector<float> enclosure_nodes() const { return {enclosure_.begin(), enclosure_.end()}; }

 private:
  size_t index(int x, int y, int z) const {
    return (size_t(z) * size_t(n_[1]) + size_t(y)) * size_t(n_[0]) + size_t(x);
  }
  // Planes of z [first, end).
  struct Planes {
    int first = 0, end = 0;
    int count() const { return end - first; }
    bool empty() const { return end <= first; }
  };
  // The nodes a deposit lays its quads out on: node i of an axis is lattice node origin + i.
  struct QuadGrid {
    double origin[3] = {0.0, 0.0, 0.0};
    int n[3] = {2, 2, 2};
  };
  void set_grid(const Extent &global, double radius, int64_t max_nodes);
  QuadGrid volume_grid() const;
  // Where the volume's node 0 lies in quad_grid_, per axis (>= 0 whenever the quads are read).
  std::array<int, 3> quad_offset() const;
  // One part's deposits on quads of nodes (see the .cpp): 32-bit sums per node and its
  // neighbours, the 64-bit sums of earlier particles where more than 32 bits would be needed
  // (else empty), the quads' planes zeroed so far (of quad_grid_; the others are not even
  // zeroed) and the particles added since the quads were last zeroed.
  struct QuadDeposit {
    UninitializedBuffer<uint32_t> quads;
    std::vector<int64_t> spilled;
    Planes zeroed;
    int64_t on_quads = 0;
  };
  // This rank's deposits in deposits_[0] (the parts' added up), held on the planes `occupied`.
  void deposit(const ParticleArrays &particles, const CutPlanes &planes, int threads,
               Planes *occupied);
  // A deposit on `grid` begun in `parts` parts (deposit(), arm_tap()); located particles added
  // to one; the parts then added to the first.
  void start_deposit(const QuadGrid &grid, int parts);
  object_occlusion_detail::NodeGrid located_grid() const;
  void add_located(QuadDeposit &to, const object_occlusion_detail::NodeWeights &located, int n);
  void merge_parts(int parts);
  // Adds the quads of the planes `d.zeroed` to d.spilled and zeroes them (before a 32-bit sum
  // could overflow).
  void spill(QuadDeposit &d);
  // Zeroes the quads of d's planes [first, end) that d.zeroed does not hold, and widens it.
  void zero_planes(QuadDeposit &d, Planes planes);
  // Nodes [x0, x0 + nx) x [y0, y0 + ny) of d's quads' plane z, from the quads alone.
  void nodes_from_quads(const QuadDeposit &d, int z, size_t x0, size_t y0, size_t nx, size_t ny,
                        int64_t *out) const;
  // This rank's deposits on the nodes of `planes` (zeros off `occupied`) from the quads,
  // plane after plane.
  void nodes_of(Planes occupied, Planes planes, int64_t *out) const;
  Planes slab_of(int rank, int ranks) const;
  Planes reach_of(Planes slab) const;
  Status sum_over_ranks(MPI_Comm comm, Planes occupied, Planes reach,
                        UninitializedBuffer<int64_t> *summed);
  // Fills smoothed_ for `slab`; returns its largest sum. In lanes of T (int32_t where every sum
  // fits, else int64_t).
  template <typename T>
  int64_t smooth(const int64_t *deposits, Planes given, Planes slab);
  void bin_slab(const int64_t *deposits, float top, int64_t *histogram) const;
  // From the histogram of every node and the largest smoothed value, `top`.
  void find_bulk(const std::vector<int64_t> &histogram, float top);
  float enclosure_at(const glm::dvec3 &x) const;

  glm::dvec3 lo_{0.0};                  // node 0: origin_ cells
  double origin_[3] = {0.0, 0.0, 0.0};  // node 0's lattice index, per axis (an integer)
  double cell_ = 1.0, inverse_cell_ = 1.0;
  float strength_ = 0.0f;
  double bulk_ = 0.0;  // particles per cell^3 in the bulk (0: nothing drawn anywhere)
  double face_ = 1.0;  // o_face (1: no darkening at all)
  std::array<int, 3> n_{2, 2, 2};
  // Per node: (smoothed / bulk - o_face) / (1 - o_face), the share of a flat face's open
  // half-space that is filled; empty where nothing darkens.
  UninitializedBuffer<float> enclosure_;
  // The build's scratch, kept between builds (a volume kept from frame to frame allocates and
  // faults in its pages once) and not zero-filled (every element is written before it is read):
  // deposit()'s quads, one deposit per part (as many as a step has used; the first holds the
  // sum), the deposits sent to and received from other ranks, the deposits summed over ranks on
  // the planes this rank smooths, and the smoothed values of its slab.
  std::vector<QuadDeposit> deposits_ = std::vector<QuadDeposit>(1);
  QuadGrid quad_grid_;  // what the deposits are laid out on
  // The tapped deposit of this step (take_tapped()): armed, the spacing it deposits with, and
  // per part: failed (a stripe out of order or a position not finite), its first index and the
  // next one expected (-1: none yet), its time.
  struct PartTap {
    bool failed = false;
    int64_t first = -1, next = -1;
    double ms = 0.0;
  };
  struct TapState {
    bool armed = false;
    double cell = 0.0;
    CutPlanes planes{std::vector<CutPlane>{}};  // the enabled cutting planes it deposits behind
    std::vector<PartTap> parts;
  };
  // Whether the parts of `tap` handed every index of [0, count) once, in order, all finite;
  // the time of the part that took longest in *ms (they ran at once).
  static bool tap_complete(const TapState &tap, int64_t count, double *ms);
  TapState tap_;
  bool tappable_ = false;  // the last build drew every particle of its arrays its planes left
  CutPlanes built_planes_{std::vector<CutPlane>{}};  // the last build's enabled cutting planes
  bool last_tapped_ = false;
  double last_tap_ms_ = 0.0;
  UninitializedBuffer<int64_t> outgoing_, incoming_, summed_;
  UninitializedBuffer<float> smoothed_;
};

}  // namespace lantern
