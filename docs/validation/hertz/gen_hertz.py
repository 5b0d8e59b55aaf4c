#!/usr/bin/env python3
"""Write CalculiX decks for the Hertz check (docs/validation/hertz): a rigid sphere of
radius R = 2.5 mm pressed frictionlessly on the axis of the N1 cylinder
(r in [0, 35], z in [0, 80], top z = 80, bottom fixed, axis u_r = 0),
neo-Hookean C10 = 1101.295 Pa with K = kfac * mu (or a linear-elastic
*ELASTIC law without NLGEOM, the small-strain check of the deck).

Adapted from ../shared/reference/calculix/gen_n1.py (same O-grid idea, same
rigid-strip indenter, same two-step face-to-face penalty contact), changed
for a contact radius of 0.1-0.8 mm instead of several mm:

* core square of side rho0 (default 1 mm: covers the whole contact zone,
  a <= 0.79 mm) with n x n CAX8R elements (h = rho0 / n);
* rings of 2n sectors whose aspect ratio grows from 1 (at the core) to
  A_MAX over K_RAMP rings (the far field needs no resolution), blended
  from the square to a quarter circle over rho0..3 rho0 and, beyond R_C =
  20 mm, to the rectangular outer boundary; the midside nodes of the rings
  are at the arithmetic mean radius;
* the indenter is a strip of CAX8R elements along a 50 degree sphere arc
  (no cone: the contact stays below 19 degrees), all nodes prescribed;
* the axis offset r_hole defaults to 1e-4 mm (gen_n1 used 0.01 mm, which
  is 1-10 % of the Hertz contact radius here).

Units in the deck: mm, kPa, mN (su = 1000); CalculiX prints axisymmetric
reaction forces for a 2 degree segment, so F [N] = 180 * RF [mN] / 1000.
"""
import argparse
import math
import os

import sys

# the deck generator shared with the N1 references
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../../../tests/data/calculix"))
from ccxgen import C10_NH, Mesh, geometric_sizes  # noqa: E402

RCYL, HCYL = 35.0, 80.0
CZ = HCYL
RSPH = 2.5
ARC = math.radians(50.0)       # indenter arc modelled (contact stays < 19 deg)
RHO0 = 1.0
R_C = 20.0


def ring_radii(n, a_max, k_ramp, rho0):
    """radii of the ring lines from RHO0 to R_C: aspect ratio (radial /
    angular size) ramps from 1 to a_max over k_ramp rings."""
    dq = math.pi / (4 * n)          # angular size / radius for 2n sectors
    rho = [rho0]
    k = 0
    while rho[-1] < R_C:
        a = min(a_max, 1.0 + (a_max - 1.0) * k / k_ramp)
        rho.append(rho[-1] * (1 + a * dq))
        k += 1
    # stretch the last ring lines so that the last one is exactly R_C
    f = math.log(R_C / rho0) / math.log(rho[-1] / rho0)
    return [rho0 * (r / rho0) ** f for r in rho]


def tissue_mesh(n, a_max, k_ramp, r_hole, rho0=RHO0):
    m = Mesh()
    fmap = lambda x: r_hole + x * (1.0 - r_hole / RCYL)
    h0 = rho0 / n
    m.add_block(lambda u, v: (fmap(u * h0), CZ - v * h0), n, n, "TISSUE")

    def square_pt(s):
        if s <= 0.5:
            return 1.0, 2 * s
        return 2 - 2 * s, 1.0

    rho = ring_radii(n, a_max, k_ramp, rho0)
    n_in = len(rho) - 1
    q_last = rho[-1] / rho[-2]
    theta_star = math.atan2(HCYL, RCYL)
    k_star = round(theta_star / (math.pi / 2) * 2 * n)
    s_star = k_star / (2 * n)

    def boundary_pt(s):
        if s <= s_star:
            th = s / s_star * theta_star
        else:
            th = theta_star + (s - s_star) / (1 - s_star) * (math.pi / 2 - theta_star)
        c, sn = math.cos(th), math.sin(th)
        t = RCYL / c if th <= theta_star + 1e-14 else HCYL / sn
        x, y = t * c, CZ - t * sn
        if abs(th - theta_star) < 1e-12:
            x, y = RCYL, 0.0
        if s >= 1.0 - 1e-14:
            x, y = 0.0, 0.0
        return x, y

    L = HCYL - R_C
    h_first = R_C * (q_last - 1)
    n_out = max(2, math.ceil(math.log(1 + L * (q_last - 1) / h_first) / math.log(q_last)))
    sizes = geometric_sizes(1.0, h_first / L, n_out)
    g_nodes = [0.0]
    for h in sizes:
        g_nodes.append(g_nodes[-1] + h)
    g_nodes[-1] = 1.0

    def ring_pt(t, s):
        th = s * math.pi / 2
        if t <= n_in:
            i = int(math.floor(t))
            r = rho[i] if t == i else 0.5 * (rho[i] + rho[i + 1])
            beta = min(1.0, math.log(r / rho0) / math.log(3.0))
            beta = 0.5 - 0.5 * math.cos(math.pi * beta)
            a, b = square_pt(s)
            dx = (1 - beta) * a + beta * math.cos(th)
            dy = (1 - beta) * b + beta * math.sin(th)
            return r * dx, CZ - r * dy
        tt = t - n_in
        i = int(math.floor(tt))
        g = 1.0 if i >= n_out else g_nodes[i] + (tt - i) * (g_nodes[i + 1] - g_nodes[i])
        xc, yc = R_C * math.cos(th), CZ - R_C * math.sin(th)
        xb, yb = boundary_pt(s)
        x, y = (1 - g) * xc + g * xb, (1 - g) * yc + g * yb
        if s <= 1e-14:
            y = CZ
        if s >= 1 - 1e-14:
            x = 0.0
        return x, y

    def ring_pt_mapped(u, v):
        x, y = ring_pt(u, v / (2 * n))
        return fmap(x), y

    m.add_block(ring_pt_mapped, n_in + n_out, 2 * n, "TISSUE")
    return m, dict(n_in=n_in, n_out=n_out, h0=h0)


