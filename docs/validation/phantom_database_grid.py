#!/usr/bin/env python3
"""Which curve the phantom database fitted: the grid of its mean curve.

The database (Dawood et al. 2026, `hyperelastic_parameters.json`) fitted each law to "a mean
curve" of a phantom's ten tests. Its own numbers say how many points: `S**2 (n - k - 1) = SSE`
and `AIC = n ln(SSE / n) + 2 k` hold for every law with n = 1000. The neo-Hookean fit is linear
in its one parameter, so a candidate grid is checked without any optimiser: the mean of the
tests' stresses interpolated linearly at the grid's strains, mu = <g, s> / <g, g> with
g = l - l**-2, and its SSE, against the database's mu and SSE. Candidates: 1000 strains from 0
to the smallest of the tests' final strains (the largest strain every test reaches), to the
largest, and to fixed ends.

Usage: python3 docs/validation/phantom_database_grid.py studies/data/real/phantom_dawood2026
Output (numpy 2.4.6) is recorded in docs/validation/phantom-database.md.
"""
import glob
import json
import sys

import numpy as np


def load(path):
    lines = open(path).read().splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith("Time"))
    return np.array([[float(v) for v in line.split(",")[:7]] for line in lines[start + 1:] if line.strip()])


def main():
    root = sys.argv[1]
    db = json.load(open(f"{root}/hyperelastic_parameters.json"))["engineering"]
    for name, entry in db.items():
        n_k = {law: e["SSE"] / e["S"] ** 2 + len(e["parameters"]) + 1 for law, e in entry.items()}
        aic_n = {law: e["AIC"] - 1000 * np.log(e["SSE"] / 1000) - 2 * len(e["parameters"]) for law, e in entry.items()}
        assert all(abs(v - 1000) < 1e-6 for v in n_k.values()), n_k
        assert all(abs(v) < 1e-6 for v in aic_n.values()), aic_n
        mu_db, sse_db = entry["Neo Hookean"]["parameters"][0], entry["Neo Hookean"]["SSE"]
        tests = [load(f) for f in sorted(glob.glob(f"{root}/{name}/*.csv"))]
        ends = [-t[-1, 3] for t in tests]
        line = f"{name:11s} database mu {mu_db:10.6f} SSE {sse_db:12.4f} |"
        for label, end in [("0..min end", min(ends)), ("0..max end", max(ends)), ("0..0.66", 0.66)]:
            grid = np.linspace(0, end, 1000)
            mean = -np.mean([np.interp(grid, -t[:, 3], -t[:, 4]) for t in tests], axis=0)
            stretch = 1 - grid
            g = stretch - stretch**-2
            mu = g @ mean / (g @ g)
            sse = np.sum((mu * g - mean) ** 2)
            line += f" {label}: mu {mu / mu_db - 1:+.1e} SSE {sse / sse_db - 1:+.1e} |"
        print(line)


if __name__ == "__main__":
    main()
