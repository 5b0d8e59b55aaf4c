#!/usr/bin/env python3
"""Independent reference values for palpate's ANOVA and residual checks.

Computes, with statsmodels (ols + anova_lm, normal_ad) and scipy.stats
(bartlett, levene, t quantiles), the numbers that uq/tests/integration/anova_reference.rs
compares with palpate-uq to 6 significant digits, and writes them to
docs/validation/anova_reference.json (next to this script).

    pip install statsmodels scipy pandas
    python3 docs/validation/anova_statsmodels.py

Data sets:
  * table1      -- Mesa-Munera et al. 2011, Table 1 (shared/data/published/
                   mesa2011_table1.csv): r2 ~ material * space, 2 replicates.
  * threebytwo  -- a synthetic 3 x 2 factorial with 3 replicates (numbers
                   below): multi-df terms, Levene and Bartlett on 6 cells.
  * unbalanced  -- threebytwo without its last two runs: sequential (Type I) SS.
  * filtration  -- Montgomery, Design and Analysis of Experiments, Example 6.2
                   (filtration rate, unreplicated 2^4): effects and Lenth's
                   PSE, ME, SME computed here from their definitions.
"""
import json
import os
import sys

import numpy as np
import pandas as pd
import scipy
import scipy.stats as st
import statsmodels
import statsmodels.api as sm
import statsmodels.formula.api as smf
from statsmodels.stats.diagnostic import normal_ad

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.normpath(os.path.join(HERE, "..", "..", "..", "shared"))


def blom(n):
    i = np.arange(1, n + 1)
    return st.norm.ppf((i - 0.375) / (n + 0.25))


def ryan_joiner(x):
    """Correlation with Blom scores; Minitab's p by linear interpolation."""
    y = np.sort(np.asarray(x, float))
    n = len(y)
    r = float(np.corrcoef(y, blom(n))[0, 1])
    s = np.sqrt(n)
    c = [1.0071 - 0.1371 / s - 0.3682 / n + 0.7780 / n**2,
         1.0063 - 0.1288 / s - 0.6118 / n + 1.3505 / n**2,
         0.9963 - 0.0211 / s - 1.4106 / n + 3.1791 / n**2]
    if r >= c[0]:
        return {"r": r, "p": 0.1, "p_bound": "above"}
    if r <= c[2]:
        return {"r": r, "p": 0.01, "p_bound": "below"}
    p = float(np.interp(r, [c[2], c[1], c[0]], [0.01, 0.05, 0.10]))
    return {"r": r, "p": p, "p_bound": "interpolated"}


def analyse(d, response, factors):
    rhs = "*".join(f"C({f}, Sum)" for f in factors)
    model = smf.ols(f"{response} ~ {rhs}", data=d).fit()
    tab = sm.stats.anova_lm(model, typ=1)
    ss_total = float(((d[response] - d[response].mean()) ** 2).sum())
    ss_e = float(tab.loc["Residual", "sum_sq"])
    terms = []
    for name, row in tab.iterrows():
        if name == "Residual":
            continue
        # "C(a, Sum):C(b, Sum)" -> "a:b"
        short = ":".join(p.split("(")[1].split(",")[0] for p in name.split(":"))
        ss = float(row["sum_sq"])
        terms.append({"name": short, "df": int(row["df"]), "ss": ss, "ms": float(row["mean_sq"]),
                      "f": float(row["F"]), "p": float(row["PR(>F)"]),
                      "eta_sq": ss / ss_total, "partial_eta_sq": ss / (ss + ss_e)})
    cells = [g[response].to_numpy() for _, g in d.groupby(list(factors), sort=False)]
    out = {
        "response": response, "factors": list(factors),
        "data": {c: d[c].tolist() for c in list(factors) + [response]},
        "terms": terms,
        "residual": {"df": int(tab.loc["Residual", "df"]), "ss": ss_e, "ms": float(tab.loc["Residual", "mean_sq"])},
        "r2": float(model.rsquared), "adj_r2": float(model.rsquared_adj),
    }
    a2, p = normal_ad(model.resid.to_numpy())
    out["anderson_darling"] = {"a2": float(a2), "p": float(p)}
    out["ryan_joiner"] = ryan_joiner(model.resid.to_numpy())
    b = st.bartlett(*cells)
    out["bartlett"] = {"statistic": float(b.statistic), "p": float(b.pvalue)}
    zs = [np.abs(c - np.median(c)) for c in cells]
    if all(np.ptp(z) == 0 for z in zs) or all(len(c) == 2 for c in cells):
        out["levene"] = None  # undefined: no spread of |x - median| within any cell
    else:
        for center in ("median", "mean"):
            lv = st.levene(*cells, center=center)
            out["levene" if center == "median" else "levene_mean"] = {"statistic": float(lv.statistic), "p": float(lv.pvalue)}
    return out


def lenth(effects, alpha=0.05):
    a = np.abs(np.asarray(effects, float))
    m = len(a)
    s0 = 1.5 * np.median(a)
    pse = 1.5 * np.median(a[a < 2.5 * s0])
    d = m / 3
    gamma = (1 + (1 - alpha) ** (1 / m)) / 2
    return {"s0": float(s0), "pse": float(pse), "df": d,
            "me": float(st.t.ppf(1 - alpha / 2, d) * pse), "sme": float(st.t.ppf(gamma, d) * pse)}


def main():
    ref = {"generator": "docs/validation/anova_statsmodels.py",
           "versions": {"python": sys.version.split()[0], "statsmodels": statsmodels.__version__,
                        "scipy": scipy.__version__, "pandas": pd.__version__, "numpy": np.__version__}}

    t1 = pd.read_csv(os.path.join(SHARED, "data", "published", "mesa2011_table1.csv"), comment="#")
    ref["table1"] = analyse(t1, "r2", ["material", "space"])

    a = ["low", "mid", "high"] * 6
    b = (["dry"] * 3 + ["wet"] * 3) * 3
    y = [10.2, 12.9, 15.1, 11.0, 14.8, 18.9,
         9.6, 13.5, 14.2, 11.9, 13.7, 17.6,
         10.9, 12.2, 16.3, 10.4, 15.9, 19.8]
    d = pd.DataFrame({"a": a, "b": b, "y": y})
    ref["threebytwo"] = analyse(d, "y", ["a", "b"])
    ref["unbalanced"] = analyse(d.iloc[:-2].reset_index(drop=True), "y", ["a", "b"])

    # Montgomery Example 6.2, runs in standard (Yates) order.
    rate = [45, 71, 48, 65, 68, 60, 80, 65, 43, 100, 45, 104, 75, 86, 70, 96]
    runs = np.arange(16)
    # Columns fA..fD ("C" would shadow patsy's C()).
    f = pd.DataFrame({"f" + k: np.where((runs >> i) & 1, "hi", "lo") for i, k in enumerate("ABCD")})
    f["rate"] = rate
    model = smf.ols("rate ~ C(fA, Sum)*C(fB, Sum)*C(fC, Sum)*C(fD, Sum)", data=f).fit()
    # Sum coding puts +1 on the first level ("hi" < "lo" alphabetically): effect = 2 * coef.
    effects = {}
    for name, coef in model.params.items():
        if name == "Intercept":
            continue
        letters = "".join(p.split("(")[1].split(",")[0][1:] for p in name.split(":"))
        effects[letters] = float(2 * coef)
    ref["filtration"] = {"data": {"rate": rate}, "effects": effects, "lenth": lenth(list(effects.values()))}

    path = os.path.join(HERE, "anova_reference.json")
    with open(path, "w") as fh:
        json.dump(ref, fh, indent=2)
        fh.write("\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
