//! Benchmark: Levenberg-Marquardt calibration of the C1 compression model
//! (reduced polynomial N = 2, `ecoflex-rp2`) on 200 samples.
//!
//! `cargo run --release -p palpate-inverse --example bench_lm`
//!
//! Data: the analytic C1 force for C10 = 686.428 Pa, C20 = 1929.606 Pa,
//! displacement 0..2 mm (200 samples), times the deterministic perturbation
//! `1 + 0.02 sin(1.7 i)` (reproducible in `docs/validation/bench_lm_scipy.py`).
//! Start: the law's initial values (C10 = 1e-3 MPa, C20 = 0). Each row is the
//! median (and minimum) wall time of repeated complete fits (`fit`: solver
//! plus final statistics).

use palpate_analytic::C1Compression;
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_inverse::{
    fit, DataSet, FdOptions, FitOptions, Method, Objective, QuasiNewtonOptions, ResidualKind,
};
use palpate_material::Law;
use std::sync::Arc;
use std::time::Instant;

fn main() {
    let model: Arc<dyn ForwardModel> = Arc::new(C1Compression::new(Law::ReducedPolynomial(2)));
    let d: Vec<f64> = (0..200).map(|i| 2.0 * i as f64 / 199.0).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, d);
    let truth = [686.428e-6, 1929.606e-6];
    let clean = model.predict(&truth, &loading).expect("C1 evaluates");
    let observed: Vec<f64> = clean
        .iter()
        .enumerate()
        .map(|(i, f)| f * (1.0 + 0.02 * (1.7 * i as f64).sin()))
        .collect();
    let set = DataSet::new("C1 rp2", model, loading, observed);
    let objective = Objective::new(vec![set], ResidualKind::Absolute, &[]).expect("objective");
    let serial = FdOptions {
        parallel: false,
        ..FdOptions::default()
    };
    let rows: Vec<(&str, FitOptions)> = vec![
        ("LM, parallel central FD", FitOptions::default()),
        (
            "LM, serial central FD",
            FitOptions {
                fd: serial,
                ..FitOptions::default()
            },
        ),
        (
            "LM, serial forward FD",
            FitOptions {
                fd: FdOptions {
                    central: false,
                    ..serial
                },
                ..FitOptions::default()
            },
        ),
        (
            "BFGS, serial central FD",
            FitOptions {
                method: Method::Bfgs(QuasiNewtonOptions::default()),
                fd: serial,
                ..FitOptions::default()
            },
        ),
        (
            "L-BFGS(5), serial central FD",
            FitOptions {
                method: Method::Lbfgs {
                    memory: 5,
                    options: QuasiNewtonOptions::default(),
                },
                fd: serial,
                ..FitOptions::default()
            },
        ),
    ];
    let repeats = 101;
    println!(
        "C1 reduced-polynomial N=2, 200 samples, {repeats} repeats, {} rayon threads",
        rayon::current_num_threads()
    );
    println!("| method | median ms | min ms | iterations | evaluations | SSE (N^2) | C10 (Pa) | C20 (Pa) |");
    println!("|---|---|---|---|---|---|---|---|");
    for (label, options) in rows {
        let mut times = Vec::with_capacity(repeats);
        let mut last = None;
        for _ in 0..repeats {
            let t0 = Instant::now();
            let r = fit(&objective, &options).expect("fit");
            times.push(t0.elapsed().as_secs_f64() * 1e3);
            last = Some(r);
        }
        times.sort_by(f64::total_cmp);
        let r = last.expect("ran");
        println!(
            "| {label} | {:.3} | {:.3} | {} | {} | {:.6e} | {:.4} | {:.4} |",
            times[repeats / 2],
            times[0],
            r.iterations,
            r.evaluations,
            r.sse,
            r.value("C10").unwrap_or(f64::NAN) * 1e6,
            r.value("C20").unwrap_or(f64::NAN) * 1e6,
        );
    }
}
