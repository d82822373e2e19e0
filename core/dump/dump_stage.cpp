#include "core/dump/dump_stage.h"

#include <cstdio>
#include <filesystem>
#include <vector>

#include "core/common/collective_status.h"
#include "core/dump/existing_dump.h"
#include "core/dump/frame_cut_back.h"

namespace lantern {
namespace {

enum FieldBit : int { kType = 1, kId = 2, kScalar = 4, kRadius = 8, kBondList = 16 };

int published_fields(const ParticleArrays &p) {
  return (p.has_type() ? kType : 0) | (p.has_id() ? kId : 0) | (p.has_scalar() ? kScalar : 0) |
         (p.has_radius() ? kRadius : 0);
}

int bit_of(const std::string &field) {
  if (field == "type") return kType;
  if (field == "id") return kId;
  if (field == "scalar") return kScalar;
  if (field == "radius") return kRadius;
  return 0;  // position: always written
}

const char *name_of(int bit) {
  switch (bit) {
    case kType:
      return "type";
    case kId:
      return "id";
    case kScalar:
      return "scalar";
    default:
      return "radius";
  }
}

// The bonds go into the file (by particle id) when some rank published bonds at the first dump
// and the file has ids; bonds without ids are left out, with a warning that says why.
int with_bonds(int fields, bool any_bonds, const DumpConfig &config, int rank) {
  if (!any_bonds) return fields;
  if (fields & kId) return fields | kBondList;
  if (rank == 0)
    std::fprintf(stderr,
                 "lantern: warning: dump.file: %s: bonds are published, but the dump has no 'id' "
                 "field (dump.fields, lantern_particles.id): H5MD's connectivity names particles "
                 "by id, so this dump leaves the bonds out\n",
                 config.file.c_str());
  return fields;
}

// The fields to write: the configured list, or else every array some rank published. Listing a
// field that no rank published is an error (a typo'd expectation, not a silent empty dataset).
// Plus the bond list where some rank published bonds (with_bonds).
Status choose_fields(MPI_Comm comm, const DumpConfig &config, const ParticleArrays &p,
                     const BondArrays &bonds, int *out) {
  int any = published_fields(p) | (bonds.count() > 0 ? kBondList : 0);
  MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_BOR, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const bool any_bonds = any & kBondList;
  any &= ~kBondList;
  if (config.fields.empty()) {
    *out = with_bonds(any, any_bonds, config, rank);
    return {};
  }
  int wanted = 0;
  for (const auto &f : config.fields) wanted |= bit_of(f);
  for (int bit : {kType, kId, kScalar, kRadius})
    if ((wanted & bit) && !(any & bit))
      return {StatusCode::kInvalidArgument, std::string("dump.fields: '") + name_of(bit) +
                                                "' is listed but no rank published a " +
                                                name_of(bit) + " array"};
  *out = wanted;
  return {};
}

DumpFields to_fields(int bits) {
  DumpFields f;
  f.species = bits & kType;
  f.id = bits & kId;
  f.scalar = bits & kScalar;
  f.radius = bits & kRadius;
  f.bonds = bits & kBondList;
  return f;
}

// A rank that holds particles must publish every field the file has.
Status check_local_fields(const DumpFields &f, const ParticleArrays &p, int64_t step) {
  if (p.count() == 0) return {};
  const int missing = (f.species && !p.has_type() ? kType : 0) | (f.id && !p.has_id() ? kId : 0) |
                      (f.scalar && !p.has_scalar() ? kScalar : 0) |
                      (f.radius && !p.has_radius() ? kRadius : 0);
  for (int bit : {kType, kId, kScalar, kRadius})
    if (missing & bit)
      return {StatusCode::kInvalidArgument,
              "dump: step " + std::to_string(step) + ": the dump file has a '" + name_of(bit) +
                  "' field but this rank published no " + name_of(bit) + " array"};
  return {};
}

// Rank 0's box, or the global particle bounds when rank 0 has none. Collective.
Box frame_box(MPI_Comm comm, const Extent &global, const std::optional<Box> &box) {
  Box b = box.value_or(Box{});
  int has_box = box.has_value();
  MPI_Bcast(&has_box, 1, MPI_INT, 0, comm);
  if (!has_box && !global.empty()) {
    b.low = global.lo;
    b.high = global.hi;
  }
  return b;  // only rank 0's copy is written
}

std::string mode_key(const DumpConfig &config) {
  return "'" + config.file + "' (dump.mode: append)";
}

// This rank's bonds for the dump: pairs of particle ids, each bond of the frame once over all
// ranks. Under kListedOnce every listed bond is this rank's; under kListedByBoth a bond is in the
// lists of both its atoms' ranks and goes to the one that owns the atom with the smaller id (an
// entry whose smaller-id atom is a ghost is the other rank's). With a group (mask, which covers
// the ghosts) only bonds between members are written, as only they are drawn. A bond that is bad
// now (check_bond) is left out, as the renderer leaves it out and reports it.
std::vector<int64_t> bond_ids(const BondArrays &bonds, const ParticleArrays &p) {
  std::vector<int64_t> pairs;
  const bool by_both = bonds.listing() == BondListing::kListedByBoth;
  for (int64_t k = 0; k < bonds.count(); ++k) {
    if (!bonds.check_bond(k, p).ok()) continue;
    const int64_t a = bonds.first(k), b = bonds.second(k);
    if (!p.kept(a) || !p.kept(b)) continue;
    const int64_t ida = p.id(a), idb = p.id(b);
    if (by_both && (ida < idb ? a : b) >= p.count()) continue;
    pairs.push_back(ida);
    pairs.push_back(idb);
  }
  return pairs;
}

// The configuration against an existing file (rank 0): "" or a message naming the key. Before the
// first dump (`fields` listed in the configuration) whether the run has bonds is not yet known.
std::string append_problem(const DumpConfig &config, const ExistingDump &file, int fields,
                           bool bonds_known = true) {
  if (!file.problem.empty()) return "dump.file: " + mode_key(config) + " " + file.problem;
  if (file.single_precision != config.single_precision)
    return std::string("dump.precision: ") + (config.single_precision ? "float32" : "float64") +
           ", but " + mode_key(config) + " holds " +
           (file.single_precision ? "float32" : "float64") +
           " positions (a restarted run appends in the file's precision)";
  DumpFields held = file.fields;
  if (!bonds_known) held.bonds = to_fields(fields).bonds;
  if (fields >= 0 && to_fields(fields) != held)
    return "dump.fields: the run writes [" + fields_text(to_fields(fields)) + "], but " +
           mode_key(config) + " holds [" + fields_text(file.fields) + "]";
  return {};
}

}  // namespace

Status DumpStage::check_existing_file(MPI_Comm comm) const {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  Status local;
  std::error_code ec;
  if (rank == 0 && config_.enabled && std::filesystem::exists(config_.file, ec)) {
    if (config_.mode == DumpMode::kCreate)
      local = {StatusCode::kConfig,
               "dump.file: '" + config_.file +
                   "' exists, and dump.mode: create (the default) does not replace a file: "
                   "give mode: append to continue its time series (a restarted run), mode: "
                   "overwrite to replace it, or another file"};
    else if (config_.mode == DumpMode::kAppend) {
      int listed = -1;  // the configured fields, when listed (else the published ones, later)
      if (!config_.fields.empty()) {
        listed = 0;
        for (const auto &f : config_.fields) listed |= bit_of(f);
      }
      if (const std::string problem =
              append_problem(config_, inspect_dump_file(config_.file), listed, false);
          !problem.empty())
        local = {StatusCode::kConfig, problem};
    }
  }
  return broadcast_status(comm, local, 0);
}

Status DumpStage::append_to_existing(MPI_Comm comm, int fields, int64_t first_count, int64_t step) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const std::string where = "dump.file: " + config_.file + ": step " + std::to_string(step) + ": ";
  // Rank 0 reads the file (serial HDF5) and cuts back a frame a killed or failed run left
  // part-way, before every rank opens it.
  ExistingDump file;
  Status local;
  if (rank == 0) {
    file = inspect_dump_file(config_.file);
    if (const std::string problem = append_problem(config_, file, fields); !problem.empty())
      local = {StatusCode::kConfig, problem};
    else
      local = with_context(where + "cutting back a partial frame: ",
                           cut_back_frames(config_.file, file.frames, file.rows));
  }
  if (Status s = broadcast_status(comm, local, 0); !s.ok()) return s;
  int64_t numbers[4] = {file.frames, file.rows, file.last_step, file.last_count};
  MPI_Bcast(numbers, 4, MPI_INT64_T, 0, comm);
  int periodic[4] = {file.periodic[0], file.periodic[1], file.periodic[2], file.triclinic};
  MPI_Bcast(periodic, 4, MPI_INT, 0, comm);
  DumpLayout layout;
  layout.first_count = first_count;
  layout.single_precision = config_.single_precision;
  layout.fields = to_fields(fields);
  for (int a = 0; a < 3; ++a) layout.periodic[size_t(a)] = periodic[a] != 0;
  layout.triclinic = periodic[3] != 0;
  local = with_context(where, H5mdWriter::open_existing(comm, config_.file, layout, numbers[0],
                                                        numbers[1], &writer_));
  Status agreed = agree_on_status(comm, local);
  if (!agreed.ok()) {
    writer_.reset();
    return agreed;
  }
  if (numbers[0] > 0) {
    appended_after_step_ = numbers[2];
    appended_after_count_ = numbers[3];
  }
  return {};
}

