/*
 * Lantern: in-situ rendering of particle simulations. Public C API (C99 and later; C++).
 *
 * A simulation opens one context per communicator, publishes its particle arrays (borrowed,
 * never copied), and calls lantern_execute() once per timestep. Lantern's schedule decides on
 * which steps it renders; on the other steps lantern_execute() returns at once.
 *
 * Errors: every function returns a lantern_status. On failure, lantern_error_message() names the
 * argument or configuration key at fault. No function aborts, exits, or lets a C++ exception
 * escape; after any error the context stays usable.
 *
 * Threads: a context may be used from one thread at a time. Distinct contexts are independent,
 * but all share the process's OpenGL/OSMesa state, so call Lantern from one thread only.
 *
 * MPI: lantern_open(), lantern_execute() on scheduled steps, and lantern_close() are collective
 * over the communicator given to lantern_open(): every rank must call them in the same order,
 * with the same step. Every decision to skip or fail a collective part is agreed across the ranks
 * first, so bad arguments or a failure on one rank give every rank the same status; what no rank
 * can agree on is a call one rank never makes (a NULL context, a step another rank does not
 * schedule, a communicator handle that is not one). lantern_publish() is local. If MPI is not
 * initialized when lantern_open() is called, Lantern initializes it (MPI_THREAD_FUNNELED) and
 * finalizes it at process exit (atexit).
 *
 * Units: Lantern does not impose units. Positions and radii must share one length unit; the
 * configuration's lengths (camera position, radius, cutting planes) are in that same unit.
 */
#ifndef LANTERN_LANTERN_H
#define LANTERN_LANTERN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Symbols of the C API are the only ones the shared library exports. */
#if defined(LANTERN_BUILDING_LIBRARY) && defined(__GNUC__)
#define LANTERN_API __attribute__((visibility("default")))
#else
#define LANTERN_API
#endif

/* The one definition of the version: CMakeLists.txt reads these three lines (keep their form). */
#define LANTERN_VERSION_MAJOR 0
#define LANTERN_VERSION_MINOR 1
#define LANTERN_VERSION_PATCH 0
/* One integer that orders versions: 10000*major + 100*minor + patch. The version of the
 * library a program runs against is lantern_version_number(). */
#define LANTERN_VERSION \
  (LANTERN_VERSION_MAJOR * 10000 + LANTERN_VERSION_MINOR * 100 + LANTERN_VERSION_PATCH)

/* Status codes. Append-only: existing values never change meaning. */
typedef enum lantern_status {
  LANTERN_OK = 0,
  LANTERN_ERR_NULL_ARGUMENT = 1,    /* a required pointer argument was NULL */
  LANTERN_ERR_INVALID_ARGUMENT = 2, /* an argument's value is out of range or inconsistent */
  LANTERN_ERR_CONFIG = 3,           /* the configuration is malformed or has an invalid key/value */
  LANTERN_ERR_IO = 4,               /* a file could not be read or written; later steps retry */
  LANTERN_ERR_GL = 5,               /* the OpenGL/OSMesa back end failed */
  LANTERN_ERR_MPI = 6,              /* an MPI call failed or the communicator is invalid */
  LANTERN_ERR_OUT_OF_MEMORY = 7,    /* an allocation failed; the step was skipped */
  LANTERN_ERR_INTERNAL = 8          /* a bug in Lantern; please report the message */
} lantern_status;

/* Element type of a borrowed array. LANTERN_TYPE_NONE marks an absent (optional) array. */
typedef enum lantern_datatype {
  LANTERN_TYPE_NONE = 0,
  LANTERN_FLOAT32 = 1,
  LANTERN_FLOAT64 = 2,
  LANTERN_INT32 = 3,
  LANTERN_INT64 = 4
} lantern_datatype;

/*
 * One borrowed, strided array. Element i is at (const char *)data + i * stride_bytes.
 * stride_bytes == 0 means tightly packed (the natural size of one element, or of one xyz triple
 * for interleaved positions). A zero-initialised lantern_array means "absent".
 */
typedef struct lantern_array {
  const void *data;
  lantern_datatype type;
  int64_t stride_bytes;
} lantern_array;

