#!/usr/bin/env python3
"""Runs `palpate diagnose` on every record of ../shared/data/real (and the
Treloar records of studies/data/treloar) and prints the markdown table of
docs/validation/gap-real.md.

    cargo build --release -p palpate-studies --bin palpate
    python3 docs/validation/gap_real.py [--law neo-hookean] > /tmp/table.md

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


os.makedirs(OUT, exist_ok=True)
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
          f"{best['effect'] if best else '-'} | {g(after)} | {excess*100:.0f} % | {'; '.join(other)} | {cpu:.1f} |")
