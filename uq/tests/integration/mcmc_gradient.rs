//! The exact-gradient path of the posterior (model sensitivities through
//! palpate-inverse's hook) agrees with finite differences, and NUTS with it
//! gives the same posterior for fewer evaluations.

use palpate_analytic::C1Compression;
use palpate_core::{Drive, ForwardError, ForwardModel, Loading, Table};
use palpate_inverse::Sensitivities;
use palpate_uq::likelihood::{fit_and_laplace, DataSet, NoiseModel, Posterior, Prior};
use palpate_uq::mcmc::{summarize, LogDensity, NutsSettings, Sampler};
use std::path::Path;
use std::sync::Arc;

/// Exact sensitivities of the C1 reduced polynomial N = 2, whose force is
/// linear in (C10, C20): the columns are the forces of unit parameters.
struct C1Linear(C1Compression);

impl Sensitivities for C1Linear {
    fn predict_with_jacobian(
        &self,
        theta: &[f64],
        loading: &Loading,
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), ForwardError> {
        let f = self.0.predict(theta, loading)?;
        let a = self.0.predict(&[1.0, 0.0], loading)?;
        let ab = self.0.predict(&[1.0, 1.0], loading)?;
        let b = ab.iter().zip(&a).map(|(x, y)| x - y).collect();
        Ok((f, vec![a, b]))
    }
}

fn posterior(exact: bool) -> Posterior {
    let t = Table::read(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/validation/mcmc_c1_rp2_data.csv"),
    )
    .unwrap();
    let model = C1Compression::new("reduced-polynomial:2".parse().unwrap());
    let ds = DataSet {
        name: "c1".into(),
        model: Arc::new(model.clone()),
        loading: Loading::quasi_static(
            Drive::DisplacementMm,
            t.column("displacement_mm").unwrap().to_vec(),
        ),
        observed: t.column("force_N").unwrap().to_vec(),
        noise: NoiseModel::inferred(Prior::HalfNormal { sd: 1.0 }),
    };
    let priors = vec![
        Prior::LogNormal {
            mu: -7.0,
            sigma: 1.0,
        },
        Prior::Normal {
            mean: 0.0,
            sd: 5e-3,
        },
    ];
    let post = Posterior::new(vec![ds], priors).unwrap();
    if exact {
        post.with_sensitivities(0, Arc::new(C1Linear(model)))
    } else {
        post
    }
}

#[test]
fn exact_gradient_matches_finite_differences() {
    let (ex, fd) = (posterior(true), posterior(false));
    let (mut we, mut wf) = (ex.worker(), fd.worker());
    let z0 = ex.space().to_unbounded(&[6.8e-4, 1.98e-3, 0.05]);
    for dz in [[0.0, 0.0, 0.0], [0.01, -2e-5, 0.1], [-0.02, 3e-5, -0.2]] {
        let z: Vec<f64> = z0.iter().zip(dz).map(|(a, b)| a + b).collect();
        let (mut ge, mut gf) = ([0.0; 3], [0.0; 3]);
        let (ve, ne) = we.value_and_gradient(&z, &mut ge);
        let (vf, nf) = wf.value_and_gradient(&z, &mut gf);
        assert_eq!((ne, nf), (1, 7));
        assert!((ve - vf).abs() < 1e-9 * vf.abs(), "{ve} vs {vf}");
        assert!((ve - we.log_density(&z)).abs() < 1e-9 * vf.abs());
        for k in 0..3 {
            // FD steps of 1e-5 on C20 (~2e-3) are coarse; compare relative to the gradient's scale.
            let scale = gf.iter().map(|g| g.abs()).fold(1.0, f64::max);
            assert!(
                (ge[k] - gf[k]).abs() < 1e-6 * scale,
                "{k}: exact {} fd {}",
                ge[k],
                gf[k]
            );
        }
    }
}

#[test]
fn nuts_with_exact_gradients_gives_the_same_posterior_for_fewer_evaluations() {
    let (ex, fd) = (posterior(true), posterior(false));
    let st = fit_and_laplace(&fd).unwrap();
    let nuts = Sampler::Nuts(NutsSettings {
        tune: 500,
        draws: 600,
        ..Default::default()
    });
    let re = nuts.run(&ex, &st.start, 4, None).unwrap();
    let rf = nuts.run(&fd, &st.start, 4, None).unwrap();
    let se = summarize(
        &re.chains.map(|z| ex.space().from_unbounded(z)),
        &ex.names(),
    );
    let sf = summarize(
        &rf.chains.map(|z| fd.space().from_unbounded(z)),
        &fd.names(),
    );
    for (a, b) in se.iter().zip(&sf) {
        let mc = (a.mcse_mean.powi(2) + b.mcse_mean.powi(2)).sqrt();
        assert!((a.mean - b.mean).abs() < 4.0 * mc, "{}", a.name);
        assert!((a.sd / b.sd - 1.0).abs() < 0.08, "{}", a.name);
        assert!(a.rhat < 1.01);
    }
    eprintln!(
        "evaluations: exact {} vs finite differences {}",
        re.evaluations, rf.evaluations
    );
    assert!(re.evaluations * 5 < rf.evaluations);
}
