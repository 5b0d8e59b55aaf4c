#!/usr/bin/env python3
"""Sneddon's force for a flat punch with a rounded edge on an incompressible
half-space, the closed form forward/fe/tests/integration/closed_form_experiments.rs
compares palpate's punch with (the factors there are this script's output).

Sneddon (1965), Int. J. Eng. Sci. 3, 47, for an axisymmetric punch of profile
z = f(r) (f(0) = 0) whose contact ends at radius c with a bounded pressure:

    d = int_0^c f'(r) / sqrt(1 - r^2 / c^2) dr
    F = 2 E* (c d - int_0^c r f(r) / sqrt(c^2 - r^2) dr)

The punch of radius a with an edge radius rho: flat to b = a - rho, then a
quarter circle of radius rho, vertical at r = a. Its f' grows like
1 / sqrt(a - r), so d -> infinity as c -> a: at any depth the contact ends
on the rounding (c < a) and the force is below the sharp punch's 2 E* a d.
The ratio F / (2 E* a d) depends on rho / a and d / a only.

    pip install scipy
    python3 docs/validation/sneddon_rounded_punch.py
"""
import warnings

import numpy as np
from scipy.integrate import IntegrationWarning, quad
from scipy.optimize import brentq

warnings.simplefilter("ignore", IntegrationWarning)


def profile(rho, a=1.0):
    b = a - rho

    def f(r):
        s = r - b
        return 0.0 if s <= 0 else rho - np.sqrt(max(rho * rho - s * s, 0.0))

    def fp(r):
        s = r - b
        return 0.0 if s <= 0 else s / np.sqrt(max(rho * rho - s * s, 1e-300))

    return b, f, fp


def force_ratio(rho, d, a=1.0):
    """(contact radius c, F / (2 E* a d)) for the rounded punch at depth d."""
    b, f, fp = profile(rho, a)
    opts = dict(limit=2000, epsabs=1e-14, epsrel=1e-12)

    # r = c sin(t) removes the inverse square roots at r = c
    def depth(c):
        t0 = np.arcsin(min(b / c, 1.0))
        return quad(lambda t: fp(c * np.sin(t)) * c, t0, np.pi / 2, **opts)[0]

    c = brentq(lambda c: depth(c) - d, b + 1e-12 * a, a * (1 - 1e-15), xtol=1e-15)
    t0 = np.arcsin(min(b / c, 1.0))
    i = quad(lambda t: c * np.sin(t) * f(c * np.sin(t)), t0, np.pi / 2, **opts)[0]
    return c, (c * d - i) / (a * d)


if __name__ == "__main__":
    print("| edge radius / a | depth / a | contact radius / a | F / (2 E* a d) |")
    print("|---|---|---|---|")
    for rho in [0.005, 0.01, 0.02, 0.05, 0.1]:
        for d in [0.005, 0.01, 0.02, 0.04, 0.05]:
            c, ratio = force_ratio(rho, d)
            print(f"| {rho} | {d} | {c:.6f} | {ratio:.6f} |")
