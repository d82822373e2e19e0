"""Run under mpiexec -n 2: each rank publishes its own share of a lattice on COMM_WORLD, then rank
0 renders all of it alone on COMM_SELF; the two images must be the same bytes.
Usage: mpiexec -n 2 python3 mpi_two_ranks.py OUTPUT_DIR"""
import pathlib
import sys

from mpi4py import MPI

import lantern
from conftest import lattice, scene_config

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
    split = (out / "world" / "frame_000000.png").read_bytes()
    whole = (out / "self" / "frame_000000.png").read_bytes()
    if split != whole:
        print(f"FAIL: the {world.size}-rank image differs from the 1-rank image", flush=True)
        world.Abort(1)
    print(f"{world.size} ranks: image equal to 1 rank ({len(whole)} bytes)")
world.Barrier()
