"""Renders a selection of a trajectory's atoms, colored by type, through
lantern.render.render_universe: any topology and trajectory MDAnalysis reads, any selection in
MDAnalysis's language.

    PYTHONPATH=build/python python3 examples/python/render_selection.py TOPOLOGY TRAJECTORY \\
        "SELECTION" [OUT_DIR]
e.g. conf.gro md.xtc "not resname SOL" (a solute without its water), or, for a LAMMPS dump,
dump.lammpstrj dump.lammpstrj "type 2" (give LAMMPS dumps' format: see `main`).
"""
import sys

import MDAnalysis as mda

from lantern.render import render_universe


def config(directory, size=512, color="{by: type}", radius=1.0):
    return (f"scenes:\n  - name: selection\n    width: {size}\n    height: {size}\n"
            f"    radius: {radius}\n    camera: {{azimuth: 30, elevation: 20}}\n"
            f"    color: {color}\n"
            f"    output: {{pattern: '{directory}/selection_{{step:06d}}.png'}}\n")


def main(topology, trajectory, selection, out="out/selection", **universe_options):
    if trajectory.endswith(".lammpstrj"):  # MDAnalysis does not guess LAMMPS dumps by name
        universe_options.setdefault("format", "LAMMPSDUMP")
        universe_options.setdefault("topology_format", "LAMMPSDUMP")
    universe = mda.Universe(topology, trajectory, **universe_options)
    atoms = universe.select_atoms(selection)
    # Colored by type; for a quantity, color: {by: scalar} and scalar="speed", "charges", ...
    frames = render_universe(atoms, config(out), types="auto", progress=False)
    print(f"rendered {frames} frames of {len(atoms)} atoms ({selection!r}) into {out}/")
    return frames


if __name__ == "__main__":
    main(*sys.argv[1:5])
