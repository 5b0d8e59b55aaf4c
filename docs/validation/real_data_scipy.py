#!/usr/bin/env python3
"""Independent fits of the real measurements (shared/data/real) with scipy.

Every case below is fitted here with scipy.optimize.least_squares on the
same model and residual as palpate, and the result is written to
real_data_scipy.json; tests/tests/integration/real_data_fits.rs runs palpate on the same
cases from the same starting points and compares.

The equations are written from the textbook formulas, not from the Rust
code. Incompressible, J = 1, nominal (first Piola) stresses:

  uniaxial         P = 2 (l - l^-2) (W1 + W2 / l)
  equibiaxial      P = 2 (l - l^-5) (W1 + l^2 W2)
  planar           P = 2 (l - l^-3) (W1 + W2)
  general biaxial  P1 = 2 (l1 - l3^2 / l1) (W1 + l2^2 W2), P2 likewise, l3 = 1/(l1 l2)
                   (sigma_a - sigma_3 = 2 (l_a^2 - l3^2)(W1 + l_b^2 W2); Rivlin & Saunders 1951)
  simple shear on axial stretch L, F = [[L^-1/2, g L, 0], [0, L, 0], [0, 0, L^-1/2]]:
                   P12 = sigma12 / L = 2 g (L W1 + W2),
                   I1 = L^2 (1 + g^2) + 2/L,  I2 = 2 L + L^-2 + g^2 L

Ogden W = sum 2 mu_i / a_i^2 (l1^a + l2^a + l3^a - 3): principal Cauchy
stresses sigma_a = sum 2 mu_i / a_i l_a^a_i - p; uniaxial/biaxial from the
stress-free direction; simple shear from the eigen-decomposition of
B = F F^T (numpy): sigma12 = sum_a (l_a W_a) n_a1 n_a2.

Viscoelastic, with G(t) = 1 - sum g_i (1 - exp(-t/tau_i)) and the hereditary
integral evaluated exactly for piecewise-linear histories:
  qlv:N    P(t) = int G(t - s) dPe/ds ds (Pe the elastic uniaxial stress);
  finite:N S_a(t) = int G(t - s) dSe_a/ds ds for the principal isochoric
           second Piola stresses Se_a = (l_a W_,a - mean_b l_b W_,b) / l_a^2,
           P = l S_1 - l^-2 S_2.

Residuals r_i = w s_i (f_i - y_i): absolute s = 1, relative s = 1/y (y != 0),
normalised s = 1/sqrt(sum_set y^2); w the record's weight. SSE = sum r^2.
Solver: least_squares(method='trf', bounds as palpate-material's Law::params
(C10 >= 0, Ogden alpha in (-50, 50) = OGDEN_ALPHA_BOUND, g in [0, 1], tau > 0), x_scale='jac',
ftol = xtol = gtol = 1e-15) from deterministic starts; the best SSE is kept.

Usage: python3 docs/validation/real_data_scipy.py
"""
import json
import os
import numpy as np
import scipy
from scipy.optimize import least_squares

HERE = os.path.dirname(os.path.abspath(__file__))
REAL = os.path.join(HERE, "..", "..", "..", "shared", "data", "real")
INF = np.inf
ALPHA = 50.0  # palpate_material::OGDEN_ALPHA_BOUND


# ---------------------------------------------------------------- reading
def read_csv(path):
    header, rows = None, []
    with open(os.path.join(REAL, path)) as f:
        for line in f:
            s = line.strip()
            if not s or s.startswith("#"):
                continue
            if header is None:
                header = s.split(",")
                continue
            rows.append([float(v) for v in s.split(",")])
    a = np.array(rows)
    return {h: a[:, k] for k, h in enumerate(header)}


