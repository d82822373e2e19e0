// lantern.Context: one lantern_context, opened from Python, publishing NumPy (or any buffer)
// arrays without copying them.
//
// Ownership: the Context owns its lantern_context and closes it in close(), on leaving a `with`
// block, when it is garbage collected, or (for contexts still open) at interpreter exit, before
// mpi4py finalizes MPI. It holds every published array (see ParticlePublication) until the next
// publish or close, so an array dropped by the caller stays valid while Lantern borrows it. A
// limit: holding the array does not stop `a.resize(..., refcheck=False)` from moving its memory
// (refcheck=False skips NumPy's own check for references); Lantern would then read freed memory.
// Closing is collective: close on every rank in the same order.
// Thread-safety: like the C API, one thread at a time (calls hold the GIL).
#pragma once

#include <pybind11/pybind11.h>

#include <array>
#include <cstdint>
#include <optional>

#include "lantern/lantern.h"
#include "particle_publication.h"

namespace lantern_python {

class Context {
 public:
  // config: YAML text or a path (str or os.PathLike); comm: an mpi4py communicator, an integer
  // Fortran handle, or None (MPI_COMM_WORLD). Raises lantern.Error when lantern_open fails.
  Context(const pybind11::object &config, const pybind11::object &comm);
  ~Context();
  Context(const Context &) = delete;
  Context &operator=(const Context &) = delete;

  void publish(const PublishArguments &args);
  // With `tilt` ({xy, xz, yz}): a triclinic box (lantern_set_triclinic_box).
  void set_box(const std::array<double, 3> &low, const std::array<double, 3> &high,
               const std::optional<std::array<bool, 3>> &periodic,
               const std::optional<std::array<double, 3>> &tilt);
  void execute(int64_t step, double time);
  // Flushes and frees the context; a second call does nothing. Raises lantern.Error when an
  // image written in the background could not be written.
  void close();
  bool closed() const { return ctx_ == nullptr; }
  // __exit__: closes; when the block raised (exception_type not None), a close error becomes a
  // RuntimeWarning so the block's exception stays the one raised. Returns false (never swallows).
  bool exit(const pybind11::object &exception_type);
  // Field name -> address of the data handed to lantern_publish (the zero-copy check).
  pybind11::dict published_pointers() const;

  // Closes every context still open (registered with atexit by the module).
  static void close_all();

 private:
  lantern_context *open_context(const char *function) const;
  void check(lantern_status status) const;

  lantern_context *ctx_ = nullptr;
  std::optional<ParticlePublication> published_;
};

}  // namespace lantern_python
