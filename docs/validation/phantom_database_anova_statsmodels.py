#!/usr/bin/env python3
"""Independent reference values for the phantom database study's ANOVA of
the modulus on family x thinner, in kPa and in ln kPa (the
`replicates_summary` step, studies/src/steps/replicates_summary/anova.rs, whose
unit test compares with them to 6 significant digits).

Input: the per-record moduli a run of studies/phantom-database.toml writes
(`modulus-modulus.csv`: the Yeoh fit's initial shear modulus of each test of
each phantom; derived from the phantom database of Dawood et al., CC BY 4.0,
see shared/data/real/phantom_dawood2026/README). The rows of the complete
crossing (both families at thinner 0, 12.5, 25, 37.5 and 50 %) are copied
into the JSON with the reference numbers, so the test needs neither the run
nor the shared data.

    pip install statsmodels scipy pandas
    cargo run -p palpate-studies --bin palpate -- run studies/phantom-database.toml --out runs/phantom-database
    python3 docs/validation/phantom_database_anova_statsmodels.py runs/phantom-database/modulus-modulus.csv

Writes docs/validation/phantom_database_anova_reference.json (next to this
script): for each scale (`mu0`, `ln_mu0`), statsmodels' ols + anova_lm
(Type I; the design is balanced) of y ~ C(family) * C(thinner); the batch
nested in the cells, y ~ C(family) * C(thinner) + C(family):C(thinner):C(batch),
its term tested against the records within a batch and each crossed term
tested against it; scipy's Bartlett and Levene (median) across the ten
cells; statsmodels' Anderson-Darling (normal_ad) and the Ryan-Joiner
correlation of the crossed model's residuals.
"""
import json
import os
import sys

import numpy as np
import pandas as pd
import scipy
import scipy.stats as st
import statsmodels
import statsmodels.formula.api as smf
from statsmodels.stats.anova import anova_lm
from statsmodels.stats.diagnostic import normal_ad

HERE = os.path.dirname(os.path.abspath(__file__))
CROSSING = ["0", "12.5", "25", "37.5", "50"]


def blom(n):
    i = np.arange(1, n + 1)
    return st.norm.ppf((i - 0.375) / (n + 0.25))


def scale(df, y):
    d = df.assign(y=y)
    crossed = smf.ols("y ~ C(family) * C(thinner)", data=d).fit()
    table = anova_lm(crossed, typ=1)
    names = {"C(family)": "family", "C(thinner)": "thinner", "C(family):C(thinner)": "family:thinner"}
    terms = []
    for k, name in names.items():
        row = table.loc[k]
        terms.append({"name": name, "df": int(row["df"]), "ss": float(row["sum_sq"]),
                      "f": float(row["F"]), "p": float(row["PR(>F)"])})
    res = table.loc["Residual"]
    nested = smf.ols("y ~ C(family) * C(thinner) + C(family):C(thinner):C(batch)", data=d).fit()
    nt = anova_lm(nested, typ=1)
    b = nt.loc["C(family):C(thinner):C(batch)"]
    ms_batch = b["sum_sq"] / b["df"]
    against = []
    for t in terms:
        f = t["ss"] / t["df"] / ms_batch
        against.append({"name": t["name"], "f": float(f), "p": float(st.f.sf(f, t["df"], b["df"]))})
    cells = [g["y"].to_numpy() for _, g in d.groupby(["family", "thinner"], sort=True)]
    r = crossed.resid.to_numpy()
    a2, ad_p = normal_ad(r)
    return {
        "terms": terms,
        "residual": {"df": int(res["df"]), "ss": float(res["sum_sq"])},
        "batch": {"df": int(b["df"]), "ss": float(b["sum_sq"]), "f": float(b["F"]), "p": float(b["PR(>F)"]),
                  "error_df": int(nt.loc["Residual"]["df"]),
                  "error_ms": float(nt.loc["Residual"]["sum_sq"] / nt.loc["Residual"]["df"]),
                  "against_batches": against},
        "bartlett_p": float(st.bartlett(*cells).pvalue),
        "levene_median_p": float(st.levene(*cells, center="median").pvalue),
        "anderson_darling_p": float(ad_p),
        "ryan_joiner_r": float(np.corrcoef(np.sort(r), blom(len(r)))[0, 1]),
    }


def main(csv):
    df = pd.read_csv(csv, dtype={"thinner": str})
    df = df[df["thinner"].isin(CROSSING)].reset_index(drop=True)
    assert len(df) == 100, len(df)
    out = {
        "generator": "docs/validation/phantom_database_anova_statsmodels.py",
        "versions": {"statsmodels": statsmodels.__version__, "scipy": scipy.__version__,
                     "pandas": pd.__version__, "numpy": np.__version__},
        "data": {"family": df["family"].tolist(), "thinner": df["thinner"].tolist(),
                 "batch": df["batch"].tolist(), "record": df["record"].tolist(),
                 "mu0_kPa": df["mu0_kPa"].tolist()},
        "mu0": scale(df, df["mu0_kPa"].to_numpy()),
        "ln_mu0": scale(df, np.log(df["mu0_kPa"].to_numpy())),
    }
    path = os.path.join(HERE, "phantom_database_anova_reference.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    for s in ["mu0", "ln_mu0"]:
        r = out[s]
        print(s, [(t["name"], round(t["f"], 3), t["p"]) for t in r["terms"]],
              "bartlett", r["bartlett_p"], "levene", r["levene_median_p"],
              "AD", r["anderson_darling_p"], "RJ", r["ryan_joiner_r"], "batch p", r["batch"]["p"])


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
