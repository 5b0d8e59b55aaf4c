//! Estimator tests on small nonlinear models defined here (the crate sees
//! only `dyn ForwardModel`). Each test can fail: known parameters must be
//! recovered, standard errors must match closed forms.

use palpate_core::{
    Drive, Evaluator, ForwardError, ForwardModel, Loading, Observable, ParamSpace, ParamSpec,
};
use palpate_inverse::*;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::sync::{Arc, Mutex};

type Law = fn(&[f64], f64) -> Result<f64, ForwardError>;

/// A model `y_i = law(theta, drive_i)`.
struct FnModel {
    name: &'static str,
    space: ParamSpace,
    law: Law,
}

struct FnEvaluator<'a>(&'a FnModel);

impl Evaluator for FnEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        self.0.space.check(theta)?;
        for (o, &d) in out.iter_mut().zip(&loading.drive) {
            *o = (self.0.law)(theta, d)?;
        }
        Ok(())
    }
}

impl ForwardModel for FnModel {
    fn name(&self) -> String {
        self.name.into()
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(FnEvaluator(self))
    }
}

const INF: f64 = f64::INFINITY;

fn p(name: &str, lower: f64, upper: f64, initial: f64) -> ParamSpec {
    ParamSpec::new(name, "1", lower, upper, initial)
}

/// `a exp(-b t) + c`, `b > 0`.
fn exp_decay() -> Arc<dyn ForwardModel> {
    Arc::new(FnModel {
        name: "exp decay",
        space: ParamSpace::new(vec![
            p("a", -INF, INF, 1.0),
            p("b", 0.0, INF, 1.0),
            p("c", -INF, INF, 0.0),
        ]),
        law: |t, x| Ok(t[0] * (-t[1] * x).exp() + t[2]),
    })
}

fn times(n: usize, end: f64) -> Vec<f64> {
    (0..n).map(|i| end * i as f64 / (n - 1) as f64).collect()
}

fn set(model: Arc<dyn ForwardModel>, drive: Vec<f64>, truth: &[f64]) -> DataSet {
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive);
    let observed = model.predict(truth, &loading).unwrap();
    DataSet::new(model.name(), model, loading, observed)
}

fn noisy(mut s: DataSet, sd: f64, seed: u64) -> DataSet {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let normal = Normal::new(0.0, sd).unwrap();
    for y in s.observed.iter_mut() {
        *y += normal.sample(&mut rng);
    }
    s
}

fn lm() -> FitOptions {
    FitOptions::default()
}

#[test]
fn recovers_exponential_decay_without_noise() {
    let truth = [2.5, 0.7, -0.3];
    let obj = Objective::new(
        vec![set(exp_decay(), times(40, 6.0), &truth)],
        ResidualKind::Absolute,
        &[],
    )
    .unwrap();
    let r = fit(&obj, &lm()).unwrap();
    assert!(r.converged, "{:?}", r.termination);
    for (name, t) in ["a", "b", "c"].iter().zip(truth) {
        let v = r.value(name).unwrap();
        assert!((v - t).abs() <= 1e-8 * t.abs(), "{name}: {v} vs {t}");
    }
    assert!(r.sse < 1e-20, "{}", r.sse);
    assert!(r.identifiability.identifiable, "{:?}", r.identifiability);
    assert!((r.r_squared - 1.0).abs() < 1e-12);
    // The report serialises (NaN -> null).
    let json = serde_json::to_string(&r).unwrap();
    assert!(json.contains("\"termination\""));
    // An interior optimum: nothing holds it but the data, and the report
    // does not carry the limit flag at all.
    assert!(!r.on_limit && r.constraints().is_empty() && r.determined());
    assert!(!json.contains("on_limit"));
}

#[test]
fn noisy_exponential_decay_truth_within_three_standard_errors() {
    let truth = [2.5, 0.7, -0.3];
    let mut hits = 0;
    for seed in 0..5 {
        let s = noisy(set(exp_decay(), times(60, 6.0), &truth), 0.02, seed);
        let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
        let r = fit(&obj, &lm()).unwrap();
        assert!(r.converged);
        for (name, t) in ["a", "b", "c"].iter().zip(truth) {
            let (v, se) = (r.value(name).unwrap(), r.standard_error(name).unwrap());
            assert!(se > 0.0 && se < 0.1, "{name}: se {se}");
            assert!(
                (v - t).abs() < 4.0 * se,
                "{name}: {v} +- {se} vs {t} (seed {seed})"
            );
            if (v - t).abs() < 2.0 * se {
                hits += 1;
            }
        }
        // sigma^2 estimates the noise variance.
        let s2 = r.sigma2.unwrap();
        assert!((s2.sqrt() / 0.02 - 1.0).abs() < 0.3, "sigma {}", s2.sqrt());
    }
    // ~95 % of 15 intervals of 2 SE should cover: at least 11.
    assert!(hits >= 11, "{hits} of 15 within 2 SE");
}

