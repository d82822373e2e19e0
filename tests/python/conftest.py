"""Shared helpers of the Python module's tests: a small scene, a lattice of particles, and a
render that returns the PNG's bytes (equal bytes: equal images, PNG encoding is deterministic)."""
import pathlib

import numpy as np
import pytest

import lantern


def scene_config(directory, size=40, extra=""):
    """One 40x40 scene drawn by the CPU raster (no OpenGL start-up), every step, into directory."""
    return (f"gl: none\n{extra}scenes:\n  - width: {size}\n    height: {size}\n"
            f"    radius: 0.5\n    color: {{by: type}}\n"
            f"    output: {{pattern: '{directory}/frame_{{step:06d}}.png'}}\n")


def lattice(n_side=4, dtype=np.float64):
    """n_side^3 particles on a lattice of spacings 1, 2, 3, (n, 3), C-contiguous; and their types
    (int32, i mod 5). Neither is symmetric under swapping axes, so mixed-up components show."""
    i = np.arange(n_side ** 3)
    x = np.stack([i % n_side, 2 * ((i // n_side) % n_side), 3 * (i // (n_side * n_side))], axis=1)
    return np.ascontiguousarray(x, dtype=dtype), (i % 5).astype(np.int32)


class Renderer:
    """Renders publish(**arrays) at one step in a fresh context; returns the image's bytes."""

    def __init__(self, tmp_path):
        self.tmp_path = tmp_path
        self.count = 0

    def __call__(self, step=0, **arrays):
        self.count += 1
        directory = self.tmp_path / f"render{self.count}"
        with lantern.Context(scene_config(directory)) as ctx:
            ctx.publish(**arrays)
            ctx.execute(step, 0.0)
        return (directory / f"frame_{step:06d}.png").read_bytes()


@pytest.fixture
def render(tmp_path):
    return Renderer(tmp_path)
