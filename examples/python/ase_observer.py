"""ASE molecular dynamics rendered in situ: a Cu crystal (EMT potential) integrated with
Velocity Verlet; an observer attached to the dynamics publishes ASE's own position array (a NumPy
array, borrowed, never copied) and renders every few steps.

Usage: python3 ase_observer.py [OUTPUT_DIR [CELLS [STEPS [EVERY]]]]
"""
import sys

import numpy as np
from ase import units
from ase.build import bulk
from ase.calculators.emt import EMT
from ase.md.velocitydistribution import MaxwellBoltzmannDistribution
from ase.md.verlet import VelocityVerlet

import lantern


def config(out, size=256):
    return (f"scenes:\n  - width: {size}\n    height: {size}\n    radius: 1.2\n"
            f"    color: {{by: scalar, range: [0, 0.2]}}\n"
            f"    output: {{pattern: '{out}/ase_{{step:06d}}.png'}}\n")


def kinetic_energies(atoms):
    return 0.5 * (atoms.get_momenta() ** 2).sum(axis=1) / atoms.get_masses()


def run(out=".", cells=4, steps=40, every=10, size=256):
    atoms = bulk("Cu", "fcc", a=3.6, cubic=True).repeat(cells)  # 4 cells^3 atoms, periodic
    atoms.calc = EMT()
    MaxwellBoltzmannDistribution(atoms, temperature_K=600, rng=np.random.default_rng(7))
    dyn = VelocityVerlet(atoms, 5 * units.fs)
    ctx = lantern.Context(config(out, size))
    ctx.set_box([0, 0, 0], atoms.cell.lengths(), periodic=atoms.pbc)  # a cubic cell

    def render():
        # atoms.positions is ASE's own array; publish again each time in case ASE replaced it.
        kinetic = kinetic_energies(atoms)  # eV per atom, a new array: the context keeps it alive
        ctx.publish(position=atoms.positions, scalar=kinetic)
        ctx.execute(dyn.nsteps, dyn.nsteps * dyn.dt / units.fs)

    dyn.attach(render, interval=every)
    dyn.run(steps)
    ctx.close()
    return atoms


if __name__ == "__main__":
    out, *numbers = sys.argv[1:] or ["."]
    run(out, *map(int, numbers))
    print(f"wrote {out}/ase_*.png")
