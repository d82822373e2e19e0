#include "lammps_session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#define LAMMPS_LIB_MPI 1
#include <lammps/library.h>

namespace lantern_lammps {
namespace {

constexpr int kMaxIncludeDepth = 16;

// LAMMPS's callback type differs with its integer sizes (LAMMPS_SMALLBIG, ...): an adapter of
// exactly that type forwards to Session::on_callback.
template <typename Callback>
struct CallbackAdapter;
template <typename Step, typename Tag>
struct CallbackAdapter<void (*)(void *, Step, int, Tag *, double **, double **)> {
  static void call(void *attachment, Step step, int nlocal, Tag *ids, double **x, double **f) {
    Session::on_callback(attachment, int64_t(step), nlocal, ids, x, f);
  }
};

bool has_variable(const std::string &word) {
  return word.find('$') != std::string::npos;
}

// The text of `path`, read on rank 0 and broadcast. Throws Failure on every rank if unreadable.
std::string read_on_root(MPI_Comm comm, const std::string &path, const std::string &where) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::string text;
  long long size = -1;
  if (rank == 0) {
    std::ifstream in(path, std::ios::binary);
    if (in) {
      std::ostringstream s;
      s << in.rdbuf();
      text = s.str();
      size = static_cast<long long>(text.size());
    }
  }
  MPI_Bcast(&size, 1, MPI_LONG_LONG, 0, comm);
  if (size < 0) throw Failure(where + "cannot read the input script '" + path + "'");
  text.resize(size_t(size));
  MPI_Bcast(text.data(), int(size), MPI_CHAR, 0, comm);
  return text;
}

}  // namespace

Session::Session(void *lmp, lantern_context *ctx, MPI_Comm comm, const SessionOptions &options)
    : lmp_(lmp), ctx_(ctx), comm_(comm), options_(options), scalar_(ScalarName{}) {
  MPI_Comm_rank(comm_, &rank_);
  ScalarName name;
  if (const std::string e = parse_scalar_name(options.scalar, &name); !e.empty()) throw Failure(e);
  scalar_ = PerAtomScalar(name);
}

Session::~Session() = default;

void Session::run_script(const std::string &path) {
  execute_file(path, 0);
  if (attached_.empty() && !ran_)
    throw Failure(path + ": the script defines no 'fix ID GROUP external pf/callback N M' " +
                  (options_.fix.empty() ? std::string() : "with ID '" + options_.fix + "' ") +
                  "to attach to; fixes defined: " + fixes_seen());
}

void Session::execute_file(const std::string &path, int depth) {
  if (depth > kMaxIncludeDepth) throw Failure(path + ": includes nested too deeply");
  const std::string text = read_on_root(comm_, path, "");
  for (const ScriptCommand &c : split_commands(text)) {
    const std::string where = path + ":" + std::to_string(c.line) + ": ";
    execute(c, where, depth);
    if (quit_status_) return;  // `quit`, here or in an included file, ends the whole script
  }
}

void Session::execute(const ScriptCommand &command, const std::string &where, int depth) {
  const std::vector<std::string> words = command_words(command.text);
  const std::string &verb = words.front();
  if (verb == "include") {
    if (words.size() != 2 || has_variable(words[1]))
      throw Failure(where +
                    "lantern-lammps reads 'include FILE' itself and needs the file name "
                    "written out (no variables)");
    execute_file(words[1], depth + 1);
    return;
  }
  if (verb == "jump")
    throw Failure(where +
                  "'jump' cannot run through the LAMMPS library, which lantern-lammps "
                  "drives command by command: write the loop out (or use 'run N every "
                  "M ...')");
  if (verb == "quit") {  // the end of the script: Lantern still closes its outputs
    quit_status_ = evaluate_quit_status(words, where);
    return;
  }
  if (verb == "run" || verb == "minimize" || verb == "rerun") before_run(where);
  inside_lammps_ = true;
  lammps_command(lmp_, command.text.c_str());
  inside_lammps_ = false;
  after_command(words, where);
}

