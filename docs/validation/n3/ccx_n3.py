#!/usr/bin/env python3
"""CalculiX run of N3 (BENCHMARKS.md) at small depth, the independent 3D
solver of docs/validation/fe.md "N3".

The quarter block 35 x 40 x 80 mm (x, y, z up), u_x = 0 on x = 0, u_y = 0 on
y = 0, bottom fixed, meshed as palpate's quarter O-grid
(forward/fe/src/mesh/ogrid.rs, ported below: square core around the axis,
rings blending to circles, then to the rectangle; z graded from the top)
with 20-node reduced-integration hexahedra C3D20R (straight edges; `--etype
C3D8I` for the incompatible-mode hexahedra of BENCHMARKS.md's attempt), neo-Hookean C10 =
1101.295 Pa (ecoflex-nh) with K = 1000 mu (CalculiX has no exactly
incompressible solid; tests/data/calculix/README.md).

The needle (hemispherical tip R = 2.5 mm tangent to a 15 degree cone) is a
graph z = f(r) over the plane, so its quarter surface is the same kind of
O-grid (no degenerate pole, which CalculiX cannot use as a master face),
0.1 mm cells, lifted to the profile: one layer of C3D8 whose nodes are all
prescribed (u_x = u_y = 0, u_z = -d), an exactly rigid translating body;
its lower faces are the master surface of a SURFACE TO SURFACE penalty
contact pair with the tissue's top faces within 4 mm of the axis
(frictionless, or Coulomb with --friction). Units mm, kPa, mN (as gen_n1.py:
su = 1000). A first dummy step at rest works around CalculiX 2.20 treating
penetrations in step 1 as initial overclosures (gen_n1.py).

Penalty contact makes the force low by about c / k: the script runs two
penalties and extrapolates F_inf = (k2 F2 - k1 F1) / (k2 - k1), as
docs/validation/r2/ccx_presses.py does.

Usage (needs ccx 2.20 from Debian's calculix-ccx, python3 with numpy):
    python3 docs/validation/n3/ccx_n3.py [--depth 0.5] [--friction 0]
        [--h 0.5] [--etype C3D20R] [--penalties 1,10] [--scratch /tmp/n3_ccx]
Writes docs/validation/n3/ccx_n3_<friction>.csv (depth, force per penalty,
extrapolated force; whole block, N) and prints the run statistics.
"""
import argparse
import math
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REF = os.path.normpath(os.path.join(HERE, "../../../tests/data/calculix"))
sys.path.insert(0, REF)
from ccxgen import material_card  # noqa: E402

LX, LY, LZ = 35.0, 40.0, 80.0
RTIP, HALF = 2.5, math.radians(15.0)


def grading_positions(h, zone, growth, length):
    """palpate_fe::mesh::Grading::positions (forward/fe/src/mesh/grading.rs)."""
    fine = min(zone, length)
    n_fine = max(1 if fine > 0 else 0, math.ceil(fine / h - 1e-9))
    pos = [fine * i / max(n_fine, 1) for i in range(n_fine + 1)] if n_fine else [0.0]
    rest = length - fine
    if rest > 1e-12 * length:
        h0 = fine / n_fine if n_fine else h
        sizes, hh, s = [], h0 * growth, 0.0
        while s < rest * (1 - 1e-9):
            sizes.append(hh)
            s += hh
            hh *= growth
        if len(sizes) > 1 and s - rest > 0.5 * sizes[-1]:
            s -= sizes.pop()
        x = fine
        for sz in sizes:
            x += sz * rest / s
            pos.append(x)
        pos[-1] = length
    return pos


