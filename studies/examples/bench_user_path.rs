//! Benchmark of the path a user runs: `palpate simulate --benchmark N1`
//! and `--benchmark N3` with default options (the built `palpate` binary,
//! error estimate on), timed as a user would time them, side by side with
//! CalculiX on the cheapest N1 deck within 0.5 % of the converged force
//! (`tests/data/calculix/n1/n1_nh_f0.8_k1000_n6.inp`: 480 CAX8R, one
//! thread) in the same run.
//!
//! Prints the machine's core count, each run's wall and CPU seconds (user +
//! system of the child process), the force at 10 mm against the converged
//! force (N1: Richardson extrapolation of Q1/P0 levels 2, 3, 5,
//! docs/validation/fe.md "N1 speed"; N3: of the three Q2/P1 meshes, "N3"),
//! the discretisation error palpate states, and the CPU ratio.
//!
//! ```text
//! cargo build --release -p palpate-studies --bin palpate
//! cargo run --release -p palpate-studies --example bench_user_path -- [--recorded-ccx] [--no-n3] [--page docs/validation/fe.md] [--palpate PATH]
//! ```
//!
//! Without `--release` it times the dev-profile binary (opt-level 2,
//! dependencies at 3) and the table says so. Run it on a quiet machine:
//! the table prints the load average.
//!
//! `--recorded-ccx` quotes CalculiX's run recorded in docs/validation/fe.md
//! instead of rerunning it (~5-10 min); `--page FILE` replaces the section
//! between `<!-- bench_user_path begin -->` and `<!-- bench_user_path end -->`
//! in FILE with this run's table.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

#[path = "../../forward/fe/examples/common/cpu.rs"]
mod cpu;
use cpu::cpu_seconds;

/// N1 converged force at 10 mm (N), docs/validation/fe.md "N1 speed".
const N1_CONVERGED: f64 = 0.393390;
/// N3 extrapolated force at 10 mm (N), docs/validation/fe.md "N3"
/// (Q2/P1 on 1.6, 1.2, 0.8 mm cells, observed order 3.8).
const N3_CONVERGED: f64 = 0.40626;
/// CalculiX n6 recorded (docs/validation/fe.md "N1 speed", 2026-11-23):
/// CPU seconds and F(10).
const CCX_RECORDED: (f64, f64, f64) = (188.7, 163.8, 0.394390);
const C10: &str = "C10=0.001101295";

struct Timed {
    wall: f64,
    cpu: f64,
    force: f64,
    estimate: String,
    mesh: String,
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The `palpate` binary: `--palpate PATH`, else the one beside this
/// example's directory.
fn palpate() -> PathBuf {
    let args: Vec<String> = std::env::args().collect();
    if let Some(p) = args
        .iter()
        .position(|a| a == "--palpate")
        .and_then(|k| args.get(k + 1))
    {
        return PathBuf::from(p);
    }
    let exe = std::env::current_exe().expect("current exe");
    // target/<profile>/examples/bench_user_path -> target/<profile>/palpate
    let bin = exe
        .parent()
        .and_then(|p| p.parent())
        .map(|p| p.join("palpate"))
        .expect("target directory");
    if !bin.exists() {
        eprintln!(
            "{} not found: build it first (cargo build --release -p palpate-studies --bin palpate)",
            bin.display()
        );
        std::process::exit(2);
    }
    bin
}

/// Runs `palpate simulate --benchmark B --law neo-hookean --param C10=..`
/// with default options otherwise.
fn simulate(benchmark: &str, dir: &Path) -> Timed {
    let csv = dir.join(format!("{benchmark}.csv"));
    let (t, c) = (Instant::now(), cpu_seconds(true));
    let out = Command::new(palpate())
        .args(["simulate", "--benchmark", benchmark, "--law", "neo-hookean"])
        .args(["--param", C10, "--csv"])
        .arg(&csv)
        .output()
        .expect("run palpate");
    let (wall, cpu) = (t.elapsed().as_secs_f64(), cpu_seconds(true) - c);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "palpate simulate --benchmark {benchmark}: {stderr}"
    );
    let text = std::fs::read_to_string(&csv).expect("csv");
    let last = text
        .lines()
        .rfind(|l| !l.starts_with('#') && !l.is_empty())
        .expect("a row");
    let force: f64 = last
        .split(',')
        .nth(1)
        .and_then(|f| f.parse().ok())
        .expect("force");
    let estimate = text
        .lines()
        .find(|l| l.starts_with("# discretisation error"))
        .and_then(|l| l.split("): ").nth(1))
        .unwrap_or("-")
        .to_string();
    let mesh = stderr
        .lines()
        .find(|l| l.contains(" elements, "))
        .and_then(|l| l.split(": ").nth(1))
        .and_then(|l| l.split(", F(").next())
        .unwrap_or("-")
        .to_string();
    Timed {
        wall,
        cpu,
        force,
        estimate,
        mesh,
    }
}

