/* Renders eight particles through the installed Lantern; argument: output directory. */
#include <lantern/lantern.h>
#include <stdio.h>

int main(int argc, char **argv) {
  double x[8][3];
  for (int i = 0; i < 8; ++i) x[i][0] = i & 1, x[i][1] = (i >> 1) & 1, x[i][2] = i >> 2;
  char config[512];
  snprintf(config, sizeof config,
           "scenes:\n  - width: 32\n    height: 32\n    output: {pattern: '%s/consumer.png'}\n",
           argc > 1 ? argv[1] : ".");
  lantern_context *ctx = NULL;
  lantern_particles p = {0};
  p.count = 8;
  p.position = (lantern_array){x, LANTERN_FLOAT64, 0};
  if (lantern_open(config, LANTERN_COMM_WORLD, &ctx) || lantern_publish(ctx, &p) ||
      lantern_execute(ctx, 0, 0.0)) {
    fprintf(stderr, "consumer: %s\n", lantern_error_message(ctx));
    return 1;
  }
  lantern_close(ctx);
  printf("consumer: Lantern %s rendered %s/consumer.png\n", lantern_version(),
         argc > 1 ? argv[1] : ".");
  return 0;
}
