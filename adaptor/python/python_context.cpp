#include "python_context.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "python_error.h"

namespace py = pybind11;

namespace lantern_python {
namespace {

// Contexts not yet closed, oldest first: closed at interpreter exit in the same order on every
// rank (lantern_close is collective).
std::vector<Context *> &open_contexts() {
  static std::vector<Context *> contexts;
  return contexts;
}

int fortran_handle(const py::object &comm) {
  if (comm.is_none()) return LANTERN_COMM_WORLD;
  if (py::isinstance<py::int_>(comm)) return comm.cast<int>();
  if (py::hasattr(comm, "py2f")) return comm.attr("py2f")().cast<int>();
  throw py::type_error(
      "comm: expected an mpi4py communicator, a Fortran handle (int) or None, got " +
      std::string(py::str(comm.get_type().attr("__name__"))));
}

}  // namespace

Context::Context(const py::object &config, const py::object &comm) {
  const std::string text = py::module_::import("os").attr("fspath")(config).cast<std::string>();
  // The C API reads a NUL-terminated string: whatever follows a NUL would be silently ignored.
  if (const size_t nul = text.find('\0'); nul != std::string::npos)
    throw py::value_error("config: a NUL character at offset " + std::to_string(nul) + " (of " +
                          std::to_string(text.size()) +
                          "); a configuration or its path holds no NUL, and Lantern would ignore "
                          "everything after it");
  lantern_context *ctx = nullptr;
  const lantern_status status = lantern_open(text.c_str(), fortran_handle(comm), &ctx);
  if (status != LANTERN_OK) {
    const std::string message = lantern_error_message(ctx);
    lantern_close(ctx);  // the error-only context
    raise_error(status, message);
  }
  ctx_ = ctx;
  open_contexts().push_back(this);
}

Context::~Context() {
  if (closed()) return;
  try {
    close();
  } catch (const py::error_already_set &e) {
    PyErr_Clear();  // a destructor cannot raise; lantern_close printed what failed
  }
}

lantern_context *Context::open_context(const char *function) const {
  if (closed())
    raise_error(LANTERN_ERR_INVALID_ARGUMENT,
                std::string("Context.") + function + ": the context is closed");
  return ctx_;
}

void Context::check(lantern_status status) const {
  if (status != LANTERN_OK) raise_error(status, lantern_error_message(ctx_));
}

void Context::publish(const PublishArguments &args) {
  lantern_context *ctx = open_context("publish");
  ParticlePublication next = ParticlePublication::describe(args);
  lantern_status status = lantern_publish(ctx, &next.particles());
  // Bonds refer to the particles just published (which forgot the previous bonds).
  if (status == LANTERN_OK && next.has_bonds()) status = lantern_publish_bonds(ctx, &next.bonds());
  // The old arrays were borrowed until this call returned; now Lantern holds the new ones (or,
  // after a failure, none).
  published_ = std::move(next);
  check(status);
}

void Context::set_box(const std::array<double, 3> &low, const std::array<double, 3> &high,
                      const std::optional<std::array<bool, 3>> &periodic,
                      const std::optional<std::array<double, 3>> &tilt) {
  lantern_context *ctx = open_context("set_box");
  int flags[3] = {0, 0, 0};
  if (periodic)
    for (int a = 0; a < 3; ++a) flags[a] = (*periodic)[a] ? 1 : 0;
  check(tilt ? lantern_set_triclinic_box(ctx, low.data(), high.data(), tilt->data(), flags)
             : lantern_set_box(ctx, low.data(), high.data(), flags));
}

void Context::execute(int64_t step, double time) {
  check(lantern_execute(open_context("execute"), step, time));
}

bool Context::exit(const py::object &exception_type) {
  if (exception_type.is_none()) {
    close();
    return false;
  }
  // An exception is leaving the `with` block: it stays the one the caller sees. A failure to
  // close (an image written in the background that could not be) is a warning next to it.
  try {
    close();
  } catch (py::error_already_set &e) {
    const std::string text =
        std::string("lantern: closing the context while an exception propagates failed: ") +
        e.what();
    if (PyErr_WarnEx(PyExc_RuntimeWarning, text.c_str(), 1) != 0) PyErr_Clear();
  }
  return false;
}

void Context::close() {
  if (closed()) return;
  lantern_context *ctx = ctx_;
  ctx_ = nullptr;
  auto &open = open_contexts();
  open.erase(std::remove(open.begin(), open.end(), this), open.end());
  const lantern_status status = lantern_close(ctx);
  published_.reset();  // Lantern no longer borrows the arrays
  // The context and its message are gone: lantern_close printed the details on stderr.
  if (status != LANTERN_OK) {
    const std::string what = lantern_status_string(status);
    raise_error(status, "Context.close: " + what.substr(what.find(": ") + 2) +
                            " (lantern_close printed the details above)");
  }
}

py::dict Context::published_pointers() const {
  py::dict pointers;
  if (published_)
    for (const auto &[name, address] : published_->pointers()) pointers[name.c_str()] = address;
  return pointers;
}

void Context::close_all() {
  const std::vector<Context *> open = open_contexts();  // close() edits the list
  for (Context *context : open) {
    try {
      context->close();
    } catch (const py::error_already_set &e) {
      std::fprintf(stderr, "lantern: closing a context at exit: %s\n", e.what());
    }
  }
}

}  // namespace lantern_python