/*
 * The particles this rank owns, for lantern_publish(). Zero-initialise it ({0}) and fill what
 * you have. Give positions either interleaved (`position`: x, y, z of one particle adjacent, any
 * stride of at least 3 elements) or as three separate arrays (`position_x/y/z`), never both.
 * Positions are float or double; radius and scalar float or double; type and id int32 or int64.
 *
 * Count only the particles this rank owns, never ghost/halo copies: Lantern draws every counted
 * particle once, and a ghost would be drawn twice. (Ghosts that bonds need go after the owned
 * particles, beyond `count`: see lantern_bonds.ghost_count.)
 *
 * Images do not depend on the number of ranks or on how particles are split between them, bit
 * for bit, with one exception: a pixel where two differently colored spheres have exactly the
 * same depth (two particles at the same position with the same radius, or, rarely, a pixel centre
 * exactly on the curve where two spheres meet). One rank keeps the sphere it draws first,
 * compositing across ranks the smaller RGBA value, so such pixels may differ between rank counts.
 *
 * Lifetime: the arrays are borrowed. Lantern reads them in place during every later
 * lantern_execute() call until the next lantern_publish() (or lantern_close()), so they must stay
 * valid and unchanged in size until then. Re-publish whenever the simulation reallocates or
 * changes its particle count (cheap: it only records pointers and validates them).
 */
typedef struct lantern_particles {
  int64_t count;            /* particles owned by this rank; 0 is valid; below 2^32 */
  lantern_array position;   /* interleaved x, y, z */
  lantern_array position_x; /* or separate components */
  lantern_array position_y;
  lantern_array position_z;
  lantern_array
      radius; /* optional per-particle radius (used when a scene says radius: per_particle) */
  lantern_array scalar; /* optional per-particle scalar (color by scalar) */
  lantern_array type;   /* optional per-particle integer type (color by type) */
  lantern_array id;     /* optional global particle id (kept in particle dumps) */
  /* Appended after id, so callers built against older headers are unaffected. A group of the
   * particles, without copying them: with `mask` given, particle i is part of what Lantern draws
   * and dumps only if (mask[i] & mask_bits) != 0 (LAMMPS: atom->mask and a group's bit). The
   * others are skipped everywhere - the bounds of automatic cameras, the scalar range of
   * automatic colormaps, bricks, culling, drawing, particle dumps and the stats' counts - as if
   * they had not been published. Absent (zero) mask: every particle counts and mask_bits is not
   * read. A mask with mask_bits == 0 is LANTERN_ERR_INVALID_ARGUMENT naming mask_bits. Both are
   * read at every lantern_execute(), like the other arrays: a particle may enter or leave the
   * group between steps. */
  lantern_array mask; /* optional int32/int64 per-particle bit mask */
  int64_t mask_bits;  /* with mask: draw particle i only if (mask[i] & mask_bits) != 0 */
} lantern_particles;

/* Use in place of MPI_Comm_c2f(MPI_COMM_WORLD) when the caller does not include mpi.h. */
#define LANTERN_COMM_WORLD (-1)

typedef struct lantern_context lantern_context;

/* The library's version as "major.minor.patch"; a static string, never freed. */
LANTERN_API const char *lantern_version(void);

/*
 * The LANTERN_VERSION the library was built with. LANTERN_VERSION is the header a client
 * compiled against; this is the library it runs against (they differ when the shared library
 * was replaced). Callable at any time, from any thread, without a context or MPI.
 */
LANTERN_API int lantern_version_number(void);

/*
 * Opens a context. `config` is the path of a YAML file, or an inline YAML document (any string
 * containing a newline or starting with '{' is taken as a document). `mpi_comm_f` is the Fortran
 * handle of the communicator (MPI_Comm_c2f(comm)) or LANTERN_COMM_WORLD; Lantern duplicates it.
 * On success *out owns a new context, freed by lantern_close(). On failure *out is set to a
 * context that holds only the error message (read it with lantern_error_message(), then close
 * it), or to NULL when even that could not be allocated or `out` is NULL. Collective: every rank
 * must give the same configuration text (the documents, or the files' contents, are compared by
 * hash; LANTERN_ERR_INVALID_ARGUMENT naming the first rank that differs), and every rank returns
 * the same status - a NULL `config` or `out` on one rank fails the open on every rank
 * (LANTERN_ERR_NULL_ARGUMENT) rather than leaving the others waiting. LANTERN_ERR_MPI, on the
 * rank that passed it, for a `mpi_comm_f` that is not a communicator handle (checked without
 * letting MPI's fatal error handler abort), an intercommunicator, or MPI already finalized.
 */
