"""Lantern: in-situ rendering of particle simulations.

Context(config, comm=None) opens a context; publish() borrows NumPy arrays (never copied);
execute(step, time) renders on scheduled steps. The C API binding is the compiled module
lantern._lantern, re-exported here. Submodules, imported on demand because each needs its own
program: lantern.openmm (a reporter for OpenMM simulations) and lantern.render (trajectories of
any format MDAnalysis reads; also `python3 -m lantern.render`).
"""
from . import _lantern
from ._lantern import COMM_WORLD, Context, Error, __version__

# The status codes as module constants: OK, ERR_NULL_ARGUMENT, ..., ERR_INTERNAL.
globals().update({name: getattr(_lantern, name) for name in dir(_lantern)
                  if name == "OK" or name.startswith("ERR_")})
Context.__module__ = __name__

__all__ = ["COMM_WORLD", "Context", "Error", "__version__"] + sorted(
    name for name in dir(_lantern) if name == "OK" or name.startswith("ERR_"))
