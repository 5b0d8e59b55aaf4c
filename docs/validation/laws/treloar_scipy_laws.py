#!/usr/bin/env python3
"""Independent Treloar fits of Gent, Veronda-Westmann and Humphrey with scipy.

The model equations are written here from the published energies (not from
the Rust code), with x = I1 - 3:

  Gent               W = -(mu Jm / 2) ln(1 - x / Jm)            W1 = mu Jm / (2 (Jm - x)), W2 = 0
  Veronda-Westmann   W = C1 (e^(C2 x) - 1) - C1 C2 / 2 (I2 - 3)  W1 = C1 C2 e^(C2 x),      W2 = -C1 C2 / 2
  Humphrey           W = C1 (e^(C2 x) - 1)                        W1 = C1 C2 e^(C2 x),      W2 = 0

and the incompressible homogeneous nominal stresses (Treloar 1975; Ogden
1984 sec. 7.2)

  uniaxial     P = 2 (l - l^-2) (W1 + W2 / l)
  equibiaxial  P = 2 (l - l^-5) (W1 + l^2 W2)
  planar       P = 2 (l - l^-3) (W1 + W2)

Data: studies/data/treloar/{uniaxial,biaxial,pure_shear}.csv (Treloar 1944).
Residuals: absolute r = P - y, relative r = (P - y) / y for y != 0; SSE over
the data sets (uniaxial alone, or all three). Solver:
least_squares(method='trf', bounds as palpate-material's Law::params,
ftol = xtol = gtol = 1e-15, x_scale='jac') from deterministic starts, the
best SSE kept. Gent's energy is undefined where x >= Jm: the residuals there
are 1e10 (a wall), and the starts have Jm above the data's largest x.
Writes treloar_scipy_laws.json next to this script; the same format as
docs/validation/treloar_scipy.json, read by
tests/tests/integration/treloar_fits.rs.

Usage: python3 docs/validation/laws/treloar_scipy_laws.py
"""
import json
import os

import numpy as np
from scipy.optimize import least_squares

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "..", "..", "studies", "data", "treloar")
MODES = {"uniaxial": "uniaxial.csv", "equibiaxial": "biaxial.csv", "planar": "pure_shear.csv"}
INF = np.inf
EXPONENT = 50.0  # palpate_material::EXPONENT_BOUND
JM = 1e4  # palpate_material::GENT_JM_BOUND


def read(mode):
    rows, header = [], None
    with open(os.path.join(DATA, MODES[mode])) as f:
        for line in f:
            s = line.strip()
            if not s or s.startswith("#"):
                continue
            if header is None:
                header = s.split(",")
                continue
            rows.append([float(v) for v in s.split(",")])
    a = np.array(rows)
    return a[:, header.index("stretch")], a[:, header.index("stress_MPa")]


def x_of(mode, l):
    if mode == "uniaxial":
        return l**2 + 2 / l - 3
    if mode == "equibiaxial":
        return 2 * l**2 + l**-4 - 3
    return l**2 + l**-2 - 2


def nominal(mode, l, w1, w2):
    if mode == "uniaxial":
        return 2 * (l - l**-2) * (w1 + w2 / l)
    if mode == "equibiaxial":
        return 2 * (l - l**-5) * (w1 + l**2 * w2)
    return 2 * (l - l**-3) * (w1 + w2)


def stress(law, mode, p, l):
    x = x_of(mode, l)
    if law == "gent":
        mu, jm = p
        with np.errstate(divide="ignore", invalid="ignore"):
            w1 = np.where(x < jm, mu * jm / (2 * (jm - x)), np.nan)
        return nominal(mode, l, w1, 0 * l)
    c1, c2 = p
    w1 = c1 * c2 * np.exp(c2 * x)
    if law == "veronda_westmann":
        return nominal(mode, l, w1, -c1 * c2 / 2 + 0 * l)
    if law == "humphrey":
        return nominal(mode, l, w1, 0 * l)
    raise ValueError(law)


# Names, bounds (as palpate-material Law::params) and starting points.
LAWS = {
    "gent": (["mu", "Jm"], [0, 0], [INF, JM], [[0.4, 100.0], [0.3, 80.0], [0.5, 200.0], [0.2, 1000.0]]),
    "veronda_westmann": (["C1", "C2"], [0, 0], [INF, EXPONENT],
                         [[1.0, 0.2], [0.5, 0.05], [2.0, 0.01], [0.1, 1.0]]),
    "humphrey": (["C1", "C2"], [0, 0], [INF, EXPONENT],
                 [[1.0, 0.2], [0.5, 0.05], [2.0, 0.01], [0.1, 1.0]]),
}


def fit(law, modes, residual):
    names, lo, hi, starts = LAWS[law]
    data = [(m,) + read(m) for m in modes]

    def res(p):
        out = []
        for m, l, y in data:
            with np.errstate(over="ignore", invalid="ignore"):
                f = stress(law, m, p, l)
            if residual == "relative":
                keep = y != 0
                out.append((f[keep] - y[keep]) / y[keep])
            else:
                out.append(f - y)
        r = np.concatenate(out)
        return np.where(np.isfinite(r), r, 1e10)

    best = None
    for x0 in starts:
        x0 = np.clip(np.array(x0, float), np.array(lo) + 1e-9, np.array(hi) - 1e-9)
        sol = least_squares(res, x0, bounds=(lo, hi), method="trf", x_scale="jac",
                            ftol=1e-15, xtol=1e-15, gtol=1e-15, max_nfev=5000)
        sse = float(np.sum(sol.fun**2))
        if best is None or sse < best[0]:
            best = (sse, sol.x.copy())
    sse, x = best
    n = sum(len(l) if residual == "absolute" else int(np.sum(y != 0)) for _, l, y in data)
    return {"law": law, "data": "+".join(modes), "residual": residual, "sse": sse,
            "n": n, "params": dict(zip(names, [float(v) for v in x])),
            "starts": [[float(v) for v in s] for s in starts]}


def main():
    out = []
    for law in LAWS:
        for modes in [["uniaxial"], ["uniaxial", "equibiaxial", "planar"]]:
            for residual in ["absolute", "relative"]:
                r = fit(law, modes, residual)
                print(f"{law:17s} {r['data']:28s} {residual:9s} SSE={r['sse']:.8e} {r['params']}")
                out.append(r)
    with open(os.path.join(HERE, "treloar_scipy_laws.json"), "w") as f:
        json.dump({"generator": "docs/validation/laws/treloar_scipy_laws.py",
                   "scipy": __import__("scipy").__version__, "numpy": np.__version__,
                   "fits": out}, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