LANTERN_API lantern_status lantern_open(const char *config, int mpi_comm_f, lantern_context **out);

/*
 * Replaces the configuration of an open context: `config` takes the same forms as lantern_open's
 * (a YAML file path, or an inline document). The new scenes, schedule and stats apply from the
 * next lantern_execute() on; images already written are untouched. What carries over is kept:
 * bricks, the OpenGL session, the dump file, and each scene's buffers, asynchronous writer and
 * per-brick cutting-plane state, matched by scene name (a scene whose cut_planes changed
 * reclassifies only the bricks those planes touch). A text identical to the running one, from the
 * same place, costs one hash and three small collectives: nothing is parsed or rebuilt.
 *
 * May not change while running (LANTERN_ERR_CONFIG naming the key): gl, egl_device, and the dump
 * section's enabled, file, fields, precision and mode (dump.schedule may change).
 *
 * On any error the running configuration stays in effect and every rank returns the same status:
 * LANTERN_ERR_CONFIG for a file that cannot be read, malformed YAML, an unknown key or a bad
 * value (the message names it, as for lantern_open); LANTERN_ERR_INVALID_ARGUMENT when the ranks
 * passed different texts (compared by hash; the message names the first rank that differs).
 * With `watch: true` in the new file, Lantern follows that file from then on (see README.md).
 * Collective: every rank calls it, between the same two lantern_execute() calls, with the same
 * text. Not thread-safe with other calls on the same context.
 */
LANTERN_API lantern_status lantern_reconfigure(lantern_context *ctx, const char *config);

/* Records (borrows) this rank's particles; see lantern_particles for lifetimes. Local. A failed
 * publish leaves this rank with no particles until the next successful one. */
LANTERN_API lantern_status lantern_publish(lantern_context *ctx,
                                           const lantern_particles *particles);

/*
 * Describes the simulation box, recorded with particle dumps (the H5MD `box`: edges high - low,
 * and `boundary` periodic/none per axis) and giving bonds their minimum image along periodic
 * axes (see lantern_bonds). `low` and `high` are the box's corners (finite, low <= high per
 * axis); `periodic` is 0 or non-zero per axis (NULL: non-periodic). Optional: without it dumps
 * record the global bounds of the particles and bonds join their atoms directly. Local, but give
 * every rank the same box (rank 0's is the one written). Stays in effect until the next call.
 */
LANTERN_API lantern_status lantern_set_box(lantern_context *ctx, const double low[3],
                                           const double high[3], const int periodic[3]);

/*
 * Describes a triclinic simulation box in LAMMPS's restricted form (lammps_extract_box() gives
 * exactly these): the box's edge vectors from the corner `low` are a = (lx, 0, 0),
 * b = (xy, ly, 0) and c = (xz, yz, lz), where (lx, ly, lz) = high - low and `tilt` is
 * {xy, xz, yz}. A box given as three vectors in that form (OpenMM's and GROMACS's reduced box
 * vectors, MDAnalysis's triclinic_vectors) maps to low = origin, high = origin + (a_x, b_y, c_z),
 * tilt = {b_x, c_x, c_y}. Otherwise as lantern_set_box(), which it replaces: dumps record the
 * edges as the H5MD matrix of a, b, c (rows); bonds take their minimum image along c, then b,
 * then a, as LAMMPS does; the `box` overlay draws the parallelepiped. Zero tilt is still a
 * triclinic box for dumps (a box that shears from zero tilt keeps one layout), and draws as the
 * axis-aligned one. `tilt` must be finite (LANTERN_ERR_INVALID_ARGUMENT naming it). Local, but
 * give every rank the same box.
 */
LANTERN_API lantern_status lantern_set_triclinic_box(lantern_context *ctx, const double low[3],
                                                     const double high[3], const double tilt[3],
                                                     const int periodic[3]);

