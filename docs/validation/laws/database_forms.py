#!/usr/bin/env python3
"""Which energies the phantom database's "Veronda Westmann" and "Humphrey" parameters belong to.

The database (Dawood et al. 2026, `hyperelastic_parameters.json`) gives [C1, C2] for both laws
without their formulas. This script fits candidate forms to the mean engineering curve of a
phantom's ten compression tests (linear interpolation on a common strain grid of 200 points) and
evaluates the database's own parameters under each form: the form whose fitted parameters match
the database's, and under which the database's parameters fit the curve, is the one it used.

Candidate forms (incompressible uniaxial P = 2 (l - l^-2)(W1 + W2 / l), x = I1 - 3):
  VW  (FEBio)        W = C1 (e^(C2 x) - 1) - C1 C2 / 2 (I2 - 3)
  VW  (halved)       W = C1 / 2 (e^(C2 x) - 1) - C1 C2 / 4 (I2 - 3)   [W1 = C1 C2 e / 2]
  Humphrey           W = C1 (e^(C2 x) - 1)
  Humphrey (scaled)  W = C1 / (2 C2) (e^(C2 x) - 1)                   [mu0 = C1]

Usage: python3 docs/validation/laws/database_forms.py PATH/TO/phantom_dawood2026 [PHANTOM]
Output (EF10_0T, scipy 1.17.1) is recorded in docs/validation/laws/README.md.
"""
import glob
import json
import sys

import numpy as np
from scipy.optimize import least_squares


def load(path):
    lines = open(path).read().splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith("Time"))
    rows = [[float(v) for v in line.split(",")[:7]] for line in lines[start + 1:] if line.strip()]
    return np.array(rows)


def nominal(w1, w2, l):
    return 2 * (l - l**-2) * (w1 + w2 / l)


def x_of(l):
    return l * l + 2 / l - 3


FORMS = {
    "VW (FEBio)": lambda p, l: nominal(p[0] * p[1] * np.exp(p[1] * x_of(l)), -p[0] * p[1] / 2, l),
    "VW (halved)": lambda p, l: nominal(p[0] * p[1] / 2 * np.exp(p[1] * x_of(l)), -p[0] * p[1] / 4, l),
    "Humphrey": lambda p, l: nominal(p[0] * p[1] * np.exp(p[1] * x_of(l)), 0 * l, l),
    "Humphrey (scaled)": lambda p, l: nominal(p[0] / 2 * np.exp(p[1] * x_of(l)), 0 * l, l),
}


def main():
    root = sys.argv[1]
    phantom = sys.argv[2] if len(sys.argv) > 2 else "EF10_0T"
    db = json.load(open(f"{root}/hyperelastic_parameters.json"))["engineering"][phantom]
    curves = [load(f) for f in sorted(glob.glob(f"{root}/{phantom}/*.csv"))]
    grid = np.linspace(0, min(-c[:, 3].min() for c in curves), 200)
    mean = np.mean([np.interp(grid, -c[:, 3], -c[:, 4]) for c in curves], axis=0)
    stretch, stress = 1 - grid, -mean  # compression: stretch < 1, nominal stress < 0 (kPa)
    print(f"{phantom}: {len(curves)} tests, strain 0..{grid[-1]:.3f}")
    for name, form in FORMS.items():
        fit = least_squares(lambda p: form(p, stretch) - stress, [20.0, 0.2])
        key = "Veronda Westmann" if name.startswith("VW") else "Humphrey"
        theirs = db[key]["parameters"]
        sse_theirs = float(np.sum((form(theirs, stretch) - stress) ** 2))
        print(f"{name:18s} fitted C1 = {fit.x[0]:9.4f} C2 = {fit.x[1]:.5f} SSE = {2 * fit.cost:10.2f} | "
              f"database C1 = {theirs[0]:9.4f} C2 = {theirs[1]:.5f} SSE here = {sse_theirs:12.2f}")


if __name__ == "__main__":
    main()
