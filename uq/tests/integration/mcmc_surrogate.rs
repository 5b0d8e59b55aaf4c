//! The surrogate (reduced basis + GP per coefficient) reproduces the C1
//! model inside its training box, refuses outside it, survives its stored
//! form, and gives the same posterior as the model itself (the analytic
//! stand-in for an FE model, whose direct sampling would be too slow).

use palpate_analytic::C1Compression;
use palpate_core::ForwardModel;
use palpate_uq::likelihood::{fit_and_laplace, DataSet, NoiseModel, Posterior, Prior};
use palpate_uq::mcmc::{summarize, DemcSettings, Sampler};
use palpate_uq::surrogate::{ParamBox, Surrogate, SurrogateOptions, SurrogateRequest};
use std::sync::Arc;

use crate::common;
use common::c1_rp2_record as data;

fn posterior(model: Arc<dyn ForwardModel>) -> Posterior {
    let (loading, observed, sigma) = data();
    let ds = DataSet {
        name: "c1".into(),
        model,
        loading,
        observed,
        noise: NoiseModel::known(sigma),
    };
    Posterior::new(vec![ds], vec![Prior::Flat; 2]).unwrap()
}

#[test]
fn emulated_posterior_matches_the_direct_one() {
    let model = Arc::new(C1Compression::new("reduced-polynomial:2".parse().unwrap()));
    let direct = posterior(model.clone());
    let st = fit_and_laplace(&direct).unwrap();
    let (mean, sd) = st.laplace_physical(&direct);
    // Training box: Laplace mean +- 8 SD.
    let lower: Vec<f64> = (0..2).map(|k| mean[k] - 8.0 * sd[k]).collect();
    let upper: Vec<f64> = (0..2).map(|k| mean[k] + 8.0 * sd[k]).collect();
    let (loading, _, sigma) = data();
    let request = SurrogateRequest {
        model: model.as_ref(),
        loading: &loading,
        bounds: ParamBox::new(model.space(), &lower, &upper).unwrap(),
        options: SurrogateOptions {
            training_runs: 30,
            validation_runs: 20,
            ..Default::default()
        },
        description: "C1 rp2, test".into(),
    };
    let em = Surrogate::build(&request, None).unwrap();
    let v = em.validation().clone();
    eprintln!("basis {}; validation {v:?}", em.basis_size());
    // Far below the noise (sigma is 2 % of the peak force).
    assert!(v.max_relative_error < 1e-3, "{v:?}");
    let peak = 2.72;
    assert!(v.max_relative_error * peak < 0.05 * sigma);
    assert_eq!(em.error_variance(0).len(), loading.len());
    assert_eq!(em.key(), request.key());

    // The stored form answers the same.
    let back = Surrogate::from_json(&em.to_json()).unwrap();
    let mid: Vec<f64> = (0..2).map(|k| 0.5 * (lower[k] + upper[k])).collect();
    assert_eq!(
        back.predict(&mid, &loading).unwrap(),
        em.predict(&mid, &loading).unwrap()
    );
    // Outside the box: a refusal naming the parameter and the box.
    let mut out = mid.clone();
    out[1] = upper[1] + 0.5 * (upper[1] - lower[1]);
    let e = em.predict(&out, &loading).unwrap_err().to_string();
    assert!(e.contains("C20") && e.contains("trained box"), "{e}");
    // Another loading: refused too.
    let other = loading.with_drive(loading.drive.iter().map(|d| 0.5 * d).collect());
    assert!(em.predict(&mid, &other).is_err());

    let emulated = posterior(Arc::new(em));
    let st_e = fit_and_laplace(&emulated).unwrap();
    let sampler = Sampler::Demc(DemcSettings {
        draws: 4000,
        ..Default::default()
    });
    let a = sampler.run(&direct, &st.start, 3, None).unwrap();
    let b = sampler.run(&emulated, &st_e.start, 3, None).unwrap();
    let sa = summarize(
        &a.chains.map(|z| direct.space().from_unbounded(z)),
        &direct.names(),
    );
    let sb = summarize(
        &b.chains.map(|z| emulated.space().from_unbounded(z)),
        &emulated.names(),
    );
    for k in 0..2 {
        eprintln!(
            "{}: direct {:.6e} +- {:.3e}, emulated {:.6e} +- {:.3e}",
            sa[k].name, sa[k].mean, sa[k].sd, sb[k].mean, sb[k].sd
        );
        let mc = (sa[k].mcse_mean.powi(2) + sb[k].mcse_mean.powi(2)).sqrt();
        assert!(
            (sa[k].mean - sb[k].mean).abs() < 0.05 * sa[k].sd + 4.0 * mc,
            "{}",
            sa[k].name
        );
        assert!((sb[k].sd / sa[k].sd - 1.0).abs() < 0.05, "{}", sa[k].name);
        assert!(sb[k].rhat < 1.01);
    }
}
