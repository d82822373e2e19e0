// LAMMPS as a real Lantern client: runs the LAMMPS "in.lj" Lennard-Jones melt through the
// LAMMPS library interface and hands Lantern LAMMPS's own arrays (no copy) every N steps.
//
//   lammps_lantern CONFIG.yaml [--cells L] [--steps N] [--every K] [--input in.file]
//                  [--compare-dump-image DIR --image-size W]
//
// --cells L      fcc lattice of L^3 unit cells (4 L^3 atoms; L = 63 gives 1,000,188 atoms)
// --input FILE   run this LAMMPS input instead of the built-in in.lj set-up
// --compare-dump-image DIR   at every rendered step, also render with LAMMPS's own image dump
//                (write_dump ... image, W x W pixels, PNG in DIR) and print seconds per image
//                for both and the ratio: the benchmark of tests/bench/lammps_dump_image.sh.
//
// What Lantern borrows: x (double[nmax][3]; LAMMPS allocates 2-D arrays as one block, so x[0]
// with a 24-byte stride covers every local atom, checked below), type (int) and the atom ids
// (tagint: int32 or int64 depending on how LAMMPS was built). Only the nlocal owned atoms are
// published, never ghosts. LAMMPS may reallocate these arrays when atoms migrate, so they are
// published again before every lantern_execute().
#include <mpi.h>

#define LAMMPS_LIB_MPI 1
#include <lammps/library.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "lantern/lantern.h"

namespace {

struct Options {
  std::string config, input, compare_dir;
  int cells = 10, steps = 100, every = 10, image_size = 1024;
};

Options parse(int argc, char **argv) {
  Options o;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--cells")
      o.cells = std::stoi(value());
    else if (a == "--steps")
      o.steps = std::stoi(value());
    else if (a == "--every")
      o.every = std::stoi(value());
    else if (a == "--input")
      o.input = value();
    else if (a == "--compare-dump-image")
      o.compare_dir = value();
    else if (a == "--image-size")
      o.image_size = std::stoi(value());
    else if (a.rfind("--", 0) == 0)
      throw std::runtime_error("unknown option " + a);
    else
      positional.push_back(a);
  }
  if (positional.size() != 1) throw std::runtime_error("expected one CONFIG.yaml");
  if (o.cells < 1 || o.steps < 0 || o.every < 1 || o.image_size < 16)
    throw std::runtime_error("--cells, --every >= 1, --steps >= 0, --image-size >= 16");
  o.config = positional[0];
  return o;
}

// The LAMMPS bench/in.lj problem (fcc at reduced density 0.8442, T = 3.0, rc = 2.5).
std::string lj_setup(int cells) {
  const std::string l = std::to_string(cells);
  return "units lj\n"
         "atom_style atomic\n"
         "lattice fcc 0.8442\n"
         "region box block 0 " +
         l + " 0 " + l + " 0 " + l +
         "\n"
         "create_box 1 box\n"
         "create_atoms 1 box\n"
         "mass 1 1.0\n"
         "velocity all create 3.0 87287 loop geom\n"
         "pair_style lj/cut 2.5\n"
         "pair_coeff 1 1 1.0 1.0 2.5\n"
         "neighbor 0.3 bin\n"
         "neigh_modify delay 0 every 20 check no\n"
         "fix 1 all nve\n";
}

// Owns the LAMMPS instance.
struct LammpsCloser {
  void operator()(void *lmp) const { lammps_close(lmp); }
};
using Lammps = std::unique_ptr<void, LammpsCloser>;

struct ContextCloser {
  void operator()(lantern_context *ctx) const { lantern_close(ctx); }
};
using Context = std::unique_ptr<lantern_context, ContextCloser>;

void check_lammps(void *lmp, const char *what) {
  if (lammps_has_error(lmp)) {
    char message[1024] = {0};
    lammps_get_last_error_message(lmp, message, sizeof(message));
    throw std::runtime_error(std::string(what) + ": LAMMPS: " + message);
  }
}

void check_lantern(lantern_context *ctx, lantern_status st, const char *what) {
  if (st != LANTERN_OK)
    throw std::runtime_error(std::string(what) + ": " + lantern_error_message(ctx));
}

// Publishes LAMMPS's current local atoms (borrowed) and box.
void publish(void *lmp, lantern_context *ctx) {
  const int nlocal = lammps_extract_setting(lmp, "nlocal");
  const auto x = static_cast<double **>(lammps_extract_atom(lmp, "x"));
  const auto type = static_cast<const int *>(lammps_extract_atom(lmp, "type"));
  const void *id = lammps_extract_atom(lmp, "id");
  if (nlocal > 1 && x[1] != x[0] + 3)  // the no-copy hand-over relies on one contiguous block
    throw std::runtime_error("LAMMPS x is not one contiguous [n][3] block");
  lantern_particles p{};
  p.count = nlocal;
  if (nlocal > 0) {
    p.position = {x[0], LANTERN_FLOAT64, 3 * sizeof(double)};
    p.type = {type, LANTERN_INT32, 0};
    p.id = {id, lammps_extract_setting(lmp, "tagint") == 8 ? LANTERN_INT64 : LANTERN_INT32, 0};
  }
  check_lantern(ctx, lantern_publish(ctx, &p), "lantern_publish");

  double lo[3], hi[3], xy, yz, xz;
  int periodic[3], changed;
  lammps_extract_box(lmp, lo, hi, &xy, &yz, &xz, periodic, &changed);
  check_lantern(ctx, lantern_set_box(ctx, lo, hi, periodic), "lantern_set_box");
}

