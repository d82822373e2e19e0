"""The C API's minimal example from Python: 100,000 particles (a 50x50x40 lattice) into
minimal_000000.png, the same image as examples/minimal.c. NumPy arrays are borrowed, not copied.

Usage: python3 numpy_minimal.py [OUTPUT_DIR]   (PYTHONPATH: the folder holding the lantern module)
"""
import sys

import numpy as np

import lantern


def main(out="."):
    nx, ny, nz = 50, 50, 40
    i = np.arange(nx * ny * nz)
    x = np.stack([i % nx, (i // nx) % ny, i // (nx * ny)], axis=1).astype(np.float64)
    types = ((i // (nx * ny)) % 3).astype(np.int32)
    config = f"scenes:\n  - output: {{pattern: '{out}/minimal_{{step:06d}}.png'}}\n    radius: 0.5\n"
    with lantern.Context(config) as ctx:
        ctx.publish(position=x, type=types)
        ctx.execute(0, 0.0)
    print(f"wrote {out}/minimal_000000.png")


if __name__ == "__main__":
    main(*sys.argv[1:])