def record(spec):
    """A --data spec `kind[opts]=path` -> dict with kind, x, y, time, weight, lam."""
    head, path = spec.split("]=") if "]=" in spec else spec.split("=", 1)
    opts = {}
    if "[" in head:
        kind, o = head.split("[")
        for kv in o.split(","):
            k, v = kv.split("=")
            opts[k] = v
    else:
        kind = head
    c = read_csv(path)
    unit = {"MPa": 1.0, "kPa": 1e-3, "Pa": 1e-6}[opts.get("stress_unit", "MPa")]
    r = {"kind": kind, "weight": float(opts.get("weight", 1)), "lam": float(opts.get("axial_stretch", 1))}
    if kind == "simple_shear":
        r["x"] = c["amount_of_shear"]
        r["y"] = c["shear_stress_MPa"] * unit
    elif kind == "biaxial" and "lambda1" in c:
        r["kind"] = "general_biaxial"
        r["l1"], r["l2"] = c["lambda1"], c["lambda2"]
        r["y"] = np.column_stack([c["stress1_MPa"], c["stress2_MPa"]]).ravel() * unit
    else:
        r["x"] = c["stretch"] if "stretch" in c else 1.0 + c["strain"]
        r["y"] = c["stress_MPa"] * unit
    r["time"] = c.get("time_s")
    return r


# ---------------------------------------------------------------- laws
def law_spec(law):
    """(parameter names, lower bounds, upper bounds)."""
    if law == "neo_hookean":
        return ["C10"], [0], [INF]
    if law == "mooney_rivlin":
        # Fitted as (C10, S = C10 + C01) with S >= 0: palpate's admissible domain
        # (initial shear modulus 2 (C10 + C01) > 0, either term of either sign).
        return ["C10", "S"], [-INF, 0], [INF, INF]
    if law == "yeoh":
        return ["C10", "C20", "C30"], [0, -INF, -INF], [INF, INF, INF]
    if law.startswith("ogden"):
        n = int(law[5:])
        names, lo, hi = [], [], []
        for i in range(1, n + 1):
            names += [f"mu{i}", f"alpha{i}"]
            lo += [-INF, -ALPHA]
            hi += [INF, ALPHA]
        return names, lo, hi
    raise ValueError(law)


def w12(law, p, i1, i2):
    if law == "neo_hookean":
        return p[0] + 0 * i1, 0 * i1
    if law == "mooney_rivlin":
        return p[0] + 0 * i1, (p[1] - p[0]) + 0 * i1
    if law == "yeoh":
        x = i1 - 3
        return p[0] + 2 * p[1] * x + 3 * p[2] * x**2, 0 * i1
    raise ValueError(law)


