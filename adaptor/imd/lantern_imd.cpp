// lantern-imd HOST:PORT -lantern CONFIG.yaml [options]
//
// Renders a running simulation from another process, through the IMD protocol (imd_protocol.h)
// that LAMMPS (`fix imd`), GROMACS (`mdrun -imdport`) and NAMD serve: the simulation needs no
// code change and no relink. Rank 0 connects, receives every frame on a thread of its own
// (frame_receiver.h), splits its atoms spatially over the ranks (spatial_split.h) and scatters
// them; every rank publishes its part (float32, as IMD sends them) through the C API and
// lantern_execute renders the frame at its step, so a configuration gives the images it gives
// in situ.
//
// It survives the simulation pausing (it waits), ending or disconnecting (a message, exit 0, the
// images written so far intact), and stops cleanly on SIGINT/SIGTERM or after --frames frames,
// telling the simulation it leaves (IMD_DISCONNECT). A bad or hostile stream is an error (exit 1)
// with a message, never a crash or an unbounded allocation. Exit codes: 0, 1 error, 2 usage.
#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "atom_table.h"
#include "command_line/usage_reply.h"
#include "frame_receiver.h"
#include "lantern/lantern.h"
#include "spatial_split.h"

namespace {

using lantern_imd::AtomTable;
using lantern_imd::Event;
using lantern_imd::Frame;

constexpr const char *kUsage =
    "usage: lantern-imd HOST:PORT -lantern CONFIG.yaml [options]\n"
    "       lantern-imd --help | --version\n"
    "  --every N          steps between frames when the stream has no step numbers (LAMMPS: the\n"
    "                     fix imd trate; default 1, or --trate)\n"
    "  --first-step S     step of the first frame without step numbers (default: N)\n"
    "  --trate N          ask the simulation to send a frame every N steps (IMD_TRATE)\n"
    "  --step-offset K    add K to the steps of IMD_ENERGIES records (GROMACS: -1, see README)\n"
    "  --types FILE       atom types and ids: a LAMMPS text dump (id type ...) or H5MD file\n"
    "  --frames K         stop after K frames, leaving the simulation running\n"
    "  --drop-frames      never hold the simulation: drop the oldest frame waiting to be rendered\n"
    "  --dt DT            simulation time per step, for Lantern's time (default 0)\n"
    "  --max-atoms N      refuse larger frames (default 178956970, the most IMD can describe)\n"
    "  --connect-timeout S  keep trying to connect for S seconds (default 60)\n"
    "  --idle-timeout S   give up when the simulation sends nothing for S seconds (default: "
    "wait)\n";

// Set by SIGINT/SIGTERM: finish the frame in hand, disconnect, close the outputs, exit 0.
std::atomic<bool> stop_requested{false};
extern "C" void on_stop_signal(int) {
  stop_requested = true;
}

struct Options {
  std::string host, port, config, types;
  int64_t every = 0, first_step = -1, trate = 0, frames = 0, step_offset = 0;
  int64_t max_atoms = 178956970;  // INT32_MAX / 12: an IMD frame's bytes fit an int32 length
  double dt = 0, connect_seconds = 60, idle_seconds = 0;
  bool drop = false;
};

bool parse_number(const std::string &text, double *out) {
  char *end = nullptr;
  *out = std::strtod(text.c_str(), &end);
  return !text.empty() && end && *end == '\0';
}

// "" and *out, "help" or "version" when asked, or a usage error.
std::string parse(int argc, char **argv, Options *out) {
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") return "help";
    if (arg == "--version") return "version";
    if (arg.rfind("-", 0) != 0) {
      positional.push_back(arg);
      continue;
    }
    if (arg == "--drop-frames") {
      out->drop = true;
      continue;
    }
    if (i + 1 >= argc) return arg + " needs a value";
    const std::string value = argv[++i];
    if (arg == "-lantern" || arg == "--lantern") {
      out->config = value;
      continue;
    }
    if (arg == "--types") {
      out->types = value;
      continue;
    }
    double v = 0;
    if (!parse_number(value, &v)) return arg + ": '" + value + "' is not a number";
    const bool whole = v == double(int64_t(v));
    if (arg == "--every" || arg == "--trate" || arg == "--frames" || arg == "--max-atoms") {
      if (!whole || v < 1) return arg + " must be a positive integer, not '" + value + "'";
      int64_t &field = arg == "--every"    ? out->every
                       : arg == "--trate"  ? out->trate
                       : arg == "--frames" ? out->frames
                                           : out->max_atoms;
      field = int64_t(v);
    } else if (arg == "--step-offset") {
      if (!whole) return arg + " must be an integer, not '" + value + "'";
      out->step_offset = int64_t(v);
    } else if (arg == "--first-step") {
      if (!whole || v < 0) return arg + " must be a step (an integer >= 0), not '" + value + "'";
      out->first_step = int64_t(v);
    } else if (arg == "--dt" || arg == "--connect-timeout" || arg == "--idle-timeout") {
      if (!(v >= 0)) return arg + " must be >= 0, not '" + value + "'";
      (arg == "--dt"                ? out->dt
       : arg == "--connect-timeout" ? out->connect_seconds
                                    : out->idle_seconds) = v;
    } else {
      return "unknown option " + arg;
    }
  }
  if (positional.size() != 1) return "expected one HOST:PORT";
  if (out->config.empty()) return "give Lantern's configuration: -lantern CONFIG.yaml";
  const std::string &address = positional[0];
  const size_t colon = address.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == address.size())
    return "'" + address + "' is not HOST:PORT";
  out->host = address.substr(0, colon);
  if (out->host.size() > 2 && out->host.front() == '[' && out->host.back() == ']')
    out->host = out->host.substr(1, out->host.size() - 2);  // [::1]:port
  out->port = address.substr(colon + 1);
  if (out->every == 0) out->every = out->trate > 0 ? out->trate : 1;
  if (out->first_step < 0) out->first_step = out->every;
  return {};
}

