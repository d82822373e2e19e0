// The compositing algorithms behind composite_frames (internal to core/composite).
//
// Each method is split in two so that allocation failures can be agreed on before any rank enters
// a collective: prepare_scratch() runs first (it may throw std::bad_alloc), then run_method()
// does only MPI and arithmetic. Both take the same, collectively validated, arguments.
// Scratch is at most about two chunks whatever the frame size, and is kept between frames (its
// capacity only grows), so steady-state frames pay no allocation and no page faults.
#pragma once

#include <mpi.h>

#include <cstddef>
#include <string>

#include "core/common/status.h"
#include "core/common/uninitialized_buffer.h"
#include "core/composite/composite_traffic.h"
#include "core/composite/depth_compositor.h"
#include "core/view/frame.h"

namespace lantern {

// The most pixels binary swap and direct send receive per step (a segment): 256 KiB of depth and
// 256 KiB of colour of scratch, kept between frames. Half a 1024 x 1024 frame in one step kept
// 4 MiB resident between frames (0.8 bytes per particle at 5 M particles per rank) for a buffer
// only compositing uses; segments cost a few more messages of the same total bytes.
inline constexpr size_t kExchangeSegmentPixels = size_t(1) << 16;

struct MethodScratch {
  PackedBuffer packed;                // reductions: one chunk of packed pixels
  PackedBuffer block;                 // reduce-scatter: this rank's reduced block of a chunk
  UninitializedBuffer<float> depth;   // binary swap: one received segment, depth
  UninitializedBuffer<uint8_t> rgba;  // binary swap: one received segment, color
};

// Sizes the buffers for one call; they depend only on (method, pixels, ranks, chunk), so they
// agree on every rank. May throw std::bad_alloc.
void prepare_scratch(CompositeMethod method, size_t pixels, int ranks, size_t chunk_pixels,
                     MethodScratch &scratch);

// Runs one concrete method. Returns OK, kMpi with the MPI error message, or kInternal for kAuto.
// Adds what moved to *traffic.
Status run_method(CompositeMethod method, MPI_Comm comm, Frame &frame, int root,
                  size_t chunk_pixels, MethodScratch &scratch, CompositeTraffic *traffic);

// The methods: OK or kMpi with the MPI error message.
Status composite_reduce64(MPI_Comm comm, Frame &frame, int root, MethodScratch &scratch,
                          CompositeTraffic *traffic);
Status composite_reduce_scatter(MPI_Comm comm, Frame &frame, int root, MethodScratch &scratch,
                                CompositeTraffic *traffic);
Status composite_binary_swap(MPI_Comm comm, Frame &frame, int root, MethodScratch &scratch,
                             CompositeTraffic *traffic);
Status composite_direct_send(MPI_Comm comm, Frame &frame, int root, MethodScratch &scratch,
                             CompositeTraffic *traffic);

// OK for MPI_SUCCESS, else kMpi with "<what>: <MPI error string>".
Status mpi_error(int code, const char *what);

}  // namespace lantern