def sphere_mesh(first_node, first_elem, ds0, ds_max, r_hole, thick=0.4):
    """strip of CAX8R along the sphere arc (outer face = sphere, tip at
    (r_hole, CZ)); returns (nodes, elems, master faces)."""
    L = RSPH * ARC
    s_list = [0.0]
    ds = ds0
    while s_list[-1] < L - 1e-9:
        s_list.append(min(L, s_list[-1] + ds))
        ds = min(ds_max, ds * 1.1)

    def pt(s):
        a = s / RSPH
        return (RSPH * math.sin(a), CZ + RSPH - RSPH * math.cos(a), math.sin(a), -math.cos(a))

    nodes, elems, faces = {}, {}, []
    nid = first_node

    def add(x, y):
        nonlocal nid
        nodes[nid] = (x + r_hole, y)
        nid += 1
        return nid - 1

    outer, inner, side_mid, outer_mid, inner_mid = [], [], [], [], []
    for s in s_list:
        x, y, nx, ny = pt(s)
        xi, yi = x - thick * nx, y - thick * ny
        outer.append(add(x, y))
        inner.append(add(xi, yi))
        side_mid.append(add(0.5 * (x + xi), 0.5 * (y + yi)))
    for k in range(len(s_list) - 1):
        x, y, nx, ny = pt(0.5 * (s_list[k] + s_list[k + 1]))
        outer_mid.append(add(x, y))
        inner_mid.append(add(x - thick * nx, y - thick * ny))
    eid = first_elem
    for k in range(len(s_list) - 1):
        c = [outer[k], outer[k + 1], inner[k + 1], inner[k],
             outer_mid[k], side_mid[k + 1], inner_mid[k], side_mid[k]]
        p = [nodes[i] for i in c[:4]]
        a = sum(p[i][0] * p[(i + 1) % 4][1] - p[(i + 1) % 4][0] * p[i][1] for i in range(4))
        face = 1
        if a < 0:
            c = [c[0], c[3], c[2], c[1], c[7], c[6], c[5], c[4]]
            face = 4
        elems[eid] = c
        faces.append((eid, face))
        eid += 1
    return nodes, elems, faces


