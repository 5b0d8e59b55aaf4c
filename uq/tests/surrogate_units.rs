//! A surrogate assembled from its design's runs computed one at a time
//! (`Surrogate::design`, `run_point`, `from_runs`: what a study's shards
//! do) is the surrogate `Surrogate::build` makes in one go, and a wrong
//! number of runs is refused.

use palpate_analytic::C1Compression;
use palpate_core::ForwardModel;
use palpate_uq::surrogate::{ParamBox, Surrogate, SurrogateOptions, SurrogateRequest};

mod common;
use common::c1_rp2_record as data;

#[test]
fn runs_one_at_a_time_assemble_to_the_built_surrogate() {
    let model = C1Compression::new("reduced-polynomial:2".parse().unwrap());
    let (loading, _, _) = data();
    let request = SurrogateRequest {
        model: &model,
        loading: &loading,
        bounds: ParamBox::new(model.space(), &[4e-4, 1e-3], &[1e-3, 3e-3]).unwrap(),
        options: SurrogateOptions {
            training_runs: 12,
            validation_runs: 4,
            ..Default::default()
        },
        description: "C1 rp2, units test".into(),
    };
    let built = Surrogate::build(&request, None).unwrap();
    let points = Surrogate::design(&request).unwrap();
    assert_eq!(points.len(), 16);
    // In reverse order, as shards would finish them.
    let mut runs: Vec<(usize, Result<Vec<f64>, String>)> = (0..points.len())
        .rev()
        .map(|k| (k, Surrogate::run_point(&model, &loading, &points[k])))
        .collect();
    runs.sort_by_key(|(k, _)| *k);
    let runs: Vec<_> = runs.into_iter().map(|(_, r)| r).collect();
    let parts = Surrogate::from_runs(&request, runs.clone()).unwrap();
    // Equal but for the build times (the stored form holds them).
    let strip = |s: &Surrogate| {
        let mut v: serde_json::Value = serde_json::from_str(&s.to_json()).unwrap();
        v["build_time_s"] = serde_json::Value::Null;
        v["build_cpu_s"] = serde_json::Value::Null;
        v
    };
    assert_eq!(strip(&parts), strip(&built));
    let e = Surrogate::from_runs(&request, runs[..15].to_vec())
        .unwrap_err()
        .to_string();
    assert!(e.contains("15 model runs given for a design of 16"), "{e}");
}