// Seconds of f() on the slowest rank (what the user waits for).
template <typename F>
double timed(F &&f) {
  MPI_Barrier(MPI_COMM_WORLD);
  const double t0 = MPI_Wtime();
  f();
  double dt = MPI_Wtime() - t0;
  MPI_Allreduce(MPI_IN_PLACE, &dt, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return dt;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int run(const Options &o, int rank) {
  std::vector<char *> args;
  std::string a0 = "lammps", a1 = "-log", a2 = "none", a3 = "-screen", a4 = "none", a5 = "-nocite";
  for (std::string *s : {&a0, &a1, &a2, &a3, &a4, &a5}) args.push_back(s->data());
  const Lammps lmp(lammps_open(int(args.size()), args.data(), MPI_COMM_WORLD, nullptr));
  if (!lmp) throw std::runtime_error("lammps_open failed");
  if (o.input.empty())
    lammps_commands_string(lmp.get(), lj_setup(o.cells).c_str());
  else
    lammps_file(lmp.get(), o.input.c_str());
  check_lammps(lmp.get(), "set-up");

  lantern_context *raw = nullptr;
  const lantern_status opened = lantern_open(o.config.c_str(), MPI_Comm_c2f(MPI_COMM_WORLD), &raw);
  const Context ctx(raw);
  check_lantern(ctx.get(), opened, "lantern_open");

  const double dt = *static_cast<double *>(lammps_extract_global(lmp.get(), "dt"));
  const auto natoms = static_cast<long long>(lammps_get_natoms(lmp.get()));
  if (rank == 0)
    std::printf("LAMMPS LJ: %lld atoms, %d steps, image every %d\n", natoms, o.steps, o.every);
  double lantern_s = 0, lammps_s = 0, md_s = 0;
  std::vector<double> lantern_each, lammps_each;  // per image: medians resist a slow first frame
  int images = 0;
  bool first_run = true;
  for (int step = 0; step <= o.steps; step += o.every) {
    if (step > 0) {
      const std::string cmd =
          "run " + std::to_string(o.every) + (first_run ? "" : " pre no post no");
      md_s += timed([&] { lammps_command(lmp.get(), cmd.c_str()); });
      check_lammps(lmp.get(), "run");
      first_run = false;
    }
    publish(lmp.get(), ctx.get());  // every time: LAMMPS may have reallocated x and type
    const double t = timed([&] {
      check_lantern(ctx.get(), lantern_execute(ctx.get(), step, step * dt), "lantern_execute");
    });
    double tl = 0;
    if (!o.compare_dir.empty()) {
      const std::string size = std::to_string(o.image_size);
      char name[64];
      std::snprintf(name, sizeof(name), "/lammps_%06d.png", step);
      const std::string cmd = "write_dump all image " + o.compare_dir + name + " type type size " +
                              size + " " + size + " adiam 1.0";
      tl = timed([&] { lammps_command(lmp.get(), cmd.c_str()); });
      check_lammps(lmp.get(), "write_dump image");
      lammps_s += tl;
    }
    lantern_s += t;
    lantern_each.push_back(t);
    if (!o.compare_dir.empty()) lammps_each.push_back(tl);
    ++images;
    if (rank == 0)
      std::printf("step %6d  lantern %.3f s%s\n", step, t,
                  o.compare_dir.empty()
                      ? ""
                      : ("  lammps dump image " + std::to_string(tl) + " s").c_str());
  }
  if (rank == 0) {
    std::printf("MD: %.2f s for %d steps\n", md_s, o.steps);
    std::printf("images: %d  lantern: %.3f s/image", images, lantern_s / images);
    if (!o.compare_dir.empty())
      std::printf("  lammps dump image: %.3f s/image  ratio: %.1fx", lammps_s / images,
                  lammps_s / lantern_s);
    std::printf("\n");
    const double lantern_median = median(lantern_each);
    std::printf("median per image: lantern: %.3f s", lantern_median);
    if (!o.compare_dir.empty())
      std::printf("  lammps dump image: %.3f s  ratio: %.1fx", median(lammps_each),
                  median(lammps_each) / lantern_median);
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char **argv) {
  MPI_Init(&argc, &argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  int code = 0;
  try {
    code = run(parse(argc, argv), rank);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "lammps_lantern: error: %s\n", e.what());
    code = 1;
  }
  MPI_Finalize();
  return code;
}
