/* The C API driven from C99, as a simulation would: separate float arrays, a padded struct
 * array for the interleaved case, errors checked by status. Exits non-zero on any failed check
 * and prints "N passed, M failed". Argument: an output directory. */
#include <lantern/lantern.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

static int passed = 0, failed = 0;
#define CHECK(cond)                                                            \
  do {                                                                         \
    if (cond) {                                                                \
      ++passed;                                                                \
    } else {                                                                   \
      ++failed;                                                                \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
    }                                                                          \
  } while (0)

/* An MD code's atom record: position plus other fields, 48 bytes. */
typedef struct {
  double x[3];
  double v[2];
  int type;
  int flags;
} atom;

static int file_exists(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return 0;
  fclose(f);
  return 1;
}

int main(int argc, char **argv) {
  const char *dir = argc > 1 ? argv[1] : ".";
  char config[1024], png[512];
  snprintf(config, sizeof config,
           "schedule: {every: 10}\n"
           "scenes:\n"
           "  - name: c\n"
           "    width: 64\n"
           "    height: 48\n"
           "    radius: 0.4\n"
           "    output: {pattern: '%s/c_api_{step:04d}.png'}\n",
           dir);
  CHECK(strlen(lantern_version()) >= 5);
  CHECK(LANTERN_VERSION == 100);
  CHECK(lantern_version_number() == LANTERN_VERSION);
  /* Status names: static, never NULL, also for values that are no status. */
  CHECK(strncmp(lantern_status_string(LANTERN_ERR_IO), "LANTERN_ERR_IO: ", 16) == 0);
  CHECK(strncmp(lantern_status_string(LANTERN_OK), "LANTERN_OK: ", 12) == 0);
  CHECK(strcmp(lantern_status_string((lantern_status)1000), "unknown lantern_status") == 0);
  CHECK(strcmp(lantern_status_string((lantern_status)-1), "unknown lantern_status") == 0);

  lantern_context *ctx = NULL;
  CHECK(lantern_open(config, LANTERN_COMM_WORLD, &ctx) == LANTERN_OK);
  CHECK(ctx != NULL);

  /* Separate float32 arrays. */
  enum { N = 27 };
  float xs[N], ys[N], zs[N];
  for (int i = 0; i < N; ++i)
    xs[i] = (float)(i % 3), ys[i] = (float)((i / 3) % 3), zs[i] = (float)(i / 9);
  lantern_particles p;
  memset(&p, 0, sizeof p);
  p.count = N;
  p.position_x = (lantern_array){xs, LANTERN_FLOAT32, 0};
  p.position_y = (lantern_array){ys, LANTERN_FLOAT32, 0};
  p.position_z = (lantern_array){zs, LANTERN_FLOAT32, 0};
  CHECK(lantern_publish(ctx, &p) == LANTERN_OK);
  CHECK(lantern_execute(ctx, 10, 0.05) == LANTERN_OK);
  snprintf(png, sizeof png, "%s/c_api_0010.png", dir);
  CHECK(file_exists(png));
  /* A step the schedule skips writes nothing. */
  CHECK(lantern_execute(ctx, 11, 0.055) == LANTERN_OK);
  snprintf(png, sizeof png, "%s/c_api_0011.png", dir);
  CHECK(!file_exists(png));

  /* Interleaved positions inside a padded record, type from the same record. */
  atom atoms[N];
  memset(atoms, 0, sizeof atoms);
  for (int i = 0; i < N; ++i)
    atoms[i].x[0] = xs[i], atoms[i].x[1] = ys[i], atoms[i].x[2] = zs[i], atoms[i].type = i % 2;
  memset(&p, 0, sizeof p);
  p.count = N;
  p.position = (lantern_array){atoms[0].x, LANTERN_FLOAT64, sizeof(atom)};
  p.type = (lantern_array){&atoms[0].type, LANTERN_INT32, sizeof(atom)};
  CHECK(lantern_publish(ctx, &p) == LANTERN_OK);
  CHECK(lantern_execute(ctx, 20, 0.1) == LANTERN_OK);

  /* Bad input from C: status plus a message naming the field; the context stays usable. */
  p.position.stride_bytes = 16;
  CHECK(lantern_publish(ctx, &p) == LANTERN_ERR_INVALID_ARGUMENT);
  CHECK(strstr(lantern_error_message(ctx), "stride_bytes") != NULL);
  CHECK(lantern_publish(ctx, NULL) == LANTERN_ERR_NULL_ARGUMENT);
  CHECK(lantern_publish(NULL, &p) == LANTERN_ERR_NULL_ARGUMENT);
  CHECK(lantern_execute(NULL, 0, 0.0) == LANTERN_ERR_NULL_ARGUMENT);
  CHECK(strlen(lantern_error_message(NULL)) > 0);
  p.position.stride_bytes = sizeof(atom);
  CHECK(lantern_publish(ctx, &p) == LANTERN_OK);
  CHECK(lantern_execute(ctx, 30, 0.15) == LANTERN_OK);

  /* A datatype that is no lantern_datatype (a C caller can store any int there): rejected with
   * a message naming the field and the value. Stored as bytes, as a caller's memcpy would. A
   * UBSan build (-fsanitize=enum) also checks that Lantern never loads it as the enum. */
  {
    lantern_particles bad = p;
    const int not_a_datatype = 77;
    memcpy(&bad.type.type, &not_a_datatype, sizeof not_a_datatype);
    CHECK(lantern_publish(ctx, &bad) == LANTERN_ERR_INVALID_ARGUMENT);
    CHECK(strstr(lantern_error_message(ctx), "particles.type.type") != NULL);
    CHECK(strstr(lantern_error_message(ctx), "77") != NULL);
    CHECK(lantern_publish(ctx, &p) == LANTERN_OK);
  }

  /* Bonds as LAMMPS holds them: int bondlist[n][3] rows of (first, second, type), read in place
   * with a stride of 12 bytes; a scene with bonds draws them. */
  {
    char bond_config[1024];
    snprintf(bond_config, sizeof bond_config,
             "scenes:\n"
             "  - name: c_bonds\n"
             "    width: 64\n"
             "    height: 48\n"
             "    radius: 0.2\n"
             "    bonds: {radius: 0.1, color: by_type}\n"
             "    output: {pattern: '%s/c_api_bonds_{step:04d}.png'}\n",
             dir);
    lantern_context *bctx = NULL;
    CHECK(lantern_open(bond_config, LANTERN_COMM_WORLD, &bctx) == LANTERN_OK);
    CHECK(lantern_publish(bctx, &p) == LANTERN_OK);
    int bondlist[N - 1][3];
    for (int i = 0; i + 1 < N; ++i)
      bondlist[i][0] = i, bondlist[i][1] = i + 1, bondlist[i][2] = i % 2;
    lantern_bonds b;
    memset(&b, 0, sizeof b);
    b.count = N - 1;
    b.first = (lantern_array){&bondlist[0][0], LANTERN_INT32, sizeof bondlist[0]};
    b.second = (lantern_array){&bondlist[0][1], LANTERN_INT32, sizeof bondlist[0]};
    b.type = (lantern_array){&bondlist[0][2], LANTERN_INT32, sizeof bondlist[0]};
    b.listing = LANTERN_BONDS_LISTED_ONCE;
    CHECK(lantern_publish_bonds(bctx, &b) == LANTERN_OK);
    CHECK(lantern_execute(bctx, 0, 0.0) == LANTERN_OK);
    snprintf(png, sizeof png, "%s/c_api_bonds_0000.png", dir);
    CHECK(file_exists(png));
    /* A listing that is no lantern_bond_listing, stored as bytes: refused, naming it. */
    lantern_bonds bad = b;
    const int not_a_listing = 9;
    memcpy(&bad.listing, &not_a_listing, sizeof not_a_listing);
    CHECK(lantern_publish_bonds(bctx, &bad) == LANTERN_ERR_INVALID_ARGUMENT);
    CHECK(strstr(lantern_error_message(bctx), "bonds.listing: 9") != NULL);
    bondlist[3][1] = 1000; /* out of range: refused, naming the bond */
    CHECK(lantern_publish_bonds(bctx, &b) == LANTERN_ERR_INVALID_ARGUMENT);
    CHECK(strstr(lantern_error_message(bctx), "bonds.second[3]: 1000") != NULL);
    CHECK(lantern_publish_bonds(bctx, NULL) == LANTERN_ERR_NULL_ARGUMENT);
    CHECK(lantern_execute(bctx, 1, 0.0) == LANTERN_OK); /* the particles still render */
    CHECK(lantern_close(bctx) == LANTERN_OK);
  }

  CHECK(lantern_close(ctx) == LANTERN_OK);
  CHECK(lantern_close(NULL) == LANTERN_OK);

  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
