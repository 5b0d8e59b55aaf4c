#!/usr/bin/env python3
"""The coverage test on separate FE records (docs/validation/r2-localisation.md,
"50 FE records"): 50 records, each an FE rolled pass at RD 6 on the finer mesh
(h = 1.5 mm, every 1 mm) over three nodules at random positions and depths with
1 % seeded noise, each localised on the same RD 6 model (surrogate on h = 2 mm).

Record k: nodules at x uniform on [25, 45], [65, 85], [105, 125] mm and depths
uniform on [8, 22] mm (random.Random(1000 + k)); noise seed 2000 + k. Each is a
copy of studies/rolling-tumour.toml with `rds = [6]`, run by `palpate run` in
its own folder; the first trains the RD 6 model (9 FE runs) and the others
start from a copy of its folder, so they compute only their own record and
posterior (PALPATE_CODE_VERSION keeps the cache keys of one binary).

    python3 docs/validation/r2/coverage_records.py run --palpate target/release/palpate --work /tmp/cov50
    python3 docs/validation/r2/coverage_records.py analyse --work /tmp/cov50

`--start K` resumes at record K (out0, the trained model, must be there).

The records' FE passes do not depend on the localisation model,
so another model is compared on the same records by localising each record
again with `palpate localize` (its own surrogate cache), results in
<work>/<tag>/r{k}.json:

    python3 docs/validation/r2/coverage_records.py localise --work /tmp/cov50 --tag along --palpate target/release/palpate
    python3 docs/validation/r2/coverage_records.py analyse --work /tmp/cov50 --tag along

Cost: ~97 s of wall time a record on 2 cores (3.5 min for the first;
measured 2026-11-26, commit ac408c4).
"""
import argparse
import json
import os
import random
import shutil
import statistics as st
import subprocess
import time

HERE = os.path.dirname(os.path.abspath(__file__))
MANIFEST = os.path.join(HERE, "..", "..", "..", "studies", "rolling-tumour.toml")


def layout(k):
    rng = random.Random(1000 + k)
    xs = [rng.uniform(25, 45), rng.uniform(65, 85), rng.uniform(105, 125)]
    ds = [rng.uniform(8, 22) for _ in range(3)]
    return [(round(x, 1), round(d, 1)) for x, d in zip(xs, ds)]


def manifest(k):
    t = open(MANIFEST).read()
    nod = ",".join(f"{x:.1f}:{d:.1f}" for x, d in layout(k))
    for old, new in [
        ("rds = [3, 6]", "rds = [6]"),
        ('nodules = "37.5:10,75:15,112.5:20"', f'nodules = "{nod}"'),
        ("seed = 11", f"seed = {2000 + k}"),
        ('name = "rolling-tumour"', f'name = "coverage-{k}"'),
    ]:
        if old not in t:
            raise SystemExit(f"{MANIFEST}: `{old}` not found (the manifest changed)")
        t = t.replace(old, new)
    return t


def run(a):
    os.makedirs(a.work, exist_ok=True)
    env = dict(os.environ, PALPATE_CODE_VERSION=a.code_version)
    first = os.path.join(a.work, "out0")
    for k in range(a.start, a.records):
        path = os.path.join(a.work, f"r{k}.toml")
        open(path, "w").write(manifest(k))
        out = os.path.join(a.work, f"out{k}")
        if k > 0:
            shutil.rmtree(out, ignore_errors=True)
            shutil.copytree(first, out)
        t0 = time.time()
        r = subprocess.run([a.palpate, "run", path, "--out", out], env=env,
                           capture_output=True, text=True)
        with open(os.path.join(a.work, "times.txt"), "a") as f:
            f.write(f"{k} {r.returncode} {time.time() - t0:.1f}\n")
        if r.returncode != 0:
            print(f"record {k}: palpate failed\n{r.stderr}")


def records_done(a):
    done = set()
    for line in open(os.path.join(a.work, "times.txt")):
        w = line.split()
        if len(w) == 3 and w[1] == "0":
            done.add(int(w[0]))
    return sorted(done)