/*
 * Bonds: a second primitive, drawn as cylinders between published particles where a scene has a
 * `bonds:` section (config/README.md). A bond joins two entries of the arrays given to
 * lantern_publish(), by index.
 *
 * Ghosts. A domain-decomposed code keeps copies of its neighbours' atoms ("ghosts" or "halo":
 * LAMMPS's x[nlocal .. nlocal + nghost)), and its bond list refers to them. Give their number as
 * ghost_count: entries count .. count + ghost_count - 1 of the same particle arrays (position,
 * and type, scalar, mask where given) then hold the ghosts, and the arrays passed to
 * lantern_publish() must be that long. Ghosts are only bond ends: never drawn as spheres, dumped
 * or counted. Ghosts need the id array (lantern_particles.id), which must then cover them too:
 * a ghost is named by its global id (in error messages, and where bonds are written to dumps).
 *
 * How a bond is drawn. Every bond is two half-bonds, each a closed cylinder from one atom's
 * centre to the bond's midpoint: the half of atom p goes from x_p to x_p + d / 2, where d is the
 * vector from p to the other atom q, taken as the minimum image along each periodic axis of the
 * box given to lantern_set_box() (the plain difference without a box or along other axes). A
 * bond that crosses a periodic face (its atoms more than half the box apart along that axis) is
 * thus two half-bonds, each at its own atom, reaching out of opposite faces to where the bond's
 * midpoint lies in the minimum image - as LAMMPS's dump image and OVITO draw it.
 *
 * Which rank draws what (`listing`), so that each half-bond is drawn exactly once over all ranks:
 *  - LANTERN_BONDS_LISTED_ONCE: every bond is in exactly one rank's list (a serial code, or
 *    LAMMPS with newton_bond on, whose neighbor->bondlist holds each bond on one rank). The rank
 *    that lists it draws both halves, each at the position it holds for that atom - a ghost's half
 *    at the ghost's position (LAMMPS lists the ghost image closest to the owned atom, so the bond
 *    stays whole on that atom's side of the box).
 *  - LANTERN_BONDS_LISTED_BY_BOTH: every rank lists the bonds of each atom it owns, with that
 *    atom's own index (LAMMPS with newton_bond off; codes that keep a bond table per atom), so a
 *    bond between atoms of two ranks is in both lists. Each entry gives the halves of its owned
 *    atoms (index < count) only; the other half is its owner's. A bond between two atoms of one
 *    rank is listed once with both own indices, or once from each side (LAMMPS does so when one
 *    side is a periodic image: (i, image of j) and (j, image of i)).
 * Either way a bond needs at least one atom the listing rank owns, and each half-bond must come
 * from one entry (a half listed twice is drawn twice over itself: the image is the same, the
 * stats count it twice). Images with bonds do not
 * depend on the rank count or split as long as each half-bond is computed from the same two
 * positions: an owned atom's own, and its partner's as a copy or the image the host made of it.
 * (A ghost made as x + L of an atom at x may differ from it in the last bit; that can move a
 * pixel only where the difference crosses a float rounding of the drawn geometry.)
 *
 * Cutting planes, groups and culling: a half-bond goes with its atom - it is cut away exactly
 * when its atom's centre is (so a cut through a bond keeps the surviving atom's half), and it
 * follows the atom's type opacity. With a mask (lantern_particles.mask, which must then cover the
 * ghosts too), a bond is drawn only when both its atoms are in the group.
 *
 * Bad input: lantern_publish_bonds() checks every bond and returns LANTERN_ERR_INVALID_ARGUMENT
 * naming the first bad one and its index (e.g. "bonds.second[12]: 5000 is not below count +
 * ghost_count (4000 + 900)"): an index outside 0 .. count + ghost_count - 1, a bond from an atom
 * to itself, a bond between two ghosts, an atom with a NaN or infinite coordinate, ghosts without
 * ids; a failed call leaves this rank without bonds (its particles are still drawn) until the next
 * successful one. lantern_execute() checks the bonds again, since it reads the arrays in place:
 * a bond gone bad since is skipped, everything else is drawn and written, and every rank returns
 * LANTERN_ERR_INVALID_ARGUMENT naming the first bad bond.
 */

/* How the ranks' bond lists share the bonds out (lantern_bonds.listing); see above. */
typedef enum lantern_bond_listing {
  LANTERN_BONDS_LISTED_ONCE = 0,   /* each bond on one rank, which draws all of it */
  LANTERN_BONDS_LISTED_BY_BOTH = 1 /* on both atoms' ranks; each draws its atoms' halves */
} lantern_bond_listing;

