#!/usr/bin/env python3
"""CalculiX presses for the R2 comparison (docs/validation/fe.md, "R2").

With a frictionless wheel the state depends on the wheel position only, so
a press at x equals the rolled force at x (CalculiX checked it: 3.370553 vs
3.370548 N, tests/data/calculix/README.md). Each case presses the
wheel to RD at x with the shared production generator
(tests/data/calculix/r2/gen_r2.py: CPS8R, 0.1 mm section, node-to-
surface penalty contact), on the 1 mm top mesh, at two contact penalties
(1 and 10 MPa/mm); the penalty bias is removed by extrapolating
F = F_inf - c / k (the form press_x10.csv shows). Writes ccx_presses.csv
next to this script: one row per case and penalty, then the extrapolated
rows (penalty `inf`).

Usage (from the repository root; needs ccx, python3 with numpy and gmsh):
    python3 docs/validation/r2/ccx_presses.py [SCRATCH_DIR]
"""
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REF = os.path.normpath(os.path.join(HERE, "../../../tests/data/calculix/r2"))
NODULES = "37.5:10,75:15,112.5:20"
POSITIONS = [37.5, 56.25, 75.0, 93.75, 112.5]
RDS = [3.0, 6.0]
PENALTIES = [1.0, 10.0]
HTOP = 1.0


def final_force(case):
    name = os.path.basename(case)
    txt = open(os.path.join(case, name + ".dat")).read()
    pat = re.compile(r"total force \(fx,fy,fz\) for set (\S+) and time\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)")
    rows = [(float(m.group(2)), float(m.group(3)), float(m.group(4))) for m in pat.finditer(txt)]
    return rows[-1] if rows else None


def main():
    scratch = sys.argv[1] if len(sys.argv) > 1 else "/tmp/r2_ccx"
    os.makedirs(scratch, exist_ok=True)
    out = []
    for rd in RDS:
        for x in POSITIONS:
            res = {}
            for kp in PENALTIES:
                name = f"p{x:g}_rd{rd:g}_kp{kp:g}".replace(".", "p")
                case = os.path.join(scratch, name)
                if not os.path.exists(os.path.join(case, "run_stats.txt")):
                    subprocess.run([sys.executable, os.path.join(REF, "gen_r2.py"), case,
                                    "--rd", str(rd), "--nodules", NODULES, "--x0", str(x),
                                    "--noroll", "--htop", str(HTOP), "--kpen", str(kp)],
                                   check=True)
                    subprocess.run(["bash", os.path.join(REF, "run_case.sh"), case, "3000"])
                stats = dict(l.strip().split("=", 1) for l in open(os.path.join(case, "run_stats.txt")))
                info = dict(l.strip().split("=", 1) for l in open(os.path.join(case, "model_info.txt")))
                scale = float(info["scale"])
                f = final_force(case)
                done = f is not None and abs(f[0] - 1.0) < 1e-9 and stats.get("finished") == "1"
                fy = -f[2] * scale if f else float("nan")
                fx = f[1] * scale if f else float("nan")  # RF on the wheel = force of the wheel on the block
                cpu = float(stats.get("user_s", "nan")) + float(stats.get("sys_s", "nan"))
                res[kp] = (fy, fx, done)
                out.append((x, rd, f"{kp:g}", fy, fx, int(done), info["block_elements"], cpu))
                print(name, fy, fx, done, flush=True)
            (f1, x1, d1), (f2, x2, d2) = res[PENALTIES[0]], res[PENALTIES[1]]
            k1, k2 = PENALTIES
            if d1 and d2:
                finf = (k2 * f2 - k1 * f1) / (k2 - k1)
                xinf = (k2 * x2 - k1 * x1) / (k2 - k1)
                out.append((x, rd, "inf", finf, xinf, 1, "", float("nan")))
    with open(os.path.join(HERE, "ccx_presses.csv"), "w") as fo:
        fo.write("# R2 presses at x (frictionless wheel, nodules " + NODULES + "), CalculiX 2.20 CPS8R, "
                 "0.1 mm section scaled to 50 mm, top mesh 1 mm; penalty inf = extrapolated F_inf - c/k "
                 "from 1 and 10 MPa/mm. force_x_N: force of the wheel on the block along +x.\n")
        fo.write("position_mm,rd_mm,penalty_MPa_per_mm,force_N,force_x_N,finished,elements,cpu_s\n")
        for r in out:
            fo.write(f"{r[0]:g},{r[1]:g},{r[2]},{r[3]:.6f},{r[4]:.6f},{r[5]},{r[6]},{r[7]:.1f}\n")


if __name__ == "__main__":
    main()