def localise(a):
    out = os.path.join(a.work, a.tag)
    os.makedirs(out, exist_ok=True)
    for k in records_done(a):
        js = os.path.join(out, f"r{k}.json")
        if os.path.exists(js):
            continue
        t0 = time.time()
        r = subprocess.run([a.palpate, "localize", "--benchmark", "R2", "--rd", "6",
                            "--data", os.path.join(a.work, f"out{k}", "r2-rd6-record.csv"),
                            "--nodules", "3", "--seed", str(2000 + k), "--json", js,
                            "--cache", os.path.join(out, "cache")] + a.extra,
                           capture_output=True, text=True)
        with open(os.path.join(out, "times.txt"), "a") as f:
            f.write(f"{k} {r.returncode} {time.time() - t0:.1f}\n")
        if r.returncode != 0:
            print(f"record {k}: palpate localize failed\n{r.stderr}")


def analyse(a):
    done = records_done(a)
    if a.tag:
        done = [k for k in done if os.path.exists(os.path.join(a.work, a.tag, f"r{k}.json"))]
        path = lambda k: os.path.join(a.work, a.tag, f"r{k}.json")
    else:
        path = lambda k: os.path.join(a.work, f"out{k}", "r2-rd6.json")
    rows = [(k, json.load(open(path(k)))) for k in done]
    n = len(rows)
    print(f"records {n}")
    if not rows:
        return
    rh = [r["rhat_max"] for _, r in rows]
    print(f"R-hat max {max(rh):.4f}, median {st.median(rh):.4f}, < 1.01 in "
          f"{sum(x < 1.01 for x in rh)}/{n}; bulk ESS min "
          f"{min(r['ess_bulk_min'] for _, r in rows):.0f}")
    bands = {}
    for k, r in rows:
        for e, (tx, td) in zip(r["nodules"], layout(k)):
            b = "8-12" if td < 12 else ("12-17" if td < 17 else "17-22")
            B = bands.setdefault(b, dict(n=0, id=0, x1=0, d05=0, cx=0, cd=0, dx=[], dd=[]))
            x, d = e["x_mm"], e["depth_mm"]
            B["n"] += 1
            B["cx"] += x["hdi_3"] <= tx <= x["hdi_97"]
            B["cd"] += d["hdi_3"] <= td <= d["hdi_97"]
            if e["identifiable"]:
                B["id"] += 1
                B["dx"].append(x["mean"] - tx)
                B["dd"].append(d["mean"] - td)
                B["x1"] += abs(x["mean"] - tx) < 1.0
                B["d05"] += abs(d["mean"] - td) < 0.5
    print("| true depth mm | nodules | identifiable | x within 1 mm (max abs err) "
          "| depth within 0.5 mm (max abs err) | x 94 % HDI covers | depth 94 % HDI covers |")
    print("|---|---|---|---|---|---|---|")
    tot = {key: 0 for key in ["n", "id", "x1", "d05", "cx", "cd"]}
    for b in ["8-12", "12-17", "17-22"]:
        if b not in bands:
            continue
        B = bands[b]
        mx = max(map(abs, B["dx"]), default=float("nan"))
        md = max(map(abs, B["dd"]), default=float("nan"))
        print(f"| {b} | {B['n']} | {B['id']} | {B['x1']} ({mx:.2f}) | {B['d05']} ({md:.2f}) "
              f"| {B['cx']} | {B['cd']} |")
        for key in tot:
            tot[key] += B[key]
    print(f"| all | {tot['n']} | {tot['id']} | {tot['x1']} | {tot['d05']} | "
          f"{tot['cx']} ({tot['cx'] / tot['n']:.1%}) | {tot['cd']} ({tot['cd'] / tot['n']:.1%}) |")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("what", choices=["run", "localise", "analyse"])
    p.add_argument("--work", required=True)
    p.add_argument("--palpate", default="target/release/palpate")
    p.add_argument("--records", type=int, default=50)
    p.add_argument("--start", type=int, default=0,
                   help="first record to run (resume; out0 must exist when > 0)")
    p.add_argument("--code-version", default="coverage-records")
    p.add_argument("--tag", default="",
                   help="localise/analyse: the folder under --work of a re-localisation")
    p.add_argument("--extra", nargs="*", default=[],
                   help="localise: more options for palpate localize (e.g. --scan centre)")
    a = p.parse_args()
    {"run": run, "localise": localise, "analyse": analyse}[a.what](a)


if __name__ == "__main__":
    main()
