// Test helper: renders a deterministic particle set through the C API (each rank publishing the
// same share lantern-render would read) and writes the same particles as a LAMMPS text dump, so
// a test can check that lantern-render on that dump produces byte-identical images.
//
//   dump_api_render CONFIG.yaml DUMP.lammpstrj [varying]
//
// With `varying`, the particle count changes from step to step: step 0 has
// 3000 particles, step 10 loses every fifth (2400, from the middle of the id range, as
// evaporation would), step 20 gains new ones beyond the first count (3200).
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/dump/particle_frame.h"
#include "lantern/lantern.h"

namespace {

constexpr int64_t kCount = 3000;
const std::vector<int64_t> kSteps = {0, 10};
const std::vector<int64_t> kVaryingSteps = {0, 10, 20};

double coord(int64_t i, int c, int64_t step) {
  return 10.0 * std::fmod(std::sin(12.9898 * i + 78.233 * c) * 43758.5453 + 0.01 * step, 1.0) +
         (c == 0 ? 0.3 * step : 0.0);
}

// The particle indices present at a step, in the order every writer uses.
std::vector<int64_t> present(int64_t step, bool varying) {
  std::vector<int64_t> out;
  const int64_t n = !varying || step < 20 ? kCount : 4000;
  for (int64_t i = 0; i < n; ++i)
    if (!varying || step == 0 || i % 5 != 2) out.push_back(i);
  return out;
}

void write_dump(const std::string &path, const std::vector<int64_t> &steps, bool varying) {
  FILE *f = std::fopen(path.c_str(), "w");
  if (!f) return;
  for (const int64_t step : steps) {
    const std::vector<int64_t> ids = present(step, varying);
    std::fprintf(f, "ITEM: TIMESTEP\n%lld\nITEM: NUMBER OF ATOMS\n%lld\n", (long long)step,
                 (long long)ids.size());
    std::fprintf(f, "ITEM: BOX BOUNDS pp pp pp\n-10 20\n-10 10\n-10 10\n");
    std::fprintf(f, "ITEM: ATOMS id type x y z vx\n");
    for (const int64_t i : ids)  // %.17g: the exact doubles survive the text round trip
      std::fprintf(f, "%lld %lld %.17g %.17g %.17g 0.0\n", (long long)(i + 1), (long long)(i % 4),
                   coord(i, 0, step), coord(i, 1, step), coord(i, 2, step));
  }
  std::fclose(f);
}

}  // namespace

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 1, code = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const bool varying = argc == 4 && std::string(argv[3]) == "varying";
  if (argc != 3 && !varying) {
    std::fprintf(stderr, "usage: dump_api_render CONFIG.yaml DUMP.lammpstrj [varying]\n");
    MPI_Finalize();
    return 2;
  }
  const std::vector<int64_t> &steps = varying ? kVaryingSteps : kSteps;
  if (rank == 0) write_dump(argv[2], steps, varying);
  lantern_context *ctx = nullptr;
  if (lantern_open(argv[1], MPI_Comm_c2f(MPI_COMM_WORLD), &ctx) != LANTERN_OK) {
    std::fprintf(stderr, "dump_api_render: %s\n", lantern_error_message(ctx));
    code = 1;
  }
  for (const int64_t step : steps) {
    if (code) break;
    const std::vector<int64_t> ids = present(step, varying);
    const auto [begin, end] = lantern::rank_share(int64_t(ids.size()), rank, size);
    std::vector<double> xyz;
    std::vector<int64_t> type, id;
    for (int64_t k = begin; k < end; ++k) {
      const int64_t i = ids[k];
      for (int c = 0; c < 3; ++c) xyz.push_back(coord(i, c, step));
      type.push_back(i % 4);
      id.push_back(i + 1);
    }
    lantern_particles p{};
    p.count = int64_t(id.size());
    p.position = {xyz.data(), LANTERN_FLOAT64, 0};
    p.type = {type.data(), LANTERN_INT64, 0};
    p.id = {id.data(), LANTERN_INT64, 0};
    const double low[3] = {-10, -10, -10}, high[3] = {20, 10, 10};
    const int periodic[3] = {1, 1, 1};
    if (lantern_publish(ctx, &p) != LANTERN_OK ||
        lantern_set_box(ctx, low, high, periodic) != LANTERN_OK ||
        lantern_execute(ctx, step, double(step)) != LANTERN_OK) {
      std::fprintf(stderr, "dump_api_render: %s\n", lantern_error_message(ctx));
      code = 1;
    }
  }
  lantern_close(ctx);
  MPI_Finalize();
  return code;
}