int Session::evaluate_quit_status(const std::vector<std::string> &words, const std::string &where) {
  if (words.size() < 2) return 0;
  if (words.size() > 2) throw Failure(where + "'quit' takes at most one argument (the status)");
  // LAMMPS expands $x, ${name} and $(expression) in a command before running it: an equal-style
  // variable made of the word gets the status as lmp would see it.
  const std::string name = "lantern_quit_status";
  inside_lammps_ = true;
  lammps_command(lmp_, ("variable " + name + " equal " + words[1]).c_str());
  inside_lammps_ = false;
  double *value = static_cast<double *>(lammps_extract_variable(lmp_, name.c_str(), nullptr));
  if (!value) throw Failure(where + "'quit " + words[1] + "': the status is not a number");
  const double status = *value;
  lammps_free(value);
  lammps_command(lmp_, ("variable " + name + " delete").c_str());
  if (!(status == std::floor(status)) || std::abs(status) > 1e9)
    throw Failure(where + "'quit " + words[1] + "': the status must be an integer");
  return static_cast<int>(status);
}

void Session::after_command(const std::vector<std::string> &words, const std::string &where) {
  const std::string &verb = words.front();
  if (verb == "clear") {  // LAMMPS forgot every fix, group and variable
    attached_.clear(), fixes_.clear(), atom_variables_.clear();
    groups_deleted_ = false;
  } else if (verb == "fix" && words.size() >= 4) {
    const std::string &id = words[1], &group = words[2], &style = words[3];
    fixes_.erase(
        std::remove_if(fixes_.begin(), fixes_.end(), [&](const auto &f) { return f.first == id; }),
        fixes_.end());
    fixes_.emplace_back(id, style);
    attached_.erase(id);  // a fix redefined under the same ID is a new fix
    if (style == "external" && (options_.fix.empty() || options_.fix == id)) {
      if (words.size() < 5 || words[4] != "pf/callback")
        throw Failure(where + "fix " + id +
                      ": lantern-lammps renders from 'external pf/callback "
                      "N M' fixes, not '" +
                      (words.size() < 5 ? "" : words[4]) + "'");
      if (has_variable(id) || has_variable(group))
        throw Failure(where + "fix " + id + ": write the fix ID and group out (no variables)");
      attach(id, group, where);
    }
  } else if (verb == "unfix" && words.size() >= 2) {
    attached_.erase(words[1]);
    fixes_.erase(std::remove_if(fixes_.begin(), fixes_.end(),
                                [&](const auto &f) { return f.first == words[1]; }),
                 fixes_.end());
  } else if (verb == "group" && words.size() >= 3 && words[2] == "delete") {
    groups_deleted_ = true;
  } else if (verb == "variable" && words.size() >= 3) {
    if (words[2] == "atom")
      atom_variables_.insert(words[1]);
    else if (words[2] == "delete")
      atom_variables_.erase(words[1]);
  }
}

// LAMMPS gives group number k (in the order groups were made, "all" first) the mask bit 1 << k;
// the library lists group names in that order. A deleted group leaves a hole that the list does
// not show, so after a `group ... delete` only group all can be used.
int64_t Session::group_bits(const std::string &group, const std::string &where) const {
  if (group == "all") return 0;
  if (groups_deleted_)
    throw Failure(where + "group '" + group +
                  "': after a 'group ... delete' the library cannot "
                  "tell a group's mask bit; define the groups without deleting any");
  const int n = lammps_id_count(lmp_, "group");
  char name[256];
  for (int k = 0; k < n && k < 32; ++k)
    if (lammps_id_name(lmp_, "group", k, name, sizeof(name)) && group == name)
      return int64_t(1) << k;
  throw Failure(where + "group '" + group + "' is not defined");
}

void Session::attach(const std::string &fix, const std::string &group, const std::string &where) {
  auto a = std::make_unique<Attachment>();
  a->session = this;
  a->fix = fix;
  a->group = group;
  a->group_bits = group_bits(group, where);
  lammps_set_fix_external_callback(lmp_, fix.c_str(), &CallbackAdapter<FixExternalFnPtr>::call,
                                   a.get());
  attached_[fix] = std::move(a);
  if (rank_ == 0)
    std::fprintf(stderr, "lantern-lammps: rendering from fix %s (group %s)\n", fix.c_str(),
                 group.c_str());
}

