#!/usr/bin/env python3
"""Discretisation error of a CalculiX reference from its mesh levels.

usage: levels.py CURVE_L1.csv:H1 CURVE_L2.csv:H2 [CURVE_L3.csv:H3] [--at D ...]

Each curve is given with its characteristic element size H (mm). At each
displacement D (default: every sample of the finest curve) it prints the
forces, the relative change between successive levels and, with three
levels, Richardson's extrapolation with the observed order p (from the
three forces and the size ratios; with two levels p = 2 is assumed, the
order of 8-node elements on a smooth solution, which contact edges and
re-entrant corners lower: the observed p is the one to trust). The stated
error of the finest level is |F_finest - F_extrapolated| / F_extrapolated.
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare import interpolate, read_curve  # noqa: E402


def richardson(f, h):
    """(extrapolated force, order) from forces f on sizes h (coarse first)."""
    if len(f) == 2:
        p = 2.0
        r = h[0] / h[1]
        return f[1] + (f[1] - f[0]) / (r ** p - 1), p
    (f1, f2, f3), (h1, h2, h3) = f, h
    d1, d2 = f2 - f1, f3 - f2
    if d1 == 0 or d2 == 0 or d1 * d2 < 0:
        return None, None            # not monotone: no asymptotic range
    r1, r2 = h1 / h2, h2 / h3
    # solve d1 / d2 = (r1^p - 1) r2^p / (r2^p - 1) for p (bisection)
    target = d1 / d2

    def g(p):
        return (r1 ** p - 1) * r2 ** p / (r2 ** p - 1) - target

    lo, hi = 0.05, 8.0
    if g(lo) * g(hi) > 0:
        return None, None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0:
            hi = mid
        else:
            lo = mid
    p = 0.5 * (lo + hi)
    return f3 + d2 / (r2 ** p - 1), p


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("curves", nargs="+")
    ap.add_argument("--at", type=float, nargs="*")
    a = ap.parse_args()
    curves, sizes = [], []
    for c in a.curves:
        path, h = c.rsplit(":", 1)
        curves.append(read_curve(path))
        sizes.append(float(h))
    at = a.at or [d for d, _ in curves[-1]]
    print("displacement_mm," + ",".join(f"F_h{h:g}" for h in sizes)
          + ",change_last,F_extrapolated,order,error_finest")
    for d in at:
        f = [interpolate(c, d) for c in curves]
        if d <= 0 or any(x is None for x in f):
            continue
        fx, p = richardson(f, sizes)
        change = (f[-1] - f[-2]) / f[-1]
        err = abs(f[-1] - fx) / abs(fx) if fx else float("nan")
        print(f"{d:g}," + ",".join(f"{x:.6g}" for x in f) + f",{100 * change:+.3f}%,"
              + (f"{fx:.6g},{p:.2f},{100 * err:.3f}%" if fx is not None else "-,-,-"))


if __name__ == "__main__":
    main()
