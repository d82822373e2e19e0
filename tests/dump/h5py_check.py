"""h5py reads a Lantern H5MD dump back: layout, attributes, shapes, dtypes, fill values and the
values of the LAMMPS text dump holding the same particles (per frame, matched by id; the count
may change from frame to frame).

usage: h5py_check.py FILE.h5 SOURCE.lammpstrj [--atol A] [--expect-counts n0,n1,...]
                     [--lammps-counts COUNTS.txt] [--expect-loss]
  --lammps-counts: "step atoms" lines (LAMMPS `print`/`fix print` of its own atom count); every
                   frame's count must equal LAMMPS's count at that step.
  --expect-loss:   some frame must hold fewer particles than the first (atoms evaporated)."""
import argparse

import h5py
import numpy as np


def read_lammps(path):
    """[(step, box lo, box hi, periodic, ids, types, xyz)] of every frame, rows sorted by id."""
    frames, lines, i = [], open(path).read().splitlines(), 0
    while i < len(lines):
        step, n = int(lines[i + 1]), int(lines[i + 3])
        flags = lines[i + 4].split()[3:6]
        bounds = np.array([lines[i + 5 + a].split()[:2] for a in range(3)], dtype=float)
        cols = lines[i + 8].split()[2:]
        rows = np.array([l.split() for l in lines[i + 9:i + 9 + n]], dtype=float).reshape(n, -1)
        ids = rows[:, cols.index("id")].astype(np.int64)
        order = np.argsort(ids)
        frames.append((step, bounds[:, 0], bounds[:, 1], [f == "pp" for f in flags], ids[order],
                       rows[order, cols.index("type")].astype(np.int64),
                       rows[order][:, [cols.index(c) for c in ("x", "y", "z")]]))
        i += 9 + n
    return frames


def read_counts(path):
    counts = {}
    for line in open(path):
        if line.strip() and not line.startswith("#"):
            step, atoms = line.split()[:2]
            counts[int(float(step))] = int(float(atoms))
    return counts


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("h5")
    ap.add_argument("source")
    ap.add_argument("--atol", type=float, default=1e-6)
    ap.add_argument("--expect-counts")
    ap.add_argument("--lammps-counts")
    ap.add_argument("--expect-loss", action="store_true")
    args = ap.parse_args()
    expected = read_lammps(args.source)
    counts = [len(e[4]) for e in expected]
    with h5py.File(args.h5, "r") as f:
        assert list(f["h5md"].attrs["version"]) == [1, 1], f["h5md"].attrs["version"]
        assert f["h5md/creator"].attrs["name"] == b"Lantern"
        assert "name" in f["h5md/author"].attrs
        box = f["particles/all/box"]
        assert box.attrs["dimension"] == 3
        assert [b.decode() == "periodic" for b in box.attrs["boundary"]] == expected[0][3]
        pos = f["particles/all/position"]
        species, ids = f["particles/all/species/value"], f["particles/all/id/value"]
        frames, rows = len(expected), max(counts)
        assert pos["value"].shape == (frames, rows, 3), (pos["value"].shape, frames, rows)
        assert pos["value"].maxshape == (None, None, 3), "frames and particle axes extensible"
        assert pos["value"].dtype in (np.float32, np.float64), pos["value"].dtype
        assert species.dtype == np.int32 and ids.dtype == np.int64
        # H5MD: an id equal to the fill value is "no particle"; reals pad with NaN.
        assert np.isnan(pos["value"].fillvalue) and ids.fillvalue == -1 and species.fillvalue == -1
        assert list(pos["step"][:]) == [e[0] for e in expected]
        count = f["observables/particle_count"]
        assert list(count["value"][:]) == counts, (list(count["value"][:]), counts)
        assert list(count["step"][:]) == [e[0] for e in expected]
        for k, (step, lo, hi, _, want_ids, types, xyz) in enumerate(expected):
            n = counts[k]
            got_ids = ids[k]
            assert np.all(got_ids[n:] == -1) and np.all(species[k][n:] == -1)
            assert np.all(np.isnan(pos["value"][k][n:]))
            present = got_ids != -1  # what a generic H5MD reader does
            assert present.sum() == n, (step, present.sum(), n)
            order = np.argsort(got_ids[present])
            np.testing.assert_array_equal(got_ids[present][order], want_ids)
            np.testing.assert_array_equal(species[k][present][order], types)
            np.testing.assert_allclose(pos["value"][k][present][order], xyz, rtol=1e-6,
                                       atol=args.atol)
            np.testing.assert_allclose(box["edges/value"][k], hi - lo, rtol=1e-6)
    if args.expect_counts:
        assert counts == [int(c) for c in args.expect_counts.split(",")], counts
    if args.lammps_counts:
        lammps = read_counts(args.lammps_counts)
        steps = [e[0] for e in expected]
        assert all(s in lammps for s in steps), (steps, sorted(lammps))
        assert [lammps[s] for s in steps] == counts, ([lammps[s] for s in steps], counts)
    if args.expect_loss:
        assert min(counts) < counts[0], counts
    print(f"h5py: {args.h5} OK ({frames} frames; particles per frame {counts})")


if __name__ == "__main__":
    main()