def ogrid_plane(lx, ly, rho, n, circle_radius):
    """The plane quarter O-grid of forward/fe/src/mesh/ogrid.rs: nodes and
    counter-clockwise quads."""
    last = len(rho) - 1
    s = rho[n]
    blend = 3.0 * s
    kc = max(k for k in range(last + 1) if rho[k] <= circle_radius + 1e-9)
    assert rho[kc] >= blend - 1e-9 and kc < last, "circle radius"
    nodes, quads = [], []
    for j in range(n + 1):
        for i in range(n + 1):
            nodes.append((rho[i], rho[j]))
    core = lambda i, j: j * (n + 1) + i
    for j in range(n):
        for i in range(n):
            quads.append((core(i, j), core(i + 1, j), core(i + 1, j + 1), core(i, j + 1)))
    ring = [core(n, a) if a <= n else core(2 * n - a, n) for a in range(2 * n + 1)]
    c = (blend - math.sqrt(2) * s) / (blend - s)

    def square_point(a):
        return (1.0, rho[a] / rho[n]) if a <= n else (rho[2 * n - a] / rho[n], 1.0)

    def boundary_point(a):
        th = math.pi / 2 * a / (2 * n)
        if a == n:
            return (lx, ly)
        if a < n:
            return (lx, ly * math.tan(th))
        if a == 2 * n:
            return (0.0, ly)
        return (lx * math.tan(math.pi / 2 - th), ly)

    for k in range(n + 1, last + 1):
        r = rho[k]
        new = []
        for a in range(2 * n + 1):
            th = math.pi / 2 * a / (2 * n)
            if k <= kc:
                if r >= blend:
                    beta = 1.0
                else:
                    diag = math.sqrt(2) * s + c * (r - s)
                    beta = min(1.0, max(0.0, (math.sqrt(2) - diag / r) / (math.sqrt(2) - 1)))
                q = square_point(a)
                p = (r * ((1 - beta) * q[0] + beta * math.cos(th)),
                     r * ((1 - beta) * q[1] + beta * math.sin(th)))
            else:
                g = (r - rho[kc]) / (rho[last] - rho[kc])
                b = boundary_point(a)
                rc = rho[kc]
                p = ((1 - g) * rc * math.cos(th) + g * b[0],
                     (1 - g) * rc * math.sin(th) + g * b[1])
            if a == 0:
                p = (p[0], 0.0)
            if a == 2 * n:
                p = (0.0, p[1])
            nodes.append(p)
            new.append(len(nodes) - 1)
        for a in range(2 * n):
            quads.append((ring[a], new[a], new[a + 1], ring[a + 1]))
        ring = new
    return nodes, quads


def needle_height(r):
    """Height of the needle surface above its tip at radius r (mm)."""
    rt = RTIP * math.cos(HALF)
    if r <= rt:
        return RTIP - math.sqrt(RTIP * RTIP - r * r)
    zt = RTIP - math.sqrt(RTIP * RTIP - rt * rt)
    return zt + (r - rt) / math.tan(HALF)


