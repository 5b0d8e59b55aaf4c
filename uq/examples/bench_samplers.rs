//! Sampler benchmark on the C1 reduced-polynomial (N = 2) posterior (the
//! problem of `uq/tests/integration/mcmc_c1.rs` and `docs/validation/mcmc_emcee.py`):
//! ESS per second and per 1000 model evaluations for each sampler, beside
//! emcee and PyMC when their result files are present
//! (`docs/validation/mcmc_emcee.json`, `mcmc_pymc.json`, written by the
//! scripts of the same names on the same machine).
//!
//!     cargo run --release -p palpate-uq --example bench_samplers
//!
//! ESS is the minimum bulk ESS over the parameters; times are the sampling
//! wall time (the least-squares fit and Laplace start, timed separately, are
//! printed once).

use palpate_analytic::C1Compression;
use palpate_core::ForwardModel;
use palpate_uq::likelihood::{fit_and_laplace, DataSet, NoiseModel, Posterior, Prior};
use palpate_uq::mcmc::{summarize, DemcSettings, EnsembleSettings, NutsSettings, Sampler};
use std::path::Path;
use std::sync::Arc;

#[path = "../tests/integration/common/mod.rs"]
mod common;

fn main() {
    let (loading, observed, sigma) = common::c1_rp2_record();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/validation");
    let model: Arc<dyn ForwardModel> =
        Arc::new(C1Compression::new("reduced-polynomial:2".parse().unwrap()));
    let post = Posterior::new(
        vec![DataSet {
            name: "c1".into(),
            model,
            loading,
            observed,
            noise: NoiseModel::known(sigma),
        }],
        vec![Prior::Flat; 2],
    )
    .unwrap();
    let t0 = std::time::Instant::now();
    let start = fit_and_laplace(&post).unwrap();
    println!(
        "start: LM fit + Laplace in {:.3} s ({} + {} evaluations); threads: {}",
        t0.elapsed().as_secs_f64(),
        start.fit.evaluations,
        start.laplace.evaluations,
        rayon::current_num_threads()
    );
    {
        use palpate_uq::mcmc::LogDensity;
        let mut w = post.worker();
        let n = 20_000;
        let t1 = std::time::Instant::now();
        let mut acc = 0.0;
        for i in 0..n {
            let mut z = start.start.center.clone();
            z[0] += 1e-9 * i as f64;
            acc += w.log_density(&z);
        }
        println!(
            "one log-density evaluation (200-point C1 curve, one thread): {:.2} us (checksum {acc:.3e})",
            1e6 * t1.elapsed().as_secs_f64() / n as f64
        );
        let ds = &post.datasets()[0];
        let mut ev = ds.model.evaluator();
        let mut out = vec![0.0; ds.loading.len()];
        let theta = post.space().from_unbounded(&start.start.center);
        let t2 = std::time::Instant::now();
        for i in 0..n {
            let th = [theta[0] * (1.0 + 1e-9 * i as f64), theta[1]];
            ev.predict_into(&th, &ds.loading, &mut out).unwrap();
            acc += out[1];
        }
        println!(
            "of which the forward model alone: {:.2} us (checksum {acc:.3e})",
            1e6 * t2.elapsed().as_secs_f64() / n as f64
        );
    }
    let samplers = [
        Sampler::Ensemble(EnsembleSettings {
            ensembles: 2,
            walkers: 16,
            tune: 1000,
            draws: 12000,
            ..Default::default()
        }),
        Sampler::Demc(DemcSettings {
            populations: 2,
            chains: 3,
            tune: 2000,
            draws: 20000,
            ..Default::default()
        }),
        Sampler::Nuts(NutsSettings {
            chains: 4,
            tune: 1000,
            draws: 1000,
            ..Default::default()
        }),
    ];
    println!(
        "{:<22} {:>10} {:>10} {:>9} {:>8} {:>10} {:>14}",
        "sampler", "draws", "evals", "wall_s", "ess_min", "ess/s", "ess/1000 evals"
    );
    for s in &samplers {
        let run = s.run(&post, &start.start, 1, None).unwrap();
        let x = run.chains.map(|z| post.space().from_unbounded(z));
        let sum = summarize(&x, &post.names());
        let ess = sum.iter().map(|p| p.ess_bulk).fold(f64::INFINITY, f64::min);
        let rhat = sum.iter().map(|p| p.rhat).fold(0.0, f64::max);
        println!(
            "{:<22} {:>10} {:>10} {:>9.3} {:>8.0} {:>10.0} {:>14.1}   (max R-hat {rhat:.4})",
            format!("palpate {}", run.sampler),
            x.n_chains * x.n_draws,
            run.evaluations,
            run.wall_time_s,
            ess,
            ess / run.wall_time_s,
            1000.0 * ess / run.evaluations as f64
        );
    }
    for (name, file, time_key, evals_key) in [
        ("emcee", "mcmc_emcee.json", "wall_time_s", "evaluations"),
        (
            "PyMC NUTS",
            "mcmc_pymc.json",
            "sampling_time_s",
            "gradient_evaluations",
        ),
    ] {
        let Ok(text) = std::fs::read_to_string(dir.join(file)) else {
            println!(
                "{name:<22} (no {file}: run docs/validation/{})",
                file.replace(".json", ".py")
            );
            continue;
        };
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let ess = ["C10", "C20"]
            .iter()
            .map(|p| v["params"][p]["ess_bulk"].as_f64().unwrap())
            .fold(f64::INFINITY, f64::min);
        let wall = v[time_key].as_f64().unwrap();
        let evals = v[evals_key].as_f64().unwrap();
        println!(
            "{:<22} {:>10} {:>10} {:>9.3} {:>8.0} {:>10.0} {:>14.1}   (from {file})",
            name,
            "-",
            evals,
            wall,
            ess,
            ess / wall,
            1000.0 * ess / evals
        );
    }
}
