#!/usr/bin/env python3
"""How well can any estimator place R2's nodules from a rolled pass with 1 %
noise? The Cramer-Rao bound of the nodules' x and depth at RD 6
(docs/validation/r2-localisation.md, "The information limit").

13 FE rolled passes of R2's three nodules (37.5:10, 75:15, 112.5:20) at RD 6
on the localisation model's mesh (level 1, 2 mm), output every 0.5 mm: the
nominal one and each nodule's x and depth moved by +-0.25 mm. The Jacobian
of the force by central differences, with the modulus scale s (the
posterior's, prediction = s x model: dF/ds = F) as a nuisance; Gaussian noise
of SD 1 % of the peak force (the study's), records sampled every 0.5 mm (the
forward model's output) or 1 mm (the coverage records'). The inverse Fisher
information bounds the variance of any unbiased estimator; "P miss" is the
chance that such an estimator with exactly the bound misses by more than
0.5 mm in depth (1 mm in x).

    python3 docs/validation/r2/depth_information.py --palpate target/release/palpate --work /tmp/crb

About 15 min of CPU on 2 cores for the 13 passes (skipped when the CSV files
are there).
"""
import argparse
import csv
import os
import subprocess
from concurrent.futures import ThreadPoolExecutor
from math import erf, sqrt

import numpy as np

NODULES = [(37.5, 10.0), (75.0, 15.0), (112.5, 20.0)]
H = 0.25


def cases():
    yield "base", NODULES
    for i in range(3):
        for p, j in (("x", 0), ("d", 1)):
            for sign, tag in ((1, "p"), (-1, "m")):
                nod = [list(n) for n in NODULES]
                nod[i][j] += sign * H
                yield f"{p}{i + 1}{tag}", nod


def run(palpate, work, name, nod):
    out = os.path.join(work, f"{name}.csv")
    if os.path.exists(out):
        return
    spec = ",".join(f"{x}:{d}" for x, d in nod)
    subprocess.run([palpate, "simulate", "--benchmark", "R2", "--rd", "6", "--nodules", spec,
                    "--mesh", "1", "--error-estimate", "off", "--csv", out],
                   check=True, capture_output=True)


def load(work, name):
    lines = [l for l in open(os.path.join(work, f"{name}.csv")) if not l.startswith("#")]
    rows = list(csv.reader(lines))
    head = rows[0]
    a = np.array([[float(v) for v in r] for r in rows[1:]])
    return a[:, head.index("position_mm")], a[:, head.index("force_N")]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--palpate", default="target/release/palpate")
    ap.add_argument("--work", default="/tmp/crb")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    with ThreadPoolExecutor(2) as ex:
        list(ex.map(lambda c: run(a.palpate, a.work, *c), cases()))
    x, f = load(a.work, "base")
    cols, names = [f], ["s"]
    for i in (1, 2, 3):
        for p in "xd":
            fp = load(a.work, f"{p}{i}p")[1]
            fm = load(a.work, f"{p}{i}m")[1]
            cols.append((fp - fm) / (2 * H))
            names.append(f"{p}{i}")
    jac = np.array(cols).T
    sigma = 0.01 * f.max()
    print(f"peak {f.max():.3f} N, noise SD {sigma:.4f} N; positions {x[0]}..{x[-1]} mm")
    print("| record step | nodule | x SD (mm) | depth SD (mm) | P(|depth error| > 0.5 mm) | depth SD with x and s known |")
    print("|---|---|---|---|---|---|")
    for step in (0.5, 1.0):
        k = int(round(step / (x[1] - x[0])))
        j = jac[::k]
        info = j.T @ j / sigma**2
        sd = np.sqrt(np.diag(np.linalg.inv(info)))
        for n, (xn, dn) in enumerate(NODULES):
            sx, sdp = sd[1 + 2 * n], sd[2 + 2 * n]
            miss = 1 - erf(0.5 / sdp / sqrt(2))
            alone = 1 / np.sqrt(info[2 + 2 * n, 2 + 2 * n])
            print(f"| {step} mm ({len(j)} samples) | {xn}:{dn} | {sx:.3f} | {sdp:.3f} | {100 * miss:.1f} % | {alone:.3f} |")


if __name__ == "__main__":
    main()
