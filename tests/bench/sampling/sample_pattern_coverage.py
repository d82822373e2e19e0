#!/usr/bin/env python3
"""How far can a fixed 16-sample pixel pattern's coverage be from the true area of an edge?

Backs the choice of the ordered 4 x 4 grid for `samples: 16` (config/README.md, "Pattern"):
for every pattern tried, some edge pixels are off by more than 1/16 of their area, so no fixed
pattern meets "within 1/16 per edge pixel" everywhere (discrepancy theory: for any N points some
half-plane is off by at least c N^-3/4; Beck 1987).

Prints, for the ordered grid, Direct3D's standard 16x pattern and the best N-rooks pattern found
by a seeded random search + hill climb (samples kept inside their grid cell, as the sample frame
needs):
  - the worst error over all half-planes (straight edges at every angle and offset), exact;
  - over the edge pixels of discs of several radii (sphere silhouettes), the worst error, the
    mean error and the share of edge pixels off by more than 1/16.
Usage: /usr/bin/python3 sample_pattern_coverage.py [SEARCH_ITERATIONS]   (numpy; about a minute)
"""
import sys

import numpy as np

S = 4
N = S * S
ANGLES = np.linspace(0.0, np.pi, 721)[:-1] + 1e-4  # avoid the exactly axis-aligned degenerate case
COS, SIN = np.cos(ANGLES)[:, None], np.sin(ANGLES)[:, None]


def halfplane_area(a, b, t):
    """Area of {(u, v) in the unit square: a u + b v < t}, exactly (a, b nonzero)."""
    t = t - (np.minimum(a, 0) + np.minimum(b, 0))
    a, b = np.abs(a), np.abs(b)
    r = lambda x: np.maximum(x, 0.0) ** 2
    return (r(t) - r(t - a) - r(t - b) + r(t - a - b)) / (2 * a * b)


def worst_halfplane_error(p):
    proj = np.sort(COS * p[None, :, 0] + SIN * p[None, :, 1], axis=1)
    below = halfplane_area(COS, SIN, proj - 1e-12)  # k samples strictly below the line
    above = halfplane_area(COS, SIN, proj + 1e-12)  # k + 1 samples at or below it
    k = np.arange(N)[None, :]
    return max(np.abs(k / N - below).max(), np.abs((k + 1) / N - above).max())


def n_rooks(u, v):
    """Sample of cell (a, b) at column a*S + u[a][b], row b*S + v[b][a] of an N x N grid."""
    return np.array([((a * S + u[a][b] + 0.5) / N, (b * S + v[b][a] + 0.5) / N)
                     for a in range(S) for b in range(S)])


def search(iterations, rng):
    best, best_uv = None, None
    for _ in range(iterations // 4):
        u = np.array([rng.permutation(S) for _ in range(S)])
        v = np.array([rng.permutation(S) for _ in range(S)])
        d = worst_halfplane_error(n_rooks(u, v))
        if best is None or d < best:
            best, best_uv = d, (u, v)
    u, v = best_uv
    for _ in range(iterations):
        u2, v2 = u.copy(), v.copy()
        m = u2 if rng.random() < 0.5 else v2
        row = rng.integers(S)
        i, j = rng.choice(S, 2, replace=False)
        m[row, [i, j]] = m[row, [j, i]]
        d = worst_halfplane_error(n_rooks(u2, v2))
        if d <= best:
            best, u, v = d, u2, v2
    return n_rooks(u, v)


def disc_errors(p, radius, centre=(64.37, 64.71), fine=128):
    g = (np.arange(fine) + 0.5) / fine
    cx, cy = centre
    errs = []
    for py in range(int(cy - radius) - 1, int(cy + radius) + 2):
        for px in range(int(cx - radius) - 1, int(cx + radius) + 2):
            x, y = np.meshgrid(px + g, py + g)
            area = np.mean((x - cx) ** 2 + (y - cy) ** 2 < radius * radius)
            if area <= 0.0 or area >= 1.0:
                continue
            cov = np.mean((px + p[:, 0] - cx) ** 2 + (py + p[:, 1] - cy) ** 2 < radius * radius)
            errs.append(abs(cov - area))
    return np.array(errs)


def main():
    iterations = int(sys.argv[1]) if len(sys.argv) > 1 else 8000
    d3d = [(1, 1), (-1, -3), (-3, 2), (4, -1), (-5, -2), (2, 5), (5, 3), (3, -5), (-2, 6), (0, -7),
           (-4, -6), (-6, 4), (-8, 0), (7, -4), (6, 7), (-7, -8)]
    patterns = {
        "ordered 4x4 grid": np.array([((a + 0.5) / S, (b + 0.5) / S)
                                      for a in range(S) for b in range(S)]),
        "Direct3D 16x": np.array([((x + 8) / 16, (y + 8) / 16) for x, y in d3d]),
        "best N-rooks found": search(iterations, np.random.default_rng(1)),
    }
    print("pattern              worst half-plane   disc r   worst   mean   share > 1/16")
    for name, p in patterns.items():
        hp = worst_halfplane_error(p)
        for r in (5.3, 10.7, 20.3, 47.1):
            e = disc_errors(p, r)
            print(f"{name:20s} {hp:16.4f} {r:8.1f} {e.max():7.4f} {e.mean():6.4f} "
                  f"{np.mean(e > 1 / N):13.3f}")


if __name__ == "__main__":
    main()
