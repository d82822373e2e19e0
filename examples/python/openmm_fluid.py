"""An OpenMM Lennard-Jones fluid of argon and xenon (periodic, Verlet), rendered in situ by
lantern.openmm.Reporter: every `every` steps an image colored by element and one colored by
speed. Lengths in nm.

    PYTHONPATH=build/python:examples/python python3 examples/python/openmm_fluid.py [OUT_DIR]
"""
import sys

import openmm
import openmm.app as app

from lantern.openmm import Reporter


def config(directory, size=256):
    """Two scenes: atoms by element (type), and by speed (scalar). Radius: about sigma / 2."""
    scene = ("  - name: {name}\n    width: {size}\n    height: {size}\n    radius: 0.17\n"
             "    camera: {{azimuth: 30, elevation: 20}}\n    color: {color}\n"
             "    output: {{pattern: '{directory}/{name}_{{step:06d}}.png'}}\n")
    return "scenes:\n" + "".join(
        scene.format(name=name, size=size, color=color, directory=directory)
        for name, color in (("element", "{by: type}"), ("speed", "{by: scalar}")))


def build(n_side=8, spacing=0.40, temperature=120.0, seed=1):
    """A simple-cubic start of n_side^3 atoms (every fifth one xenon) in a periodic box, velocities
    at `temperature` K. Returns an OpenMM Simulation on the Reference platform (deterministic)."""
    topology = app.Topology()
    chain = topology.addChain()
    system = openmm.System()
    lj = openmm.NonbondedForce()
    lj.setNonbondedMethod(openmm.NonbondedForce.CutoffPeriodic)
    lj.setCutoffDistance(min(1.0, 0.49 * n_side * spacing))
    positions = []
    for i in range(n_side ** 3):
        xenon = i % 5 == 0
        element = app.Element.getBySymbol("Xe" if xenon else "Ar")
        residue = topology.addResidue(element.symbol.upper(), chain)
        topology.addAtom(element.symbol.upper(), element, residue)
        system.addParticle(element.mass)
        # charge, sigma (nm), epsilon (kJ/mol)
        lj.addParticle(0.0, 0.41 if xenon else 0.34, 1.83 if xenon else 0.996)
        cell = (i % n_side, (i // n_side) % n_side, i // (n_side * n_side))
        positions.append(openmm.Vec3(*[spacing * c for c in cell]))  # atoms on the faces
    system.addForce(lj)
    edge = n_side * spacing
    box = [openmm.Vec3(edge, 0, 0), openmm.Vec3(0, edge, 0), openmm.Vec3(0, 0, edge)]
    system.setDefaultPeriodicBoxVectors(*box)
    topology.setPeriodicBoxVectors(box)
    simulation = app.Simulation(topology, system, openmm.VerletIntegrator(0.002),
                                openmm.Platform.getPlatformByName("Reference"))
    simulation.context.setPositions(positions)
    simulation.context.setVelocitiesToTemperature(temperature, seed)
    return simulation


def run(directory, n_side=8, steps=1000, every=250, size=256):
    """Runs the fluid with a Reporter for each scene; returns the simulation."""
    simulation = build(n_side)
    with Reporter(config(directory, size), every, types="element", scalar="speed") as reporter:
        simulation.reporters.append(reporter)
        simulation.step(steps)
    return simulation


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "out/openmm"
    run(out)
    print(f"wrote {out}/element_*.png and {out}/speed_*.png")
