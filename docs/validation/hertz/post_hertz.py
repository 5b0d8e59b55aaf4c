#!/usr/bin/env python3
"""Read the sphere reaction force from a gen_hertz.py deck's .dat file and
write depth_mm, force_N, hertz_N, sneddon_N as CSV (stdout or --out), with
FE/Hertz - 1 and FE/Sneddon - 1 printed as a table on stderr.

Hertz (paraboloid, half-space): F = (4/3) E* sqrt(R) d^1.5.
Sneddon (1965, exact sphere, half-space): d = (a/2) ln((R+a)/(R-a)),
F = (E*/2) [(a^2 + R^2) ln((R+a)/(R-a)) - 2 a R].
E* = 2 mu / (1 - nu): nu = 1/2 -> 4 mu; the deck's K = kfac mu gives
nu = (3 kfac - 2) / (2 (3 kfac + 1)); the linear deck states nu.
"""
import argparse
import math
import re
import sys

C10 = 1101.295e-6
MU = 2 * C10
R = 2.5


def hertz(d, estar):
    return 4.0 / 3.0 * estar * math.sqrt(R) * d ** 1.5


def sneddon(d, estar):
    lo, hi = 0.0, R * (1 - 1e-12)
    for _ in range(200):
        a = 0.5 * (lo + hi)
        if 0.5 * a * math.log((R + a) / (R - a)) > d:
            hi = a
        else:
            lo = a
    lg = math.log((R + a) / (R - a))
    return 0.5 * estar * ((a * a + R * R) * lg - 2 * a * R)


def dat_totals(path, setname="NSPHERE"):
    out = []
    pat = re.compile(r"total force \(fx,fy,fz\) for set (\S+) and time\s+(\S+)")
    lines = open(path).read().splitlines()
    for i, ln in enumerate(lines):
        m = pat.search(ln)
        if m and m.group(1).upper() == setname:
            j = i + 1
            while not lines[j].strip():
                j += 1
            out.append((float(m.group(2)), *[float(x) for x in lines[j].split()[:3]]))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dat")
    ap.add_argument("--nu", type=float, help="Poisson ratio for E* (default: from --kfac)")
    ap.add_argument("--kfac", type=float, default=1000.0)
    ap.add_argument("--out")
    ap.add_argument("--header", default="")
    a = ap.parse_args()
    nu = a.nu if a.nu is not None else (3 * a.kfac - 2) / (2 * (3 * a.kfac + 1))
    estar = 2 * MU / (1 - nu)
    # the dummy first step takes total time 1; in the indentation step the
    # step time is the depth (mm)
    rows = [(t - 1.0, -fy * 180.0 / 1000.0) for t, fx, fy, fz in dat_totals(a.dat)]
    lines = []
    if a.header:
        lines.append("# " + a.header)
    lines.append(f"# E* = 2 mu / (1 - nu), nu = {nu:.6f}, mu = {MU:.9e} MPa, R = {R} mm")
    lines.append("depth_mm,force_N,hertz_N,sneddon_N")
    print(f"{'d':>8} {'F (N)':>12} {'F/Hertz-1':>10} {'F/Sneddon-1':>12}", file=sys.stderr)
    last = None
    for d, f in rows:
        # CalculiX prints the last time point twice when it ends the step
        if d <= 0 or (last is not None and abs(d - last) < 1e-9):
            continue
        last = d
        h, s = hertz(d, estar), sneddon(d, estar)
        lines.append(f"{d:.6f},{f:.9e},{h:.9e},{s:.9e}")
        print(f"{d:8.4f} {f:12.6e} {100 * (f / h - 1):9.3f}% {100 * (f / s - 1):11.3f}%",
              file=sys.stderr)
    text = "\n".join(lines) + "\n"
    if a.out:
        open(a.out, "w").write(text)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