def ogden_terms(p):
    return [(p[2 * i], p[2 * i + 1]) for i in range(len(p) // 2)]


def uniaxial(law, p, l):
    if law.startswith("ogden"):
        return sum(2 * m / a * (l ** (a - 1) - l ** (-a / 2 - 1)) for m, a in ogden_terms(p))
    i1, i2 = l**2 + 2 / l, 2 * l + l**-2
    a, b = w12(law, p, i1, i2)
    return 2 * (l - l**-2) * (a + b / l)


def equibiaxial(law, p, l):
    if law.startswith("ogden"):
        return sum(2 * m / a * (l**a - l ** (-2 * a)) / l for m, a in ogden_terms(p))
    i1, i2 = 2 * l**2 + l**-4, l**4 + 2 * l**-2
    a, b = w12(law, p, i1, i2)
    return 2 * (l - l**-5) * (a + l**2 * b)


def planar(law, p, l):
    if law.startswith("ogden"):
        return sum(2 * m / a * (l**a - l ** (-a)) / l for m, a in ogden_terms(p))
    i1 = l**2 + 1 + l**-2
    a, b = w12(law, p, i1, i1)
    return 2 * (l - l**-3) * (a + b)


def general_biaxial(law, p, l1, l2):
    l3 = 1 / (l1 * l2)
    if law.startswith("ogden"):
        p1 = sum(2 * m / a * (l1**a - l3**a) / l1 for m, a in ogden_terms(p))
        p2 = sum(2 * m / a * (l2**a - l3**a) / l2 for m, a in ogden_terms(p))
    else:
        i1 = l1**2 + l2**2 + l3**2
        i2 = (l1 * l2) ** 2 + (l2 * l3) ** 2 + (l1 * l3) ** 2
        a, b = w12(law, p, i1, i2)
        p1 = 2 * (l1 - l3**2 / l1) * (a + l2**2 * b)
        p2 = 2 * (l2 - l3**2 / l2) * (a + l1**2 * b)
    return np.column_stack([p1, p2]).ravel()


def simple_shear(law, p, g, lam):
    if law.startswith("ogden"):
        out = np.empty_like(g)
        t = lam**-0.5
        for k, gk in enumerate(g):
            f = np.array([[t, gk * lam, 0], [0, lam, 0], [0, 0, t]])
            ev, vec = np.linalg.eigh(f @ f.T)
            ls = np.sqrt(ev)
            s12 = 0.0
            for a_ in range(3):
                lw = sum(2 * m / a * ls[a_] ** a for m, a in ogden_terms(p))
                s12 += lw * vec[0, a_] * vec[1, a_]
            out[k] = s12 / lam
        return out
    i1 = lam**2 * (1 + g**2) + 2 / lam
    i2 = 2 * lam + lam**-2 + g**2 * lam
    a, b = w12(law, p, i1, i2)
    return 2 * g * (lam * a + b)


def principal_dw(law, p, lam):
    """l_a dW/dl_a for the three principal stretches (arrays)."""
    if law.startswith("ogden"):
        return [sum(2 * m / a * l**a for m, a in ogden_terms(p)) for l in lam]
    i1 = sum(l**2 for l in lam)
    i2 = (lam[0] * lam[1]) ** 2 + (lam[1] * lam[2]) ** 2 + (lam[0] * lam[2]) ** 2
    a, b = w12(law, p, i1, i2)
    # l dW/dl = 2 W1 l^2 + 2 W2 (l^2 I1 - l^4)
    return [2 * a * l**2 + 2 * b * (l**2 * i1 - l**4) for l in lam]


# ---------------------------------------------------------------- viscoelasticity
def convolve(time, fe, prony):
    """Exact hereditary integral of G for piecewise-linear fe (Taylor, Pister & Goudreau 1970)."""
    terms = len(prony) // 2
    ginf = 1 - sum(prony[0::2])
    h = np.full(terms, fe[0])
    out = np.empty_like(fe)
    out[0] = ginf * fe[0] + sum(prony[2 * i] * h[i] for i in range(terms))
    for k in range(1, len(fe)):
        dt = time[k] - time[k - 1]
        d = fe[k] - fe[k - 1]
        for i in range(terms):
            x = dt / prony[2 * i + 1]
            phi = -np.expm1(-x) / x if x > 0 else 1.0
            h[i] = np.exp(-x) * h[i] + d * phi
        out[k] = ginf * fe[k] + sum(prony[2 * i] * h[i] for i in range(terms))
    return out


def predict(case, p, r):
    law, visc = case["law"], case.get("viscous")
    nlaw = len(law_spec(law)[0])
    lp, prony = p[:nlaw], p[nlaw:]
    kind = r["kind"]
    if kind == "simple_shear":
        return simple_shear(law, lp, r["x"], r["lam"])
    if kind == "general_biaxial":
        return general_biaxial(law, lp, r["l1"], r["l2"])
    if kind in ("biaxial", "equibiaxial"):
        return equibiaxial(law, lp, r["x"])
    if kind == "planar":
        return planar(law, lp, r["x"])
    l = r["x"]
    if visc is None:
        return uniaxial(law, lp, l)
    if visc.startswith("qlv"):
        return convolve(r["time"], uniaxial(law, lp, l), prony)
    t = l**-0.5
    g = principal_dw(law, lp, [l, t, t])
    mean = (g[0] + g[1] + g[2]) / 3
    s1 = convolve(r["time"], (g[0] - mean) / l**2, prony)
    s2 = convolve(r["time"], (g[1] - mean) / t**2, prony)
    return l * s1 - s2 / l**2


def factors(residual, y, w):
    if residual == "absolute":
        return np.full(len(y), w), np.ones(len(y), bool)
    if residual == "relative":
        keep = y != 0
        return w / np.where(keep, y, 1), keep
    return np.full(len(y), w / np.sqrt(np.sum(y**2))), np.ones(len(y), bool)


def residuals(case, p, recs):
    out = []
    for r in recs:
        f, keep = factors(case["residual"], r["y"], r["weight"])
        out.append((f * (predict(case, p, r) - r["y"]))[keep])
    return np.concatenate(out)


def bounds(case):
    _, lo, hi = law_spec(case["law"])
    lo, hi = list(lo), list(hi)
    if case.get("viscous"):
        n = int(case["viscous"].split(":")[1])
        lo += [0, 0] * n
        hi += [1, INF] * n
    return lo, hi


def starts(case, recs):
    law = case["law"]
    base = {
        "neo_hookean": [[1e-3], [0.1]],
        "mooney_rivlin": [[1e-3, 1.1e-3], [0.1, 0.11]],
        "yeoh": [[1e-3, 0, 0], [0.1, 0.0, 0.0]],
        "ogden1": [[1e-3, 2], [1e-3, -2], [1e-3, -15], [0.1, 2], [0.1, 5]],
        "ogden2": [[1e-3, 2, 1e-4, -2], [0.1, 2, 0.01, -2], [0.1, 1.5, 0.001, 6], [1e-3, -10, 1e-4, 4], [0.3, 1.3, 0.01, 5]],
        "ogden3": [[0.1, 2, 0.01, -2, 0.001, 4], [0.3, 1.3, 0.003, 5, -0.01, -2]],
    }[law]
    if not case.get("viscous"):
        return base
    n = int(case["viscous"].split(":")[1])
    # Elastic fit first, then Prony terms log-spaced over the resolvable decades (as palpate does).
    el = best({**case, "viscous": None}, recs, base)["params"]
    dt = min(np.min(np.diff(r["time"])[np.diff(r["time"]) > 0]) for r in recs)
    span = max(r["time"][-1] - r["time"][0] for r in recs)
    lo, hi = max(min(10 * dt, span / 4), 1e-6), max(span / 2, 1e-6)
    out = []
    for gscale in (1.0, 0.5):
        s = list(el)
        for i in range(1, n + 1):
            s += [gscale * 0.5 / n, lo * (hi / lo) ** (i / (n + 1))]
        out.append(s)
    return out


def best(case, recs, start_list):
    lo, hi = bounds(case)
    top = None
    for s in start_list:
        s = np.clip(np.array(s, float), np.array(lo) + 1e-12, np.array(hi) - 1e-12)
        try:
            res = least_squares(lambda p: residuals(case, p, recs), s, bounds=(lo, hi), method="trf",
                                x_scale="jac", ftol=1e-15, xtol=1e-15, gtol=1e-15, max_nfev=20000)
        except ValueError:
            continue
        if not np.all(np.isfinite(res.fun)):
            continue
        sse = float(np.sum(res.fun**2))
        if top is None or sse < top["sse"]:
            top = {"sse": sse, "params": [float(v) for v in res.x]}
    return top


REGIONS = ["cortex", "basal_ganglia", "corona_radiata", "corpus_callosum"]
MARECHAL = ["dragon_skin_10_medium", "dragon_skin_20", "dragon_skin_30", "ecoflex_0010", "ecoflex_0030",
            "ecoflex_0050", "mold_star_20t", "rtv615", "sortaclear_40"]
EXTRAS = ["0d75", "0d80", "0d85", "0d90", "0d95", "1d05", "1d10", "1d15", "1d20", "1d25"]


def cases():
    out = []
    b = "brain_budday2017/"
    for r in REGIONS:
        ct = f"uniaxial={b}{r}_compression_tension.csv"
        sh = f"simple_shear={b}{r}_simple_shear.csv"
        for law in ["neo_hookean", "mooney_rivlin", "ogden1"]:
            out.append({"id": f"{r}-ct-{law}", "law": law, "residual": "absolute", "data": [ct]})
        for law in ["neo_hookean", "ogden1"]:
            out.append({"id": f"{r}-shear-{law}", "law": law, "residual": "absolute", "data": [sh]})
        for law in ["mooney_rivlin", "ogden1"]:
            for res in ["absolute", "normalised"]:
                out.append({"id": f"{r}-joint-{law}-{res}", "law": law, "residual": res, "data": [ct, sh]})
    extras = [f"simple_shear[axial_stretch={float(e.replace('d', '.'))},stress_unit=kPa,weight=0.2]="
              f"{b}extra_corona_radiata_shear_at_axial_stretch_{e}.csv" for e in EXTRAS]
    for law in ["mooney_rivlin", "ogden1"]:
        out.append({"id": f"corona_radiata-combined-{law}", "law": law, "residual": "normalised",
                    "data": [f"uniaxial={b}corona_radiata_compression_tension.csv",
                             f"simple_shear={b}corona_radiata_simple_shear.csv"] + extras})
    for law in ["mooney_rivlin", "yeoh", "ogden2"]:
        out.append({"id": f"kawabata-{law}", "law": law, "residual": "absolute",
                    "data": ["biaxial=kawabata1981/biaxial.csv"]})
    m = "meunier2008_silicone/"
    for law in ["mooney_rivlin", "yeoh", "ogden2"]:
        out.append({"id": f"meunier-all-{law}", "law": law, "residual": "absolute",
                    "data": [f"uniaxial={m}uniaxial.csv", f"biaxial={m}biaxial.csv", f"planar={m}pure_shear.csv"]})
    for f in MARECHAL:
        for law in ["mooney_rivlin", "yeoh"]:
            out.append({"id": f"marechal-{f}-{law}", "law": law, "residual": "absolute",
                        "data": [f"uniaxial=silicone_tensile_marechal/{f}.csv"]})
    v = "vhb4910_zhao/"
    for s in ["1d5", "3d0", "6d0"]:
        out.append({"id": f"vhb-relax-{s}-nh-qlv2", "law": "neo_hookean", "viscous": "qlv:2",
                    "residual": "absolute", "data": [f"uniaxial={v}relaxation_stretch_{s}.csv"]})
    for visc in ["qlv:2", "finite:2"]:
        out.append({"id": f"vhb-cycles-yeoh-{visc.replace(':', '')}", "law": "yeoh", "viscous": visc,
                    "residual": "absolute",
                    "data": [f"uniaxial={v}load_unload_0d01_2d0.csv", f"uniaxial={v}load_unload_0d03_2d0_1.csv",
                             f"uniaxial={v}load_unload_0d05_2d0.csv"]})
    return out


def main():
    fits = []
    for case in cases():
        recs = [record(d) for d in case["data"]]
        st = starts(case, recs)
        top = best(case, recs, st)
        names = list(law_spec(case["law"])[0])
        params = list(top["params"])
        if case["law"] == "mooney_rivlin":  # report C01 = S - C10, starts likewise
            names[1] = "C01"
            params[1] -= params[0]
            for s_ in st:
                s_[1] -= s_[0]
        if case.get("viscous"):
            n = int(case["viscous"].split(":")[1])
            for i in range(1, n + 1):
                names += [f"g{i}", f"tau{i}_s"]
        n = sum(int(np.sum(factors(case["residual"], r["y"], 1)[1])) for r in recs)
        fits.append({**case, "sse": top["sse"], "n": n, "params": dict(zip(names, params)),
                     "starts": [list(map(float, s)) for s in st]})
        print(f"{case['id']:48s} SSE {top['sse']:.6e}  {dict(zip(names, np.round(params, 6)))}")
    with open(os.path.join(HERE, "real_data_scipy.json"), "w") as f:
        json.dump({"generator": "docs/validation/real_data_scipy.py", "scipy": scipy.__version__, "fits": fits},
                  f, indent=1)


if __name__ == "__main__":
    main()
