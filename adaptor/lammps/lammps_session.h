// lantern-lammps's driver: executes a LAMMPS input script command by command through LAMMPS's
// library interface and renders with Lantern from every `fix ID GROUP external pf/callback N M`
// the script defines.
//
// Why command by command: a `fix external` in pf/callback mode needs its callback before the next
// run (LAMMPS stops with "callback function not set" otherwise), and lammps_file() gives no
// chance to set it in between. So the script is cut into commands (script_reader.h) and each goes
// to lammps_command(); after a `fix ... external` the callback is attached, and before every
// run/minimize/rerun the script is checked (a fix to attach to, a known scalar). `include` files
// are read the same way; `jump` (loops) cannot work through the library and is refused.
//
// What is published at every callback, without a copy: LAMMPS's x (one [nmax][3] block, stride
// 24), type, id (tagint), the fix's group as LAMMPS's own atom mask and the group's bit (no mask
// for group all), and the YAML's scalar (per_atom_scalar.h). Where a scene draws bonds, also
// LAMMPS's bonds and ghost atoms (bond_list.h): x, type, id and mask then reach past nlocal to
// the ghosts, which LAMMPS keeps in the same arrays; the scalar, which LAMMPS does not give its
// ghosts, is then a copy with the ghosts' values communicated from their owners (ghost_scalar.h).
// LAMMPS reallocates and reorders these arrays when atoms migrate or are sorted, so they are
// published again at every callback. fix external adds its fexternal array to the forces of the
// group's atoms; lantern-lammps keeps that array zero (before every run and at every callback), so
// the trajectory is LAMMPS's own.
//
// Errors: bad input (no fix to attach to, an unknown scalar, a failed publish or render) throws
// Failure on every rank alike - from inside a LAMMPS run too, after the ranks agreed on it - so
// no rank waits for another in a collective. Thread-safety: LAMMPS's thread only.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "bond_list.h"
#include "ghost_scalar.h"
#include "lantern/lantern.h"
#include "per_atom_scalar.h"
#include "script_reader.h"

namespace lantern_lammps {

// A failure every rank raised alike; what() is the message for the user.
struct Failure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct SessionOptions {
  std::string fix;     // lammps.fix: the one fix ID to attach to ("" = the fix external the script
                       // defines; two defined at once before a run are refused)
  std::string scalar;  // lammps.scalar: per-atom quantity to publish as the scalar ("" = none)
  bool bonds = false;  // a scene draws bonds: publish LAMMPS's bonds and ghosts
};

class Session {
 public:
  // Borrows `lmp` (opened on `comm`) and `ctx` (opened on the same ranks); both outlive it.
  Session(void *lmp, lantern_context *ctx, MPI_Comm comm, const SessionOptions &options);
  ~Session();
  Session(const Session &) = delete;
  Session &operator=(const Session &) = delete;

  // Executes the script at `path` (read on rank 0). Collective; throws Failure.
  void run_script(const std::string &path);

  // True while a LAMMPS command is executing: a Failure thrown then left LAMMPS mid-command,
  // and it must not be closed (only MPI finalised).
  bool inside_lammps() const { return inside_lammps_; }
  int64_t images() const { return rendered_; }  // callbacks that called lantern_execute
  // The status of the script's `quit N` (0 for a bare `quit`), once one was executed: the exit
  // code lmp would give.
  std::optional<int> quit_status() const { return quit_status_; }
  // Seconds of each lantern_execute() on this rank, in call order (the same calls on every rank).
  const std::vector<double> &execute_seconds() const { return execute_seconds_; }

  // What LAMMPS calls (through an adapter to its FixExternalFnPtr type): publishes, agrees on
  // errors across ranks, renders. `attachment` is the Attachment given with the callback.
  static void on_callback(void *attachment, int64_t step, int nlocal, const void *ids, double **x,
                          double **f);

 private:
  struct Attachment {
    Session *session = nullptr;
    std::string fix, group;
    int64_t group_bits = 0;  // 0: group all, no mask
    // The fix's force rows as last zeroed: their first row and LAMMPS's nmax then.
    mutable const double *zeroed_rows = nullptr;
    mutable int zeroed_nmax = 0;
  };

  void execute_file(const std::string &path, int depth);
  void execute(const ScriptCommand &command, const std::string &where, int depth);
  void after_command(const std::vector<std::string> &words, const std::string &where);
  void attach(const std::string &fix, const std::string &group, const std::string &where);
  int64_t group_bits(const std::string &group, const std::string &where) const;
  void before_run(const std::string &where);
  void zero_external_forces(const Attachment &a, double **f, bool again) const;
  // `quit [status]`: the status as LAMMPS evaluates it (a number, or variables LAMMPS expands).
  int evaluate_quit_status(const std::vector<std::string> &words, const std::string &where);
  std::string fixes_seen() const;

  void callback(const Attachment &a, int64_t step, int nlocal, const void *ids, double **x,
                double **f);
  // This rank's particles as LAMMPS holds them now, without a copy: "" or an error (local).
  std::string describe(const Attachment &a, int nlocal, const void *ids, double **x,
                       lantern_particles *out);
  // Publishes them, the bonds and the box: "" or an error (local).
  std::string publish(const lantern_particles &p);
  void agree(const std::string &local_error) const;
  double time_of(int64_t step) const;

  void *lmp_;
  lantern_context *ctx_;
  MPI_Comm comm_;
  int rank_ = 0;
  SessionOptions options_;
  PerAtomScalar scalar_;
  BondList bonds_;
  GhostScalar ghost_scalar_;   // the scalar with ghosts' rows, where bonds are drawn
  bool bonds_logged_ = false;  // the bonds' source was printed (first callback)
  std::map<std::string, std::unique_ptr<Attachment>> attached_;  // by fix ID
  std::vector<std::pair<std::string, std::string>> fixes_;       // (ID, style) defined so far
  std::set<std::string> atom_variables_;                         // atom-style variables
  bool groups_deleted_ = false;
  bool inside_lammps_ = false;
  bool ran_ = false;
  std::optional<int> quit_status_;  // set by `quit`: no command runs after it
  int64_t last_step_ = -1;  // the step last rendered: a run's set-up repeats the previous end
  int64_t rendered_ = 0;
  std::vector<double> execute_seconds_;
};

}  // namespace lantern_lammps
