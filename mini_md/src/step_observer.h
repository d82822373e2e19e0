// StepObserver: how the physics library reports to an in-situ consumer (the Lantern bridge in
// the mini_md executable) without depending on it.
#pragma once

#include <cstdint>

#include "atoms.h"

namespace mini_md {

class StepObserver {
 public:
  virtual ~StepObserver() = default;
  // After setup and after every rebuild: migration, sorting and ghost growth may have moved or
  // resized the owned arrays, so a borrower must take the new pointers and count.
  virtual void on_publish(const Atoms &atoms) = 0;
  // Once per step (and for step 0) when the step is complete; atoms.scalar holds each owned
  // atom's kinetic energy.
  virtual void on_step(int64_t step, double time) = 0;
};

}  // namespace mini_md
