// Runs the HDF5 calls of one parallel file so that a failure on one rank never leaves the other
// ranks waiting in a collective call.
//
// Parallel HDF5 (MPI-IO, collective metadata and transfers) needs every rank to make the same
// collective calls in the same order. A rank whose local work fails (a hyperslab selection, an
// allocation, a pre-check of the file) must therefore not simply skip ahead: CollectiveCalls
// keeps its failure pending, and before each collective call all ranks agree on the outcome so
// far (one MPI_Allreduce). If any rank failed, every rank throws the same Hdf5Error (the message
// of the lowest failing rank) instead of entering the call. A collective call that fails on one
// rank (e.g. a write on a full disk) has still been made on every rank; its failure is agreed
// at the next collective call or at settle(). After an agreed failure the file must not see
// further collective I/O except its close.
//
// Limits: a failure *inside* HDF5 that makes one rank leave a collective call before its peers
// (HDF5's own internal collectives) is out of Lantern's reach.
// Not thread-safe; one object per sequence of calls, used by every rank of `comm`.
#pragma once

#include <mpi.h>

#include <exception>
#include <string>
#include <utility>

#include "core/common/injected_fault.h"
#include "core/dump/hdf5_handle.h"

namespace lantern {

class CollectiveCalls {
 public:
  explicit CollectiveCalls(MPI_Comm comm) : comm_(comm) {}

  // Local work (no communication): runs fn unless a failure is pending; a Hdf5Error or other
  // std::exception it throws becomes the pending failure.
  template <typename F>
  void local(const std::string &what, F &&fn) {
    if (!pending_.empty()) return;
    if (take_injected_fault(what)) {
      pending_ = what + " (injected fault)";
      return;
    }
    capture(std::forward<F>(fn));
  }

  // A collective HDF5 call: first agrees on everything pending (throws the agreed Hdf5Error on
  // every rank if any rank failed), then runs fn on every rank. fn's failure stays pending until
  // the next agreement. An injected fault is reported after fn ran, as a failed write would be.
  template <typename F>
  void collective(const std::string &what, F &&fn) {
    settle();
    capture(std::forward<F>(fn));
    if (pending_.empty() && take_injected_fault(what)) pending_ = what + " (injected fault)";
  }

  // Collective: agrees on the pending failures; throws the agreed Hdf5Error on every rank if any.
  void settle();

 private:
  template <typename F>
  void capture(F &&fn) {
    try {
      fn();
    } catch (const std::exception &e) {  // Hdf5Error, or bad_alloc from a buffer
      pending_ = e.what();
    }
  }

  MPI_Comm comm_;
  std::string pending_;  // this rank's first failure since the last agreement; "" when none
};

}  // namespace lantern