def write_deck(path, depth, friction, h, penalty, etype="C3D20R", su=1000.0, dmax=0.05,
               dt_out=0.125):
    """The deck; returns its sizes. etype C3D20R (default: 20-node
    reduced-integration hexahedra, straight edges, mid-edge nodes at the
    middle) or C3D8I."""
    rho = grading_positions(h, 2.5, 1.3, min(LX, LY))
    zs = [LZ - t for t in reversed(grading_positions(h, 2.5, 1.3, LZ))]
    n = max(3, round(1.5 / h))
    pn, pq = ogrid_plane(LX, LY, rho, n, 0.5 * min(LX, LY))
    npl = len(pn)
    nid = lambda q, k: k * npl + q + 1
    coords = {}
    for k, z in enumerate(zs):
        for q, (x, y) in enumerate(pn):
            coords[nid(q, k)] = (x, y, z)
    nt = len(coords)
    # needle: O-grid over r <= 3 mm, 0.1 mm cells, lifted to the profile
    rho_n = grading_positions(0.1, 3.0, 1.0, 3.0)
    qn, qq = ogrid_plane(3.0, 3.0, rho_n + [3.0 + 0.1 * i for i in range(1, 4)], 8, 3.0)
    # (the extra rings only complete the plane routine's outer blend; the
    # needle keeps the nodes and cells inside r <= 3)
    keep = [i for i, p in enumerate(qn) if math.hypot(*p) <= 3.0 + 1e-9]
    index = {i: j for j, i in enumerate(keep)}
    qq = [q for q in qq if all(a in index for a in q)]
    needle_id = lambda i, layer: nt + layer * len(keep) + index[i] + 1
    for layer, dz in enumerate((0.0, 0.3)):
        for i in keep:
            x, y = qn[i]
            coords[needle_id(i, layer)] = (x, y, LZ + needle_height(math.hypot(x, y)) + dz)
    needle_nodes = [needle_id(i, layer) for layer in (0, 1) for i in keep]
    # tissue cells
    cells, top_faces = [], []
    for k in range(len(zs) - 1):
        for q in pq:
            c = [nid(a, k) for a in q] + [nid(a, k + 1) for a in q]
            cells.append(c)
            if k == len(zs) - 2 and max(math.hypot(*pn[a]) for a in q) <= 4.0 + 1e-9:
                top_faces.append(len(cells))
    if etype == "C3D20R":
        mids = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in mids:
                i = len(coords) + 1
                coords[i] = tuple(0.5 * (u + v) for u, v in zip(coords[a], coords[b]))
                mids[key] = i
            return mids[key]

        edges = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4),
                 (0, 4), (1, 5), (2, 6), (3, 7)]
        cells = [c + [mid(c[a], c[b]) for a, b in edges] for c in cells]
    lines = [f"** N3 quarter block, {etype}, NH C10 = 1101.295 Pa, K = 1000 mu, friction {friction},"
             f" penalty {penalty} MPa/mm; h = {h} mm, core {n}; generated by ccx_n3.py",
             "*NODE, NSET=NALL"]
    lines += [f"{i}, {x:.12g}, {y:.12g}, {z:.12g}" for i, (x, y, z) in sorted(coords.items())]
    lines.append(f"*ELEMENT, TYPE={etype}, ELSET=TISSUE")
    for e, c in enumerate(cells):
        lines.append(f"{e + 1}, " + ", ".join(map(str, c[:15])))
        if len(c) > 15:
            lines.append(", ".join(map(str, c[15:])))
    eid = len(cells)
    lines.append("*ELEMENT, TYPE=C3D8, ELSET=NEEDLE")
    master = []
    for q in qq:
        eid += 1
        c = [needle_id(a, 0) for a in q] + [needle_id(a, 1) for a in q]
        lines.append(f"{eid}, " + ", ".join(map(str, c)))
        master.append(eid)

    def nset(name, ids):
        ids = sorted(set(ids))
        out = [f"*NSET, NSET={name}"]
        for i in range(0, len(ids), 12):
            out.append(", ".join(map(str, ids[i:i + 12])) + ",")
        return out

    tol = 1e-9
    tissue = [i for i in coords if i <= nt or i > nt + len(needle_nodes)]
    x0 = [i for i in tissue if abs(coords[i][0]) < tol]
    y0 = [i for i in tissue if abs(coords[i][1]) < tol]
    bottom = [i for i in tissue if abs(coords[i][2]) < tol]
    lines += nset("X0", x0) + nset("Y0", y0) + nset("BOTTOM", bottom) + nset("NNEEDLE", needle_nodes)
    lines.append("*SURFACE, NAME=SLAVE, TYPE=ELEMENT")
    lines += [f"{e}, S2" for e in top_faces]
    lines.append("*SURFACE, NAME=MASTER, TYPE=ELEMENT")
    lines += [f"{e}, S1" for e in master]
    lines.append(material_card("TISSUEMAT", "nh", 1000.0, su).strip())
    lines.append(f"*MATERIAL, NAME=STEEL\n*ELASTIC\n{1000.0 * su:g}, 0.3")
    lines.append("*SOLID SECTION, ELSET=TISSUE, MATERIAL=TISSUEMAT")
    lines.append("*SOLID SECTION, ELSET=NEEDLE, MATERIAL=STEEL")
    lines.append("*CONTACT PAIR, INTERACTION=INT1, TYPE=SURFACE TO SURFACE\nSLAVE, MASTER")
    lines.append("*SURFACE INTERACTION, NAME=INT1")
    lines.append(f"*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{penalty * su:g}")
    if friction > 0:
        lines.append(f"*FRICTION\n{friction:g}, {penalty * su / 10:g}")
    npts = int(round(depth / dt_out))
    lines.append(f"*TIME POINTS, NAME=TP, GENERATE\n0., {depth:.6f}, {depth / npts:.8f}")
    bc = "*BOUNDARY\nX0, 1, 1, 0.\nY0, 2, 2, 0.\nBOTTOM, 1, 3, 0.\nNNEEDLE, 1, 2, 0.\n"
    lines.append("*STEP, NLGEOM\n*STATIC\n1., 1.\n" + bc + "NNEEDLE, 3, 3, 0.\n*END STEP")
    lines.append(f"*STEP, NLGEOM, INC=100000\n*STATIC\n{min(dmax, 0.01):.8f}, {depth:.6f}, 1e-9, {dmax:.8f}")
    lines.append(bc + f"NNEEDLE, 3, 3, {-depth}")
    lines.append("*NODE PRINT, NSET=NNEEDLE, TOTALS=ONLY, TIME POINTS=TP\nRF")
    lines.append("*END STEP")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return dict(etype=etype, tissue_elements=len(cells), nodes=len(coords),
                needle_elements=len(master), slave_faces=len(top_faces))


