"""Shared pieces of the CalculiX decks in docs/validation/experiments:
structured CAX8R meshes on graded tensor-product grids, rigid tools as strips
of fully prescribed elements, the material card, and the .dat -> CSV
post-processing.

Units in the decks: mm, kPa, mN (stress unit factor SU = 1000, as in
docs/validation/hertz: CalculiX's residual tolerances behave better than
in MPa for moduli of a few kPa). CalculiX prints axisymmetric reaction
forces for a 2 degree segment, so the whole body's force is
F [N] = 180 * RF [mN] / 1000.

Element node order (CalculiX/Abaqus): corners 1-4 counter-clockwise,
midsides 5 (1-2), 6 (2-3), 7 (3-4), 8 (4-1); faces S1 = 1-2, S2 = 2-3,
S3 = 3-4, S4 = 4-1. Coordinates (x, y) = (r, z).
"""
import math
import re

SU = 1000.0                       # MPa -> kPa
AXI_FACTOR = 180.0 / SU           # RF (mN, 2 degree segment) -> N, whole body


def nh_card(name, c10, bulk_ratio):
    """*MATERIAL card of a neo-Hookean solid: C10 in MPa, K = bulk_ratio * mu,
    mu = 2 C10, D1 = 2 / K (CalculiX's W = C10 (I1bar - 3) + (J - 1)^2 / D1)."""
    mu = 2.0 * c10 * SU
    k = bulk_ratio * mu
    return (f"*MATERIAL, NAME={name}\n*HYPERELASTIC, NEO HOOKE\n"
            f"{c10 * SU:.9e}, {2.0 / k:.9e}\n")


# ------------------------------------------------------------ 1D gradings
def graded(a, b, h_a, h_b, growth=1.2):
    """Node coordinates from a to b whose element sizes start at h_a (at a)
    and change geometrically by `growth` per element towards h_b, then stay
    at h_b; scaled to end exactly at b."""
    L = b - a
    if L <= 0:
        raise ValueError("graded: b must exceed a")
    sizes = []
    h = h_a
    g = growth if h_b >= h_a else 1.0 / growth
    while sum(sizes) < L - 1e-12:
        sizes.append(h)
        h = min(h * g, h_b) if h_b >= h_a else max(h * g, h_b)
    # drop a last sliver and rescale to fit exactly
    if len(sizes) > 1 and sum(sizes) - L > 0.5 * sizes[-1]:
        sizes.pop()
    s = L / sum(sizes)
    xs = [a]
    for h in sizes:
        xs.append(xs[-1] + h * s)
    xs[-1] = b
    return xs


def uniform(a, b, h):
    n = max(1, round((b - a) / h))
    return [a + (b - a) * k / n for k in range(n + 1)]


def join(*parts):
    """Concatenate coordinate lists that share their end points."""
    out = list(parts[0])
    for p in parts[1:]:
        assert abs(p[0] - out[-1]) < 1e-9, (p[0], out[-1])
        out.extend(p[1:])
    return out


def refine(xs, f):
    """Split every interval into f equal ones (nested meshes: level f)."""
    out = [xs[0]]
    for a, b in zip(xs[:-1], xs[1:]):
        for k in range(1, f + 1):
            out.append(a + (b - a) * k / f)
    return out