#[test]
fn rosenbrock_residuals_are_solved_from_the_classical_start() {
    // r = (10 (x2 - x1^2), 1 - x1) written as predictions minus observations.
    let model: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "rosenbrock",
        space: ParamSpace::new(vec![p("x1", -INF, INF, -1.2), p("x2", -INF, INF, 1.0)]),
        law: |t, d| {
            Ok(if d == 0.0 {
                10.0 * (t[1] - t[0] * t[0])
            } else {
                -t[0]
            })
        },
    });
    let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 1.0]);
    let s = DataSet::new("rosenbrock", model, loading, vec![0.0, -1.0]);
    let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
    let r = fit(&obj, &lm()).unwrap();
    assert!(r.converged, "{:?}", r.termination);
    assert!((r.value("x1").unwrap() - 1.0).abs() < 1e-8);
    assert!((r.value("x2").unwrap() - 1.0).abs() < 1e-8);
    // n == p: sigma^2 undefined, no standard errors, correlation still defined.
    assert!(r.sigma2.is_none() && r.standard_error("x1").is_none());
}

fn line() -> Arc<dyn ForwardModel> {
    Arc::new(FnModel {
        name: "line",
        space: ParamSpace::new(vec![p("a", -INF, INF, 0.0), p("b", -INF, INF, 1.0)]),
        law: |t, x| Ok(t[0] + t[1] * x),
    })
}

#[test]
fn standard_errors_match_linear_regression_formulas() {
    let x = times(25, 4.0);
    let s = noisy(set(line(), x.clone(), &[1.0, 0.5]), 0.1, 7);
    let y = s.observed.clone();
    let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
    let r = fit(&obj, &lm()).unwrap();
    let n = x.len() as f64;
    let xm = x.iter().sum::<f64>() / n;
    let ym = y.iter().sum::<f64>() / n;
    let sxx: f64 = x.iter().map(|v| (v - xm).powi(2)).sum();
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - xm) * (b - ym)).sum();
    let b = sxy / sxx;
    let a = ym - b * xm;
    let sse: f64 = x
        .iter()
        .zip(&y)
        .map(|(xi, yi)| (yi - a - b * xi).powi(2))
        .sum();
    let s2 = sse / (n - 2.0);
    let se_b = (s2 / sxx).sqrt();
    let se_a = (s2 * (1.0 / n + xm * xm / sxx)).sqrt();
    let corr = -xm / (xm * xm + sxx / n).sqrt();
    let rel = |u: f64, v: f64| (u - v).abs() / v.abs();
    assert!(rel(r.value("a").unwrap(), a) < 1e-10);
    assert!(rel(r.value("b").unwrap(), b) < 1e-10);
    assert!(rel(r.sse, sse) < 1e-10);
    assert!(
        rel(r.standard_error("a").unwrap(), se_a) < 1e-7,
        "{:?} vs {se_a}",
        r.standard_error("a")
    );
    assert!(rel(r.standard_error("b").unwrap(), se_b) < 1e-7);
    assert!(
        rel(r.correlation[0][1], corr) < 1e-7,
        "{} vs {corr}",
        r.correlation[0][1]
    );
    let ss_tot: f64 = y.iter().map(|v| (v - ym).powi(2)).sum();
    assert!(rel(r.sets[0].r_squared, 1.0 - sse / ss_tot) < 1e-10);
}

#[test]
fn bfgs_and_lbfgs_reach_the_levenberg_marquardt_optimum() {
    let truth = [2.5, 0.7, -0.3];
    let s = noisy(set(exp_decay(), times(50, 6.0), &truth), 0.02, 11);
    let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
    let reference = fit(&obj, &lm()).unwrap();
    for method in [
        Method::Bfgs(QuasiNewtonOptions::default()),
        Method::Lbfgs {
            memory: 5,
            options: QuasiNewtonOptions::default(),
        },
    ] {
        let r = fit(&obj, &FitOptions::with_method(method)).unwrap();
        assert!(
            (r.sse / reference.sse - 1.0).abs() < 1e-9,
            "{}: {} vs {}",
            r.method,
            r.sse,
            reference.sse
        );
        for name in ["a", "b", "c"] {
            let (u, v) = (r.value(name).unwrap(), reference.value(name).unwrap());
            let se = reference.standard_error(name).unwrap();
            assert!((u - v).abs() < 1e-4 * se, "{}: {name} {u} vs {v}", r.method);
        }
    }
}

#[test]
fn collinear_parameters_are_not_identifiable() {
    let model: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "collinear",
        space: ParamSpace::new(vec![
            p("a", -INF, INF, 1.0),
            p("b", -INF, INF, 0.5),
            p("c", -INF, INF, 0.0),
        ]),
        law: |t, x| Ok((t[0] + t[1]) * x + t[2]),
    });
    let s = noisy(set(model, times(20, 2.0), &[1.0, 1.0, 0.2]), 0.01, 3);
    let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
    let r = fit(&obj, &lm()).unwrap();
    let id = &r.identifiability;
    assert!(!id.identifiable, "{id:?}");
    assert!(
        id.involved.contains(&"a".to_string()) && id.involved.contains(&"b".to_string()),
        "{id:?}"
    );
    assert!(!id.involved.contains(&"c".to_string()), "{id:?}");
    assert_eq!(id.rank, 2, "{id:?}");
    assert!(id.condition_number > MAX_CONDITION, "{id:?}");
    // No standard error for parameters in the null space; c keeps its own.
    assert!(r.standard_error("a").is_none() && r.standard_error("b").is_none());
    assert!(r.standard_error("c").unwrap() < 0.01);
    // The sum is still determined.
    assert!((r.value("a").unwrap() + r.value("b").unwrap() - 2.0).abs() < 0.05);
}

