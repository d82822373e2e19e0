"""Run under mpiexec -n 2: each rank publishes its own share of a lattice on COMM_WORLD, then rank
0 renders all of it alone on COMM_SELF; the two images must be the same bytes. The same for a
bonded chain split into blocks, each rank holding its neighbours' end atoms as ghosts, with the
bonds listed once and listed by both ranks.
Usage: mpiexec -n 2 python3 mpi_two_ranks.py OUTPUT_DIR"""
import pathlib
import sys

import numpy as np
from mpi4py import MPI

import lantern
from conftest import lattice, scene_config


def compare(name, split, whole):
    if split != whole:
        print(f"FAIL: {name}: the {world.size}-rank image differs from the 1-rank image",
              flush=True)
        world.Abort(1)
    print(f"{name}: {world.size} ranks: image equal to 1 rank ({len(whole)} bytes)")


def chain(n=40):
    """A helical chain of n atoms (types i mod 3), ids 100 + i, bonded i to i + 1."""
    i = np.arange(n)
    x = np.stack([np.cos(0.6 * i) * 3, np.sin(0.6 * i) * 3, 0.5 * i], axis=1)
    return x, (i % 3).astype(np.int32), (100 + i).astype(np.int64)


def render_chain(directory, comm, listed):
    """This rank's block of the chain with its neighbours' end atoms as ghosts, rendered."""
    x, t, ids = chain()
    n = len(x)
    lo, hi = n * comm.rank // comm.size, n * (comm.rank + 1) // comm.size
    ghosts = [g for g in (lo - 1, hi) if 0 <= g < n]
    rows = list(range(lo, hi)) + ghosts
    local = {atom: k for k, atom in enumerate(rows)}
    first = lo if listed == "once" else max(lo - 1, 0)  # once: by the lower atom's rank
    pairs = [(local[a], local[a + 1]) for a in range(first, min(hi, n - 1))]
    bonds = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    config = scene_config(directory, size=64) + "    bonds: {radius: 0.3}\n"
    with lantern.Context(config, comm=comm) as ctx:
        ctx.publish(position=x[rows], type=t[rows], id=ids[rows], bonds=bonds,
                    ghost_count=len(ghosts), bonds_listed=listed)
        ctx.execute(0, 0.0)
    return (directory / "frame_000000.png").read_bytes()


world = MPI.COMM_WORLD
out = pathlib.Path(sys.argv[1])
x, t = lattice(6)
mine = slice(world.rank, None, world.size)  # an interleaved split: every rank sees all of space
with lantern.Context(scene_config(out / "world"), comm=world) as ctx:
    ctx.publish(position=x[mine], type=t[mine])  # strided views, borrowed in place
    ctx.execute(0, 0.0)
if world.rank == 0:
    with lantern.Context(scene_config(out / "self"), comm=MPI.COMM_SELF) as ctx:
        ctx.publish(position=x, type=t)
        ctx.execute(0, 0.0)
    compare("lattice", (out / "world" / "frame_000000.png").read_bytes(),
            (out / "self" / "frame_000000.png").read_bytes())
for listed in ("once", "by_both"):
    split = render_chain(out / f"chain_{listed}_world", world, listed)
    if world.rank == 0:
        compare(f"chain listed {listed}", split,
                render_chain(out / f"chain_{listed}_self", MPI.COMM_SELF, listed))
world.Barrier()