std::string Session::fixes_seen() const {
  if (fixes_.empty()) return "none";
  std::string list;
  for (const auto &[id, style] : fixes_)
    list += (list.empty() ? "" : ", ") + id + " (" + style + ")";
  return list;
}

void Session::before_run(const std::string &where) {
  if (attached_.empty()) {
    const std::string wanted = options_.fix.empty()
                                   ? "a 'fix ID GROUP external pf/callback N M'"
                                   : "the fix '" + options_.fix + "' (lammps.fix) as 'fix " +
                                         options_.fix + " GROUP external pf/callback N M'";
    throw Failure(where + "no fix to render from before this run: the script must define " +
                  wanted + "; fixes defined: " + fixes_seen());
  }
  // Two fixes would both call back at the steps they share, each rendering the same scenes into
  // the same files: say which one renders.
  if (attached_.size() > 1) {
    std::string ids;
    for (const auto &entry : attached_) ids += (ids.empty() ? "" : ", ") + entry.first;
    throw Failure(where + "the script defines " + std::to_string(attached_.size()) +
                  " 'fix ... external pf/callback' fixes (" + ids +
                  "): name the one to render from as lammps: {fix: ID}, or unfix the others");
  }
  if (const std::string e = scalar_.check_known(lmp_, atom_variables_); !e.empty())
    throw Failure(where + e);
  for (const auto &entry : attached_)
    zero_external_forces(*entry.second, lammps_fix_external_get_force(lmp_, entry.first.c_str()),
                         true);
  ran_ = true;
}

// fix external adds its fexternal array to the group's forces on every step of its napply
// cadence, also on set-up steps where it calls nobody, and LAMMPS leaves the array
// uninitialised when it allocates or grows it: zero every row it has. Otherwise LAMMPS only
// copies rows among atoms (copy_arrays, exchange between ranks; fix_external.cpp), so zeroed rows
// stay zero until the array moves or grows: then (or with `again`) they are zeroed, not on every
// call (24 bytes a row, local and ghost atoms: about 0.7 ms of each call of the 1 M-atom melt on
// 2 ranks, perf of examples/lammps/in.lj).
void Session::zero_external_forces(const Attachment &a, double **f, bool again) const {
  const int nmax = lammps_extract_setting(lmp_, "nmax");
  if (!f || !f[0] || nmax <= 0) return;
  if (!again && f[0] == a.zeroed_rows && nmax == a.zeroed_nmax) return;
  std::memset(f[0], 0, sizeof(double) * 3 * size_t(nmax));
  a.zeroed_rows = f[0], a.zeroed_nmax = nmax;
}

void Session::on_callback(void *attachment, int64_t step, int nlocal, const void *ids, double **x,
                          double **f) {
  const auto *a = static_cast<const Attachment *>(attachment);
  a->session->callback(*a, step, nlocal, ids, x, f);
}

double Session::time_of(int64_t step) const {
  const auto *dt = static_cast<const double *>(lammps_extract_global(lmp_, "dt"));
  const auto *atime = static_cast<const double *>(lammps_extract_global(lmp_, "atime"));
  const auto *atimestep = static_cast<const int64_t *>(lammps_extract_global(lmp_, "atimestep"));
  if (!dt) return 0.0;
  // atime is the time at step atimestep (LAMMPS keeps it across changes of dt).
  if (atime && atimestep) return *atime + double(step - *atimestep) * *dt;
  return double(step) * *dt;
}

std::string Session::describe(const Attachment &a, int nlocal, const void *ids, double **x,
                              lantern_particles *out) {
  lantern_particles &p = *out;
  p = lantern_particles{};
  p.count = nlocal;
  if (nlocal > 0) {
    if (nlocal > 1 && x[1] != x[0] + 3)  // the hand-over without a copy needs one [n][3] block
      return "LAMMPS x is not one contiguous [n][3] block";
    p.position = {x[0], LANTERN_FLOAT64, 3 * sizeof(double)};
    p.type = {lammps_extract_atom(lmp_, "type"), LANTERN_INT32, 0};
    p.id = {ids, lammps_extract_setting(lmp_, "tagint") == 8 ? LANTERN_INT64 : LANTERN_INT32, 0};
    if (a.group_bits != 0) {
      p.mask = {lammps_extract_atom(lmp_, "mask"), LANTERN_INT32, 0};
      p.mask_bits = a.group_bits;
    }
  }
  return scalar_.extract(lmp_, a.group, nlocal, &p.scalar);
}

