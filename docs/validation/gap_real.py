#!/usr/bin/env python3
"""Runs `palpate diagnose` on every record of ../shared/data/real (and the
Treloar records of studies/data/treloar) and prints the markdown table of
docs/validation/gap-real.md.

    cargo build --release -p palpate-studies --bin palpate
    python3 docs/validation/gap_real.py [--law neo-hookean] > /tmp/table.md

It prints two tables: the single-effect verdict of each record, then the
explanation as a set (each member with its share of the excess misfit, in the
order of selection and dropped one out), the remainder over the noise and,
where the remainder is above 3 x the noise, where it lies.

The JSON of each diagnosis goes to target/gap_real/<set>__<file>.json (or $GAP_REAL_OUT).
The test kind of each file follows from its folder and name (the files' own
headers say which test they record); the only per-file option is the kPa
unit of the ten extra corona-radiata shear files (real-data.md).
"""
import json, os, re, subprocess, sys, time

ROOT = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(ROOT, "..", ".."))
REAL = os.path.normpath(os.path.join(REPO, "..", "shared", "data", "real"))
BIN = os.environ.get("PALPATE_BIN", os.path.join(REPO, "target", "release", "palpate"))
OUT = os.environ.get("GAP_REAL_OUT", os.path.join(REPO, "target", "gap_real"))
LAW = sys.argv[sys.argv.index("--law") + 1] if "--law" in sys.argv else "neo-hookean"


def named(entry):
    """An effect's name, with the law `material_form` chose (`form`)."""
    form = entry.get("form")
    return f"{entry['effect']} ({form})" if form else entry["effect"]


def kind(folder, name):
    """The --data TEST[options] of a file."""
    if "simple_shear" in name:
        return "simple_shear"
    m = re.search(r"shear_at_axial_stretch_(\d)d(\d+)", name)
    if m:
        # Their values are kPa although the header says MPa
        # (docs/validation/real-data.md, "Corona radiata, shear superposed").
        return f"simple_shear[axial_stretch={m.group(1)}.{m.group(2)},stress_unit=kPa]"
    if name.startswith("biaxial"):
        return "biaxial"
    if name.startswith("pure_shear"):
        return "planar"
    return "uniaxial"


def records():
    for folder in sorted(os.listdir(REAL)):
        for name in sorted(os.listdir(os.path.join(REAL, folder))):
            if name.endswith(".csv"):
                yield folder, name, os.path.join(REAL, folder, name)
    tre = os.path.join(REPO, "studies", "data", "treloar")
    for name in sorted(os.listdir(tre)):
        if name.endswith(".csv"):
            yield "treloar1944 (studies/data)", name, os.path.join(tre, name)


def g(x):
    return f"{x:.3g}"


def pct(x):
    return "-" if x is None else f"{x * 100:.0f} %"


def set_row(folder, name, r):
    """The explanation of one record as a set, for the second table."""
    noise = r["noise_sd"]
    members = r.get("explanation") or []
    text = "; ".join(
        f"{named(m)} ({pct(m.get('share_marginal'))} / {pct(m.get('share_dropped'))})"
        for m in members) or "none"
    rem = r.get("remainder") or {}
    over = rem.get("misfit_over_noise")
    if over is None and rem.get("misfit") is not None:
        over = rem["misfit"] / noise
    where = ""
    if over is not None and over > 3.0:
        spans = [f"{w['axis']} {w['from']:.3g}..{w['to']:.3g}" for w in (rem.get("where") or [])]
        where = ", ".join(spans) if spans else "the whole record"
    return (f"| {folder} | {name} | {text} | {pct(rem.get('share_unexplained'))} | "
            f"{'-' if over is None else g(over)} | {where} |")


os.makedirs(OUT, exist_ok=True)
sets = []
print("| set | file | test | verdict | noise SD (MPa) | misfit/noise before | best effect | misfit/noise after | share of excess explained | other findings | CPU s |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for folder, name, path in records():
    test = kind(folder, name)
    js = os.path.join(OUT, f"{folder.split()[0]}__{name[:-4]}.json")
    t0 = os.times()
    p = subprocess.run([BIN, "diagnose", "--data", f"{test}={path}", "--law", LAW, "--json", js],
                       capture_output=True, text=True)
    t1 = os.times()
    cpu = (t1.children_user - t0.children_user) + (t1.children_system - t0.children_system)
    if p.returncode != 0:
        msg = p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "failed"
        print(f"| {folder} | {name} | {test} | *not run*: {msg} | | | | | | | {cpu:.1f} |")
        continue
    r = json.load(open(js))
    sets.append(set_row(folder, name, r))
    noise = r["noise_sd"]
    best = r["ranking"][0] if r["ranking"] else None
    before = r["base"]["misfit"] / noise
    # The diagnosis's own practical size of the best-ranked effect.
    after = best["practical"]["misfit_over_noise_after"] if best else float("nan")
    share = best["practical"]["excess_explained"] if best else None
    excess = share if share is not None else float("nan")
    other = []
    if r["immaterial"]:
        other.append("immaterial: " + ", ".join(r["immaterial"]))
    if r["confounded"]:
        other.append("confounded: " + ", ".join(r["confounded"]))
    if r.get("partly_explained"):
        other.append("partly explained")
    if r["failed"]:
        other.append("failed: " + ", ".join(str(f.get("effect", f)) if isinstance(f, dict) else str(f) for f in r["failed"]))
    print(f"| {folder} | {name} | {test} | **{r['verdict']}** | {noise:.2e} | {g(before)} | "
          f"{named(best) if best else '-'} | {g(after)} | {excess*100:.0f} % | {'; '.join(other)} | {cpu:.1f} |")
    if r.get("caveat"):
        sets[-1] = sets[-1][:-1] + f" caveat: {r['caveat']} |"

print()
print("| set | file | explanation (share of the excess: in order / dropped one out) | excess left | remainder / noise | where the remainder lies (above 3 x noise) |")
print("|---|---|---|---|---|---|")
for row in sets:
    print(row)
