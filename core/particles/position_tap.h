// A stage that reads every particle's position once a step can share that read with another
// pass that streams them anyway (the bricks' refit): the pass hands it the positions stripe by
// stripe, while they are still in cache, instead of the stage reading them from memory again.
// Why: on the 1 M-atom LJ frame (2 ranks, Intel Xeon) object-space ambient occlusion read a
// rank's 12 MB of positions in about 1.5 ms of its 2.1 ms deposit, as long as the refit's own
// read; with the positions in cache the deposit took 0.7 ms.
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