Status DumpStage::open_writer(MPI_Comm comm, const ParticleArrays &particles,
                              const BondArrays &bonds, const Box &box, int64_t first_count,
                              int64_t step) {
  int fields = 0;
  if (Status s = choose_fields(comm, config_, particles, bonds, &fields); !s.ok()) return s;
  if (config_.mode == DumpMode::kAppend) {
    int exists = 0;
    std::error_code ec;
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    if (rank == 0) exists = std::filesystem::exists(config_.file, ec);
    MPI_Bcast(&exists, 1, MPI_INT, 0, comm);
    if (exists) return append_to_existing(comm, fields, first_count, step);
  }
  DumpLayout layout;
  layout.first_count = first_count;
  layout.first_bonds = bonds.count();  // listed over all ranks (by both: some twice): a chunk size
  MPI_Allreduce(MPI_IN_PLACE, &layout.first_bonds, 1, MPI_INT64_T, MPI_SUM, comm);
  layout.single_precision = config_.single_precision;
  layout.fields = to_fields(fields);
  int periodic[4] = {box.periodic[0], box.periodic[1], box.periodic[2], box.triclinic};
  MPI_Bcast(periodic, 4, MPI_INT, 0, comm);
  for (int a = 0; a < 3; ++a) layout.periodic[a] = periodic[a] != 0;
  layout.triclinic = periodic[3] != 0;

  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  Status local;
  if (rank == 0) {  // a dump into a new directory: create it, as image outputs do
    const auto dir = std::filesystem::path(config_.file).parent_path();
    std::error_code ec;
    if (!dir.empty()) std::filesystem::create_directories(dir, ec);
    if (ec)
      local = {StatusCode::kIo, "dump.file: " + config_.file + ": cannot create directory " +
                                    dir.string() + " (" + ec.message() + ")"};
  }
  if (Status s = agree_on_status(comm, local); !s.ok()) return s;
  local = with_context("dump.file: " + config_.file + ": step " + std::to_string(step) + ": ",
                       H5mdWriter::create(comm, config_.file, layout, &writer_,
                                          /*replace=*/config_.mode == DumpMode::kOverwrite));
  Status agreed = agree_on_status(comm, local);
  if (!agreed.ok()) writer_.reset();
  return agreed;
}

