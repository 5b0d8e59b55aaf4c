#!/usr/bin/env python3
"""CalculiX deck: a neo-Hookean cylinder 50 mm across and 30 mm high
compressed between platens (default 40 %, 12 mm; `--travel`), bonded (no
slip) on both faces, frictionless (`--platens slip`) or with Coulomb
friction (`--platens friction --mu 0.3`).

Model: the top half (r in [0, 25], z in [0, 15]) with a symmetry plane at
mid-height (z = 0: u_z = 0, u_r free), axisymmetric CAX8R. The top face is
bonded to the upper platen (u_r = 0, u_z = -6 mm at the end: half of the
12 mm platen travel). Beyond about 8 mm of travel the bulging side folds
over onto the platen next to the bonded edge: the platen is therefore also
a rigid strip (r from 25 to 40 mm, all nodes prescribed, moving with the
top face) in frictionless penalty contact with the upper half of the side.
The whole body's force is the top face's reaction plus the strip's; the
displacement written to the curve is the platens' travel (twice the half
model's).

With `--platens friction` the top face is not prescribed: the platen is a
rigid strip from the axis to r = 40 mm in penalty contact with Coulomb
friction `mu` (stick slope `--stick`) with the top face and the upper half
of the side, and the force is the strip's reaction; the strip's first
0.01 mm at the axis is left out of the master surface (CalculiX's contact
fails on a master face at the axis, as in tests/data/calculix/gen_n1.py).
The deck says `** TRAVEL t` for post.py.

Mesh level f: a base grid (radial sizes 2.5 mm at the axis down to 0.625
mm at the free side, vertical sizes 2.5 mm at the mid-plane down to 0.625
mm at the platen: 14 x 10 elements), every element split into f x f.
Increments <= 1/96 of the travel (0.125 mm).

usage: gen.py LEVEL [--out DECK.inp] [--platens bonded|slip|friction] [--mu MU]
              [--travel MM] [--penalty MPa/mm] [--stick MPa/mm] [--etype CAX8R|CAX8]
              [--gap MM] [--hmin MM] [--growth G] [--controls LINE] [--dmin FRAC]
              [--exponential P0 C0] [--slave-from Z]   (gen.py -h lists them all)
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from ccxexp import (SU, Mesh, graded, nh_card, refine, rigid_strip, stations,  # noqa: E402
                    write_nset, write_surface)

R, H = 25.0, 30.0
C10, BULK = 2e-2, 1000.0
TRAVEL = 12.0                      # platen travel, whole body (40 %)
N_OUT = 24                         # curve samples (every 0.5 mm)
PLATEN_R0, PLATEN_R = 25.0, 40.0   # the platen strip beyond the bonded face


def base_grid(hmin=0.625, growth=1.2):
    # fine at r = R and at the platen: graded from there inwards
    xs = [R - x for x in graded(0.0, R, hmin, 2.5, growth=growth)][::-1]
    ys = [H / 2 - y for y in graded(0.0, H / 2, hmin, 2.5, growth=growth)][::-1]
    return xs, ys


def write(path, level, platens="bonded", penalty=10.0, dmax=1.0 / 96, r0=PLATEN_R0,
          corner_face=True, travel=TRAVEL, mu=0.0, stick=10.0, n_out=N_OUT,
          pair="SURFACE TO SURFACE", loose=False, etype="CAX8R", gap=None,
          hmin=0.625, growth=1.2, controls=None, dmin="1e-7", behavior=None, slave_from=None):
    xs, ys = base_grid(hmin, growth)
    xs, ys = refine(xs, level), refine(ys, level)
    m = Mesh()
    m.add_grid(xs, ys, "SPEC")
    tol = 1e-9
    zt = H / 2
    top = m.nodes_where(lambda x, y: abs(y - zt) < tol)
    mid = m.nodes_where(lambda x, y: abs(y) < tol)
    axis = m.nodes_where(lambda x, y: abs(x) < tol)
    side = m.nodes_where(lambda x, y: abs(x - R) < tol)
    zs = zt / 2 if slave_from is None else slave_from  # the side in contact from zs up
    slave = m.faces_where(lambda x, y: abs(x - R) < tol and y >= zs - tol)
    friction = platens == "friction"
    if friction:                # the top face meets the platen by contact
        r0 = 0.0
        slave = m.faces_where(lambda x, y: abs(y - zt) < tol) + slave
    if not corner_face:         # leave out the side face at the bonded edge
        slave = [(e, f) for e, f in slave
                 if max(m.nodes[n][1] for n in m.face_nodes(e, f)) < zt - tol]

    if gap is None:
        gap = 0.002 if friction else 0.0

    def pt(s):      # the platen's face from PLATEN_R0 out, normal down
        return (r0 + s, zt + gap, 0.0, -1.0)

    st = stations(PLATEN_R - r0, 0.05 / level, 0.5 / level,
                  breaks=[R - r0] if r0 < R else [])
    if friction:                # a first sliver at the axis, left out
        st = [0.0, 0.01] + [s for s in st if s > 0.01 + 1e-9]
    tn, te, mf = rigid_strip(pt, st, len(m.nodes) + 1, len(m.elems) + 1, thick=0.5,
                             skip_first=friction)
    with open(path, "w") as fh:
        what = f"friction {mu:g} platens" if friction else f"{platens} platens"
        fh.write(f"** cylinder D = {2 * R} mm, H = {H} mm, compressed {travel:g} mm between "
                 f"{what}; top half, symmetry at mid-height\n")
        fh.write(f"** TRAVEL {travel:g}\n")
        if gap:
            fh.write(f"** GAP {gap:g}\n")
        fh.write(f"** neo-Hookean C10 = {C10} MPa, K = {BULK:g} mu; level {level}: "
                 f"{len(m.elems)} {etype} elements, {len(m.nodes)} nodes; platen strip "
                 f"{len(te)} elements, penalty {penalty:g} MPa/mm with the "
                 f"{'top and the side, friction ' + format(mu, 'g') if friction else 'side, frictionless'}\n")
        fh.write("** UNITS: length mm, stress kPa, force mN for a 2 degree segment\n"
                 "** generated by gen.py\n")
        m.write_nodes(fh, extra=tn)
        m.write_elems(fh, "SPEC", etype)
        fh.write("*ELEMENT, TYPE=CAX8R, ELSET=TOOL\n")
        for eid, c in te.items():
            fh.write(f"{eid}, " + ", ".join(str(k) for k in c) + "\n")
        write_nset(fh, "TOP", top)
        write_nset(fh, "MID", mid)
        write_nset(fh, "AXIS", axis)
        write_nset(fh, "SIDE", side)
        write_nset(fh, "NTOOL", list(tn))
        write_surface(fh, "SLAVE", slave)
        write_surface(fh, "MASTER", mf)
        fh.write(nh_card("SPECMAT", C10, BULK))
        fh.write(f"*MATERIAL, NAME=STEEL\n*ELASTIC\n{1000. * SU:g}, 0.3\n")
        fh.write("*SOLID SECTION, ELSET=SPEC, MATERIAL=SPECMAT\n")
        fh.write("*SOLID SECTION, ELSET=TOOL, MATERIAL=STEEL\n")
        fh.write(f"*CONTACT PAIR, INTERACTION=INT1, TYPE={pair}\nSLAVE, MASTER\n")
        fh.write("*SURFACE INTERACTION, NAME=INT1\n")
        if behavior:    # (p0 MPa, c0 mm): exponential pressure-overclosure
            fh.write("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=EXPONENTIAL\n"
                     f"{behavior[1]:g}, {behavior[0] * SU:g}\n")
        else:
            fh.write(f"*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{penalty * SU:g}\n")
        if friction and mu > 0:
            fh.write(f"*FRICTION\n{mu:g}, {stick * SU:g}\n")
        if gap:     # the half model's platen moves travel / 2 + gap
            fh.write("*TIME POINTS, NAME=TP\n")
            for k in range(1, n_out + 1):
                fh.write(f"{(travel * k / n_out + 2 * gap) / (travel + 2 * gap):.10f}\n")
        else:
            fh.write(f"*TIME POINTS, NAME=TP, GENERATE\n0., 1., {1.0 / n_out:.8f}\n")
        bcs = "AXIS, 1, 1, 0.\nMID, 2, 2, 0.\nNTOOL, 1, 1, 0.\n"
        if platens == "bonded":
            bcs += "TOP, 1, 1, 0.\n"
        # step 1 holds everything (CalculiX 2.20 takes penetrations found
        # in the first step as initial overclosures)
        held = "NTOOL, 2, 2, 0.\n" if friction else "TOP, 2, 2, 0.\nNTOOL, 2, 2, 0.\n"
        moved = (f"NTOOL, 2, 2, {-(travel / 2 + gap)}\n" if friction
                 else f"TOP, 2, 2, {-travel / 2}\nNTOOL, 2, 2, {-travel / 2}\n")
        fh.write("*STEP, NLGEOM\n*STATIC\n1., 1.\n*BOUNDARY\n" + bcs + held + "*END STEP\n")
        fh.write(f"*STEP, NLGEOM, INC=100000\n*STATIC\n{dmax:.8f}, 1., {dmin}, {dmax:.8f}\n")
        if loose:   # residual and correction tolerances 10 x CalculiX's defaults
            fh.write("*CONTROLS, PARAMETERS=FIELD\n0.05, 0.1\n")
        if controls:    # time incrementation: I0, IR, IP, IC, IL, IG, IS, IA
            fh.write("*CONTROLS, PARAMETERS=TIME INCREMENTATION\n" + controls + "\n")
        fh.write("*BOUNDARY\n" + bcs + moved)
        if not friction:
            fh.write("*NODE PRINT, NSET=TOP, TOTALS=ONLY, TIME POINTS=TP\nRF\n")
        fh.write("*NODE PRINT, NSET=NTOOL, TOTALS=ONLY, TIME POINTS=TP\nRF\n")
        fh.write("*NODE PRINT, NSET=SIDE, TIME POINTS=TP\nU\n")
        fh.write("*END STEP\n")
    return dict(elements=len(m.elems), nodes=len(m.nodes), nr=len(xs) - 1, nz=len(ys) - 1,
                platen_elements=len(te), slave_faces=len(slave))


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("level", type=int)
    ap.add_argument("--out")
    ap.add_argument("--platens", default="bonded", choices=["bonded", "slip", "friction"])
    ap.add_argument("--mu", type=float, default=0.3, help="Coulomb friction (--platens friction)")
    ap.add_argument("--stick", type=float, default=10.0,
                    help="stick slope of the friction (MPa/mm)")
    ap.add_argument("--travel", type=float, default=TRAVEL,
                    help="platen travel, whole body (mm)")
    ap.add_argument("--samples", type=int, default=N_OUT, help="curve samples")
    ap.add_argument("--dmax", type=float, default=1.0 / 96,
                    help="largest increment, a fraction of the travel")
    ap.add_argument("--penalty", type=float, default=10.0)
    ap.add_argument("--pair", default="surface", choices=["surface", "node"],
                    help="face-to-face (surface) or node-to-face (node) contact")
    ap.add_argument("--loose", action="store_true",
                    help="Newton's residual and correction tolerances 10 x the defaults")
    ap.add_argument("--platen-r0", type=float, default=PLATEN_R0,
                    help="where the platen strip's face starts (mm)")
    ap.add_argument("--no-corner-face", action="store_true",
                    help="leave the side face at the bonded edge out of the contact")
    ap.add_argument("--etype", default="CAX8R", choices=["CAX8R", "CAX8"],
                    help="the specimen's elements (reduced or full integration)")
    ap.add_argument("--gap", type=float,
                    help="initial platen gap, half model (mm; friction default 0.002)")
    ap.add_argument("--hmin", type=float, default=0.625,
                    help="base grid's element size at the side and the platen (mm)")
    ap.add_argument("--growth", type=float, default=1.2, help="base grid's growth ratio")
    ap.add_argument("--controls",
                    help="*CONTROLS, PARAMETERS=TIME INCREMENTATION line, e.g. '4,8,9,16,10,4,,20'")
    ap.add_argument("--dmin", default="1e-7",
                    help="smallest increment, a fraction of the travel")
    ap.add_argument("--exponential", type=float, nargs=2, metavar=("P0", "C0"),
                    help="exponential pressure-overclosure: p0 (MPa) at contact, c0 (mm)")
    ap.add_argument("--slave-from", type=float,
                    help="the side is in contact from this height up (mm, half model; default 7.5)")
    a = ap.parse_args()
    out = a.out or f"cyl_l{a.level}.inp"
    print(out, write(out, a.level, a.platens, a.penalty, dmax=a.dmax, r0=a.platen_r0,
                     corner_face=not a.no_corner_face, travel=a.travel, mu=a.mu,
                     stick=a.stick, n_out=a.samples,
                     pair="NODE TO SURFACE" if a.pair == "node" else "SURFACE TO SURFACE",
                     loose=a.loose, etype=a.etype, gap=a.gap, hmin=a.hmin, growth=a.growth,
                     controls=a.controls, dmin=a.dmin, behavior=a.exponential,
                     slave_from=a.slave_from))
