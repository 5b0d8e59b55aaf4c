//! Likelihood options recover what generated the data: an inferred noise SD
//! and AR(1) coefficient; and the Laplace evidence prefers the law that made
//! the data.

use palpate_analytic::{C1Compression, Homogeneous, Mode};
use palpate_core::{Drive, ForwardModel, Loading, Table};
use palpate_uq::likelihood::{
    fit_and_laplace, Correlation, DataSet, NoiseModel, NoiseSd, Posterior, Prior,
};
use palpate_uq::mcmc::{chain_rng, summarize, DemcSettings, Sampler};
use rand::Rng;
use std::path::Path;
use std::sync::Arc;

fn sample(post: &Posterior, seed: u64) -> Vec<palpate_uq::mcmc::ParamSummary> {
    let st = fit_and_laplace(post).unwrap();
    let run = Sampler::Demc(DemcSettings {
        draws: 4000,
        ..Default::default()
    })
    .run(post, &st.start, seed, None)
    .unwrap();
    summarize(
        &run.chains.map(|z| post.space().from_unbounded(z)),
        &post.names(),
    )
}

#[test]
fn inferred_sigma_and_ar1_coefficient_are_recovered() {
    let model: Arc<dyn ForwardModel> = Arc::new(Homogeneous::new(
        "neo-hookean".parse().unwrap(),
        Mode::Uniaxial,
    ));
    let stretch: Vec<f64> = (0..300).map(|i| 1.0 + i as f64 / 299.0).collect();
    let loading = Loading::quasi_static(Drive::Stretch, stretch);
    let truth = [0.2];
    let clean = model.predict(&truth, &loading).unwrap();
    let (sigma, phi) = (0.02 * clean.last().unwrap(), 0.8);
    let mut rng = chain_rng(99, 0);
    let mut e = sigma * rng.sample::<f64, _>(rand_distr::StandardNormal);
    let observed: Vec<f64> = clean
        .iter()
        .map(|c| {
            let y = c + e;
            e = phi * e
                + sigma
                    * (1.0 - phi * phi).sqrt()
                    * rng.sample::<f64, _>(rand_distr::StandardNormal);
            y
        })
        .collect();
    let make = |correlation| {
        let ds = DataSet {
            name: "u".into(),
            model: model.clone(),
            loading: loading.clone(),
            observed: observed.clone(),
            noise: NoiseModel {
                sd: NoiseSd::Inferred(Prior::HalfNormal { sd: 1.0 }),
                correlation,
            },
        };
        Posterior::new(vec![ds], vec![Prior::Flat]).unwrap()
    };
    let ar1 = make(Correlation::Ar1Inferred(Prior::Uniform {
        lower: -1.0,
        upper: 1.0,
    }));
    assert_eq!(ar1.names(), vec!["C10", "sigma", "phi"]);
    let s = sample(&ar1, 1);
    for (p, t) in s.iter().zip([truth[0], sigma, phi]) {
        eprintln!(
            "{}: {:.5} +- {:.5} (truth {t:.5}), rhat {:.4}",
            p.name, p.mean, p.sd, p.rhat
        );
        assert!(
            (p.mean - t).abs() < 3.0 * p.sd,
            "{}: {} +- {} vs {t}",
            p.name,
            p.mean,
            p.sd
        );
        assert!(p.rhat < 1.01);
    }
    // Ignoring the correlation makes the C10 interval too narrow.
    let indep = sample(&make(Correlation::Independent), 2);
    eprintln!(
        "C10 sd: AR(1) {:.3e}, independent {:.3e}",
        s[0].sd, indep[0].sd
    );
    assert!(indep[0].sd < 0.6 * s[0].sd);
}

#[test]
fn laplace_evidence_prefers_the_generating_law() {
    let t = Table::read(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/validation/mcmc_c1_rp2_data.csv"),
    )
    .unwrap();
    let loading = Loading::quasi_static(
        Drive::DisplacementMm,
        t.column("displacement_mm").unwrap().to_vec(),
    );
    let observed = t.column("force_N").unwrap().to_vec();
    let evidence = |law: &str, priors: Vec<Prior>| {
        let ds = DataSet {
            name: "c1".into(),
            model: Arc::new(C1Compression::new(law.parse().unwrap())),
            loading: loading.clone(),
            observed: observed.clone(),
            noise: NoiseModel::inferred(Prior::HalfNormal { sd: 1.0 }),
        };
        let post = Posterior::new(vec![ds], priors).unwrap();
        assert!(post.priors_proper());
        fit_and_laplace(&post).unwrap().laplace.log_evidence
    };
    let c10 = Prior::LogNormal {
        mu: (1e-3f64).ln(),
        sigma: 1.0,
    };
    let nh = evidence("neo-hookean", vec![c10]);
    let rp2 = evidence(
        "reduced-polynomial:2",
        vec![
            c10,
            Prior::Normal {
                mean: 0.0,
                sd: 5e-3,
            },
        ],
    );
    eprintln!("log evidence: neo-Hookean {nh:.2}, reduced polynomial N=2 {rp2:.2}");
    assert!(rp2 - nh > 10.0, "{rp2} vs {nh}");
}
