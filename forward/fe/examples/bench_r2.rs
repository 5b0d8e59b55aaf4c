//! R2 speed bench (goal: a full pass in 30 s or less on 2 cores): the
//! docs/benchmarks.md R2 rolled pass, x 10 -> 140 mm every 0.5 mm, RD 6, the
//! three default nodules, frictionless, at the accuracy-level mesh (level 1,
//! h = 2 mm: within 0.63 % of h = 1 at the RD 3 presses of
//! docs/validation/fe.md R2), solved by `R2Rolling::rolled_pass` in
//! `--segments` parallel segments (default 2, the cores here). Prints the
//! wall time, the CPU time (user + sys of the process, all threads), and the
//! force error of the pass against presses on the finer mesh (h = 1 mm) at
//! a few positions over and between the nodules (a press at x equals the
//! rolled state at x for this contact, tests/integration/r2_rolling.rs).
//!
//! `cargo run --release -p palpate-fe --example bench_r2 -- [--segments 2]
//!  [--step 0.5] [--rd 6] [--x 37.5,56.25,75,112.5|none]
//!  [--from X0] [--to X1] [--no-press] [--predictor secant|0|1] [--h MM]`
//! (`--from`/`--to`: a shorter pass, for profiling; `--no-press`: print the
//! pass forces at `--x` without the h = 1 presses; `--predictor`: the
//! stepper's secant instead of the default wheel-following prediction,
//! `R2Rolling::predictor`; `--h`: another element size than level 1's 2 mm)

use std::time::Instant;

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::R2Rolling;
use palpate_material::Law;

#[path = "common/cpu.rs"]
mod cpu;
use cpu::cpu_seconds;

fn list(v: &str) -> Vec<f64> {
    if v == "none" {
        return Vec::new();
    }
    v.split(',').map(|x| x.parse().expect("a number")).collect()
}

