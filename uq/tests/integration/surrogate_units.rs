//! A surrogate assembled from its design's runs computed one at a time
//! (`Surrogate::design`, `run_point`, `from_runs`: what a study's shards
//! do) is the surrogate `Surrogate::build` makes in one go, and a wrong
//! number of runs is refused.

use palpate_analytic::C1Compression;
use palpate_core::ForwardModel;
use palpate_uq::surrogate::{ParamBox, Surrogate, SurrogateOptions, SurrogateRequest};

use crate::common;
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

/// Runs that leave outputs undefined (NaN; an R2 scan's wheel positions off
/// the rolled path for a nodule near the block's end) give one trend + GP
/// per output on the runs that define it: the defined outputs of held-out
/// runs are predicted, the validation skips the undefined ones and its
/// error variance is finite everywhere. Model: a bump
/// exp(-(o - c)^2 / (2 w^2)) of amplitude a over offsets o = -5..5, whose
/// outputs with o < -c are undefined (c in [1, 6]).
#[test]
fn runs_with_undefined_outputs_fit_one_gp_per_output() {
    use palpate_core::{
        Drive, Evaluator, ForwardError, Loading, Observable, ParamSpace, ParamSpec,
    };
    struct Bump(ParamSpace);
    struct Eval;
    impl Evaluator for Eval {
        fn predict_into(
            &mut self,
            t: &[f64],
            l: &Loading,
            out: &mut [f64],
        ) -> Result<(), ForwardError> {
            let (a, c) = (t[0], t[1]);
            for (y, o) in out.iter_mut().zip(&l.drive) {
                *y = if *o < -c {
                    f64::NAN
                } else {
                    a * (-(o - 0.1 * c).powi(2) / 8.0).exp()
                };
            }
            Ok(())
        }
    }
    impl ForwardModel for Bump {
        fn name(&self) -> String {
            "bump".into()
        }
        fn space(&self) -> &ParamSpace {
            &self.0
        }
        fn observable(&self) -> Observable {
            Observable::ForceN
        }
        fn evaluator(&self) -> Box<dyn Evaluator + '_> {
            Box::new(Eval)
        }
    }
    let model = Bump(ParamSpace::new(vec![
        ParamSpec::new("a", "N", 0.0, 10.0, 1.0),
        ParamSpec::new("c", "mm", 0.0, 10.0, 3.0),
    ]));
    let loading = Loading::quasi_static(Drive::PositionMm, (-5..=5).map(f64::from).collect());
    let request = SurrogateRequest {
        model: &model,
        loading: &loading,
        bounds: ParamBox::new(model.space(), &[1.0, 1.0], &[3.0, 6.0]).unwrap(),
        options: SurrogateOptions {
            training_runs: 30,
            validation_runs: 6,
            ..Default::default()
        },
        description: "bump with undefined outputs".into(),
    };
    let s = Surrogate::build(&request, None).unwrap();
    let v = s.validation();
    assert_eq!(v.points, 6);
    assert!(v.max_relative_error < 1e-2, "{v:?}");
    assert!(v.error_variance.iter().all(|e| e.is_finite()), "{v:?}");
    // a defined output between the design points
    let f = s.predict(&[2.2, 4.3], &loading).unwrap();
    let want = 2.2 * (-(0.0f64 - 0.43).powi(2) / 8.0).exp();
    assert!((f[5] - want).abs() < 1e-2 * want, "{} vs {want}", f[5]);
}