# ------------------------------------------------------------ mesh
class Mesh:
    def __init__(self):
        self.nodes = {}        # id -> (x, y)
        self.key2id = {}
        self.elems = {}        # id -> [8 node ids]
        self.elsets = {}

    def node(self, x, y, tol=1e-9):
        key = (round(x / tol), round(y / tol))
        nid = self.key2id.get(key)
        if nid is None:
            nid = len(self.nodes) + 1
            self.nodes[nid] = (x, y)
            self.key2id[key] = nid
        return nid

    def add_grid(self, xs, ys, elset, xmap=lambda x: x):
        """Tensor-product block of CAX8R elements on node lines xs, ys;
        midside nodes at the interval midpoints; xmap maps r (the axis
        offset)."""
        def coord(c, t2):
            i = t2 // 2
            return c[i] if t2 % 2 == 0 else 0.5 * (c[i] + c[i + 1])

        nu, nv = len(xs) - 1, len(ys) - 1
        grid = {}
        for i2 in range(2 * nu + 1):
            for j2 in range(2 * nv + 1):
                if i2 % 2 == 1 and j2 % 2 == 1:
                    continue
                grid[(i2, j2)] = self.node(xmap(coord(xs, i2)), coord(ys, j2))
        for i in range(nu):
            for j in range(nv):
                a, b = 2 * i, 2 * j
                c = [grid[(a, b)], grid[(a + 2, b)], grid[(a + 2, b + 2)], grid[(a, b + 2)],
                     grid[(a + 1, b)], grid[(a + 2, b + 1)], grid[(a + 1, b + 2)], grid[(a, b + 1)]]
                eid = len(self.elems) + 1
                self.elems[eid] = c
                self.elsets.setdefault(elset, []).append(eid)

    def face_nodes(self, eid, face):
        c = self.elems[eid]
        corner = [(0, 1, 4), (1, 2, 5), (2, 3, 6), (3, 0, 7)][face - 1]
        return [c[k] for k in corner]

    def boundary_faces(self):
        cnt = {}
        for eid in self.elems:
            for f in range(1, 5):
                a, b, _ = self.face_nodes(eid, f)
                cnt.setdefault((min(a, b), max(a, b)), []).append((eid, f))
        return [v[0] for v in cnt.values() if len(v) == 1]

    def faces_where(self, pred):
        """boundary faces whose two corner nodes both satisfy pred(x, y)."""
        out = []
        for eid, f in self.boundary_faces():
            a, b, _ = self.face_nodes(eid, f)
            if pred(*self.nodes[a]) and pred(*self.nodes[b]):
                out.append((eid, f))
        return sorted(out)

    def nodes_where(self, pred):
        return sorted(i for i, (x, y) in self.nodes.items() if pred(x, y))

    # writers
    def write_nodes(self, fh, extra=None):
        fh.write("*NODE, NSET=NALL\n")
        for nid, (x, y) in self.nodes.items():
            fh.write(f"{nid}, {x:.12g}, {y:.12g}, 0.\n")
        for nid, (x, y) in (extra or {}).items():
            fh.write(f"{nid}, {x:.12g}, {y:.12g}, 0.\n")

    def write_elems(self, fh, elset, etype="CAX8R"):
        fh.write(f"*ELEMENT, TYPE={etype}, ELSET={elset}\n")
        for eid in self.elsets[elset]:
            fh.write(f"{eid}, " + ", ".join(str(n) for n in self.elems[eid]) + "\n")


def write_nset(fh, name, ids):
    fh.write(f"*NSET, NSET={name}\n")
    ids = sorted(set(ids))
    for k in range(0, len(ids), 12):
        fh.write(", ".join(str(n) for n in ids[k:k + 12]) + ",\n")


def write_surface(fh, name, faces):
    fh.write(f"*SURFACE, NAME={name}, TYPE=ELEMENT\n")
    for eid, f in faces:
        fh.write(f"{eid}, S{f}\n")


