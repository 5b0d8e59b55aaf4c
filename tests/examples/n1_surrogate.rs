//! Posterior of an FE model: N1 needle indentation (coarse mesh, friction
//! 0.8, exact incompressibility), reduced polynomial N = 2 (C10, C20).
//!
//! Direct MCMC on the FE model would need ~1e5 solves; instead a GP curve
//! surrogate is trained on a Halton design of FE runs in a box of +-40 %
//! (C10) and 0..2x (C20) around the values of the synthetic experiment, validated against fresh
//! FE runs, and the posterior is sampled on the surrogate (DE-MCz).
//!
//! The "measurement" is the FE curve at ecoflex-rp2 (C10 = 686.428 Pa,
//! C20 = 1929.606 Pa), every 0.25 mm to 10 mm, plus Gaussian noise of SD 2 %
//! of the peak force (seeded).
//!
//!     cargo run --release -p palpate-tests --example n1_surrogate [RUNS]

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::{Bulk, MeshDensity, N1Needle};
use palpate_uq::likelihood::{fit_and_laplace, DataSet, NoiseModel, Posterior, Prior};
use palpate_uq::mcmc::{chain_rng, summarize, DemcSettings, Sampler};
use palpate_uq::surrogate::{ParamBox, Surrogate, SurrogateOptions, SurrogateRequest};
use rand::Rng;
use std::sync::Arc;
use std::time::Instant;

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(30);
    let truth = [686.428e-6, 1929.606e-6];
    let mut fe = N1Needle::new("reduced-polynomial:2".parse().unwrap());
    fe.mesh = MeshDensity::COARSE;
    fe.bulk = Bulk::Exact;
    fe.options.max_step = 0.5;
    let drive: Vec<f64> = (1..=40).map(|i| 0.25 * i as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive);
    println!("threads: {}", rayon::current_num_threads());

    let t = Instant::now();
    let clean = fe
        .predict(&truth, &loading)
        .expect("FE run at the true values");
    let one_run = t.elapsed().as_secs_f64();
    let peak = clean.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let sigma = 0.02 * peak;
    let mut rng = chain_rng(20240611, 0);
    let observed: Vec<f64> = clean
        .iter()
        .map(|f| f + sigma * rng.sample::<f64, _>(rand_distr::StandardNormal))
        .collect();
    println!("one FE run: {one_run:.2} s; peak force {peak:.4} N, sigma {sigma:.4} N");

    // The box must hold the whole posterior (the surrogate's bounds are the
    // posterior's support): C20 is much less well determined by this curve
    // than C10, so its range is wider.
    let lower = [0.6 * truth[0], 0.0];
    let upper = [1.4 * truth[0], 2.0 * truth[1]];
    let t = Instant::now();
    let request = SurrogateRequest {
        model: &fe,
        loading: &loading,
        bounds: ParamBox::new(fe.space(), &lower, &upper).expect("box"),
        options: SurrogateOptions {
            training_runs: runs,
            validation_runs: 6,
            ..Default::default()
        },
        description: "n1_surrogate example".into(),
    };
    let em = Surrogate::build(&request, None).expect("training runs");
    let train_s = t.elapsed().as_secs_f64();
    let v = em.validation().clone();
    println!(
        "trained on {runs} FE runs + 6 held out in {train_s:.1} s ({} basis vectors); held-out max |error| = {:.2e} of the peak force ({:.3} sigma), RMS {:.2e}",
        em.basis_size(),
        v.max_relative_error,
        v.max_relative_error * peak / sigma,
        v.rms_relative_error
    );
    let error_variance = em.error_variance(0);

    let ds = DataSet {
        name: "n1".into(),
        model: Arc::new(em),
        loading,
        observed,
        noise: NoiseModel::known(sigma),
    };
    let post = Posterior::new(vec![ds], vec![Prior::Flat; 2])
        .unwrap()
        .with_model_error(0, error_variance)
        .unwrap();
    let t = Instant::now();
    let st = fit_and_laplace(&post).expect("start");
    let run = Sampler::Demc(DemcSettings {
        draws: 12000,
        ..Default::default()
    })
    .run(&post, &st.start, 1, None)
    .unwrap();
    let s = summarize(
        &run.chains.map(|z| post.space().from_unbounded(z)),
        &post.names(),
    );
    println!(
        "posterior on the surrogate in {:.2} s ({} surrogate evaluations):",
        t.elapsed().as_secs_f64(),
        run.evaluations
    );
    for (k, p) in s.iter().enumerate() {
        println!(
            "  {}: mean {:.5e} sd {:.3e} hdi94 [{:.5e}, {:.5e}] rhat {:.4} ess_bulk {:.0}  (truth {:.5e}, {:+.2} sd)",
            p.name,
            p.mean,
            p.sd,
            p.hdi_3,
            p.hdi_97,
            p.rhat,
            p.ess_bulk,
            truth[k],
            (p.mean - truth[k]) / p.sd
        );
        let margin = ((p.hdi_3 - lower[k]).min(upper[k] - p.hdi_97)) / p.sd;
        println!("     94 % HDI lies {margin:.1} sd inside the training box");
    }
    println!(
        "total FE runs {} (training {runs} + validation 6 + data 1); equivalent direct DE-MCz would need {} FE runs",
        runs + 7,
        run.evaluations
    );
}
