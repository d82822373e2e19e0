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


def png_pixels(data):
    """The pixels of an 8-bit, non-interlaced PNG (what Lantern writes) as an (h, w, channels)
    uint8 array: the PNG filters undone by hand, so the tests need nothing beyond NumPy."""
    import struct
    import zlib
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunk = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", chunk)
        elif kind == b"IDAT":
            idat += chunk
        pos += 12 + length
    width, height, depth, color_type, _, _, interlace = header
    assert depth == 8 and interlace == 0, "only 8-bit non-interlaced PNGs"
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[color_type]
    raw = zlib.decompress(idat)
    stride = width * channels
    out = np.zeros((height, stride), dtype=np.uint8)
    previous = np.zeros(stride, dtype=np.int32)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        row = np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        line = np.zeros(stride, dtype=np.int32)
        for i in range(stride):
            left = line[i - channels] if i >= channels else 0
            up = previous[i]
            corner = previous[i - channels] if i >= channels else 0
            if kind == 0:
                predictor = 0
            elif kind == 1:
                predictor = left
            elif kind == 2:
                predictor = up
            elif kind == 3:
                predictor = (left + up) // 2
            else:  # Paeth
                p = left + up - corner
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - corner)
                predictor = left if pa <= pb and pa <= pc else (up if pb <= pc else corner)
            line[i] = (row[i] + predictor) & 0xFF
        out[y] = line
        previous = line
    return out.reshape(height, width, channels)
