#include "core/dump/dump_stage.h"

#include <filesystem>
#include <vector>

#include "core/common/collective_status.h"
#include "core/dump/frame_cut_back.h"

namespace lantern {
namespace {

enum FieldBit : int { kType = 1, kId = 2, kScalar = 4, kRadius = 8 };

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

// The fields to write: the configured list, or else every array some rank published. Listing a
// field that no rank published is an error (a typo'd expectation, not a silent empty dataset).
Status choose_fields(MPI_Comm comm, const DumpConfig &config, const ParticleArrays &p, int *out) {
  int any = published_fields(p);
  MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_BOR, comm);
  if (config.fields.empty()) {
    *out = any;
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

}  // namespace

Status DumpStage::open_writer(MPI_Comm comm, const ParticleArrays &particles, const Box &box,
                              int64_t first_count, int64_t step) {
  int fields = 0;
  if (Status s = choose_fields(comm, config_, particles, &fields); !s.ok()) return s;
  DumpLayout layout;
  layout.first_count = first_count;
  layout.single_precision = config_.single_precision;
  layout.fields = to_fields(fields);
  int periodic[3] = {box.periodic[0], box.periodic[1], box.periodic[2]};
  MPI_Bcast(periodic, 3, MPI_INT, 0, comm);
  for (int a = 0; a < 3; ++a) layout.periodic[a] = periodic[a] != 0;

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
                       H5mdWriter::create(comm, config_.file, layout, &writer_));
  Status agreed = agree_on_status(comm, local);
  if (!agreed.ok()) writer_.reset();
  return agreed;
}

Status DumpStage::write(MPI_Comm comm, const ParticleArrays &particles, const Extent &global,
                        const std::optional<Box> &box, int64_t step, double time) {
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
    if (Status s = open_writer(comm, particles, b, total, step); !s.ok()) return s;
  if (Status s =
          agree_on_status(comm, check_local_fields(writer_->layout().fields, particles, step));
      !s.ok())
    return s;

  const Status appended =
      with_context(where, writer_->append({&particles, particles.has_mask() ? &rows : nullptr,
                                           offset, total, step, time, b}));
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