// A broadcast that waits without spinning: the other ranks sleep between tests while rank 0
// waits for the simulation (which may take minutes).
void broadcast(void *data, int count, MPI_Datatype type) {
  MPI_Request request;
  MPI_Ibcast(data, count, type, 0, MPI_COMM_WORLD, &request);
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    // MPI_Test completed the request (the analyzer's MPI checker knows only MPI_Wait).
    if (done) return;  // NOLINT(clang-analyzer-optin.mpi.MPI-Checker)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

// Rank 0's message on every rank ("" stays "").
std::string broadcast_text(std::string text) {
  int length = int(text.size());
  broadcast(&length, 1, MPI_INT);
  text.resize(size_t(length));
  broadcast(text.data(), length, MPI_CHAR);
  return text;
}

// Collective: the first rank's error with one, on every rank ("" if none).
std::string agree(const std::string &local) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int first = local.empty() ? size : rank;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == size) return {};
  int length = int(local.size());
  MPI_Bcast(&length, 1, MPI_INT, first, MPI_COMM_WORLD);
  std::string message = local;
  message.resize(size_t(length));
  MPI_Bcast(message.data(), length, MPI_CHAR, first, MPI_COMM_WORLD);
  return message;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// This rank's atoms of the current frame, in the arrays lantern_publish borrows.
struct LocalAtoms {
  std::vector<float> xyz;
  std::vector<int32_t> index, type;
  std::vector<int64_t> id;
};

// What rank 0 tells every rank about the next event.
struct Announcement {
  int64_t kind = 0;  // Event::Kind
  int64_t atoms = 0;
  int64_t step = 0;
};

class Renderer {
 public:
  Renderer(const Options &options, lantern_context *ctx, int rank, int size)
      : options_(options), ctx_(ctx), rank_(rank), size_(size) {}

