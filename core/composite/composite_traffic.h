// What compositing moved for one rank: the messages and bytes it handed to MPI and received, and
// the CPU time of its own work (scanning, encoding, merging; not the time spent waiting in MPI,
// which on an oversubscribed machine is mostly other ranks' turn on the core).
//
// For the MPI collectives (reduce64, reduce_scatter) the bytes are what the rank hands to MPI and
// gets back from it, not the traffic inside MPI's reduction tree.
#pragma once

#include <cstdint>

namespace lantern {

struct CompositeTraffic {
  uint64_t bytes_sent = 0, bytes_received = 0;
  uint64_t messages_sent = 0, messages_received = 0;
  double work_cpu_ms = 0.0;
};

// This thread's CPU time in milliseconds (what CompositeTraffic::work_cpu_ms adds up).
double thread_cpu_ms();

}  // namespace lantern
