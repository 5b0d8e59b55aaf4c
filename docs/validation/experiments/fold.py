#!/usr/bin/env python3
"""When the free side of a cylinder deck folds onto the upper platen.

usage: fold.py DECK.dat [--tol 0.02]

Reads the side's nodal displacements (`*NODE PRINT, NSET=SIDE` U) of a
cylinder deck written by cylinder_bonded_platens/gen.py, the nodes' initial
coordinates from DECK.inp and the platen's travel (`** TRAVEL t`, `** GAP
g`): at each printed time the platen is at z = top + gap - (travel / 2 +
gap) (t - 1) in the half model. A side node below the top corner whose
deformed height comes within `tol` mm of the platen (penalty contact lets
it in a little) has folded over onto it. Prints, per printed time, the
whole-body travel, the strain and the number of folded side nodes, and the
first travel at which one folded.
"""
import argparse
import re


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dat")
    ap.add_argument("--tol", type=float, default=0.02)
    a = ap.parse_args()
    inp = a.dat[:-4] + ".inp"
    travel, gap, nodes, in_nodes = 12.0, 0.0, {}, False
    for ln in open(inp):
        if ln.startswith("** TRAVEL"):
            travel = float(ln.split()[2])
        elif ln.startswith("** GAP"):
            gap = float(ln.split()[2])
        elif ln.upper().startswith("*NODE") and "PRINT" not in ln.upper():
            in_nodes = True
            continue
        elif ln.startswith("*"):
            in_nodes = False
        if in_nodes and ln.strip():
            p = [x.strip() for x in ln.split(",")]
            nodes[int(p[0])] = (float(p[1]), float(p[2]))
    pat = re.compile(r"displacements \(vx,vy,vz\) for set SIDE and time\s+(\S+)")
    lines = open(a.dat).read().splitlines()
    first = None
    zt = None
    print("travel_mm,strain,folded_nodes")
    for i, ln in enumerate(lines):
        m = pat.search(ln)
        if not m:
            continue
        t = float(m.group(1))
        rows = []
        j = i + 1
        while j < len(lines) and not lines[j].strip():
            j += 1
        while j < len(lines) and lines[j].strip():
            p = lines[j].split()
            rows.append((int(p[0]), float(p[1]), float(p[2])))
            j += 1
        if zt is None:
            zt = max(nodes[n][1] for n, _, _ in rows)
        if t <= 1.0:
            continue
        platen = zt + gap - (travel / 2 + gap) * (t - 1.0)
        d = (travel + 2 * gap) * (t - 1.0) - 2 * gap
        folded = sum(1 for n, ux, uy in rows
                     if nodes[n][1] < zt - 1e-9 and nodes[n][1] + uy >= platen - a.tol)
        print(f"{d:.4f},{d / (2 * zt):.4f},{folded}")
        if folded and first is None:
            first = d
    if first is None:
        print("# no side node reached the platen")
    else:
        print(f"# the side folds onto the platen at {first:g} mm of travel "
              f"({100 * first / (2 * zt):.1f} % strain; the first printed time with a folded node)")


if __name__ == "__main__":
    main()
