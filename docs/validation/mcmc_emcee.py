"""Independent reference posterior for the C1 reduced-polynomial (N=2) problem.

Same data (mcmc_c1_rp2_data.csv, written by uq/tests/integration/mcmc_c1.rs), same model
written in numpy, same likelihood (Gaussian, known sigma from the file's
header comment) and flat priors (C10 > 0), sampled by emcee's stretch move.
Writes mcmc_emcee.json: mean, sd, mcse_mean, ess_bulk, ess_tail, rhat per
parameter (ArviZ, every walker a chain), the posterior correlation, the
number of log-density evaluations, the wall time, and ESS per second / per
1000 evaluations for the benchmark table in mcmc.md.

    pip install emcee arviz numpy
    python docs/validation/mcmc_emcee.py
"""
import json
import os
import pathlib
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import arviz as az
import emcee
import numpy as np

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


def force(c10, c20):
    """C1 force (N, positive in compression) of the reduced polynomial N=2:
    F = -2 (l - l^-2) (C10 + 2 C20 (I1 - 3)) A."""
    return -2.0 * dlam * (c10 + 2.0 * c20 * i1m3) * AREA


evaluations = 0


def log_prob(theta):
    global evaluations
    evaluations += 1
    c10, c20 = theta
    if c10 <= 0.0:
        return -np.inf
    r = f_obs - force(c10, c20)
    return -0.5 * np.dot(r, r) / sigma**2


ndim, nwalkers, burn, steps = 2, 32, 1000, 12000
rng = np.random.default_rng(1)
p0 = np.array([6.86428e-4, 1.929606e-3]) * (1.0 + 1e-3 * rng.standard_normal((nwalkers, ndim)))
sampler = emcee.EnsembleSampler(nwalkers, ndim, log_prob)
sampler.random_state = np.random.RandomState(42).get_state()  # reproducible moves
t0 = time.perf_counter()
sampler.run_mcmc(p0, burn + steps, progress=False)
wall = time.perf_counter() - t0
chain = sampler.get_chain(discard=burn)  # (steps, walkers, dim)
names = ["C10", "C20"]
posterior = {n: chain[:, :, k].T for k, n in enumerate(names)}  # (chain, draw)
s = az.summary(az.convert_to_dataset(posterior), round_to="none")
flat = chain.reshape(-1, ndim)
out = {
    "emcee_version": emcee.__version__,
    "walkers": nwalkers,
    "burn": burn,
    "steps": steps,
    "evaluations": evaluations,
    "wall_time_s": wall,
    "acceptance": float(np.mean(sampler.acceptance_fraction)),
    "correlation": float(np.corrcoef(flat.T)[0, 1]),
    "params": {},
}
for n in names:
    row = s.loc[n]
    ess = float(row["ess_bulk"])
    out["params"][n] = {
        "mean": float(row["mean"]),
        "sd": float(row["sd"]),
        "mcse_mean": float(row["mcse_mean"]),
        "ess_bulk": ess,
        "ess_tail": float(row["ess_tail"]),
        "rhat": float(row["r_hat"]),
        "ess_per_s": ess / wall,
        "ess_per_1000_evals": 1000.0 * ess / evaluations,
    }
(here / "mcmc_emcee.json").write_text(json.dumps(out, indent=1) + "\n")
print(json.dumps(out, indent=1))
