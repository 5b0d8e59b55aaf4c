"""Reference values for palpate's MCMC diagnostics, computed by ArviZ.

Generates a deterministic set of chains (numpy seed 20240611), runs
arviz.summary / arviz.rhat / arviz.ess / arviz.mcse on them and writes
chains and results to mcmc_arviz.json beside this script. The Rust test
uq/tests/integration/mcmc_arviz.rs recomputes every number from the same chains and
requires agreement to 1e-6 relative.

    pip install arviz numpy
    python docs/validation/mcmc_arviz.py
"""
import json
import pathlib

import arviz as az
import numpy as np

rng = np.random.default_rng(20240611)
n_chain, n_draw = 4, 301  # odd length exercises the split-chain rule


def ar1(phi, shift=0.0):
    x = np.empty((n_chain, n_draw))
    for c in range(n_chain):
        v = rng.normal() / np.sqrt(1 - phi * phi)
        for t in range(n_draw):
            v = phi * v + rng.normal()
            x[c, t] = v
    return x + shift


variables = {
    "iid": ar1(0.0),
    "ar1_0.9": ar1(0.9),
    "shifted": ar1(0.5) + np.array([0.0, 0.0, 0.0, 0.8])[:, None],
    "heavy_tailed": rng.standard_t(3, size=(n_chain, n_draw)),
    "ties": np.round(ar1(0.3), 1),
}

out = {"arviz_version": az.__version__, "n_chain": n_chain, "n_draw": n_draw, "variables": {}}
# Rounded so the JSON stays small; ArviZ and the Rust test see the same numbers.
variables = {k: np.round(v, 6) for k, v in variables.items()}
for name, x in variables.items():
    idata = az.convert_to_dataset({name: x})
    s = az.summary(idata, hdi_prob=0.94, round_to="none")
    out["variables"][name] = {
        "chains": x.tolist(),
        "mean": float(s["mean"].iloc[0]),
        "sd": float(s["sd"].iloc[0]),
        "hdi_3": float(s["hdi_3%"].iloc[0]),
        "hdi_97": float(s["hdi_97%"].iloc[0]),
        "mcse_mean": float(s["mcse_mean"].iloc[0]),
        "ess_bulk": float(s["ess_bulk"].iloc[0]),
        "ess_tail": float(s["ess_tail"].iloc[0]),
        "rhat": float(s["r_hat"].iloc[0]),
        "ess_mean": float(az.ess(idata, method="mean")[name]),
    }
path = pathlib.Path(__file__).with_name("mcmc_arviz.json")
path.write_text(json.dumps(out, indent=1) + "\n")
print(f"wrote {path} (arviz {az.__version__})")
