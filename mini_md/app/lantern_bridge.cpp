#include "lantern_bridge.h"

#include <cstdio>

#include "md_error.h"

namespace mini_md {

LanternBridge::LanternBridge(const std::string &config, MPI_Comm comm) {
  MPI_Comm_rank(comm, &rank_);
  const lantern_status status = lantern_open(config.c_str(), MPI_Comm_c2f(comm), &ctx_);
  if (status != LANTERN_OK) {
    const std::string message = lantern_error_message(ctx_);
    lantern_close(ctx_);
    ctx_ = nullptr;
    throw MdError("--render: lantern_open failed (status " + std::to_string(status) +
                  "): " + message);
  }
}

LanternBridge::~LanternBridge() {
  if (ctx_ == nullptr) return;
  const lantern_status status = lantern_close(ctx_);
  if (status != LANTERN_OK && rank_ == 0) {
    std::fprintf(stderr, "mini_md: lantern_close failed (status %d)\n", static_cast<int>(status));
  }
}

void LanternBridge::report(const char *call, lantern_status status) {
  ++failures_;
  // lantern_execute returns the same status on every rank: say it once.
  if (call[8] == 'e' && rank_ != 0) return;
  // Lantern keeps the context usable after any error, and an IO error (full disk, missing
  // directory) is retried on later steps, so the simulation goes on; the message says why.
  std::fprintf(stderr, "mini_md: rank %d: %s failed (status %d): %s\n", rank_, call,
               static_cast<int>(status), lantern_error_message(ctx_));
}

void LanternBridge::set_box(const Box &box) {
  const int periodic[3] = {box.periodic[0], box.periodic[1], box.periodic[2]};
  const lantern_status status = lantern_set_box(ctx_, box.lo.data(), box.hi.data(), periodic);
  if (status != LANTERN_OK) report("lantern_set_box", status);
}

void LanternBridge::on_publish(const Atoms &atoms) {
  lantern_particles p{};
  p.count = atoms.nlocal;  // owned atoms only: ghosts follow them in x but are not passed
  p.position = {atoms.x.data(), LANTERN_FLOAT64, static_cast<int64_t>(sizeof(Vec3))};
  p.scalar = {atoms.scalar.data(), LANTERN_FLOAT64, static_cast<int64_t>(sizeof(double))};
  p.type = {atoms.type.data(), LANTERN_INT32, static_cast<int64_t>(sizeof(int32_t))};
  p.id = {atoms.id.data(), LANTERN_INT64, static_cast<int64_t>(sizeof(int64_t))};
  const lantern_status status = lantern_publish(ctx_, &p);
  if (status != LANTERN_OK) report("lantern_publish", status);
}

void LanternBridge::on_step(int64_t step, double time) {
  const lantern_status status = lantern_execute(ctx_, step, time);
  if (status != LANTERN_OK) report("lantern_execute", status);
}

}  // namespace mini_md