def forces(dat):
    """(depth, whole-block force in N) from the needle's reaction totals
    (mN for the quarter, step 2's time = depth)."""
    txt = open(dat).read()
    pat = re.compile(r"total force \(fx,fy,fz\) for set NNEEDLE and time\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)")
    rows = [(float(m.group(1)), float(m.group(4))) for m in pat.finditer(txt)]
    # total time = 1 (the dummy step at rest) + depth; the needle's
    # reaction is along -z, the force positive in compression
    return [(round(t - 1.0, 9), -4.0 * fz / 1000.0) for t, fz in rows if t > 1.0 + 1e-9]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--depth", type=float, default=0.5)
    ap.add_argument("--friction", type=float, default=0.0)
    ap.add_argument("--h", type=float, default=0.5)
    ap.add_argument("--etype", default="C3D20R")
    ap.add_argument("--penalties", default="1,10")
    ap.add_argument("--scratch", default="/tmp/n3_ccx")
    a = ap.parse_args()
    os.makedirs(a.scratch, exist_ok=True)
    results = {}
    for kp in [float(v) for v in a.penalties.split(",")]:
        name = f"n3_{a.etype}_f{a.friction:g}_h{a.h:g}_kp{kp:g}".replace(".", "p").lower()
        info = write_deck(os.path.join(a.scratch, name + ".inp"), a.depth, a.friction, a.h, kp,
                          a.etype)
        t0 = time.time()
        c0 = os.times()
        env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
        subprocess.run(["ccx", "-i", name], cwd=a.scratch, env=env,
                       stdout=open(os.path.join(a.scratch, name + ".log"), "w"),
                       stderr=subprocess.STDOUT, check=False)
        c1 = os.times()
        cpu = (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system)
        f = forces(os.path.join(a.scratch, name + ".dat"))
        results[kp] = f
        print(f"penalty {kp:g} MPa/mm: {info}, wall {time.time() - t0:.0f} s, CPU {cpu:.0f} s,"
              f" reached {f[-1][0] if f else 0:g} mm: " + ", ".join(f"{d:g}: {v:.6f}" for d, v in f))
    ks = sorted(results)
    out = os.path.join(HERE, f"ccx_n3_f{a.friction:g}.csv".replace("0.8", "0p8"))
    with open(out, "w") as fh:
        fh.write("depth_mm," + ",".join(f"F_kp{k:g}_N" for k in ks) + ",F_inf_N\n")
        depths = sorted({d for k in ks for d, _ in results[k] if d > 1e-9})
        for d in depths:
            vals = [dict(results[k]).get(d) for k in ks]
            finf = ""
            if len(ks) >= 2 and all(v is not None for v in vals[-2:]):
                k1, k2 = ks[-2], ks[-1]
                finf = f"{(k2 * vals[-1] - k1 * vals[-2]) / (k2 - k1):.6f}"
            fh.write(f"{d:g}," + ",".join("" if v is None else f"{v:.6f}" for v in vals) + f",{finf}\n")
    print("wrote", out)


if __name__ == "__main__":
    main()
