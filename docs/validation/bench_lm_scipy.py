#!/usr/bin/env python3
"""scipy counterpart of `cargo run --release -p palpate-inverse --example bench_lm`.

C1 compression (cylinder D = 38 mm, H = 9 mm, frictionless, incompressible)
with the reduced polynomial N = 2 law, written independently in numpy:
  stretch l = 1 - d / H, I1 = l^2 + 2 / l,
  P = 2 (l - l^-2) (C10 + 2 C20 (I1 - 3)),  F = -P * pi D^2 / 4.
Data: F(C10 = 686.428 Pa, C20 = 1929.606 Pa) at d = 0..2 mm (200 samples),
times 1 + 0.02 sin(1.7 i). Start C10 = 1e-3 MPa, C20 = 0.
Solvers: least_squares 'lm' (MINPACK lmdif, forward differences) and 'trf'
with tolerances ftol = 1e-12, xtol = gtol = 1e-10 (as the Rust defaults).
Prints the median and minimum wall time of repeated complete fits.
"""
import time
import numpy as np
from scipy.optimize import least_squares

H, D = 9.0, 38.0
AREA = np.pi * D * D / 4
d = 2.0 * np.arange(200) / 199.0


def force(p):
    c10, c20 = p
    l = 1 - d / H
    i1 = l**2 + 2 / l
    return -2 * (l - l**-2) * (c10 + 2 * c20 * (i1 - 3)) * AREA


y = force([686.428e-6, 1929.606e-6]) * (1 + 0.02 * np.sin(1.7 * np.arange(200)))


def res(p):
    return force(p) - y


def main():
    repeats = 101
    print(f"scipy C1 reduced-polynomial N=2, 200 samples, {repeats} repeats")
    print("| method | median ms | min ms | nfev | SSE (N^2) | C10 (Pa) | C20 (Pa) |")
    print("|---|---|---|---|---|---|---|")
    for method in ["lm", "trf"]:
        times = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            sol = least_squares(res, [1e-3, 0.0], method=method, ftol=1e-12, xtol=1e-10, gtol=1e-10)
            times.append((time.perf_counter() - t0) * 1e3)
        times.sort()
        print(f"| scipy {method} | {times[repeats // 2]:.3f} | {times[0]:.3f} | {sol.nfev} | "
              f"{np.sum(sol.fun**2):.6e} | {sol.x[0] * 1e6:.4f} | {sol.x[1] * 1e6:.4f} |")


if __name__ == "__main__":
    main()