#[test]
fn relative_residuals_skip_zero_observations() {
    let truth = [1.5, 0.4];
    // The line through zero at x = 0 gives a zero observation.
    let s = set(line(), vec![-2.0, -1.0, 0.0, 1.0, 2.0, 3.0], &[0.0, 0.0]);
    assert_eq!(s.observed[2], 0.0);
    let mut s = set(line(), times(6, 5.0), &truth);
    s.observed[0] = 0.0; // a zero observation that is ignored
    let obj = Objective::new(vec![s], ResidualKind::Relative, &[]).unwrap();
    assert_eq!(obj.n_residuals(), 5);
    let r = fit(&obj, &lm()).unwrap();
    assert_eq!(r.sets[0].kept, vec![1, 2, 3, 4, 5]);
    assert!(
        (r.value("a").unwrap() - truth[0]).abs() < 1e-8
            && (r.value("b").unwrap() - truth[1]).abs() < 1e-8
    );
    // Residuals are relative: predicted/observed - 1.
    let k = 3;
    let set = &r.sets[0];
    let expected = set.predicted[k] / set.observed[k] - 1.0;
    assert!((set.residuals[k - 1] - expected).abs() < 1e-15);
}

#[test]
fn parallel_and_serial_jacobians_are_bit_identical() {
    let s = noisy(set(exp_decay(), times(30, 6.0), &[2.5, 0.7, -0.3]), 0.02, 5);
    let obj = Objective::new(vec![s.clone(), s], ResidualKind::Normalised, &[]).unwrap();
    let z = obj.unbounded_from_theta(&[2.0, 0.9, 0.1]).unwrap();
    let serial = FdOptions {
        parallel: false,
        ..FdOptions::default()
    };
    let parallel = FdOptions::default();
    let js = jacobian_unbounded(&obj, &z, None, &serial).unwrap().matrix;
    for threads in [1, 2, 4] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let jp = pool.install(|| {
            jacobian_unbounded(&obj, &z, None, &parallel)
                .unwrap()
                .matrix
        });
        assert!(
            js.iter()
                .zip(jp.iter())
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{threads} threads"
        );
    }
    // And the FD Jacobian is a Jacobian: compare with the analytic one.
    let theta = obj.theta_from_unbounded(&z);
    let dxdz = obj.dx_dz(&z);
    let (_, f) = (0, obj.factors(0)[0].1);
    for (i, &t) in times(30, 6.0).iter().enumerate() {
        let e = (-theta[1] * t).exp();
        let exact = [
            f * e * dxdz[0],
            -f * theta[0] * t * e * dxdz[1],
            f * dxdz[2],
        ];
        for j in 0..3 {
            assert!(
                (js[(i, j)] - exact[j]).abs() < 1e-8 * (1.0 + exact[j].abs()),
                "({i},{j})"
            );
        }
    }
}

#[test]
fn a_parameter_pushed_onto_its_bound_is_reported_there() {
    // Data from a decreasing line; the slope is constrained to b >= 0.
    let bounded: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "bounded line",
        space: ParamSpace::new(vec![p("a", -INF, INF, 0.0), p("b", 0.0, INF, 1.0)]),
        law: |t, x| Ok(t[0] + t[1] * x),
    });
    let x = times(11, 2.0);
    let y: Vec<f64> = x.iter().map(|v| 3.0 - 0.5 * v).collect();
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    let s = DataSet::new(
        "line",
        bounded,
        Loading::quasi_static(Drive::DisplacementMm, x),
        y,
    );
    let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
    let r = fit(&obj, &lm()).unwrap();
    let b = r.parameter("b").unwrap();
    assert!(b.value >= 0.0 && b.value < 1e-8, "b = {}", b.value);
    assert_eq!(b.at_bound, Some(BoundSide::Lower));
    assert!(b.standard_error.is_none());
    assert!(
        (r.value("a").unwrap() - mean).abs() < 1e-8,
        "{} vs {mean}",
        r.value("a").unwrap()
    );
    assert!(r.standard_error("a").is_some());
    assert_eq!(r.identifiability.at_bound, vec!["b".to_string()]);
}

#[test]
fn fixed_parameters_are_held_and_reported() {
    let truth = [2.5, 0.7, -0.3];
    let obj = Objective::new(
        vec![set(exp_decay(), times(30, 6.0), &truth)],
        ResidualKind::Absolute,
        &[("c".to_string(), -0.3)],
    )
    .unwrap();
    assert_eq!(obj.free_names(), vec!["a", "b"]);
    let r = fit(&obj, &lm()).unwrap();
    let c = r.parameter("c").unwrap();
    assert!(c.fixed && c.value == -0.3 && c.standard_error.is_none());
    assert!((r.value("b").unwrap() - 0.7).abs() < 1e-8);
    assert_eq!(r.correlation.len(), 2);
    // Unknown names and out-of-bounds values are named errors.
    let e = Objective::new(
        vec![set(exp_decay(), times(5, 1.0), &truth)],
        ResidualKind::Absolute,
        &[("D1".to_string(), 0.0)],
    )
    .unwrap_err();
    assert!(
        matches!(e, InverseError::UnknownParameter { ref name, .. } if name == "D1"),
        "{e}"
    );
    let e = Objective::new(
        vec![set(exp_decay(), times(5, 1.0), &truth)],
        ResidualKind::Absolute,
        &[("b".to_string(), -1.0)],
    )
    .unwrap_err();
    assert!(matches!(e, InverseError::OutOfBounds { .. }), "{e}");
}

