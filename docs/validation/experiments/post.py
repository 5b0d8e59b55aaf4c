#!/usr/bin/env python3
"""Write the force-displacement curve of a finished deck as CSV
(displacement_mm,force_N; whole body, compression positive) and print its
run statistics.

usage: post.py DECK.dat --out CURVE.csv [--note TEXT]

Indentation decks (a tool node set NTOOL only): displacement = the second
step's time (mm) less the tool's initial gap (`** GAP g` in NAME.inp).
Cylinder decks (`** TRAVEL t` in NAME.inp, else sets TOP and NTOOL with
t = 12 mm): the force is TOP's reaction (bonded or frictionless platens)
plus the platen strip's; displacement = t x step time (the platens'
travel). NAME.sta and NAME.time (from run.sh) beside the .dat give
increments, iterations and CPU seconds.
"""
import argparse
import os

from ccxexp import cpu_seconds, curve, sta_summary, write_curve


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dat")
    ap.add_argument("--out", required=True)
    ap.add_argument("--note", action="append", default=[])
    a = ap.parse_args()
    text = open(a.dat).read()
    inp = a.dat[:-4] + ".inp"
    travel, gap = None, 0.0
    if os.path.exists(inp):
        for ln in open(inp):
            if ln.startswith("** TRAVEL"):
                travel = float(ln.split()[2])
            elif ln.startswith("** GAP"):
                gap = float(ln.split()[2])
    if "for set TOP and time" in text:
        travel = travel or 12.0
        top = curve(a.dat, "TOP", t0=1.0, scale=travel)
        fold = dict(curve(a.dat, "NTOOL", t0=1.0, scale=travel))
        rows = [(d, f + fold.get(d, 0.0)) for d, f in top]
        extra = [f"of which the fold on the platen beyond r = 25 mm: {fold.get(rows[-1][0], 0):.6g} N "
                 f"at {rows[-1][0]:g} mm"]
    elif travel is not None:            # the platen in contact over the top face
        # the half model's platen moves travel / 2 + gap: whole-body travel
        # (travel + 2 gap) (t - 1) - 2 gap
        rows = curve(a.dat, "NTOOL", t0=1.0 + 2 * gap / (travel + 2 * gap),
                     scale=travel + 2 * gap)
        extra = [f"platen gap {gap:g} mm (half model) subtracted"] if gap else []
    else:
        rows = curve(a.dat, "NTOOL", t0=1.0 + gap)
        extra = [f"tool gap {gap:g} mm subtracted"] if gap else []
    rows = [(round(d, 4), f) for d, f in rows]
    base = a.dat[:-4]
    stats = []
    if os.path.exists(base + ".sta"):
        inc, it, fails = sta_summary(base + ".sta")
        stats.append(f"{inc} increments, {it} Newton iterations, {fails} cut-backs")
    if os.path.exists(base + ".time"):
        stats.append(f"{cpu_seconds(base + '.time'):.0f} s CPU (ccx 2.20, one thread)")
    write_curve(a.out, rows, a.note + stats)
    print(os.path.basename(a.dat), f"F({rows[-1][0]:g} mm) = {rows[-1][1]:.6g} N;",
          "; ".join(stats + extra))


if __name__ == "__main__":
    main()
