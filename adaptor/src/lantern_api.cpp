// The C API: argument checks, and a wall that no C++ exception crosses. All real work is in
// lantern::Runtime (core/pipeline/runtime.h).
#include <cstdio>
#include <memory>
#include <new>
#include <optional>
#include <string>

#include "c_translation.h"
#include "core/common/page_allocator.h"
#include "core/pipeline/runtime.h"
#include "lantern/lantern.h"
#include "mpi_bootstrap.h"

struct lantern_context {
  std::unique_ptr<lantern::Runtime> runtime;  // null in an error-only context
  std::string error;
};

namespace {

lantern_status fail(lantern_context *ctx, lantern_status code, std::string message) {
  if (ctx) ctx->error = std::move(message);
  return code;
}

lantern_status report(lantern_context *ctx, const lantern::Status &s) {
  ctx->error = s.message;
  return lantern::to_c(s.code);
}

// Runs f, turning any exception into a status and message on ctx.
template <typename F>
lantern_status guarded(lantern_context *ctx, const char *function, F &&f) {
  try {
    return f();
  } catch (const std::bad_alloc &) {
    return fail(ctx, LANTERN_ERR_OUT_OF_MEMORY, std::string(function) + ": out of memory");
  } catch (const std::exception &e) {
    return fail(ctx, LANTERN_ERR_INTERNAL, std::string(function) + ": internal error: " + e.what());
  } catch (...) {
    return fail(ctx, LANTERN_ERR_INTERNAL, std::string(function) + ": unknown internal error");
  }
}

}  // namespace