#[test]
fn joint_fit_of_two_sets_with_different_scales_and_normalised_residuals() {
    // Same parameters, second set observed in other units (x1000) and longer.
    let truth = [2.5, 0.7, -0.3];
    let scaled: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "exp decay x1000",
        space: exp_decay().space().clone(),
        law: |t, x| Ok(1000.0 * (t[0] * (-t[1] * x).exp() + t[2])),
    });
    let s1 = noisy(set(exp_decay(), times(20, 6.0), &truth), 0.01, 1);
    let s2 = noisy(set(scaled, times(80, 6.0), &truth), 10.0, 2);
    let obj = Objective::new(vec![s1, s2], ResidualKind::Normalised, &[]).unwrap();
    let r = fit(&obj, &lm()).unwrap();
    assert_eq!(r.sets.len(), 2);
    for (name, t) in ["a", "b", "c"].iter().zip(truth) {
        let (v, se) = (r.value(name).unwrap(), r.standard_error(name).unwrap());
        assert!((v - t).abs() < 4.0 * se, "{name}: {v} +- {se}");
    }
    // Each set's normalised SSE is its relative RMS error squared: comparable magnitudes.
    let ratio = r.sets[0].sse / r.sets[1].sse;
    assert!(ratio > 0.1 && ratio < 10.0, "{ratio}");
    // Mismatched parameter names are refused.
    let other: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "other",
        space: ParamSpace::new(vec![p("a", -INF, INF, 0.0), p("k", -INF, INF, 1.0)]),
        law: |t, x| Ok(t[0] + t[1] * x),
    });
    let e = Objective::new(
        vec![
            set(exp_decay(), times(5, 1.0), &truth),
            set(other, times(5, 1.0), &[0.0, 1.0]),
        ],
        ResidualKind::Absolute,
        &[],
    )
    .unwrap_err();
    assert!(matches!(e, InverseError::ParameterMismatch { .. }), "{e}");
}

struct ExpSensitivities;
impl Sensitivities for ExpSensitivities {
    fn predict_with_jacobian(
        &self,
        t: &[f64],
        loading: &Loading,
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), ForwardError> {
        let e: Vec<f64> = loading.drive.iter().map(|x| (-t[1] * x).exp()).collect();
        let pred = e.iter().map(|e| t[0] * e + t[2]).collect();
        let da = e.clone();
        let db = e
            .iter()
            .zip(&loading.drive)
            .map(|(e, x)| -t[0] * x * e)
            .collect();
        Ok((pred, vec![da, db, vec![1.0; e.len()]]))
    }
}

#[test]
fn exact_sensitivities_replace_finite_differences() {
    let truth = [2.5, 0.7, -0.3];
    let s = noisy(set(exp_decay(), times(30, 6.0), &truth), 0.02, 9);
    let fd_obj = Objective::new(vec![s.clone()], ResidualKind::Relative, &[]).unwrap();
    let ex_obj = Objective::new(
        vec![s.with_sensitivities(Arc::new(ExpSensitivities))],
        ResidualKind::Relative,
        &[],
    )
    .unwrap();
    let z = fd_obj.unbounded_from_theta(&[2.0, 0.9, 0.1]).unwrap();
    let jf = jacobian_unbounded(&fd_obj, &z, None, &FdOptions::default()).unwrap();
    let je = jacobian_unbounded(&ex_obj, &z, None, &FdOptions::default()).unwrap();
    assert_eq!(je.evaluations, 1);
    for (a, b) in jf.matrix.iter().zip(je.matrix.iter()) {
        assert!((a - b).abs() < 1e-7 * (1.0 + b.abs()), "{a} vs {b}");
    }
    let (rf, re) = (fit(&fd_obj, &lm()).unwrap(), fit(&ex_obj, &lm()).unwrap());
    assert!((rf.value("b").unwrap() - re.value("b").unwrap()).abs() < 1e-8);
}

#[test]
fn a_forward_failure_at_the_start_names_the_set() {
    let fragile: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "fragile",
        space: ParamSpace::new(vec![p("a", -INF, INF, 5.0)]),
        law: |t, x| {
            if t[0] > 4.0 {
                Err(ForwardError::Unphysical {
                    drive: x,
                    reason: "too stiff".into(),
                })
            } else {
                Ok(t[0] * x)
            }
        },
    });
    let s = DataSet::new(
        "stiff test",
        fragile,
        Loading::quasi_static(Drive::DisplacementMm, vec![1.0, 2.0]),
        vec![1.0, 2.0],
    );
    let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
    let e = fit(&obj, &lm()).unwrap_err();
    assert!(
        matches!(e, InverseError::Forward { ref set, .. } if set == "stiff test"),
        "{e}"
    );
    assert!(e.to_string().contains("too stiff"), "{e}");
    // From an admissible start the failing region only rejects trial steps.
    let r = fit(
        &obj,
        &FitOptions {
            start: Some(vec![0.5]),
            ..lm()
        },
    )
    .unwrap();
    assert!((r.value("a").unwrap() - 1.0).abs() < 1e-10);
}

/// `y = a^3 x` whose solve fails (an FE run whose element inverts) for
/// `a > 1.2`, with its exact sensitivity `3 a^2 x`.
fn fails_above(a: f64, x: f64) -> Result<f64, ForwardError> {
    if a > 1.2 {
        return Err(ForwardError::NotConverged {
            sample: 0,
            drive: x,
            cuts: 1,
            reason: "element 110 inverted (det F = -9.070e-2)".into(),
            completed: vec![],
        });
    }
    Ok(a.powi(3) * x)
}