fn main() {
    let mut segments = 2usize;
    let mut step = 0.5;
    let mut rd = 6.0;
    let mut xs = vec![37.5, 56.25, 75.0, 112.5];
    let mut from: Option<f64> = None;
    let mut to: Option<f64> = None;
    let mut presses = true;
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let Some(k) = args.iter().position(|a| a == "--rd") {
        rd = args[k + 1].parse().expect("mm");
    }
    let mut model = R2Rolling::new(Law::ArrudaBoyce, Law::ArrudaBoyce, rd);
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().expect("a value after the option").clone();
        match a.as_str() {
            "--segments" => segments = value().parse().expect("a count"),
            "--step" => step = value().parse().expect("mm"),
            "--rd" => rd = value().parse().expect("mm"),
            "--x" => xs = list(&value()),
            "--penalty" => model.penalty = value().parse().expect("a factor"),
            "--smoothing" => model.contact_smoothing = value().parse().expect("mm"),
            "--max-update" => {
                model.options.max_update = match value().as_str() {
                    "none" => None,
                    v => Some(v.parse().expect("mm")),
                }
            }
            "--tol" => model.options.tolerance = value().parse().expect("a tolerance"),
            "--max-step" => model.options.max_step = value().parse().expect("mm"),
            "--first-step" => model.options.first_step = value().parse().expect("mm"),
            "--symmetric" => model.options.symmetric = value().parse().expect("true|false"),
            "--line-search" => {
                model.options.line_search = match value().as_str() {
                    "slope" => palpate_fe::LineSearch::Slope,
                    "residual" => palpate_fe::LineSearch::Residual,
                    v => panic!("--line-search slope|residual, not {v}"),
                }
            }
            "--chord" => model.options.reuse_factorisation = value().parse().expect("true|false"),
            "--augment" => {
                model.pure_penalty = false;
                model.options.max_augmentations = value().parse().expect("a count");
            }
            "--predictor" => {
                model.predictor = match value().as_str() {
                    "secant" => None,
                    v => Some(v.parse().expect("secant|0|1")),
                }
            }
            "--friction" => model.friction = value().parse().expect("a coefficient"),
            "--h" => model.element_size = Some(value().parse().expect("mm")),
            "--tangent-penalty" => model.tangent_penalty = value().parse().expect("a fraction"),
            "--no-press" => presses = false,
            "--from" => from = Some(value().parse().expect("mm")),
            "--to" => to = Some(value().parse().expect("mm")),
            other => panic!("unknown option {other}"),
        }
    }
    let theta = R2Rolling::BENCHMARK_PARAMS;
    if let Some(x) = from {
        model.press_x = x;
    }
    if let Some(x) = to {
        model.roll_to = x;
    }
    let positions = model.pass_positions(step);
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let mesh = model.build_mesh().expect("the R2 mesh");
    println!(
        "mesh: {} cells, {} nodes",
        mesh.cell_count(),
        mesh.nodes.len()
    );
    println!(
        "R2 full pass: x {}..{} mm every {step} mm ({} positions), RD {rd}, nodules 37.5:10,75:15,112.5:20, level {} (h = {} mm), {segments} segments, {cores} cores ({})",
        model.press_x,
        model.roll_to,
        positions.len(),
        model.level,
        model.h(),
        cpu_model()
    );
    let (c0, t0) = (cpu_seconds(false), Instant::now());
    let (pass, last) = model
        .rolled_pass(&theta, &positions, segments, None)
        .unwrap_or_else(|e| panic!("the pass failed: {e}"));
    let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds(false) - c0);
    if let Some(sys) = &last {
        let s = sys.stats;
        println!(
            "last segment: {} increments, {} Newton iterations ({:.2} per increment), {} factorisations, {} chord steps, {} cuts, assembly {:.1} s, solve {:.1} s, {} equations",
            s.increments,
            s.iterations,
            s.iterations as f64 / s.increments.max(1) as f64,
            s.factorisations,
            s.chord_steps,
            s.cuts,
            s.assembly_seconds,
            s.solve_seconds,
            sys.equations()
        );
    }
    if let (Some(f), Some(x)) = (pass.last(), positions.last()) {
        println!("force at x = {x} mm: {:.5} N, force_x {:+.5} N", f[0], f[1]);
    }
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "| pass | wall s | CPU s (user+sys) | target |\n|---|---|---|---|\n| {} positions | {wall:.1} | {cpu:.1} | 30 s wall on 2 cores: {} |",
        positions.len(),
        if wall <= 30.0 { "met" } else { "NOT met" }
    );
    println!(
        "load average at the end: {}",
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    );
    let h = model.h();
    println!("\n| x mm | pass h={h} N | press h=1 N | error h={h} | Fx pass N | CPU s (h=1 press) |\n|---|---|---|---|---|---|");
    let mut fine = model.clone();
    fine.element_size = Some(1.0);
    for &x in &xs {
        // the pass position nearest to x (56.25 is between grid points)
        let k = (0..positions.len())
            .min_by(|&a, &b| {
                (positions[a] - x)
                    .abs()
                    .total_cmp(&(positions[b] - x).abs())
            })
            .expect("a pass position");
        let x = positions[k];
        if !presses {
            println!(
                "| {x} | {:.4} | not run | | {:+.4} | |",
                pass[k][0], pass[k][1]
            );
            continue;
        }
        let mut p = fine.clone();
        p.press_x = x;
        let n = (rd / 0.5).round() as usize;
        let depths: Vec<f64> = (1..=n).map(|j| rd * j as f64 / n as f64).collect();
        let c = cpu_seconds(false);
        let f = p
            .predict(
                &theta,
                &Loading::quasi_static(Drive::DisplacementMm, depths),
            )
            .unwrap_or_else(|e| panic!("press at {x} (h = 1): {e}"));
        let f1 = *f.last().expect("one sample");
        println!(
            "| {x} | {:.4} | {f1:.4} | {:+.2} % | {:+.4} | {:.1} |",
            pass[k][0],
            100.0 * (pass[k][0] - f1) / f1,
            pass[k][1],
            cpu_seconds(false) - c
        );
    }
}

/// The processor's name (Linux: `model name` of /proc/cpuinfo), for the
/// record: the same pass takes 2.4 x longer on some 2-core VMs than on
/// others (docs/validation/fe.md R2, "Speed").
fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "processor unknown".into())
}
