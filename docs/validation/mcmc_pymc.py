"""PyMC (NUTS) on the C1 reduced-polynomial (N=2) problem, for the sampler benchmark.

Same data, model (numpy/pytensor), known sigma and flat priors as
mcmc_emcee.py and uq/examples/bench_samplers.rs. Four chains of 1000 draws
after 1000 tuning steps on 2 cores. Writes mcmc_pymc.json with the
posterior summary, the sampling wall time (PyMC's own `sampling_time`,
compilation excluded, and the whole call) and the number of gradient
evaluations (leapfrog steps, tuning included).

    pip install pymc arviz numpy
    python docs/validation/mcmc_pymc.py
"""
import json
import pathlib
import time

import arviz as az
import numpy as np
import pymc as pm

here = pathlib.Path(__file__).parent
path = here / "mcmc_c1_rp2_data.csv"
sigma = None
for line in path.read_text().splitlines():
    if line.startswith("#") and "sigma_N = " in line:
        sigma = float(line.split("sigma_N = ")[1])
data = np.loadtxt(path, delimiter=",", comments="#", skiprows=4)
d, f_obs = data[:, 0], data[:, 1]
H, AREA = 9.0, np.pi * 19.0**2
lam = 1.0 - d / H
i1m3 = lam**2 + 2.0 / lam - 3.0
dlam = lam - lam**-2

with pm.Model():
    c10 = pm.HalfFlat("C10", initval=6.8e-4)
    c20 = pm.Flat("C20", initval=1.9e-3)
    force = -2.0 * dlam * (c10 + 2.0 * c20 * i1m3) * AREA
    pm.Normal("F", mu=force, sigma=sigma, observed=f_obs)
    t0 = time.perf_counter()
    idata = pm.sample(
        draws=1000, tune=1000, chains=4, cores=2, random_seed=1,
        progressbar=False, discard_tuned_samples=False, compute_convergence_checks=False,
    )
    total = time.perf_counter() - t0

post = idata.posterior
s = az.summary(post, var_names=["C10", "C20"], round_to="none")
sampling = float(post.attrs.get("sampling_time", total))
steps = int(idata.sample_stats["n_steps"].sum()) + int(idata.warmup_sample_stats["n_steps"].sum())
out = {
    "pymc_version": pm.__version__,
    "chains": 4, "draws": 1000, "tune": 1000,
    "sampling_time_s": sampling,
    "total_time_s": total,
    "gradient_evaluations": steps,
    "correlation": float(np.corrcoef(post["C10"].values.ravel(), post["C20"].values.ravel())[0, 1]),
    "params": {},
}
for n in ["C10", "C20"]:
    row = s.loc[n]
    ess = float(row["ess_bulk"])
    out["params"][n] = {
        "mean": float(row["mean"]), "sd": float(row["sd"]), "mcse_mean": float(row["mcse_mean"]),
        "ess_bulk": ess, "ess_tail": float(row["ess_tail"]), "rhat": float(row["r_hat"]),
        "ess_per_s": ess / sampling, "ess_per_1000_evals": 1000.0 * ess / steps,
    }
(here / "mcmc_pymc.json").write_text(json.dumps(out, indent=1) + "\n")
print(json.dumps(out, indent=1))