struct CubeSensitivities;
impl Sensitivities for CubeSensitivities {
    fn predict_with_jacobian(
        &self,
        t: &[f64],
        loading: &Loading,
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), ForwardError> {
        let pred = loading
            .drive
            .iter()
            .map(|&x| fails_above(t[0], x))
            .collect::<Result<Vec<_>, _>>()?;
        let da = loading
            .drive
            .iter()
            .map(|x| 3.0 * t[0] * t[0] * x)
            .collect();
        Ok((pred, vec![da]))
    }
}

/// With exact sensitivities (one run gives residuals and Jacobian), a trial
/// step whose run fails is a rejected step: from a = 0.3 the Gauss-Newton
/// step goes to a = 3.9, where the model fails, and the fit continues with
/// shorter steps to the truth a = 1.
#[test]
fn a_failed_run_at_a_trial_point_is_a_rejected_step_with_exact_sensitivities() {
    let model: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "fails above 1.2",
        space: ParamSpace::new(vec![p("a", 0.0, INF, 0.3)]),
        law: |t, x| fails_above(t[0], x),
    });
    let s = set(model, times(10, 2.0), &[1.0]).with_sensitivities(Arc::new(CubeSensitivities));
    let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
    assert!(obj.has_exact_sensitivities());
    let r = fit(&obj, &lm()).unwrap();
    assert!((r.value("a").unwrap() - 1.0).abs() < 1e-8, "{r:?}");
    assert!(r.converged);
}

/// The exact sensitivities of `y = a^3 x` that fail for `a > 1.5` where
/// the plain model converges (an FE run whose differentiation inverts an
/// element at a perturbed state).
struct FragileCubeSensitivities;
impl Sensitivities for FragileCubeSensitivities {
    fn predict_with_jacobian(
        &self,
        t: &[f64],
        loading: &Loading,
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), ForwardError> {
        if t[0] > 1.5 {
            return fails_above(2.0, 0.0).map(|_| (vec![], vec![]));
        }
        CubeSensitivities.predict_with_jacobian(t, loading)
    }
}

/// Where the run with sensitivities fails and a plain run converges, the
/// residuals come from a plain run and the Jacobian from finite
/// differences: the fit goes on through that part of the space to the
/// optimum near the truth a = 2, with the standard error of a fit whose
/// sensitivities never fail.
#[test]
fn a_failed_run_with_sensitivities_falls_back_to_finite_differences() {
    let model: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "cube",
        space: ParamSpace::new(vec![p("a", 0.0, INF, 0.3)]),
        law: |t, x| Ok(t[0].powi(3) * x),
    });
    let s = noisy(set(model.clone(), times(10, 2.0), &[2.0]), 0.01, 3)
        .with_sensitivities(Arc::new(FragileCubeSensitivities));
    let obj = Objective::new(vec![s.clone()], ResidualKind::Absolute, &[]).unwrap();
    let r = fit(&obj, &lm()).unwrap();
    let reference = fit(
        &Objective::new(
            vec![s.with_sensitivities(Arc::new(CubeSensitivities))],
            ResidualKind::Absolute,
            &[],
        )
        .unwrap(),
        &lm(),
    )
    .unwrap();
    let (a, se) = (r.value("a").unwrap(), r.parameters[0].standard_error);
    assert!(r.converged, "{r:?}");
    assert!((a - reference.value("a").unwrap()).abs() < 1e-7, "{a}");
    let se_ref = reference.parameters[0].standard_error.unwrap();
    assert!(
        (se.unwrap() / se_ref - 1.0).abs() < 1e-4,
        "{se:?} vs {se_ref}"
    );
}

/// A model that converges at the start and nowhere else the steps reach
/// (`y = a x`, its solve failing for every a above 0.3): Levenberg-Marquardt
/// rejects each failed trial with more damping, and after
/// `MAX_FAILED_TRIALS` in a row stops with an error that names the point
/// the steps started from and the last failure's point and cause.
#[test]
fn trial_steps_that_keep_failing_end_the_fit_with_the_point_and_the_cause() {
    let model: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "stuck",
        space: ParamSpace::new(vec![p("a", 0.0, INF, 0.3)]),
        law: |t, x| {
            if t[0] > 0.3 + 1e-9 {
                fails_above(2.0, x)
            } else {
                Ok(t[0] * x)
            }
        },
    });
    let drive = times(10, 2.0);
    let observed = drive.clone();
    let s = DataSet::new(
        "stuck",
        model,
        Loading::quasi_static(Drive::DisplacementMm, drive),
        observed,
    );
    let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
    let e = fit(&obj, &lm()).unwrap_err();
    let InverseError::TrialsFailed {
        from,
        failures,
        last,
        ..
    } = &e
    else {
        panic!("{e}");
    };
    assert_eq!(*failures, palpate_inverse::lm::MAX_FAILED_TRIALS);
    assert!((from[0] - 0.3).abs() < 1e-12, "{from:?}");
    assert!(
        matches!(**last, InverseError::Forward { ref theta, .. } if theta[0] > 0.3),
        "{last}"
    );
    assert!(e.to_string().contains("element 110 inverted"), "{e}");
}

