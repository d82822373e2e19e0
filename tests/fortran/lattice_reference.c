/* The C API's image of examples/fortran/lattice_md's particles at step 4, all on one rank: the
 * reference that the Fortran example's image must equal byte for byte.
 * Usage: lattice_reference CONFIG   (run in the folder the image should go to) */
#include <lantern/lantern.h>
#include <stdio.h>

enum { NSIDE = 8, N = NSIDE * NSIDE * NSIDE, STEPS = 4 };

int main(int argc, char **argv) {
  static double x[N][3];
  static int type[N];
  for (int g = 0; g < N; ++g) {
    const double v[3] = {0.25 * (g % 3), 0.125 * (g % 2), -0.25 * (g % 5)};
    const double lattice[3] = {g % NSIDE, (g / NSIDE) % NSIDE, g / (NSIDE * NSIDE)};
    for (int a = 0; a < 3; ++a) {
      x[g][a] = lattice[a];
      for (int s = 0; s < STEPS; ++s) x[g][a] += v[a]; /* as lattice_md advances: exact */
    }
    type[g] = g % 3;
  }
  lantern_context *ctx = NULL;
  lantern_particles p = {0};
  p.count = N;
  p.position = (lantern_array){x, LANTERN_FLOAT64, 0};
  p.type = (lantern_array){type, LANTERN_INT32, 0};
  if (argc < 2 || lantern_open(argv[1], LANTERN_COMM_WORLD, &ctx) != LANTERN_OK ||
      lantern_publish(ctx, &p) != LANTERN_OK || lantern_execute(ctx, STEPS, STEPS) != LANTERN_OK) {
    fprintf(stderr, "lattice_reference: %s\n",
            argc < 2 ? "usage: lattice_reference CONFIG" : lantern_error_message(ctx));
    return 1;
  }
  return lantern_close(ctx) == LANTERN_OK ? 0 : 1;
}
