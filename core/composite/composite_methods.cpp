#include "core/composite/composite_methods.h"

#include <algorithm>

namespace lantern {
namespace {

size_t ceil_div(size_t a, size_t b) {
  return (a + b - 1) / b;
}

}  // namespace

void prepare_scratch(CompositeMethod method, size_t pixels, int ranks, size_t chunk_pixels,
                     MethodScratch &s) {
  const size_t chunk = std::max<size_t>(1, std::min(chunk_pixels, pixels));
  switch (method) {
    case CompositeMethod::kReduce64:
      s.packed.resize(chunk);
      break;
    case CompositeMethod::kReduceScatter: {
      // Each chunk is padded to a multiple of the rank count; every rank gets one block.
      const size_t block = ceil_div(chunk, size_t(ranks));
      s.packed.resize(block * size_t(ranks));
      s.block.resize(block);
      break;
    }
    case CompositeMethod::kBinarySwap:
    case CompositeMethod::kDirectSend: {
      // Frames are merged in place; only a partner's segment (at most one chunk, and at most
      // kExchangeSegmentPixels) is received. Binary swap's largest message is half the frame,
      // direct send's 1/p of it.
      const size_t segment =
          std::max<size_t>(1, std::min({ceil_div(pixels, 2), chunk, kExchangeSegmentPixels}));
      s.depth.resize(segment);
      s.rgba.resize(4 * segment);
      break;
    }
    case CompositeMethod::kAuto:
    case CompositeMethod::kActivePixels:
      break;
  }
}

Status run_method(CompositeMethod method, MPI_Comm comm, Frame &frame, int root,
                  size_t /*chunk_pixels*/, MethodScratch &scratch, CompositeTraffic *traffic) {
  switch (method) {
    case CompositeMethod::kReduce64:
      return composite_reduce64(comm, frame, root, scratch, traffic);
    case CompositeMethod::kReduceScatter:
      return composite_reduce_scatter(comm, frame, root, scratch, traffic);
    case CompositeMethod::kBinarySwap:
      return composite_binary_swap(comm, frame, root, scratch, traffic);
    case CompositeMethod::kDirectSend:
      return composite_direct_send(comm, frame, root, scratch, traffic);
    case CompositeMethod::kAuto:
    case CompositeMethod::kActivePixels:
      break;
  }
  return {StatusCode::kInternal, "composite: run_method runs the dense methods only"};
}

Status mpi_error(int code, const char *what) {
  if (code == MPI_SUCCESS) return {};
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  return {StatusCode::kMpi, std::string(what) + ": " + std::string(text, size_t(length))};
}

}  // namespace lantern
