//! Benchmark of exact FE sensitivities in a calibration: an N1
//! two-parameter fit (C10 and the needle's friction) by Levenberg-Marquardt
//! on one synthetic record and one mesh, side by side by the
//! finite-difference route (central differences of whole runs) and the
//! exact route (direct differentiation through the converged increments,
//! `palpate_fe::sensitivity`, plugged in by `DataSet::with_model_sensitivities`).
//!
//! Prints per route the iterations, objective evaluations (forward runs:
//! with exact sensitivities each run gives its Jacobian too, so the
//! Jacobian of an accepted point costs none) and Jacobians, the runs per
//! iteration, the CPU seconds (user + system of this process), the FE-run equivalents
//! (CPU over the CPU of one plain run at the truth), and the estimates with
//! their standard errors.
//!
//! ```text
//! cargo run -p palpate-studies --example bench_sensitivity -- [--level L] [--depth D]
//! ```
//!
//! `--level` (default 1, the coarse N1 mesh; 2 is the default mesh of N1)
//! and `--depth` (default 5 mm, samples every 0.5 mm) choose the problem.
//! The synthetic record is the model's force at C10 = 1.101295e-3 MPa and
//! friction 0.3 with a deterministic 0.5 % ripple; both fits start at
//! C10 = 0.8e-3, friction 0.5.

use std::sync::Arc;

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::{MeshDensity, N1Needle};
use palpate_inverse::{fit, DataSet, FitOptions, Method, Objective, ResidualKind};

#[path = "../../forward/fe/examples/common/cpu.rs"]
mod cpu;
use cpu::cpu_seconds;

const TRUTH: [f64; 2] = [1101.295e-6, 0.3];
const START: [f64; 2] = [0.8e-3, 0.5];

fn arg(name: &str, default: f64) -> f64 {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .map(|v| {
            v.parse()
                .unwrap_or_else(|_| panic!("{name} {v}: expected a number"))
        })
        .unwrap_or(default)
}

fn main() {
    let level = arg("--level", 1.0);
    let depth = arg("--depth", 5.0);
    let mut m = N1Needle::new("neo-hookean".parse().expect("a law"));
    m.mesh = MeshDensity {
        level: level as usize,
    };
    m.friction = TRUTH[1];
    m.set_friction_parameter(true);
    let model: Arc<dyn ForwardModel> = Arc::new(m);
    let n = (depth / 0.5).round() as usize;
    let drive: Vec<f64> = (1..=n).map(|k| 0.5 * k as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive);

    let c0 = cpu_seconds(false);
    let clean = model
        .predict(&TRUTH, &loading)
        .expect("the synthetic record");
    let run_cpu = cpu_seconds(false) - c0;
    let observed: Vec<f64> = clean
        .iter()
        .enumerate()
        .map(|(i, f)| f * (1.0 + 0.005 * (1.7 * i as f64).sin()))
        .collect();
    println!(
        "N1 (level {level}, needle, neo-Hookean, friction as a parameter), {n} samples to {depth} mm"
    );
    println!("one plain run: {run_cpu:.1} s CPU");
    println!(
        "{:<20} {:>5} {:>6} {:>5} {:>7} {:>8} {:>8} {:>14} {:>10} {:>10} {:>10}",
        "route",
        "iter",
        "evals",
        "jacs",
        "runs/it",
        "CPU s",
        "FE runs",
        "C10 MPa",
        "SE",
        "friction",
        "SE"
    );
    for exact in [false, true] {
        let mut set = DataSet::new(
            "synthetic",
            Arc::clone(&model),
            loading.clone(),
            observed.clone(),
        );
        if exact {
            set = set.with_model_sensitivities();
            assert!(set.sensitivities.is_some(), "N1 offers exact sensitivities");
        }
        let objective =
            Objective::new(vec![set], ResidualKind::Absolute, &[]).expect("an objective");
        let options = FitOptions {
            start: Some(START.to_vec()),
            ..FitOptions::with_method(Method::LevenbergMarquardt(Default::default()))
        };
        let c0 = cpu_seconds(false);
        let report = fit(&objective, &options).expect("a fit");
        let cpu = cpu_seconds(false) - c0;
        let p = &report.parameters;
        println!(
            "{:<20} {:>5} {:>6} {:>5} {:>7.2} {:>8.1} {:>8.1} {:>14.6e} {:>10.2e} {:>10.5} {:>10.2e}",
            if exact {
                "exact sensitivities"
            } else {
                "finite differences"
            },
            report.iterations,
            report.evaluations,
            report.jacobians,
            report.evaluations as f64 / report.iterations.max(1) as f64,
            cpu,
            cpu / run_cpu,
            p[0].value,
            p[0].standard_error.unwrap_or(f64::NAN),
            p[1].value,
            p[1].standard_error.unwrap_or(f64::NAN),
        );
    }
}