Status DumpStage::write(MPI_Comm comm, const ParticleArrays &particles, const BondArrays &bonds,
                        const Extent &global, const std::optional<Box> &box, int64_t step,
                        double time) {
  // A group (mask) dumps only its members: their indices, in the published order.
  std::vector<int64_t> rows;
  if (particles.has_mask())
    for (int64_t i = 0; i < particles.count(); ++i)
      if (particles.kept(i)) rows.push_back(i);
  int64_t count = particles.has_mask() ? int64_t(rows.size()) : particles.count();
  int64_t offset = 0, total = 0;
  MPI_Exscan(&count, &offset, 1, MPI_INT64_T, MPI_SUM, comm);
  MPI_Allreduce(&count, &total, 1, MPI_INT64_T, MPI_SUM, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) offset = 0;  // MPI_Exscan leaves rank 0's result undefined
  const std::string where = "dump.file: " + config_.file + ": step " + std::to_string(step) + ": ";
  if (total == 0)
    return {StatusCode::kInvalidArgument, where + "no rank has particles; nothing dumped"};

  const Box b = frame_box(comm, global, box);
  if (!writer_)
    if (Status s = open_writer(comm, particles, bonds, b, total, step); !s.ok()) return s;
  // A file made for an orthogonal box's edge lengths cannot record a tilt (rank 0's box).
  int tilted = b.triclinic && (b.tilt[0] != 0.0 || b.tilt[1] != 0.0 || b.tilt[2] != 0.0);
  MPI_Bcast(&tilted, 1, MPI_INT, 0, comm);
  if (tilted && !writer_->layout().triclinic)
    return {StatusCode::kInvalidArgument,
            where +
                "the box is triclinic, but the dump file records an orthogonal box's edge "
                "lengths (its first frame's box was orthogonal): give the box with "
                "lantern_set_triclinic_box from the first dumped step on (zero tilt is "
                "fine), or dump to a new file"};
  if (appended_after_step_) {
    // The same on every rank (broadcast when the file was opened). A restarted run that dumps a
    // step the file already holds would make its steps go back: that step is refused, and the
    // dump carries on from the next step after the file's last.
    if (step <= *appended_after_step_)
      return {StatusCode::kInvalidArgument,
              where + "dump.mode: append, and " + config_.file +
                  " already holds frames up to step " + std::to_string(*appended_after_step_) +
                  "; frames are appended after it (this step is not dumped)"};
    if (rank == 0 && total != appended_after_count_)
      std::fprintf(stderr,
                   "lantern: warning: dump.file: %s: step %lld: %lld particles, appended after a "
                   "frame of %lld (step %lld): a restarted run normally has the same particles\n",
                   config_.file.c_str(), static_cast<long long>(step),
                   static_cast<long long>(total), static_cast<long long>(appended_after_count_),
                   static_cast<long long>(*appended_after_step_));
    appended_after_step_.reset();
  }
  if (Status s =
          agree_on_status(comm, check_local_fields(writer_->layout().fields, particles, step));
      !s.ok())
    return s;

  DumpFrame frame{&particles, particles.has_mask() ? &rows : nullptr, offset, total, step, time, b};
  std::vector<int64_t> pairs;
  if (writer_->layout().fields.bonds) {
    pairs = bond_ids(bonds, particles);
    const int64_t mine = int64_t(pairs.size() / 2);
    MPI_Exscan(&mine, &frame.bond_offset, 1, MPI_INT64_T, MPI_SUM, comm);
    MPI_Allreduce(&mine, &frame.bond_total, 1, MPI_INT64_T, MPI_SUM, comm);
    if (rank == 0) frame.bond_offset = 0;
    frame.bond_ids = &pairs;
  }
  const Status appended = with_context(where, writer_->append(frame));
  if (appended.ok()) return appended;
  // Agreed by the writer: every rank closes the file here, together, and stops dumping; then rank
  // 0 cuts the failed frame back from every time series (serially, on the closed file).
  const int64_t kept = writer_->frames(), kept_rows = writer_->rows();
  writer_.reset();
  stopped_ = true;
  const Status cut = broadcast_status(
      comm, rank == 0 ? cut_back_frames(config_.file, kept, kept_rows) : Status(), 0);
  return {appended.code,
          appended.message + " (dump stopped for the rest of the run; " + config_.file +
              " keeps its " + std::to_string(kept) + " earlier frame" + (kept == 1 ? "" : "s") +
              (cut.ok() ? ")"
                        : "; cutting the failed frame back failed: " + cut.message +
                              ", so some datasets may be one frame longer than their step)")};
}

}  // namespace lantern
