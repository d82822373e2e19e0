/* Renders 100,000 particles (a 50x50x40 lattice) into minimal_000000.png through the C API. */
#include <lantern/lantern.h>
#include <stdio.h>
#include <stdlib.h>

int main(void) {
  enum { NX = 50, NY = 50, NZ = 40, N = NX * NY * NZ };
  double(*x)[3] = malloc(sizeof(double[N][3]));
  int *type = malloc(sizeof(int[N]));
  for (int i = 0; i < N; ++i) {
    x[i][0] = i % NX, x[i][1] = (i / NX) % NY, x[i][2] = i / (NX * NY);
    type[i] = (i / (NX * NY)) % 3;
  }
  lantern_context *ctx = NULL;
  lantern_particles p = {0};
  p.count = N;
  p.position = (lantern_array){x, LANTERN_FLOAT64, 0};
  p.type = (lantern_array){type, LANTERN_INT32, 0};
  if (lantern_open("scenes:\n  - output: {pattern: 'minimal_{step:06d}.png'}\n    radius: 0.5\n",
                   LANTERN_COMM_WORLD, &ctx) != LANTERN_OK ||
      lantern_publish(ctx, &p) != LANTERN_OK || lantern_execute(ctx, 0, 0.0) != LANTERN_OK) {
    fprintf(stderr, "lantern: %s\n", lantern_error_message(ctx));
    return 1;
  }
  lantern_close(ctx);
  free(x), free(type);
  puts("wrote minimal_000000.png");
  return 0;
}