  // Collective: distributes `frame` (rank 0; nullptr elsewhere) and renders it. "" or an error
  // (the same on every rank).
  std::string render(const Announcement &a, const Frame *frame) {
    if (table_.type.empty()) {  // the first frame: types and ids, once
      std::string e = rank_ == 0 ? lantern_imd::load_atom_table(options_.types, a.atoms, &table_)
                                 : std::string();
      if (e = agree(e); !e.empty()) return e;
      if (size_ > 1) {
        table_.type.resize(size_t(a.atoms));
        table_.id.resize(size_t(a.atoms));
        MPI_Bcast(table_.type.data(), int(a.atoms), MPI_INT32_T, 0, MPI_COMM_WORLD);
        MPI_Bcast(table_.id.data(), int(a.atoms), MPI_INT64_T, 0, MPI_COMM_WORLD);
      }
    }
    lantern_particles p{};
    if (size_ == 1) {  // the frame as received: no copy
      p.count = frame->atoms;
      p.position = {frame->xyz.data(), LANTERN_FLOAT32, 0};
      p.type = {table_.type.data(), LANTERN_INT32, 0};
      p.id = {table_.id.data(), LANTERN_INT64, 0};
    } else {
      scatter(frame);
      p.count = int64_t(local_.index.size());
      p.position = {local_.xyz.data(), LANTERN_FLOAT32, 0};
      p.type = {local_.type.data(), LANTERN_INT32, 0};
      p.id = {local_.id.data(), LANTERN_INT64, 0};
    }
    const std::string where = "step " + std::to_string(a.step) + ": ";
    const std::string local =
        lantern_publish(ctx_, &p) == LANTERN_OK ? "" : where + lantern_error_message(ctx_);
    if (std::string e = agree(local); !e.empty()) return e;
    const double t0 = MPI_Wtime();
    const lantern_status st = lantern_execute(ctx_, a.step, double(a.step) * options_.dt);
    execute_seconds_.push_back(MPI_Wtime() - t0);
    if (st == LANTERN_ERR_IO) {  // a full or unwritable disk: warn, the next frame tries again
      if (rank_ == 0)
        std::fprintf(stderr, "lantern-imd: warning: %s%s\n", where.c_str(),
                     lantern_error_message(ctx_));
      return {};
    }
    return st == LANTERN_OK ? "" : where + lantern_error_message(ctx_);
  }

  const std::vector<double> &execute_seconds() const { return execute_seconds_; }

 private:
  // Rank 0 splits the frame spatially; every rank receives its part's coordinates and stream
  // indices, and looks its types and ids up in the table.
  void scatter(const Frame *frame) {
    std::vector<int> counts(static_cast<size_t>(size_)), offsets(static_cast<size_t>(size_));
    if (rank_ == 0) {
      split_.split(frame->xyz.data(), frame->atoms, size_);
      counts = split_.counts();
      offsets = split_.offsets();
      send_xyz_.resize(3 * size_t(frame->atoms));
      for (size_t k = 0; k < split_.order().size(); ++k)
        std::copy_n(frame->xyz.data() + 3 * size_t(split_.order()[k]), 3, &send_xyz_[3 * k]);
    }
    int mine = 0;
    MPI_Scatter(counts.data(), 1, MPI_INT, &mine, 1, MPI_INT, 0, MPI_COMM_WORLD);
    local_.index.resize(size_t(mine));
    MPI_Scatterv(split_.order().data(), counts.data(), offsets.data(), MPI_INT32_T,
                 local_.index.data(), mine, MPI_INT32_T, 0, MPI_COMM_WORLD);
    for (int r = 0; r < size_ && rank_ == 0; ++r) counts[size_t(r)] *= 3, offsets[size_t(r)] *= 3;
    local_.xyz.resize(3 * size_t(mine));
    MPI_Scatterv(send_xyz_.data(), counts.data(), offsets.data(), MPI_FLOAT, local_.xyz.data(),
                 3 * mine, MPI_FLOAT, 0, MPI_COMM_WORLD);
    local_.type.resize(size_t(mine));
    local_.id.resize(size_t(mine));
    for (size_t k = 0; k < size_t(mine); ++k) {
      local_.type[k] = table_.type[size_t(local_.index[k])];
      local_.id[k] = table_.id[size_t(local_.index[k])];
    }
  }

  const Options &options_;
  lantern_context *ctx_;
  int rank_, size_;
  AtomTable table_;
  lantern_imd::SpatialSplit split_;
  std::vector<float> send_xyz_;
  LocalAtoms local_;
  std::vector<double> execute_seconds_;
};

int report(int rank, const std::string &message, int code) {
  if (rank == 0)
    std::fprintf(stderr, "lantern-imd: %s%s\n", code ? "error: " : "", message.c_str());
  return code;
}

