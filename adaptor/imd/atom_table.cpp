#include "atom_table.h"

#include <mpi.h>

#include <algorithm>
#include <memory>
#include <numeric>

#include "frame_source.h"

namespace lantern_imd {

std::string load_atom_table(const std::string &path, int64_t n, AtomTable *out) {
  if (path.empty()) {
    out->type.assign(size_t(n), 0);
    out->id.resize(size_t(n));
    std::iota(out->id.begin(), out->id.end(), int64_t(1));
    return {};
  }
  const std::string where = "--types " + path + ": ";
  std::unique_ptr<lantern::FrameSource> source;
  if (std::string e = lantern::open_frame_source(path, MPI_COMM_SELF, &source); !e.empty())
    return where + e;
  if (source->frames().empty()) return where + "no frame";
  const int64_t count = source->frames().front().count;
  if (count != n)
    return where + "its first frame has " + std::to_string(count) + " atoms, the stream " +
           std::to_string(n);
  lantern::ParticleFrame frame;
  if (std::string e = source->read(0, 0, count, &frame); !e.empty()) return where + e;
  if (frame.type.empty()) return where + "no type column";
  std::vector<size_t> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), size_t(0));
  if (!frame.id.empty()) {
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return frame.id[a] < frame.id[b]; });
    for (size_t k = 1; k < order.size(); ++k)
      if (frame.id[order[k]] == frame.id[order[k - 1]])
        return where + "atom id " + std::to_string(frame.id[order[k]]) + " appears twice";
  }
  out->type.resize(size_t(n));
  out->id.resize(size_t(n));
  for (size_t k = 0; k < order.size(); ++k) {
    out->type[k] = int32_t(frame.type[order[k]]);
    out->id[k] = frame.id.empty() ? int64_t(k) + 1 : frame.id[order[k]];
  }
  return {};
}

}  // namespace lantern_imd