#[test]
fn multistart_escapes_a_local_minimum_and_the_observer_sees_progress() {
    // y = sin(w t): from w0 = 1 the nearest minimum is not the truth w = 3.
    let model: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "sine",
        space: ParamSpace::new(vec![p("w", 0.0, INF, 1.0)]),
        law: |t, x| Ok((t[0] * x).sin()),
    });
    let s = set(model, times(60, 6.0), &[3.0]);
    let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
    let single = fit(&obj, &lm()).unwrap();
    assert!(
        single.sse > 1.0,
        "single start found {}",
        single.value("w").unwrap()
    );
    let seen = Arc::new(Mutex::new(Vec::new()));
    let log = seen.clone();
    let options = FitOptions {
        multistart: MultiStart {
            starts: 8,
            spread: 1.5,
        },
        observer: Some(shared_observer(move |p: &Progress| {
            log.lock().unwrap().push((p.start, p.sse))
        })),
        ..lm()
    };
    let r = fit(&obj, &options).unwrap();
    assert!(
        (r.value("w").unwrap() - 3.0).abs() < 1e-8,
        "w = {}",
        r.value("w").unwrap()
    );
    assert_eq!(r.starts, 8);
    assert_ne!(r.best_start, 0);
    let seen = seen.lock().unwrap();
    assert!(seen.len() >= 8 && seen.iter().any(|&(k, _)| k == 7));
}

#[test]
fn an_optimum_on_an_admissibility_limit_is_reached_along_it() {
    // A line whose law rejects a + b <= 0 (not a box bound); the data's
    // unconstrained fit (a = -1, b = 0.5) is inadmissible, so the optimum
    // lies on a + b = 0: the model is b (x - 1), with the closed-form
    // least-squares b* = sum (x - 1) y / sum (x - 1)^2.
    let walled: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "walled line",
        space: ParamSpace::new(vec![p("a", -INF, INF, 1.0), p("b", -INF, INF, 1.0)]),
        law: |t, x| {
            if t[0] + t[1] > 0.0 {
                Ok(t[0] + t[1] * x)
            } else {
                Err(ForwardError::InvalidParameter {
                    name: "a + b".into(),
                    value: t[0] + t[1],
                    reason: "must be > 0".into(),
                })
            }
        },
    });
    let x = times(11, 4.0);
    let y: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, v)| -1.0 + 0.5 * v + if i % 2 == 0 { 0.05 } else { -0.05 })
        .collect();
    let b_star = x.iter().zip(&y).map(|(v, w)| (v - 1.0) * w).sum::<f64>()
        / x.iter().map(|v| (v - 1.0).powi(2)).sum::<f64>();
    let sse_star: f64 = x
        .iter()
        .zip(&y)
        .map(|(v, w)| (b_star * (v - 1.0) - w).powi(2))
        .sum();
    let s = DataSet::new(
        "line",
        walled,
        Loading::quasi_static(Drive::DisplacementMm, x),
        y,
    );
    let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
    let r = fit(&obj, &lm()).unwrap();
    let (a, b) = (r.value("a").unwrap(), r.value("b").unwrap());
    assert!(a + b > 0.0 && a + b < 1e-8, "a + b = {}", a + b);
    assert!(
        (b - b_star).abs() < 1e-6 * b_star.abs(),
        "b = {b} vs {b_star}"
    );
    assert!(
        r.sse >= sse_star * (1.0 - 1e-12) && r.sse <= sse_star * (1.0 + 1e-8),
        "SSE {} vs {sse_star}",
        r.sse
    );
    // The fit is reported as held by the limit, not as a determined minimum.
    assert!(r.on_limit);
    assert_eq!(
        r.constraints(),
        ["stopped on an admissibility limit of the model"]
    );
    assert!(!r.determined());
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(json["on_limit"], true);
}

/// The exponential decay offering [`ExpSensitivities`] as its capability.
struct ExpWithSensitivities(Arc<dyn ForwardModel>);
impl ForwardModel for ExpWithSensitivities {
    fn name(&self) -> String {
        self.0.name()
    }
    fn space(&self) -> &ParamSpace {
        self.0.space()
    }
    fn observable(&self) -> palpate_core::Observable {
        self.0.observable()
    }
    fn evaluator(&self) -> Box<dyn palpate_core::Evaluator + '_> {
        self.0.evaluator()
    }
    fn as_sensitivities(&self) -> Option<&dyn Sensitivities> {
        Some(&ExpSensitivities)
    }
}

/// `with_model_sensitivities` takes a model's capability when it offers
/// one (the Jacobian is then its, one evaluation) and leaves a set on
/// finite differences otherwise.
#[test]
fn model_sensitivities_are_used_when_the_model_offers_them() {
    let truth = [2.5, 0.7, -0.3];
    let plain = set(exp_decay(), times(30, 6.0), &truth);
    assert!(plain
        .clone()
        .with_model_sensitivities()
        .sensitivities
        .is_none());
    let offering = DataSet {
        model: Arc::new(ExpWithSensitivities(exp_decay())),
        ..plain.clone()
    }
    .with_model_sensitivities();
    assert!(offering.sensitivities.is_some());
    let fd_obj = Objective::new(vec![plain], ResidualKind::Absolute, &[]).unwrap();
    let ex_obj = Objective::new(vec![offering], ResidualKind::Absolute, &[]).unwrap();
    let z = fd_obj.unbounded_from_theta(&[2.0, 0.9, 0.1]).unwrap();
    let jf = jacobian_unbounded(&fd_obj, &z, None, &FdOptions::default()).unwrap();
    let je = jacobian_unbounded(&ex_obj, &z, None, &FdOptions::default()).unwrap();
    assert_eq!((jf.evaluations, je.evaluations), (6, 1));
    for (a, b) in jf.matrix.iter().zip(je.matrix.iter()) {
        assert!((a - b).abs() < 1e-7 * (1.0 + b.abs()), "{a} vs {b}");
    }
}