std::string Session::publish(const lantern_particles &p) {
  if (lantern_publish(ctx_, &p) != LANTERN_OK) return lantern_error_message(ctx_);
  scalar_.published();
  if (options_.bonds) {
    lantern_bonds b{};
    if (std::string e = bonds_.describe(lmp_, &b); !e.empty()) return e;
    if (lantern_publish_bonds(ctx_, &b) != LANTERN_OK) return lantern_error_message(ctx_);
    if (rank_ == 0 && !bonds_logged_)
      std::fprintf(stderr, "lantern-lammps: %s\n", bonds_.summary().c_str());
    bonds_logged_ = true;
  }

  double lo[3], hi[3], xy, yz, xz;
  int periodic[3], changed;
  lammps_extract_box(lmp_, lo, hi, &xy, &yz, &xz, periodic, &changed);
  // A triclinic box (even at zero tilt, as one that `fix deform` shears from zero) as LAMMPS
  // holds it: origin lo, edge lengths hi - lo and the tilts.
  const double tilt[3] = {xy, xz, yz};
  const lantern_status set = lammps_extract_setting(lmp_, "triclinic") != 0
                                 ? lantern_set_triclinic_box(ctx_, lo, hi, tilt, periodic)
                                 : lantern_set_box(ctx_, lo, hi, periodic);
  if (set != LANTERN_OK) return lantern_error_message(ctx_);
  return "";
}

// Every rank learns whether any failed, and the first failing rank's message: then all throw.
void Session::agree(const std::string &local_error) const {
  int size = 1;
  MPI_Comm_size(comm_, &size);
  const int mine = local_error.empty() ? size : rank_;
  int first = size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm_);
  if (first == size) return;
  int length = int(local_error.size());
  MPI_Bcast(&length, 1, MPI_INT, first, comm_);
  std::string message = local_error;
  message.resize(size_t(length));
  MPI_Bcast(message.data(), length, MPI_CHAR, first, comm_);
  throw Failure("rank " + std::to_string(first) + ": " + message);
}

void Session::callback(const Attachment &a, int64_t step, int nlocal, const void *ids, double **x,
                       double **f) {
  // Whatever fix external adds to the forces stays zero: the trajectory is LAMMPS's own.
  zero_external_forces(a, f, false);
  // A run's set-up calls back at the step where the previous run ended: rendered already.
  if (step == last_step_) return;
  const std::string where = "step " + std::to_string(step) + ", fix " + a.fix + ": ";
  lantern_particles p;
  const std::string described = describe(a, nlocal, ids, x, &p);
  agree(described.empty() ? "" : where + described);
  // A half-bond colored by its atom reads a ghost's scalar, which LAMMPS does not communicate:
  // collective, so after the ranks agreed that every one has its scalar.
  if (options_.bonds && scalar_.wanted()) ghost_scalar_.extend(lmp_, p.scalar, &p.scalar);
  const std::string published = publish(p);
  agree(published.empty() ? "" : where + published);
  const double t0 = MPI_Wtime();
  const lantern_status st = lantern_execute(ctx_, step, time_of(step));  // same on every rank
  execute_seconds_.push_back(MPI_Wtime() - t0);
  last_step_ = step;
  ++rendered_;
  if (st == LANTERN_ERR_IO) {  // a full or unwritable disk: warn, the next step tries again
    if (rank_ == 0)
      std::fprintf(stderr, "lantern-lammps: warning: %s%s\n", where.c_str(),
                   lantern_error_message(ctx_));
    return;
  }
  if (st != LANTERN_OK) throw Failure(where + lantern_error_message(ctx_));
}

}  // namespace lantern_lammps