// Connects, receives and renders until the stream ends. Returns the exit code.
int run(const Options &options, lantern_context *ctx, int rank, int size) {
  std::unique_ptr<lantern_imd::ImdConnection> connection;
  std::string e;
  if (rank == 0) {
    e = lantern_imd::ImdConnection::open(options.host, options.port, options.connect_seconds,
                                         stop_requested, &connection);
    if (e.empty() && options.trate > 0)
      e = connection->send(lantern_imd::MessageType::kTransferRate, int32_t(options.trate));
  }
  if (e = broadcast_text(e); !e.empty()) return report(rank, e, 1);
  std::unique_ptr<lantern_imd::FrameReceiver> receiver;
  if (rank == 0) {
    std::fprintf(stderr, "lantern-imd: connected to %s%s\n", connection->address().c_str(),
                 connection->swap() ? " (payloads in the other byte order)" : "");
    lantern_imd::ReceiverOptions ro;
    ro.max_atoms = options.max_atoms;
    ro.first_step = options.first_step;
    ro.every = options.every;
    ro.step_offset = options.step_offset;
    ro.drop_oldest = options.drop;
    ro.idle_seconds = options.idle_seconds;
    receiver =
        std::make_unique<lantern_imd::FrameReceiver>(std::move(connection), ro, stop_requested);
  }
  Renderer renderer(options, ctx, rank, size);
  std::vector<double> receive_seconds;
  int64_t frames = 0, first_step = 0, last_step = 0;
  int code = 0;
  std::string ending;
  for (;;) {
    Event event;
    Announcement a;
    if (rank == 0) {
      event = stop_requested ? Event{Event::Kind::kEnd, nullptr, "stopped by a signal"}
                             : receiver->next();
      a.kind = int64_t(event.kind);
      if (event.frame) a.atoms = event.frame->atoms, a.step = event.frame->step;
    }
    broadcast(&a, 3, MPI_INT64_T);
    if (Event::Kind(a.kind) != Event::Kind::kFrame) {
      ending = broadcast_text(event.message);
      code = Event::Kind(a.kind) == Event::Kind::kError ? 1 : 0;
      break;
    }
    if (std::string failure = renderer.render(a, event.frame.get()); !failure.empty()) {
      ending = failure;
      code = 1;
      break;
    }
    if (rank == 0) {
      receive_seconds.push_back(event.frame->receive_seconds);
      receiver->recycle(std::move(event.frame));
    }
    first_step = frames == 0 ? a.step : first_step;
    last_step = a.step;
    if (++frames == options.frames) {
      ending = "rendered --frames " + std::to_string(frames) + " frames; leaving the simulation";
      break;
    }
  }
  const int64_t dropped = rank == 0 ? receiver->dropped() : 0;
  receiver.reset();  // IMD_DISCONNECT if the simulation is still there
  report(rank, ending, code);
  if (rank == 0)
    std::fprintf(stderr,
                 "lantern-imd: %lld frames rendered (steps %lld..%lld), %lld dropped; per "
                 "frame (medians): receive %.4f s, render %.4f s\n",
                 static_cast<long long>(frames), static_cast<long long>(first_step),
                 static_cast<long long>(last_step), static_cast<long long>(dropped),
                 median(receive_seconds), median(renderer.execute_seconds()));
  return code;
}

}  // namespace

int main(int argc, char **argv) {
  Options options;
  const std::string usage_error = parse(argc, argv, &options);
  // --help and --version answer on stdout without starting MPI; a usage error goes to stderr.
  if (const std::optional<int> code =
          lantern_tools::reply_to_usage("lantern-imd", usage_error, kUsage))
    return *code;
  // The receiving thread does no MPI: only the main thread calls it.
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);

  int code = 0;
  lantern_context *ctx = nullptr;
  if (lantern_open(options.config.c_str(), MPI_Comm_c2f(MPI_COMM_WORLD), &ctx) != LANTERN_OK) {
    code = report(rank, options.config + ": " + lantern_error_message(ctx), 1);
  } else {
    code = run(options, ctx, rank, size);
  }
  if (lantern_close(ctx) != LANTERN_OK && code == 0)
    code = report(rank, "closing Lantern's outputs failed", 1);
  MPI_Finalize();
  return code;
}