/// The exponential decay counting its runs: plain ones (through its
/// evaluator) and those with sensitivities ([`ExpSensitivities`]).
struct CountingExp {
    inner: Arc<dyn ForwardModel>,
    plain: std::sync::atomic::AtomicUsize,
    exact: std::sync::atomic::AtomicUsize,
    /// Every run in order: with sensitivities, and its parameters.
    log: Mutex<Vec<(bool, Vec<f64>)>>,
}

impl CountingExp {
    fn new() -> Arc<CountingExp> {
        Arc::new(CountingExp {
            inner: exp_decay(),
            plain: Default::default(),
            exact: Default::default(),
            log: Default::default(),
        })
    }
    /// (plain runs, runs with sensitivities).
    fn runs(&self) -> (usize, usize) {
        use std::sync::atomic::Ordering::SeqCst;
        (self.plain.load(SeqCst), self.exact.load(SeqCst))
    }
}

struct CountingEvaluator<'a> {
    inner: Box<dyn Evaluator + 'a>,
    model: &'a CountingExp,
}

impl Evaluator for CountingEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        (self.model.plain).fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        self.model.log.lock().unwrap().push((false, theta.to_vec()));
        self.inner.predict_into(theta, loading, out)
    }
}

impl ForwardModel for CountingExp {
    fn name(&self) -> String {
        self.inner.name()
    }
    fn space(&self) -> &ParamSpace {
        self.inner.space()
    }
    fn observable(&self) -> Observable {
        self.inner.observable()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(CountingEvaluator {
            inner: self.inner.evaluator(),
            model: self,
        })
    }
    fn as_sensitivities(&self) -> Option<&dyn Sensitivities> {
        Some(self)
    }
}

impl Sensitivities for CountingExp {
    fn predict_with_jacobian(
        &self,
        t: &[f64],
        loading: &Loading,
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), ForwardError> {
        self.exact.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        self.log.lock().unwrap().push((true, t.to_vec()));
        ExpSensitivities.predict_with_jacobian(t, loading)
    }
}

/// A start of the exponential decay far from its optimum.
const START_FAR: [f64; 3] = [0.2, 6.0, 2.0];

/// A noisy exponential-decay objective on a [`CountingExp`] with exact
/// sensitivities.
fn counted_objective(model: &Arc<CountingExp>) -> Objective {
    let truth = [2.5, 0.7, -0.3];
    let s = noisy(set(exp_decay(), times(30, 6.0), &truth), 0.02, 9);
    let model: Arc<dyn ForwardModel> = model.clone();
    let s = DataSet { model, ..s }.with_model_sensitivities();
    assert!(s.sensitivities.is_some());
    Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap()
}

/// With exact sensitivities Levenberg-Marquardt gets the Jacobian at an
/// accepted trial point from a run there, never from a run of its own
/// when the trial's run had it, and the statistics at the optimum reuse
/// the optimum's run. The runs of both kinds are the report's evaluations,
/// and there are fewer than one evaluation plus one Jacobian per iteration
/// (what recomputing the run inside each Jacobian cost).
#[test]
fn exact_jacobians_reuse_the_run_of_their_point() {
    let model = CountingExp::new();
    let obj = counted_objective(&model);
    let report = fit(&obj, &lm()).unwrap();
    assert!(report.converged, "{:?}", report.termination);
    let (plain, exact) = model.runs();
    assert_eq!(plain + exact, report.evaluations, "{report:?}");
    // every accepted iteration asked for a Jacobian, none cost a run
    assert!(report.jacobians as u64 > report.iterations, "{report:?}");
    assert!(
        plain + exact < report.jacobians + report.iterations as usize,
        "runs {plain} + {exact}, jacobians {}, iterations {}",
        report.jacobians,
        report.iterations
    );
    // the start, each accepted point once, and no run for the statistics
    // (each accepted point's run is kept): at most one rejected trial with
    // sensitivities per accepted step
    assert!(
        exact <= 1 + 2 * report.iterations as usize,
        "{exact} runs with sensitivities in {} iterations",
        report.iterations
    );
}

