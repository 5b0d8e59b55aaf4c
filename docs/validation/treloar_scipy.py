#!/usr/bin/env python3
"""Independent Treloar fits with scipy.optimize.least_squares.

The model equations are written here from the textbook formulas (not from
the Rust code): incompressible homogeneous deformations with nominal stress

  uniaxial     P = 2 (l - l^-2) (W1 + W2 / l)
  equibiaxial  P = 2 (l - l^-5) (W1 + l^2 W2)
  planar       P = 2 (l - l^-3) (W1 + W2)

for invariant laws W(I1, I2) (Treloar 1975; Ogden 1984 sec. 7.2), and for
Ogden W = sum 2 mu_i / alpha_i^2 (l1^a + l2^a + l3^a - 3) (Abaqus form)

  P = (1 / l1) sum 2 mu_i / alpha_i (l1^a_i - lf^a_i)

with lf the stretch of the stress-free direction (uniaxial l^-1/2,
equibiaxial l^-2, planar 1/l). Arruda-Boyce is the 5-term series
W = mu sum C_i / lm^(2i-2) (I1^i - 3^i), C = 1/2, 1/20, 11/1050, 19/7000,
519/673750.

Residuals: absolute r = P - y, relative r = (P - y) / y for y != 0.
Objective SSE = sum r^2 over the data sets (uniaxial alone, or all three).
Solver: least_squares(method='trf', bounds as in palpate-material's Law::params,
ftol = xtol = gtol = 1e-15, x_scale='jac'), from many deterministic starts;
the best SSE is kept. Writes treloar_scipy.json next to this script.

Usage: python3 docs/validation/treloar_scipy.py
"""
import json
import os
import numpy as np
from scipy.optimize import least_squares

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "..", "..", "shared", "data", "treloar")
MODES = {"uniaxial": "uniaxial.csv", "equibiaxial": "biaxial.csv", "planar": "pure_shear.csv"}
AB = [0.5, 1 / 20, 11 / 1050, 19 / 7000, 519 / 673750]
INF = np.inf
ALPHA = 50.0  # palpate_material::OGDEN_ALPHA_BOUND


def read(mode):
    rows = []
    header = None
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


def invariants(mode, l):
    if mode == "uniaxial":
        return l**2 + 2 / l, 2 * l + l**-2
    if mode == "equibiaxial":
        return 2 * l**2 + l**-4, l**4 + 2 * l**-2
    return l**2 + 1 + l**-2, l**2 + 1 + l**-2


def invariant_stress(mode, l, w1, w2):
    if mode == "uniaxial":
        return 2 * (l - l**-2) * (w1 + w2 / l)
    if mode == "equibiaxial":
        return 2 * (l - l**-5) * (w1 + l**2 * w2)
    return 2 * (l - l**-3) * (w1 + w2)


def stress(law, mode, p, l):
    i1, i2 = invariants(mode, l)
    zero = np.zeros_like(l)
    if law == "neo_hookean":
        return invariant_stress(mode, l, p[0] + zero, zero)
    if law == "mooney_rivlin":
        # Fitted as (C10, S = C10 + C01), both >= 0: palpate's admissible
        # domain (C10 > 0 and initial shear modulus 2 (C10 + C01) > 0).
        return invariant_stress(mode, l, p[0] + zero, p[1] - p[0] + zero)
    if law == "yeoh":
        x = i1 - 3
        return invariant_stress(mode, l, p[0] + 2 * p[1] * x + 3 * p[2] * x**2, zero)
    if law == "arruda_boyce":
        mu, lm = p
        w1 = sum(mu * c * (k + 1) * i1**k / lm ** (2 * k) for k, c in enumerate(AB))
        return invariant_stress(mode, l, w1, zero)
    if law == "ogden3":
        lf = {"uniaxial": l**-0.5, "equibiaxial": l**-2.0, "planar": 1 / l}[mode]
        out = zero.copy()
        for i in range(3):
            mu, a = p[2 * i], p[2 * i + 1]
            out += 2 * mu / a * (l**a - lf**a)
        return out / l
    raise ValueError(law)


