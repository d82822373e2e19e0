// A stage that reads every particle's position once a step can share that read with another
// pass that streams them anyway (the bricks' refit): the pass hands it the positions stripe by
// stripe, while they are still in cache, instead of the stage reading them from memory again.
// Why: on the 1 M-atom LJ frame (2 ranks, Intel Xeon) object-space ambient occlusion spent about
// 1.5 ms of its 2.8 ms deposit a rank reading the 12 MB of positions the refit had just read;
// handed them stripe by stripe, the stage went from 13.6-13.8 % to 9.1-9.4 % of the step
// (tests/bench/cues/results/object_ao_refit_tap_ab.txt).
//
// Ownership: the pass borrows the tap for one call. Thread-safety: begin() runs before any
// take(); take() of different parts may run at once on different threads, of one part one at a
// time. Units: the simulation's lengths.
#pragma once

#include <cstdint>

namespace lantern {

class PositionTap {
 public:
  // The pass is about to hand stripes to `parts` parts (its threads), on the calling thread.
  virtual void begin(int parts) = 0;

  // Particles [first, end) of the host's positions, stored as x y z doubles one after the other
  // (particle i at xyz[3 i]), handed to part `part` (< the parts of begin()): each part's stripes
  // in increasing index order, each once, and part p's after part p - 1's, so that the parts
  // in order cover the indices from 0. The pass makes no promise to cover every particle (it
  // hands none where it reads the positions another way): the tap checks what it got. Never
  // throws.
  virtual void take(int part, const double *xyz, int64_t first, int64_t end) = 0;

  // Milliseconds spent in take() by the part that spent most, added by the pass that calls it
  // once its parts have joined: about the wall time the tap added (so that the pass's own time
  // can be told apart from the tap's).
  double ms = 0.0;

 protected:
  ~PositionTap() = default;
};

}  // namespace lantern
