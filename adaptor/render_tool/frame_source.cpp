#include "frame_source.h"

#include "core/dump/h5md_reader.h"
#include "core/dump/lammps_dump_reader.h"

namespace lantern {
namespace {

template <typename Reader>
class ReaderSource : public FrameSource {
 public:
  explicit ReaderSource(std::unique_ptr<Reader> reader) : reader_(std::move(reader)) {}
  const std::vector<FrameInfo> &frames() const override { return reader_->frames(); }
  std::string read(size_t index, int64_t begin, int64_t end, ParticleFrame *out) const override {
    return reader_->read(index, begin, end, out).message;
  }

 protected:
  std::unique_ptr<Reader> reader_;
};

class H5mdSource : public ReaderSource<H5mdReader> {
 public:
  using ReaderSource::ReaderSource;
  bool has_bonds() const override { return reader_->has_bonds(); }
  std::string read_bonds(size_t index, BondTopology *out) const override {
    *out = BondTopology{};
    if (Status s = reader_->read_bonds(index, &out->first_id, &out->second_id, &out->pair); !s.ok())
      return s.message;
    out->type.assign(out->first_id.size(), 0);  // H5MD's pair lists carry no bond type
    out->origin = reader_->bonds_dataset(index);
    return {};
  }
};

}  // namespace

std::string open_frame_source(const std::string &path, MPI_Comm comm,
                              std::unique_ptr<FrameSource> *out) {
  // H5MD as soon as one rank sees an HDF5 file: H5mdReader::open then agrees on whether every
  // rank can read it before its collective open (a rank taking the text reader instead would
  // leave the others waiting there).
  int hdf5 = has_hdf5_signature(path) ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &hdf5, 1, MPI_INT, MPI_MAX, comm);
  if (hdf5 != 0) {
    std::unique_ptr<H5mdReader> reader;
    if (Status s = H5mdReader::open(path, comm, &reader); !s.ok()) return s.message;
    *out = std::make_unique<H5mdSource>(std::move(reader));
    return {};
  }
  std::unique_ptr<LammpsDumpReader> reader;
  if (Status s = LammpsDumpReader::open(path, &reader); !s.ok()) return s.message;
  *out = std::make_unique<ReaderSource<LammpsDumpReader>>(std::move(reader));
  return {};
}

}  // namespace lantern