extern "C" {

const char *lantern_version(void) {
#define LANTERN_STR2(x) #x
#define LANTERN_STR(x) LANTERN_STR2(x)
  return LANTERN_STR(LANTERN_VERSION_MAJOR) "." LANTERN_STR(LANTERN_VERSION_MINOR) "." LANTERN_STR(
      LANTERN_VERSION_PATCH);
}

lantern_status lantern_open(const char *config, int mpi_comm_f, lantern_context **out) {
  if (out) *out = nullptr;
  std::unique_ptr<lantern_context> ctx;
  try {
    ctx = std::make_unique<lantern_context>();
  } catch (...) {
    return LANTERN_ERR_OUT_OF_MEMORY;
  }
  const lantern_status status = guarded(ctx.get(), "lantern_open", [&]() -> lantern_status {
    MPI_Comm comm = MPI_COMM_NULL;
    // Without a usable communicator there is no one to agree with: this rank alone fails.
    if (auto e = lantern::acquire_mpi(mpi_comm_f, &comm); !e.empty())
      return fail(ctx.get(), LANTERN_ERR_MPI, e);
    // A NULL argument on one rank still takes part in the collective open, so the ranks that
    // passed good ones are not left waiting for it: every rank returns the first failure.
    lantern::Status caller;
    if (!config)
      caller = {lantern::StatusCode::kNullArgument, "config: NULL (give a YAML path or document)"};
    else if (!out)
      caller = {lantern::StatusCode::kNullArgument,
                "out: NULL (give the address of a lantern_context pointer)"};
    return report(ctx.get(),
                  lantern::Runtime::open(config ? config : "", comm, &ctx->runtime, caller));
  });
  if (out) *out = ctx.release();  // owned by the caller until lantern_close
  return status;
}

lantern_status lantern_publish(lantern_context *ctx, const lantern_particles *particles) {
  if (!ctx) return LANTERN_ERR_NULL_ARGUMENT;
  return guarded(ctx, "lantern_publish", [&]() -> lantern_status {
    if (!ctx->runtime)
      return fail(ctx, LANTERN_ERR_INVALID_ARGUMENT, "ctx: this context failed to open");
    if (!particles) return fail(ctx, LANTERN_ERR_NULL_ARGUMENT, "particles: NULL");
    return report(ctx, ctx->runtime->publish(lantern::from_c(*particles)));
  });
}

lantern_status lantern_publish_bonds(lantern_context *ctx, const lantern_bonds *bonds) {
  if (!ctx) return LANTERN_ERR_NULL_ARGUMENT;
  return guarded(ctx, "lantern_publish_bonds", [&]() -> lantern_status {
    if (!ctx->runtime)
      return fail(ctx, LANTERN_ERR_INVALID_ARGUMENT, "ctx: this context failed to open");
    if (!bonds) return fail(ctx, LANTERN_ERR_NULL_ARGUMENT, "bonds: NULL");
    return report(ctx, ctx->runtime->publish_bonds(lantern::from_c(*bonds)));
  });
}

namespace {

// lantern_set_box and lantern_set_triclinic_box (`tilt` null: the axis-aligned box).
lantern_status set_box(lantern_context *ctx, const char *function, const double low[3],
                       const double high[3], const double tilt[3], const int periodic[3]) {
  return guarded(ctx, function, [&]() -> lantern_status {
    if (!ctx->runtime)
      return fail(ctx, LANTERN_ERR_INVALID_ARGUMENT, "ctx: this context failed to open");
    if (!low) return fail(ctx, LANTERN_ERR_NULL_ARGUMENT, "low: NULL");
    if (!high) return fail(ctx, LANTERN_ERR_NULL_ARGUMENT, "high: NULL");
    lantern::Box box;
    box.triclinic = tilt != nullptr;
    for (int a = 0; a < 3; ++a) {
      box.low[a] = low[a];
      box.high[a] = high[a];
      box.tilt[a] = tilt ? tilt[a] : 0.0;
      box.periodic[a] = periodic && periodic[a] != 0;
    }
    return report(ctx, ctx->runtime->set_box(box));
  });
}

}  // namespace

lantern_status lantern_set_box(lantern_context *ctx, const double low[3], const double high[3],
                               const int periodic[3]) {
  if (!ctx) return LANTERN_ERR_NULL_ARGUMENT;
  return set_box(ctx, "lantern_set_box", low, high, nullptr, periodic);
}

lantern_status lantern_set_triclinic_box(lantern_context *ctx, const double low[3],
                                         const double high[3], const double tilt[3],
                                         const int periodic[3]) {
  if (!ctx) return LANTERN_ERR_NULL_ARGUMENT;
  if (!tilt) return fail(ctx, LANTERN_ERR_NULL_ARGUMENT, "tilt: NULL");
  return set_box(ctx, "lantern_set_triclinic_box", low, high, tilt, periodic);
}

lantern_status lantern_execute(lantern_context *ctx, int64_t step, double time) {
  if (!ctx) return LANTERN_ERR_NULL_ARGUMENT;
  return guarded(ctx, "lantern_execute", [&]() -> lantern_status {
    if (!ctx->runtime)
      return fail(ctx, LANTERN_ERR_INVALID_ARGUMENT, "ctx: this context failed to open");
    return report(ctx, ctx->runtime->execute(step, time));
  });
}

lantern_status lantern_reconfigure(lantern_context *ctx, const char *config) {
  if (!ctx) return LANTERN_ERR_NULL_ARGUMENT;
  return guarded(ctx, "lantern_reconfigure", [&]() -> lantern_status {
    if (!ctx->runtime)
      return fail(ctx, LANTERN_ERR_INVALID_ARGUMENT, "ctx: this context failed to open");
    // NULL still enters the collective (as "no text"), so ranks that passed a text are not left
    // waiting: every rank then returns LANTERN_ERR_NULL_ARGUMENT.
    return report(
        ctx, ctx->runtime->reconfigure(config ? std::optional<std::string>(config) : std::nullopt));
  });
}

const char *lantern_error_message(const lantern_context *ctx) {
  if (!ctx) return "ctx: NULL context (lantern_open failed to allocate or was not called)";
  return ctx->error.c_str();
}

const char *lantern_load_summary(const lantern_context *ctx) {
  if (!ctx || !ctx->runtime) return "";
  return ctx->runtime->load_summary().c_str();
}

lantern_status lantern_close(lantern_context *ctx) {
  if (!ctx) return LANTERN_OK;
  std::unique_ptr<lantern_context> owned(ctx);
  lantern_status status = LANTERN_OK;
  try {
    if (ctx->runtime) {
      const lantern::Status s = ctx->runtime->finish();
      // The context (and its message) is gone after close: say what went wrong here.
      if (!s.ok()) std::fprintf(stderr, "lantern: lantern_close: %s\n", s.message.c_str());
      status = lantern::to_c(s.code);
    }
    ctx->runtime.reset();
  } catch (...) {
    status = LANTERN_ERR_INTERNAL;
  }
  owned.reset();
  // The scratch kept lazily freed for the next step goes back to the system now.
  lantern::drop_reused_pages();
  return status;
}

int lantern_version_number(void) {
  return LANTERN_VERSION;
}

const char *lantern_status_string(lantern_status status) {
  // No default: the compiler warns (-Wswitch) when a status is added without a string.
  switch (status) {
    case LANTERN_OK:
      return "LANTERN_OK: success";
    case LANTERN_ERR_NULL_ARGUMENT:
      return "LANTERN_ERR_NULL_ARGUMENT: a required pointer argument was NULL";
    case LANTERN_ERR_INVALID_ARGUMENT:
      return "LANTERN_ERR_INVALID_ARGUMENT: an argument's value is out of range or inconsistent";
    case LANTERN_ERR_CONFIG:
      return "LANTERN_ERR_CONFIG: the configuration is malformed or has an invalid key or value";
    case LANTERN_ERR_IO:
      return "LANTERN_ERR_IO: a file could not be read or written";
    case LANTERN_ERR_GL:
      return "LANTERN_ERR_GL: the OpenGL/OSMesa back end failed";
    case LANTERN_ERR_MPI:
      return "LANTERN_ERR_MPI: an MPI call failed or the communicator is invalid";
    case LANTERN_ERR_OUT_OF_MEMORY:
      return "LANTERN_ERR_OUT_OF_MEMORY: an allocation failed";
    case LANTERN_ERR_INTERNAL:
      return "LANTERN_ERR_INTERNAL: a bug in Lantern (please report the error message)";
  }
  return "unknown lantern_status";
}

}  // extern "C"
