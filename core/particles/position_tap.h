// A stage that reads every particle's position once a step can share that read with another
// pass that streams them anyway (the bricks' refit): the pass hands it the positions stripe by
// stripe, while they are still in cache, instead of the stage reading them from memory again.
// Why: on the 1 M-atom LJ frame (2 ranks, Intel Xeon) object-space ambient occlusion spent about
// 1.5 ms of its 2.8 ms deposit a rank reading the 12 MB of positions the refit had just read;
// handed them stripe by stripe, the stage went from 13.6-13.8 % to 9.1-9.4 % of the step
// (tests/bench/cues/results/object_ao_refit_tap_ab.txt).
//
// Ownership: the pass borrows the tap for one call. Thread-safety: take() is called from one
// thread at a time. Units: the simulation's lengths.
#pragma once

#include <cstdint>

namespace lantern {

class PositionTap {
 public:
  // Particles [first, end) of the host's positions, stored as x y z doubles one after the other
  // (particle i at xyz[3 i]): stripes in increasing index order, from 0, each once. The pass
  // makes no promise to cover every particle (it hands none where it reads the positions another
  // way): the tap checks what it got. Never throws.
  virtual void take(const double *xyz, int64_t first, int64_t end) = 0;

  // Milliseconds spent in take(), added by the pass that calls it (so that the pass's own time
  // can be told apart from the tap's).
  double ms = 0.0;

 protected:
  ~PositionTap() = default;
};

}  // namespace lantern
