//! Evidence estimates against the exact evidence of a linear-Gaussian model.
//!
//! The C1 force of the reduced polynomial N = 2 is linear in (C10, C20):
//! F = A theta. With known sigma and normal priors N(mu0, S0), the evidence
//! is exact: y ~ N(A mu0, sigma^2 I + A S0 A^T) (Bishop 2006, eq. 3.86 in
//! its general Gaussian form). Both the Laplace estimate and thermodynamic
//! integration must reproduce it.

use nalgebra::{DMatrix, DVector};
use palpate_analytic::C1Compression;
use palpate_core::ForwardModel;
use palpate_uq::likelihood::{
    fit_and_laplace, thermodynamic_integration, DataSet, NoiseModel, Posterior, Prior,
};
use palpate_uq::mcmc::{DemcSettings, Sampler};
use std::sync::Arc;

use crate::common;

#[test]
fn laplace_and_thermodynamic_integration_match_the_exact_evidence() {
    let (loading, y, sigma) = common::c1_rp2_record();
    let model = Arc::new(C1Compression::new("reduced-polynomial:2".parse().unwrap()));
    let (mu0, sd0) = ([7e-4, 2e-3], [2e-4, 1e-3]);

    // Exact evidence.
    let n = y.len();
    let f1 = model.predict(&[1e-3, 0.0], &loading).unwrap();
    let f2 = model.predict(&[1e-3, 1e-3], &loading).unwrap();
    let a = DMatrix::from_fn(n, 2, |i, k| {
        if k == 0 {
            f1[i] / 1e-3
        } else {
            (f2[i] - f1[i]) / 1e-3
        }
    });
    let s0 = DMatrix::from_diagonal(&DVector::from_vec(vec![sd0[0] * sd0[0], sd0[1] * sd0[1]]));
    let cov = DMatrix::identity(n, n) * (sigma * sigma) + &a * s0 * a.transpose();
    let r = DVector::from_vec(y.clone()) - &a * DVector::from_vec(mu0.to_vec());
    let ch = cov.cholesky().unwrap();
    let log_det: f64 = 2.0 * (0..n).map(|i| ch.l()[(i, i)].ln()).sum::<f64>();
    let exact = -0.5 * n as f64 * (2.0 * std::f64::consts::PI).ln()
        - 0.5 * log_det
        - 0.5 * r.dot(&ch.solve(&r));

    let ds = DataSet {
        name: "c1".into(),
        model: model.clone(),
        loading,
        observed: y,
        noise: NoiseModel::known(sigma),
    };
    let priors = vec![
        Prior::Normal {
            mean: mu0[0],
            sd: sd0[0],
        },
        Prior::Normal {
            mean: mu0[1],
            sd: sd0[1],
        },
    ];
    let post = Posterior::new(vec![ds], priors).unwrap();
    let st = fit_and_laplace(&post).unwrap();
    let sampler = Sampler::Demc(DemcSettings {
        tune: 500,
        draws: 1500,
        ..Default::default()
    });
    let ti = thermodynamic_integration(&post, &st.laplace.mode, 20, &sampler, 5).unwrap();
    eprintln!(
        "log evidence: exact {exact:.4}, Laplace {:.4}, thermodynamic {:.4} ({} evaluations)",
        st.laplace.log_evidence, ti.log_evidence, ti.evaluations
    );
    assert!(
        (st.laplace.log_evidence - exact).abs() < 0.05,
        "Laplace {}",
        st.laplace.log_evidence
    );
    // 20 rungs: the ladder's discretisation error is ~0.5 with 10 rungs, ~0.005 with 20.
    assert!(
        (ti.log_evidence - exact).abs() < 0.05,
        "TI {}",
        ti.log_evidence
    );
}