/*
 * This rank's bonds, for lantern_publish_bonds(). Zero-initialise it ({0}) and fill what you have.
 * `first` and `second` hold each bond's two atoms as 0-based indices into the published particle
 * arrays (int32 or int64, any stride: for LAMMPS's int bondlist[n][3], first = &bondlist[0][0],
 * second = &bondlist[0][1], type = &bondlist[0][2], all with stride 12).
 *
 * Lifetime: borrowed like the particle arrays - read in place at every later lantern_execute()
 * until the next lantern_publish_bonds(), lantern_publish() or lantern_close(). lantern_publish()
 * forgets the bonds (their indices refer to the arrays it replaces): publish the bonds after every
 * lantern_publish().
 *
 * ABI: a separate structure and call rather than fields appended to lantern_particles, so that
 * lantern_particles keeps its size: a program built against an older header passes a smaller
 * lantern_particles, and Lantern must never read fields past its end. Only programs built with
 * this header call lantern_publish_bonds().
 */
typedef struct lantern_bonds {
  int64_t count;        /* bonds in this rank's list; 0 is valid (no bonds) */
  lantern_array first;  /* int32/int64: index of each bond's first atom */
  lantern_array second; /* int32/int64: index of its second atom */
  lantern_array type;   /* optional int32/int64 bond type (a scene's bonds.color: by_type) */
  int64_t ghost_count;  /* ghosts after the owned particles in the particle arrays; >= 0 */
  lantern_bond_listing listing; /* LANTERN_BONDS_LISTED_ONCE (0) or _LISTED_BY_BOTH */
} lantern_bonds;

/* Records (borrows) this rank's bonds, indices into the particles of the last lantern_publish()
 * (call that first); see lantern_bonds and the notes above. Local. NULL bonds is
 * LANTERN_ERR_NULL_ARGUMENT; a lantern_bonds with count 0 removes the bonds. */
LANTERN_API lantern_status lantern_publish_bonds(lantern_context *ctx, const lantern_bonds *bonds);

/*
 * Tells Lantern that the simulation reached `step` at simulation time `time`. On steps the
 * schedule skips this returns LANTERN_OK at once (no communication). On scheduled steps it
 * renders every scene, composites across ranks and writes the outputs; collective, and every
 * rank returns the same status. Particles with NaN or infinite coordinates are skipped and
 * counted in the stats (a warning is printed once per context).
 */
LANTERN_API lantern_status lantern_execute(lantern_context *ctx, int64_t step, double time);

/* The last error of this context, or "" if none. Owned by the context; valid until the next
 * call on it. NULL context gives a static message. */
LANTERN_API const char *lantern_error_message(const lantern_context *ctx);

/*
 * How the last rendered step's work spread over the ranks, for a log at the end of a run: a
 * header line ("step N, R ranks:") and one line per scene with the particles drawn and culled,
 * the milliseconds of each rank's own work (before compositing) and the rank's finite particles
 * as min..max per rank, the
 * imbalance (max over mean) and the rank holding the max. The same numbers are in the stats
 * line's "per_rank" object. Needs `stats:` in the configuration (the small reduction behind it
 * runs only then). On rank 0 of the context's communicator; "" on other ranks, before the first
 * rendered step, without stats, or for a NULL context. Owned by the context; valid until the
 * next lantern_execute() or lantern_close(). Local: no communication.
 */
LANTERN_API const char *lantern_load_summary(const lantern_context *ctx);

/*
 * The name and a one-line English description of a status, such as
 * "LANTERN_ERR_IO: a file could not be read or written", for logs. A value that is not a
 * lantern_status gives "unknown lantern_status"; never NULL. The string is static: never free
 * it. Callable at any time, from any thread, without a context or MPI. For what went wrong in a
 * particular call, use lantern_error_message().
 */
LANTERN_API const char *lantern_status_string(lantern_status status);

/* Flushes outputs (waits for images written in the background, see output.asynchronous, and for
 * the movie frames still queued, then completes the movie files, see output.movie) and frees the
 * context, and with it the per-step scratch that Lantern keeps lazily freed for the next step
 * (that of every context of the process: another open context only maps it again). Returns
 * LANTERN_ERR_IO if such an image or movie could not be written. Safe on NULL. Collective. If
 * the host already called MPI_Finalize, the context is released without any MPI call (its images
 * and movie frames are still waited for) and LANTERN_ERR_MPI says so; lantern_execute() on a
 * scheduled step and lantern_reconfigure() return LANTERN_ERR_MPI then too.
 */
LANTERN_API lantern_status lantern_close(lantern_context *ctx);

#ifdef __cplusplus
}
#endif

#endif /* LANTERN_LANTERN_H */