/// Trial points Levenberg-Marquardt will probably reject (the first, and
/// any after a rejection or a poor gain) are evaluated by plain runs; the
/// start, the accepted points and a trial after a good step run with
/// sensitivities, and an accepted plain trial gets one more run, with
/// them. From a start far from the optimum the damping grows through
/// rejected trials in a row: requesting sensitivities for every trial
/// would make each of them a run with sensitivities.
#[test]
fn rejected_trials_do_not_pay_for_sensitivities() {
    let model = CountingExp::new();
    let obj = counted_objective(&model);
    let accepted = Arc::new(Mutex::new(Vec::<Vec<f64>>::new()));
    let seen = accepted.clone();
    let options = FitOptions {
        start: Some(START_FAR.to_vec()),
        observer: Some(shared_observer(move |p: &Progress| {
            seen.lock().unwrap().push(p.theta.clone())
        })),
        ..lm()
    };
    let report = fit(&obj, &options).unwrap();
    assert!(report.converged, "{:?}", report.termination);
    assert!(
        (report.value("b").unwrap() - 0.7).abs() < 0.05,
        "{report:?}"
    );
    let (plain, exact) = model.runs();
    assert_eq!(plain + exact, report.evaluations);
    let accepted = accepted.lock().unwrap().clone();
    let log = model.log.lock().unwrap().clone();
    // the start, with sensitivities
    assert_eq!(log[0], (true, START_FAR.to_vec()));
    // walk the trials: a rejected one is a point never accepted
    let (mut rejected, mut rejected_exact, mut after_rejection) = (0, 0, 0);
    let mut previous_rejected = true; // the first trial has no gain ratio
    let mut k = 1;
    while k < log.len() {
        let (with, theta) = &log[k];
        if accepted.contains(theta) {
            // an accepted plain trial: one more run there, with sensitivities
            if !with {
                assert_eq!(log.get(k + 1), Some(&(true, theta.clone())), "run {k}");
                k += 1;
            }
            previous_rejected = false;
        } else {
            rejected += 1;
            if *with {
                rejected_exact += 1;
                assert!(
                    !previous_rejected,
                    "run {k}: sensitivities after a rejection"
                );
            } else if previous_rejected {
                after_rejection += 1;
            }
            previous_rejected = true;
        }
        k += 1;
    }
    // the start is far: the first trials are rejected in a row
    assert!(after_rejection >= 2, "{log:?}");
    assert!(rejected_exact < rejected, "{rejected_exact} of {rejected}");
    assert_eq!(exact, 1 + report.iterations as usize + rejected_exact);
}

/// The line of [`an_optimum_on_an_admissibility_limit_is_reached_along_it`]
/// whose law rejects a + b <= 0, on its 11 samples.
fn walled_line() -> Objective {
    let walled: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "walled line",
        space: ParamSpace::new(vec![p("a", -INF, INF, 1.0), p("b", -INF, INF, 1.0)]),
        law: |t, x| {
            if t[0] + t[1] > 0.0 {
                Ok(t[0] + t[1] * x)
            } else {
                Err(ForwardError::InvalidParameter {
                    name: "a + b".into(),
                    value: t[0] + t[1],
                    reason: "must be > 0".into(),
                })
            }
        },
    });
    let x = times(11, 4.0);
    let y: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, v)| -1.0 + 0.5 * v + if i % 2 == 0 { 0.05 } else { -0.05 })
        .collect();
    let s = DataSet::new(
        "line",
        walled,
        Loading::quasi_static(Drive::DisplacementMm, x),
        y,
    );
    Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap()
}

/// The wall slide after a blocked run keeps to the run's evaluation budget:
/// with 60 evaluations per run it stops after the slide that crosses the
/// budget, short of the optimum along the limit that the default budget
/// reaches.
#[test]
fn the_wall_slide_keeps_to_the_run_budget() {
    let obj = walled_line();
    let full = fit(&obj, &lm()).unwrap();
    let capped = fit(
        &obj,
        &FitOptions::with_method(Method::LevenbergMarquardt(LmOptions {
            max_evaluations: 60,
            ..LmOptions::default()
        })),
    )
    .unwrap();
    assert!(
        capped.evaluations < full.evaluations / 2,
        "{} evaluations capped, {} not",
        capped.evaluations,
        full.evaluations
    );
    assert!(capped.sse > full.sse, "{} vs {}", capped.sse, full.sse);
}

/// A deterministic noise in [-1, 1] from the bits of `theta` and `x`, as a
/// forward model solved to a tolerance gives (repeatable, not smooth).
fn solver_noise(theta: &[f64], x: f64) -> f64 {
    let mut h = theta
        .iter()
        .fold(x.to_bits(), |h, t| h.rotate_left(17) ^ t.to_bits());
    h ^= h >> 33;
    h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
    h ^= h >> 33;
    (h as f64 / u64::MAX as f64) * 2.0 - 1.0
}

/// A model whose predictions carry a solver's noise (1e-7 relative): near
/// the optimum its finite-difference gradient disagrees with its SSE, a
/// step ends where the gradient did not grow (`y . s <= 0`), and argmin's
/// BFGS alone then stops on the ascent direction its update makes ("Search
/// direction must be a descent direction"). The quasi-Newton runs restart
/// from the initial inverse Hessian there and reach the
/// Levenberg-Marquardt optimum within the noise.
#[test]
fn quasi_newton_fits_survive_a_step_where_the_gradient_did_not_grow() {
    let model: Arc<dyn ForwardModel> = Arc::new(FnModel {
        name: "noisy exp decay",
        space: ParamSpace::new(vec![p("a", -INF, INF, 1.0), p("b", 0.0, INF, 1.0)]),
        law: |t, x| Ok(t[0] * (-t[1] * x).exp() * (1.0 + 1e-7 * solver_noise(t, x))),
    });
    let s = noisy(set(model, times(30, 4.0), &[2.0, 0.5]), 0.01, 5);
    let obj = Objective::new(vec![s], ResidualKind::Absolute, &[]).unwrap();
    let reference = fit(&obj, &lm()).unwrap();
    for method in [
        Method::Bfgs(QuasiNewtonOptions::default()),
        Method::Lbfgs {
            memory: 5,
            options: QuasiNewtonOptions::default(),
        },
    ] {
        let r = fit(&obj, &FitOptions::with_method(method))
            .unwrap_or_else(|e| panic!("{}: {e}", method.name()));
        for name in ["a", "b"] {
            let (u, v) = (r.value(name).unwrap(), reference.value(name).unwrap());
            let se = reference.standard_error(name).unwrap();
            assert!((u - v).abs() < 0.01 * se, "{}: {name} {u} vs {v}", r.method);
        }
    }
}
