#!/usr/bin/env python3
"""How far the curves of a planar scene lie from their plane.

Usage: python3 scripts/curves_off_plane.py OUT_DIR [OUT_DIR ...]

Reads OUT_DIR/curves.obj (written by `curvesfm run`), fits a plane z = a x + b y + c to all curve
samples by least squares, refits four times to the samples within 3 median residuals (so stray
curves do not tilt it), and prints per-curve median distances from that plane in mm (the scene
unit taken as metres): the 50th, 75th and 90th percentiles over curves, and how many curves lie
more than 5 mm and 20 mm off. Meant for `curvesfm synth planar` scenes, whose photo lies on a
plane; plain Python, no dependencies.
"""
import sys


def read_curves(path):
    curves = []
    try:
        with open(path) as f:
            for number, line in enumerate(f, 1):
                if line.startswith("o "):
                    curves.append([])
                elif line.startswith("v "):
                    if not curves:
                        sys.exit("%s:%d: vertex before the first 'o' line" % (path, number))
                    curves[-1].append(tuple(map(float, line.split()[1:4])))
    except OSError as e:
        sys.exit("%s: cannot read: %s" % (path, e.strerror))
    except ValueError:
        sys.exit("%s:%d: expected 'v x y z'" % (path, number))
    if sum(len(curve) for curve in curves) < 3:
        sys.exit("%s: fewer than 3 curve samples, no plane to fit" % path)
    return curves


def solve3(A, b):
    M = [A[i] + [b[i]] for i in range(3)]
    for c in range(3):
        pivot = max(range(c, 3), key=lambda r: abs(M[r][c]))
        M[c], M[pivot] = M[pivot], M[c]
        for r in range(3):
            if r != c:
                f = M[r][c] / M[c][c]
                M[r] = [M[r][k] - f * M[c][k] for k in range(4)]
    return [M[i][3] / M[i][i] for i in range(3)]


def fit_plane(points):
    S = [[0.0] * 3 for _ in range(3)]
    t = [0.0] * 3
    for x, y, z in points:
        v = (x, y, 1.0)
        for i in range(3):
            t[i] += v[i] * z
            for j in range(3):
                S[i][j] += v[i] * v[j]
    return solve3(S, t)


def median(values):
    values = sorted(values)
    return values[len(values) // 2]


def report(out_dir):
    curves = read_curves(out_dir.rstrip("/") + "/curves.obj")
    points = [p for curve in curves for p in curve]
    a, b, c = fit_plane(points)
    for _ in range(4):
        residuals = [abs(z - (a * x + b * y + c)) for x, y, z in points]
        threshold = 3 * median(residuals) + 1e-12
        a, b, c = fit_plane([p for p, r in zip(points, residuals) if r < threshold])
    off = sorted(1e3 * median([abs(z - (a * x + b * y + c)) for x, y, z in curve])
                 for curve in curves if curve)
    quantile = lambda f: off[int(f * (len(off) - 1))]
    print("%s: %d curves, per-curve median distance from the plane (mm): p50 %.2f, p75 %.2f, "
          "p90 %.2f; over 5 mm: %d, over 20 mm: %d"
          % (out_dir, len(off), quantile(0.5), quantile(0.75), quantile(0.9),
             sum(d > 5 for d in off), sum(d > 20 for d in off)))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for directory in sys.argv[1:]:
        report(directory)
