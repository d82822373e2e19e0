#include "neighbor_list.h"

#include <algorithm>
#include <cmath>

namespace mini_md {

BinGrid::BinGrid(const Vec3 &lo, const Vec3 &hi, double pad, double target_size, int ring)
    : ring_(ring) {
  for (int d = 0; d < 3; ++d) {
    const double len = (hi[d] - lo[d]) + 2 * pad;
    inner_[d] = std::max(1, static_cast<int>(len / target_size));
    size_[d] = len / inner_[d];
    inv_size_[d] = 1.0 / size_[d];
    origin_[d] = lo[d] - pad;
    n_[d] = inner_[d] + 2 * ring;
  }
}

int BinGrid::bin_of(const Vec3 &p) const {
  int c[3];
  for (int d = 0; d < 3; ++d) {
    // Clamp: a ghost a hair beyond the padded region still lands in an edge bin.
    const int k = static_cast<int>(std::floor((p[d] - origin_[d]) * inv_size_[d]));
    c[d] = std::clamp(k, 0, inner_[d] - 1) + ring_;
  }
  return (c[2] * n_[1] + c[1]) * n_[0] + c[0];
}

namespace {

// A stencil row: bins [centre + offset - reach, centre + offset + reach], adjacent along x.
struct StencilRow {
  int offset;
  int reach;
};

// Rows of the (2 ring + 1)^3 bin block around a centre bin, trimmed to the bins whose nearest
// points can lie within `cut` of the centre bin.
std::vector<StencilRow> make_stencil(const BinGrid &grid, double cut, int ring) {
  std::vector<StencilRow> rows;
  const auto &n = grid.dims();
  const Vec3 &s = grid.bin_size();
  auto gap = [](int k, double size) { return std::max(0, std::abs(k) - 1) * size; };
  for (int k = -ring; k <= ring; ++k) {
    for (int j = -ring; j <= ring; ++j) {
      const double yz2 = gap(j, s[1]) * gap(j, s[1]) + gap(k, s[2]) * gap(k, s[2]);
      int reach = -1;
      for (int i = 0; i <= ring; ++i) {
        if (yz2 + gap(i, s[0]) * gap(i, s[0]) < cut * cut) reach = i;
      }
      if (reach >= 0) rows.push_back({(k * n[1] + j) * n[0], reach});
    }
  }
  return rows;
}

// For two images of the same atom (equal ids) the pair belongs to the lower one in z, y, x.
inline bool above(const Vec3 &xj, const Vec3 &xi) {
  if (xj[2] != xi[2]) return xj[2] > xi[2];
  if (xj[1] != xi[1]) return xj[1] > xi[1];
  return xj[0] > xi[0];
}

}  // namespace

void NeighborList::build(const Atoms &atoms, const Vec3 &lo, const Vec3 &hi, double list_cut) {
  // Bins of half the list cutoff: the stencil then covers less volume than 27 full-cutoff bins,
  // so fewer distance checks per atom.
  const int ring = 2;
  const BinGrid grid(lo, hi, list_cut, 0.5 * list_cut, ring);
  const std::vector<StencilRow> stencil = make_stencil(grid, list_cut, ring);
  const int ntotal = atoms.ntotal();
  const Vec3 *x = atoms.x.data();
  const int64_t *id = atoms.id.data();

  // Counting sort of all atoms into bins, with bin-ordered copies of position and id.
  atom_bin_.resize(ntotal);
  bin_start_.assign(grid.bin_count() + 1, 0);
  for (int i = 0; i < ntotal; ++i) {
    atom_bin_[i] = grid.bin_of(x[i]);
    ++bin_start_[atom_bin_[i] + 1];
  }
  for (int b = 0; b < grid.bin_count(); ++b) bin_start_[b + 1] += bin_start_[b];
  binned_x_.resize(ntotal);
  binned_id_.resize(ntotal);
  binned_index_.resize(ntotal);
  {
    std::vector<int> fill(bin_start_.begin(), bin_start_.end() - 1);
    for (int i = 0; i < ntotal; ++i) {
      const int k = fill[atom_bin_[i]]++;
      binned_x_[k] = x[i];
      binned_id_[k] = id[i];
      binned_index_[k] = i;
    }
  }

  const double cut2 = list_cut * list_cut;
  const int nlocal = atoms.nlocal;
  offsets_.resize(nlocal + 1);
  offsets_[0] = 0;
  int64_t n = 0;
  for (int i = 0; i < nlocal; ++i) {
    const Vec3 xi = x[i];
    const int64_t idi = id[i];
    const int bi = atom_bin_[i];
    int64_t candidates = 0;
    for (const StencilRow &row : stencil) {
      const int b = bi + row.offset;
      candidates += bin_start_[b + row.reach + 1] - bin_start_[b - row.reach];
    }
    if (static_cast<int64_t>(neighbors_.size()) < n + candidates) {
      // Grow by a quarter (extrapolated from the atoms done so far), not by doubling: at
      // 10^7 atoms the list is the largest array, and a doubling copy would triple it briefly.
      const int64_t projected = n / std::max(i, 1) * nlocal;
      neighbors_.resize(std::max<int64_t>({projected + projected / 4, n + candidates,
                                           static_cast<int64_t>(neighbors_.size()) * 5 / 4}));
    }
    int *out = neighbors_.data();
    for (const StencilRow &row : stencil) {
      const int b = bi + row.offset;
      const int k_end = bin_start_[b + row.reach + 1];
      for (int k = bin_start_[b - row.reach]; k < k_end; ++k) {
        const double dx = xi[0] - binned_x_[k][0];
        const double dy = xi[1] - binned_x_[k][1];
        const double dz = xi[2] - binned_x_[k][2];
        const int64_t idj = binned_id_[k];
        // The pair belongs to the atom with the smaller id (see the header); branch-free
        // append, since which candidates pass is unpredictable.
        bool keep = (dx * dx + dy * dy + dz * dz < cut2) & (idj > idi);
        if (idj == idi) keep = above(binned_x_[k], xi) && dx * dx + dy * dy + dz * dz < cut2;
        out[n] = binned_index_[k];
        n += keep;
      }
    }
    offsets_[i + 1] = n;
  }
  neighbors_.resize(n);
}

std::vector<int> spatial_sort_order(const Atoms &atoms, const Vec3 &lo, const Vec3 &hi,
                                    double list_cut) {
  const BinGrid grid(lo, hi, 0.0, list_cut, 0);
  const int n = atoms.nlocal;
  std::vector<int> bin(n);
  std::vector<int> start(grid.bin_count() + 1, 0);
  for (int i = 0; i < n; ++i) {
    bin[i] = grid.bin_of(atoms.x[i]);
    ++start[bin[i] + 1];
  }
  for (int b = 0; b < grid.bin_count(); ++b) start[b + 1] += start[b];
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[start[bin[i]]++] = i;
  return order;
}

}  // namespace mini_md
