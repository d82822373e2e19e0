"""h5py reads a Lantern H5MD dump back: layout, attributes, shapes, dtypes and the values of
the LAMMPS text dump it was converted from.  usage: h5py_check.py FILE.h5 SOURCE.lammpstrj"""
import sys

import h5py
import numpy as np


def read_lammps(path):
    frames, lines, i = [], open(path).read().splitlines(), 0
    while i < len(lines):
        step, n = int(lines[i + 1]), int(lines[i + 3])
        cols = lines[i + 8].split()[2:]
        rows = np.array([l.split() for l in lines[i + 9:i + 9 + n]], dtype=float)
        frames.append((step, rows[:, [cols.index(c) for c in ("x", "y", "z")]],
                       rows[:, cols.index("type")].astype(int), rows[:, cols.index("id")].astype(int)))
        i += 9 + n
    return frames


def main(h5_path, source):
    expected = read_lammps(source)
    with h5py.File(h5_path, "r") as f:
        assert list(f["h5md"].attrs["version"]) == [1, 1], f["h5md"].attrs["version"]
        assert f["h5md/creator"].attrs["name"] == b"Lantern"
        assert "name" in f["h5md/author"].attrs
        box = f["particles/all/box"]
        assert box.attrs["dimension"] == 3
        assert [b.decode() for b in box.attrs["boundary"]] == ["periodic"] * 3
        pos = f["particles/all/position"]
        frames, n = len(expected), len(expected[0][1])
        assert pos["value"].shape == (frames, n, 3), pos["value"].shape
        assert pos["value"].dtype == np.float32, pos["value"].dtype
        assert pos["value"].maxshape[0] is None, "frames axis must be extensible"
        assert list(pos["step"][:]) == [e[0] for e in expected]
        assert f["particles/all/species/value"].dtype == np.int32
        for k, (step, xyz, types, ids) in enumerate(expected):
            np.testing.assert_allclose(pos["value"][k], xyz, rtol=1e-6, atol=1e-6)
            np.testing.assert_array_equal(f["particles/all/species/value"][k], types)
            np.testing.assert_array_equal(f["particles/all/id/value"][k], ids)
            np.testing.assert_allclose(box["edges/value"][k], [30, 20, 20])
    print(f"h5py: {h5_path} OK ({frames} frames of {n} particles)")


if __name__ == "__main__":
    main(*sys.argv[1:])