# ------------------------------------------------------------ rigid tools
def rigid_strip(pt, stations, first_node, first_elem, thick, skip_first=False):
    """A strip of CAX8R elements whose outer face follows a tool profile.
    pt(s) -> (x, y, nx, ny): the profile point at arc length s and its
    outward normal (pointing into the specimen); stations: increasing arc
    lengths. The strip is `thick` deep inside the tool. All its nodes are
    prescribed in the decks, so it moves as a rigid body. Returns (nodes,
    elems, faces): faces are the (element, face) pairs of the profile, the
    master surface of the contact; skip_first leaves the first segment out
    of it (a tool on the axis: CalculiX's contact fails, "matrix found to
    be singular", when a master face reaches the axis, as in
    tests/data/calculix/gen_n1.py)."""
    nodes, elems, faces = {}, {}, []
    nid = first_node

    def add(x, y):
        nonlocal nid
        nodes[nid] = (x, y)
        nid += 1
        return nid - 1

    outer, inner, side = [], [], []
    for s in stations:
        x, y, nx, ny = pt(s)
        outer.append(add(x, y))
        inner.append(add(x - thick * nx, y - thick * ny))
        side.append(add(x - 0.5 * thick * nx, y - 0.5 * thick * ny))
    omid, imid = [], []
    for k in range(len(stations) - 1):
        x, y, nx, ny = pt(0.5 * (stations[k] + stations[k + 1]))
        omid.append(add(x, y))
        imid.append(add(x - thick * nx, y - thick * ny))
    eid = first_elem
    for k in range(len(stations) - 1):
        c = [outer[k], outer[k + 1], inner[k + 1], inner[k], omid[k], side[k + 1], imid[k], side[k]]
        p = [nodes[i] for i in c[:4]]
        area = sum(p[i][0] * p[(i + 1) % 4][1] - p[(i + 1) % 4][0] * p[i][1] for i in range(4))
        face = 1
        if area < 0:
            c = [c[0], c[3], c[2], c[1], c[7], c[6], c[5], c[4]]
            face = 4
        elems[eid] = c
        if k > 0 or not skip_first:
            faces.append((eid, face))
        eid += 1
    return nodes, elems, faces


def stations(total, ds0, ds_max, growth=1.1, breaks=()):
    """Arc-length stations from 0 to total, starting at ds0 and growing to
    ds_max, always including the given break points (profile corners)."""
    out = [0.0]
    ds = ds0
    for b in sorted(list(breaks) + [total]):
        while out[-1] < b - 1e-9:
            out.append(min(b, out[-1] + ds))
            ds = min(ds_max, ds * growth)
    return out


# ------------------------------------------------------------ contact deck
def write_indentation_deck(path, header, mesh, tool, supports, material, depth, n_out,
                           dmax, penalty, slave_faces, gap=0.0):
    """A deck for a rigid tool pressed vertically into the specimen.
    tool = (nodes, elems, master faces); supports: list of "*BOUNDARY" lines
    for the specimen (AXIS, BOTTOM, ...), with the node sets as dict
    name -> ids; the tool's nodes are NTOOL. Step 1 holds everything (see
    docs/validation/hertz and tests/data/calculix/gen_n1.py: CalculiX 2.20
    treats penetrations found in step 1 as initial overclosures); step 2
    moves the tool down by `depth` with step time = depth (mm), increments
    of at most dmax, and prints the tool's total reaction at n_out equal
    depths. gap: the tool starts this far above the specimen (a flat face
    flush with the surface keeps step 1 from converging); the tool then
    travels depth + gap, the samples are at gap + k depth / n_out, and the
    deck says `** GAP g` for post.py."""
    tnodes, telems, mfaces = tool
    sets, bc_lines = supports
    with open(path, "w") as fh:
        for line in header:
            fh.write(f"** {line}\n")
        fh.write("** UNITS: length mm, stress kPa, force mN for a 2 degree segment\n")
        if gap:
            fh.write(f"** GAP {gap:.6g}\n")
        mesh.write_nodes(fh, extra=tnodes)
        mesh.write_elems(fh, "SPEC")
        fh.write("*ELEMENT, TYPE=CAX8R, ELSET=TOOL\n")
        for eid, c in telems.items():
            fh.write(f"{eid}, " + ", ".join(str(k) for k in c) + "\n")
        for name, ids in sets.items():
            write_nset(fh, name, ids)
        write_nset(fh, "NTOOL", list(tnodes))
        write_surface(fh, "SLAVE", slave_faces)
        write_surface(fh, "MASTER", mfaces)
        fh.write(material)
        fh.write(f"*MATERIAL, NAME=STEEL\n*ELASTIC\n{1000. * SU:g}, 0.3\n")
        fh.write("*SOLID SECTION, ELSET=SPEC, MATERIAL=SPECMAT\n")
        fh.write("*SOLID SECTION, ELSET=TOOL, MATERIAL=STEEL\n")
        fh.write("*CONTACT PAIR, INTERACTION=INT1, TYPE=SURFACE TO SURFACE\nSLAVE, MASTER\n")
        fh.write("*SURFACE INTERACTION, NAME=INT1\n")
        fh.write(f"*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{penalty * SU:g}\n")
        if gap:
            fh.write("*TIME POINTS, NAME=TP\n")
            for k in range(1, n_out + 1):
                fh.write(f"{gap + depth * k / n_out:.8f}\n")
        else:
            fh.write(f"*TIME POINTS, NAME=TP, GENERATE\n0., {depth:.6f}, {depth / n_out:.8f}\n")
        bcs = "".join(line + "\n" for line in bc_lines)
        fh.write("*STEP, NLGEOM\n*STATIC\n1., 1.\n*BOUNDARY\n" + bcs + "NTOOL, 1, 2, 0.\n*END STEP\n")
        travel = f"{depth + gap:.8f}" if gap else f"{depth:.6f}"
        fh.write(f"*STEP, NLGEOM, INC=100000\n*STATIC\n{dmax / 2:.8f}, {travel}, 1e-9, {dmax:.8f}\n")
        fh.write("*BOUNDARY\n" + bcs + "NTOOL, 1, 1, 0.\n"
                 + f"NTOOL, 2, 2, {'-' + travel if gap else -depth}\n")
        fh.write("*NODE PRINT, NSET=NTOOL, TOTALS=ONLY, TIME POINTS=TP\nRF\n")
        fh.write("*END STEP\n")