/// Runs CalculiX on the n6 deck (one thread): wall, CPU and F(10) from the
/// needle's total reaction (the deck's 2-degree segment in mN: x 180 / 1000).
fn calculix(dir: &Path) -> Option<(f64, f64, f64)> {
    let deck = repo().join("tests/data/calculix/n1/n1_nh_f0.8_k1000_n6.inp");
    std::fs::copy(&deck, dir.join("n1.inp")).ok()?;
    let (t, c) = (Instant::now(), cpu_seconds(true));
    let status = Command::new("ccx")
        .args(["-i", "n1"])
        .current_dir(dir)
        .env("OMP_NUM_THREADS", "1")
        .stdout(std::process::Stdio::null())
        .status()
        .ok()?;
    let (wall, cpu) = (t.elapsed().as_secs_f64(), cpu_seconds(true) - c);
    if !status.success() {
        return None;
    }
    let dat = std::fs::read_to_string(dir.join("n1.dat")).ok()?;
    let lines: Vec<&str> = dat.lines().collect();
    let k = lines
        .iter()
        .rposition(|l| l.contains("total force (fx,fy,fz) for set NNEEDLE"))?;
    let fy: f64 = lines[k + 1..]
        .iter()
        .find(|l| !l.trim().is_empty())?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()?;
    Some((wall, cpu, -fy * 180.0 / 1000.0))
}

fn pct(a: f64, b: f64) -> f64 {
    100.0 * (a - b) / b
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let recorded = args.iter().any(|a| a == "--recorded-ccx");
    let no_n3 = args.iter().any(|a| a == "--no-n3");
    let page = args
        .iter()
        .position(|a| a == "--page")
        .and_then(|k| args.get(k + 1))
        .map(PathBuf::from);
    let dir = std::env::temp_dir().join(format!("palpate_bench_user_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());

    let n1 = simulate("N1", &dir);
    let (ccx, ccx_note) = match (!recorded).then(|| calculix(&dir)).flatten() {
        Some(r) => (r, "rerun in this run"),
        None => (CCX_RECORDED, "recorded 2026-11-23 (not rerun)"),
    };
    let n3 = (!no_n3).then(|| simulate("N3", &dir));
    std::fs::remove_dir_all(&dir).ok();

    let mut out = String::new();
    let bin = palpate();
    let profile = if bin.components().any(|c| c.as_os_str() == "debug") {
        "the dev-profile binary (opt-level 2, dependencies 3)"
    } else {
        "the release binary"
    };
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "unknown".into());
    out.push_str(&format!(
        "Machine: {cores} cores, load average {load} at the end of the run. \
         `palpate simulate --benchmark N1|N3 --law neo-hookean --param {C10} --csv F` \
         with default options (error estimate on), {profile}; CPU = user + system of the child process.\n\n"
    ));
    out.push_str("| run | mesh | wall (s) | CPU (s) | F(10) N | vs converged | palpate's estimate |\n|---|---|---|---|---|---|---|\n");
    let row = |name: &str, t: &Timed, conv: f64| {
        format!(
            "| {name} | {} | {:.1} | {:.1} | {:.6} | {:+.2} % | {} |\n",
            t.mesh,
            t.wall,
            t.cpu,
            t.force,
            pct(t.force, conv),
            t.estimate
        )
    };
    out.push_str(&row("palpate simulate --benchmark N1", &n1, N1_CONVERGED));
    out.push_str(&format!(
        "| CalculiX 2.20 n6, {ccx_note} | 480 CAX8R, 3078 unknowns, one thread | {:.1} | {:.1} | {:.6} | {:+.2} % | - |\n",
        ccx.0,
        ccx.1,
        ccx.2,
        pct(ccx.2, N1_CONVERGED)
    ));
    if let Some(n3) = &n3 {
        out.push_str(&row("palpate simulate --benchmark N3", n3, N3_CONVERGED));
    }
    out.push_str(&format!(
        "\nN1 against CalculiX: {:.0}x less CPU, {:.0}x less wall time.\n",
        ccx.1 / n1.cpu,
        ccx.0 / n1.wall
    ));
    print!("{out}");
    if let Some(page) = page {
        let (begin, end) = (
            "<!-- bench_user_path begin -->",
            "<!-- bench_user_path end -->",
        );
        let text = std::fs::read_to_string(&page).expect("page");
        let (Some(a), Some(b)) = (text.find(begin), text.find(end)) else {
            eprintln!("{}: no {begin} ... {end} section", page.display());
            std::process::exit(2);
        };
        let new = format!("{}{begin}\n{out}{}", &text[..a], &text[b..]);
        std::fs::write(&page, new).expect("write page");
        eprintln!("wrote the section of {}", page.display());
    }
}
