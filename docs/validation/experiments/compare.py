#!/usr/bin/env python3
"""Compare palpate's force-displacement curve of an experiment with the
CalculiX reference curve of the same experiment.

usage: compare.py PALPATE.csv CALCULIX.csv --tol 0.02 [--floor 0.05]

Both files are CSV with columns displacement_mm and force_N (force
positive in compression, whole body). A header line naming the columns is
optional (without one the first two columns are taken); lines starting
with '#' are comments; other columns are ignored. A curve that does not
start at zero displacement is taken to start at (0, 0): the touch.

At every CalculiX sample inside the displacement range of palpate's curve
the palpate force is interpolated linearly in displacement and the
relative difference (palpate - CalculiX) / CalculiX is printed. Samples
whose CalculiX force is below --floor times the largest CalculiX force are
printed but not judged (at the first contact the relative difference of
two small numbers says little). The exit status is 0 when every judged
|difference| is within --tol, 1 when one is beyond, 2 on unreadable input
or when no sample can be judged.
"""
import argparse
import sys


def read_curve(path):
    """[(displacement_mm, force_N)] sorted by displacement."""
    try:
        lines = open(path).read().splitlines()
    except OSError as e:
        raise ValueError(f"{path}: {e.strerror}")
    rows, cols = [], None
    for no, raw in enumerate(lines, 1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        cells = [c.strip() for c in line.split(",")]
        if cols is None:
            try:
                [float(c) for c in cells[:2]]
                cols = (0, 1)
            except ValueError:
                names = [c.lower() for c in cells]
                if "displacement_mm" not in names or "force_n" not in names:
                    raise ValueError(f"{path}:{no}: a header must name displacement_mm and "
                                     f"force_N; found {', '.join(cells)}")
                cols = (names.index("displacement_mm"), names.index("force_n"))
                continue
        try:
            rows.append((float(cells[cols[0]]), float(cells[cols[1]])))
        except (ValueError, IndexError):
            raise ValueError(f"{path}:{no}: expected numbers in columns {cols[0] + 1} and "
                             f"{cols[1] + 1}, found: {line}")
    if not rows:
        raise ValueError(f"{path}: no samples")
    rows.sort()
    if rows[0][0] > 0:
        rows.insert(0, (0.0, 0.0))      # no force before the touch
    return rows


def interpolate(curve, x):
    """linear interpolation, None outside the curve's range."""
    if x < curve[0][0] - 1e-9 or x > curve[-1][0] + 1e-9:
        return None
    for (x0, y0), (x1, y1) in zip(curve[:-1], curve[1:]):
        if x0 - 1e-9 <= x <= x1 + 1e-9:
            if x1 == x0:
                return y1
            t = min(1.0, max(0.0, (x - x0) / (x1 - x0)))
            return y0 + t * (y1 - y0)
    return curve[-1][1]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("palpate", help="palpate's curve (palpate simulate --output)")
    ap.add_argument("calculix", help="the CalculiX reference curve")
    ap.add_argument("--tol", type=float, required=True,
                    help="largest relative difference accepted (0.02 = 2 %%)")
    ap.add_argument("--floor", type=float, default=0.05,
                    help="judge only samples whose CalculiX force is at least this fraction "
                         "of the largest (default 0.05)")
    a = ap.parse_args(argv)
    try:
        pal, ccx = read_curve(a.palpate), read_curve(a.calculix)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    fmax = max(abs(f) for _, f in ccx)
    print(f"{'displacement_mm':>15} {'calculix_N':>13} {'palpate_N':>13} {'rel_diff':>9}")
    worst, worst_at, judged, outside = 0.0, None, 0, 0
    for d, fc in ccx:
        if d <= 0:
            continue
        fp = interpolate(pal, d)
        if fp is None:
            outside += 1
            print(f"{d:15.4f} {fc:13.6e} {'-':>13} {'outside':>9}")
            continue
        rel = (fp - fc) / fc if fc != 0 else float("inf")
        judge = abs(fc) >= a.floor * fmax
        mark = "" if judge else "  (below floor, not judged)"
        print(f"{d:15.4f} {fc:13.6e} {fp:13.6e} {100 * rel:+8.3f}%{mark}")
        if judge:
            judged += 1
            if abs(rel) > abs(worst):
                worst, worst_at = rel, d
    if outside:
        print(f"{outside} CalculiX sample(s) outside palpate's displacement range "
              f"[{pal[0][0]:g}, {pal[-1][0]:g}] mm")
    if judged == 0:
        print("error: no CalculiX sample could be judged", file=sys.stderr)
        return 2
    ok = abs(worst) <= a.tol
    print(f"max |relative difference| {100 * abs(worst):.3f}% at {worst_at:g} mm over {judged} "
          f"samples; tolerance {100 * a.tol:g}%: {'PASS' if ok else 'FAIL'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
