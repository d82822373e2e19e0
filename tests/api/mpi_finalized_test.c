/* The host calls MPI_Finalize while a Lantern context is still open (as an explicit
 * MPI.Finalize() in mpi4py would): every later call returns LANTERN_ERR_MPI naming MPI_Finalize,
 * lantern_close releases the context without any MPI call (an image still being written in the
 * background is waited for), and the process exits normally. Usage: mpi_finalized_test DIR */
#include <lantern/lantern.h>
#include <mpi.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

static int failures = 0;

static void expect(int ok, const char *what, const char *detail) {
  if (!ok) {
    fprintf(stderr, "FAILED: %s (%s)\n", what, detail);
    ++failures;
  }
}

int main(int argc, char **argv) {
  if (argc != 2) return 2;
  MPI_Init(&argc, &argv);
  char config[2048], image[1024];
  snprintf(config, sizeof config,
           "stats: '%s/finalized_stats.jsonl'\n"
           "scenes:\n  - name: f\n    width: 32\n    height: 24\n    renderer: cpu\n"
           "    output: {pattern: '%s/finalized_{step:04d}.png', asynchronous: true}\n"
           "dump:\n  file: '%s/finalized.h5'\n",
           argv[1], argv[1], argv[1]);
  char dump[1024];
  snprintf(image, sizeof image, "%s/finalized_0001.png", argv[1]);
  snprintf(dump, sizeof dump, "%s/finalized.h5", argv[1]);
  unlink(image);
  unlink(dump); /* an earlier run's: dump.mode: create would refuse it */
  double x[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  lantern_particles p;
  memset(&p, 0, sizeof p);
  p.count = 3;
  p.position.data = x;
  p.position.type = LANTERN_FLOAT64;
  lantern_context *ctx = NULL;
  lantern_status st = lantern_open(config, LANTERN_COMM_WORLD, &ctx);
  expect(st == LANTERN_OK, "open", lantern_error_message(ctx));
  expect(lantern_publish(ctx, &p) == LANTERN_OK, "publish", lantern_error_message(ctx));
  expect(lantern_execute(ctx, 0, 0.0) == LANTERN_OK, "step 0", lantern_error_message(ctx));
  expect(lantern_execute(ctx, 1, 0.1) == LANTERN_OK, "step 1", lantern_error_message(ctx));
  MPI_Finalize(); /* with the image of step 1 maybe still in flight */

  st = lantern_execute(ctx, 2, 0.2);
  expect(st == LANTERN_ERR_MPI, "execute after MPI_Finalize returns LANTERN_ERR_MPI",
         lantern_error_message(ctx));
  expect(strstr(lantern_error_message(ctx), "MPI_Finalize") != NULL, "the message names it",
         lantern_error_message(ctx));
  st = lantern_reconfigure(ctx, config);
  expect(st == LANTERN_ERR_MPI, "reconfigure after MPI_Finalize", lantern_error_message(ctx));
  expect(lantern_publish(ctx, &p) == LANTERN_OK, "publish is local", lantern_error_message(ctx));
  st = lantern_close(ctx);
  expect(st == LANTERN_ERR_MPI, "close after MPI_Finalize returns LANTERN_ERR_MPI", "");
  expect(access(image, F_OK) == 0, "the image in flight was finished", image);
  /* A new context cannot open either, and says why. */
  ctx = NULL;
  st = lantern_open(config, LANTERN_COMM_WORLD, &ctx);
  expect(st == LANTERN_ERR_MPI, "open after MPI_Finalize", lantern_error_message(ctx));
  lantern_close(ctx);
  if (failures == 0) puts("mpi_finalized_test: OK");
  return failures == 0 ? 0 : 1;
}