def write_deck(path, law="nh", kfac=1000.0, n=10, a_max=4.0, k_ramp=12, penalty=100.0,
               depth=0.25, dmax=0.0125, dt_out=0.025, r_hole=1e-4, slave_r=3.0,
               ds0=0.01, ds_max=0.04, su=1000.0, nu_lin=0.4995, rho0=RHO0):
    """law: 'nh' (NLGEOM, hyperelastic) or 'lin' (*ELASTIC E = 2 mu (1 + nu),
    no NLGEOM). penalty in MPa/mm."""
    m, info = tissue_mesh(n, a_max, k_ramp, r_hole, rho0)
    ne_t, nn_t = len(m.elems), len(m.nodes)
    nd_nodes, nd_elems, mfaces = sphere_mesh(nn_t + 1, ne_t + 1, ds0, ds_max, r_hole)
    tol = 1e-9
    axis = [i for i, (x, y) in m.nodes.items() if abs(x - r_hole) < tol]
    bottom = [i for i, (x, y) in m.nodes.items() if abs(y) < tol]
    topfaces = []
    for eid, f in m.boundary_faces():
        a, b, _ = m.face_nodes(eid, f)
        (xa, ya), (xb, yb) = m.nodes[a], m.nodes[b]
        if abs(ya - CZ) < tol and abs(yb - CZ) < tol and max(xa, xb) <= slave_r + tol:
            topfaces.append((eid, f))
    topnodes = sorted({k for eid, f in topfaces for k in m.face_nodes(eid, f)})
    mu = 2 * C10_NH
    nl = law == "nh"
    with open(path, "w") as fh:
        fh.write(f"** Hertz: rigid sphere R = {RSPH} mm, frictionless, into the N1 cylinder; "
                 f"law={law}, K/mu={kfac:g}, core {rho0:g} mm, n={n} (h = {rho0 / n:g} mm CAX8R), "
                 f"penalty={penalty:g} MPa/mm, r_hole={r_hole:g} mm\n")
        fh.write("** UNITS: length mm, stress kPa, force mN for a 2 degree segment\n")
        fh.write(f"** tissue: {ne_t} CAX8R elements, {nn_t} nodes; sphere strip: "
                 f"{len(nd_elems)} elements (all nodes prescribed)\n** generated by gen_hertz.py\n")
        m.write_nodes(fh)
        for i, (x, y) in nd_nodes.items():
            fh.write(f"{i}, {x:.12g}, {y:.12g}, 0.\n")
        m.write_elems(fh, "CAX8R", "TISSUE")
        fh.write("*ELEMENT, TYPE=CAX8R, ELSET=SPHERE\n")
        for eid, c in nd_elems.items():
            fh.write(f"{eid}, " + ", ".join(str(k) for k in c) + "\n")
        m.write_nset(fh, "AXIS", axis)
        m.write_nset(fh, "BOTTOM", bottom)
        m.write_nset(fh, "SURF", topnodes)
        m.write_nset(fh, "NSPHERE", list(nd_nodes.keys()))
        m.write_surface(fh, "SLAVE", topfaces)
        m.write_surface(fh, "MASTER", mfaces)
        if nl:
            K = kfac * mu * su
            fh.write(f"*MATERIAL, NAME=TISSUEMAT\n*HYPERELASTIC, NEO HOOKE\n"
                     f"{C10_NH * su:.9e}, {2.0 / K:.9e}\n")
        else:
            E = 2 * mu * (1 + nu_lin) * su
            fh.write(f"*MATERIAL, NAME=TISSUEMAT\n*ELASTIC\n{E:.9e}, {nu_lin:g}\n")
        fh.write(f"*MATERIAL, NAME=STEEL\n*ELASTIC\n{1000. * su:g}, 0.3\n")
        fh.write("*SOLID SECTION, ELSET=TISSUE, MATERIAL=TISSUEMAT\n")
        fh.write("*SOLID SECTION, ELSET=SPHERE, MATERIAL=STEEL\n")
        fh.write("*CONTACT PAIR, INTERACTION=INT1, TYPE=SURFACE TO SURFACE\nSLAVE, MASTER\n")
        fh.write("*SURFACE INTERACTION, NAME=INT1\n")
        fh.write(f"*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{penalty * su:g}\n")
        npts = int(round(depth / dt_out))
        fh.write(f"*TIME POINTS, NAME=TP, GENERATE\n0., {depth:.6f}, {depth / npts:.8f}\n")
        nlg = ", NLGEOM" if nl else ""
        # dummy first step (see gen_n1.py: CalculiX 2.20 phases out
        # penetrations found in step 1 as initial overclosures)
        fh.write(f"*STEP{nlg}\n*STATIC\n1., 1.\n*BOUNDARY\nAXIS, 1, 1, 0.\n"
                 "BOTTOM, 1, 2, 0.\nNSPHERE, 1, 2, 0.\n*END STEP\n")
        fh.write(f"*STEP{nlg}, INC=100000\n*STATIC\n{dmax / 2:.8f}, {depth:.6f}, 1e-9, {dmax:.8f}\n")
        fh.write("*BOUNDARY\nAXIS, 1, 1, 0.\nBOTTOM, 1, 2, 0.\nNSPHERE, 1, 1, 0.\n")
        fh.write(f"NSPHERE, 2, 2, {-depth}\n")
        fh.write("*NODE PRINT, NSET=NSPHERE, TOTALS=ONLY, TIME POINTS=TP\nRF\n")
        fh.write("*END STEP\n")
    return dict(ne_tissue=ne_t, nn_tissue=nn_t, ne_sphere=len(nd_elems),
                n_slave_faces=len(topfaces), **info)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("path")
    ap.add_argument("--law", default="nh", choices=["nh", "lin"])
    ap.add_argument("--kfac", type=float, default=1000.0)
    ap.add_argument("--n", type=int, default=10)
    ap.add_argument("--a_max", type=float, default=4.0)
    ap.add_argument("--k_ramp", type=int, default=12)
    ap.add_argument("--penalty", type=float, default=100.0)
    ap.add_argument("--depth", type=float, default=0.25)
    ap.add_argument("--dmax", type=float, default=0.0125)
    ap.add_argument("--dt_out", type=float, default=0.025)
    ap.add_argument("--r_hole", type=float, default=1e-4)
    ap.add_argument("--nu_lin", type=float, default=0.4995)
    ap.add_argument("--rho0", type=float, default=RHO0, help="core square side (mm)")
    a = ap.parse_args()
    info = write_deck(a.path, a.law, a.kfac, a.n, a.a_max, a.k_ramp, a.penalty, a.depth,
                      a.dmax, a.dt_out, a.r_hole, nu_lin=a.nu_lin, rho0=a.rho0)
    print(os.path.basename(a.path), info)