# Names, bounds (as palpate-material Law::params) and starting points.
LAWS = {
    "neo_hookean": (["C10"], [0], [INF], [[0.2], [1.0], [0.05]]),
    "mooney_rivlin": (["C10", "S"], [0, 0], [INF, INF], [[0.2, 0.21], [0.1, 0.2], [0.3, 0.25]]),
    "yeoh": (["C10", "C20", "C30"], [0, -INF, -INF], [INF] * 3,
             [[0.2, 0.0, 0.0], [0.1, -0.001, 1e-5], [0.3, 0.01, -1e-4]]),
    "arruda_boyce": (["mu", "lambda_m"], [0, 1], [INF, 100], [[0.3, 3.0], [0.2, 6.0], [0.5, 2.0], [0.3, 20.0]]),
}


def ogden_starts():
    """Deterministic starts: signs/magnitudes of alpha spread over the bounds."""
    rng = np.random.default_rng(20240501)
    starts = [[0.4, 1.3, 0.001, 5.0, -0.01, -2.0], [0.6, 1.5, 0.002, 4.0, 0.01, -2.5], [0.2, 2.0, -0.1, -2.0, 0.01, 4.0]]
    for _ in range(40):
        alphas = rng.uniform(-8, 8, 3)
        mus = rng.uniform(-0.5, 0.8, 3)
        starts.append([mus[0], alphas[0], mus[1], alphas[1], mus[2], alphas[2]])
    return starts


LAWS["ogden3"] = (["mu1", "alpha1", "mu2", "alpha2", "mu3", "alpha3"],
                  [-INF, -ALPHA] * 3, [INF, ALPHA] * 3, ogden_starts())


def fit(law, modes, residual):
    names, lo, hi, starts = LAWS[law]
    data = [(m,) + read(m) for m in modes]

    def res(p):
        out = []
        for m, l, y in data:
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
        try:
            sol = least_squares(res, x0, bounds=(lo, hi), method="trf", x_scale="jac",
                                ftol=1e-15, xtol=1e-15, gtol=1e-15, max_nfev=5000)
        except Exception:  # a start outside the domain of a law
            continue
        sse = float(np.sum(sol.fun**2))
        if best is None or sse < best[0]:
            best = (sse, sol.x.copy())
    sse, x = best
    if law == "mooney_rivlin":  # report C01 = S - C10
        names, x = ["C10", "C01"], np.array([x[0], x[1] - x[0]])
        starts = [[a, b - a] for a, b in starts]
    n = sum(len(l) if residual == "absolute" else int(np.sum(y != 0)) for _, l, y in data)
    return {"law": law, "data": "+".join(modes), "residual": residual, "sse": sse,
            "n": n, "params": dict(zip(names, [float(v) for v in x])),
            "starts": [[float(v) for v in s] for s in starts]}


def main():
    import sys
    path = os.path.join(HERE, "treloar_scipy.json")
    only = sys.argv[1:]  # refit only these laws, keep the others from the JSON
    previous = json.load(open(path))["fits"] if only and os.path.exists(path) else []
    out = []
    for law in ["neo_hookean", "mooney_rivlin", "yeoh", "arruda_boyce", "ogden3"]:
        if only and law not in only:
            out.extend(f for f in previous if f["law"] == law)
            continue
        for modes in [["uniaxial"], ["uniaxial", "equibiaxial", "planar"]]:
            for residual in ["absolute", "relative"]:
                r = fit(law, modes, residual)
                print(f"{law:14s} {r['data']:32s} {residual:9s} SSE={r['sse']:.8e} {r['params']}")
                out.append(r)
    with open(path, "w") as f:
        json.dump({"generator": "docs/validation/treloar_scipy.py", "scipy": __import__("scipy").__version__,
                   "fits": out}, f, indent=1)


if __name__ == "__main__":
    main()
