"""Lantern inside a LAMMPS run, driven by LAMMPS's own input script: add two lines to any input
(see in.lj) and put this folder and the lantern module on PYTHONPATH:

    python lantern_step here "from lantern_lammps import lantern_step"
    fix lantern all python/invoke 10 end_of_step lantern_step

LAMMPS then calls lantern_step every 10 steps; it publishes LAMMPS's own x and type arrays
(NumPy views of LAMMPS's memory, owned atoms only, never copied) and renders. The configuration
is $LANTERN_CONFIG (a YAML path or document), by default one scene into lammps_STEP.png.
Needs LAMMPS with the PYTHON package (Debian's lmp has it) and python3-lammps.
"""
import os

import lantern
from lammps import lammps

DEFAULT_CONFIG = ("scenes:\n  - width: 512\n    height: 512\n    radius: 0.5\n"
                  "    output: {pattern: 'lammps_{step:06d}.png'}\n")
_context = None  # opened at the first call, closed when Python exits (lantern's atexit)


def lantern_step(ptr):
    global _context
    lmp = lammps(ptr=ptr)  # a handle on the running LAMMPS, not a new instance
    if _context is None:
        _context = lantern.Context(os.environ.get("LANTERN_CONFIG", DEFAULT_CONFIG))
    # LAMMPS reallocates x when atoms migrate: publish again before every execute (cheap).
    _context.publish(position=lmp.numpy.extract_atom("x"), type=lmp.numpy.extract_atom("type"))
    low, high, xy, yz, xz, periodic, _ = lmp.extract_box()
    tilt = (xy, xz, yz) if lmp.extract_setting("triclinic") else None
    _context.set_box(low, high, periodic=[bool(p) for p in periodic], tilt=tilt)
    step = lmp.extract_global("ntimestep")
    _context.execute(step, step * lmp.extract_global("dt"))