# ------------------------------------------------------------ post
def dat_totals(path, setname):
    """[(time, fx, fy, fz)] from '*NODE PRINT ... TOTALS=ONLY' blocks."""
    out = []
    pat = re.compile(r"total force \(fx,fy,fz\) for set (\S+) and time\s+(\S+)")
    lines = open(path).read().splitlines()
    for i, ln in enumerate(lines):
        m = pat.search(ln)
        if m and m.group(1).upper() == setname.upper():
            j = i + 1
            while not lines[j].strip():
                j += 1
            out.append((float(m.group(2)), *[float(x) for x in lines[j].split()[:3]]))
    return out


def curve(dat, setname, t0=0.0, scale=1.0):
    """(displacement_mm, force_N) pairs: displacement = scale * (time - t0),
    force = -fy (compression positive), whole body; repeated last time
    points (CalculiX prints the step's end twice) dropped."""
    rows, last = [], None
    for t, fx, fy, fz in dat_totals(dat, setname):
        d = scale * (t - t0)
        if d <= 1e-12 or (last is not None and abs(d - last) < 1e-9):
            continue
        last = d
        rows.append((d, -fy * AXI_FACTOR))
    return rows


def write_curve(path, rows, comments=()):
    with open(path, "w") as fh:
        for c in comments:
            fh.write(f"# {c}\n")
        fh.write("displacement_mm,force_N\n")
        for d, f in rows:
            fh.write(f"{d:.6f},{f:.9e}\n")


def sta_summary(path):
    """(converged increments, Newton iterations of all attempts, attempts
    that did not converge) of the last step, from a .sta file."""
    inc, it, fails = 0, 0, 0
    last_step = None
    for ln in open(path):
        p = ln.split()
        if len(p) == 7 and p[0].isdigit() and p[1].isdigit():
            if p[0] != last_step:
                inc, it, fails, last_step = 0, 0, 0, p[0]
            it += int(p[3])
            if p[2].endswith("U"):
                fails += 1
            else:
                inc += 1
    return inc, it, fails


def cpu_seconds(path):
    """user + system CPU seconds from a `/usr/bin/time -v` report."""
    t = 0.0
    for ln in open(path):
        if "User time" in ln or "System time" in ln:
            t += float(ln.split(":")[-1])
    return t
