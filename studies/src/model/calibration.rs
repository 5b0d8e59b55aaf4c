//! The calibration service behind `palpate calibrate` and the manifests'
//! `calibrate` step: reads data files into data sets, builds the forward
//! model each test needs, fits, and adds what a material-model user expects
//! beside the fit (Drucker stability range, predictions of other tests).

use crate::model::{record_spec, test_model, ModelSpec, Viscous};
use crate::records::{TestData, TestKind};
use anyhow::Context;
use palpate_core::ForwardModel;
use palpate_inverse::{
    fit, DataSet, FdOptions, FitOptions, FitReport, Method, MultiStart, Objective, ResidualKind,
    SharedObserver,
};
use palpate_material::stability::{drucker, DruckerReport};
use palpate_material::Law;
use serde::Serialize;
use std::sync::Arc;

/// One parameter in the JSON the CLI writes: value and standard error.
#[derive(Debug, Clone, Serialize)]
pub struct ParamValue {
    pub value: f64,
    pub standard_error: Option<f64>,
    pub unit: String,
    pub fixed: bool,
}

/// Parameters keyed by name, serialised as a JSON object in the law's order
/// (C10 before C20, mu1 before alpha1), not alphabetically.
#[derive(Debug, Clone)]
pub struct NamedParams(pub Vec<(String, ParamValue)>);

impl NamedParams {
    /// Iterates (name, value) pairs in order.
    pub fn iter(&self) -> impl Iterator<Item = (&String, &ParamValue)> {
        self.0.iter().map(|(n, v)| (n, v))
    }
    /// A parameter by name.
    pub fn get(&self, name: &str) -> Option<&ParamValue> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }
}

impl Serialize for NamedParams {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }
}

/// A fitted law evaluated on a data set it was not (necessarily) fitted to.
#[derive(Debug, Clone, Serialize)]
pub struct Prediction {
    pub data: String,
    /// The record's test.
    pub test: TestKind,
    pub fitted: bool,
    pub r2: f64,
    pub rms: f64,
    pub stretch_or_displacement: Vec<f64>,
    /// Time of each sample (s), for timed records.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time: Option<Vec<f64>>,
    pub observed: Vec<f64>,
    pub predicted: Vec<f64>,
}

/// Everything a calibration produces.
#[derive(Debug, Clone, Serialize)]
pub struct Calibration {
    pub law: String,
    pub data: Vec<String>,
    pub residual: ResidualKind,
    pub estimator: String,
    /// Each parameter by its name, in the law's order.
    pub params: NamedParams,
    pub r2: f64,
    pub rms: f64,
    pub sse: f64,
    pub iterations: u64,
    pub evaluations: usize,
    pub converged: bool,
    pub identifiable: bool,
    /// Why the fitted law is degenerate, one phrase each: an initial shear
    /// modulus of ~0, a data set it predicts as ~0 throughout
    /// ([`degeneracy`]). Such a fit is not a description of the material
    /// however well it matches. Serialised only when not empty.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub degenerate: Vec<String>,
    /// Stretch ranges where the calibrated law is Drucker stable.
    pub drucker: DruckerReport,
    pub predictions: Vec<Prediction>,
    /// The estimator's full report (correlations, per-set statistics, ...).
    pub fit: FitReport,
}

/// What to fit.
pub struct Request<'a> {
    pub law: Law,
    /// The model of every data set; `None`: the model of each data set's
    /// test for `law` ([`crate::model::for_test`]).
    pub model: Option<&'a ModelSpec>,
    pub fitted: &'a [TestData],
    /// Further data sets on which the fit is evaluated.
    pub predict: &'a [TestData],
    pub residual: ResidualKind,
    pub method: Method,
    pub fixed: Vec<(String, f64)>,
    pub observer: Option<SharedObserver>,
    /// A viscoelastic form of the homogeneous tests (needs timed records).
    pub viscous: Option<Viscous>,
}

/// Parses `lm`, `bfgs` or `lbfgs`.
pub fn parse_method(s: &str) -> anyhow::Result<Method> {
    match s {
        "lm" => Ok(Method::LevenbergMarquardt(Default::default())),
        "bfgs" => Ok(Method::Bfgs(Default::default())),
        "lbfgs" => Ok(Method::Lbfgs {
            memory: 10,
            options: Default::default(),
        }),
        _ => anyhow::bail!("unknown estimator `{s}`; expected lm, bfgs or lbfgs"),
    }
}

impl<'a> Request<'a> {
    /// The plain least-squares fit of `law` to `fitted`: each record's own
    /// model, absolute residuals, Levenberg-Marquardt, nothing fixed,
    /// elastic, no further data sets and no observer.
    pub fn least_squares(law: Law, fitted: &'a [TestData]) -> Self {
        Request {
            law,
            model: None,
            fitted,
            predict: &[],
            residual: ResidualKind::Absolute,
            method: Method::LevenbergMarquardt(Default::default()),
            fixed: Vec::new(),
            observer: None,
            viscous: None,
        }
    }

    /// The forward model of a data set.
    fn model_of(&self, d: &TestData) -> anyhow::Result<Arc<dyn ForwardModel>> {
        match self.model {
            None if d.test.is_homogeneous() => {
                let m = crate::model::build(&record_spec(d, self.law, self.viscous))
                    .map_err(|e| anyhow::anyhow!("data set `{}`: {e}", d.name))?;
                Ok(Arc::from(m))
            }
            None => {
                anyhow::ensure!(
                    self.viscous.is_none(),
                    "data set `{}`: a viscoelastic form applies to homogeneous records only",
                    d.name
                );
                test_model(d.test, self.law)
            }
            Some(spec) => {
                anyhow::ensure!(
                    spec.test().ok() == Some(d.test),
                    "data set `{}` is a {:?} record; a {} model does not predict it",
                    d.name,
                    d.test,
                    spec.kind()
                );
                let mut spec = spec.clone();
                if let ModelSpec::Homogeneous(h) = &mut spec {
                    if d.test == TestKind::SimpleShear && h.axial_stretch.is_none() {
                        h.axial_stretch = Some(d.axial_stretch);
                    }
                }
                let m = crate::model::build(&spec).map_err(|e| anyhow::anyhow!("{e}"))?;
                Ok(Arc::from(m))
            }
        }
    }
}

/// Fits a law and evaluates it on the fitted and the extra data sets.
pub fn calibrate(mut req: Request<'_>) -> anyhow::Result<Calibration> {
    // an experiment's fixed parameters are held unless given here
    if let Some(ModelSpec::Experiment(e)) = req.model {
        for (name, value) in e.fixed()? {
            if !req.fixed.iter().any(|(n, _)| *n == name) {
                req.fixed.push((name, value));
            }
        }
    }
    let sets: Vec<DataSet> = req
        .fitted
        .iter()
        // exact sensitivities where the model offers them (FE models),
        // finite differences otherwise
        .map(|d| Ok(d.dataset(req.model_of(d)?).with_model_sensitivities()))
        .collect::<anyhow::Result<_>>()?;
    let expensive = sets.iter().any(|s| s.model.expensive());
    let objective = Objective::new(sets, req.residual, &req.fixed).context("setting up the fit")?;
    // Laws with exponents (Ogden, Arruda-Boyce) have several local minima: start from several points.
    let mut starts = match req.law {
        Law::Ogden(n) => 6 * n,
        Law::ArrudaBoyce => 4,
        _ => 1,
    };
    let start = match req.viscous {
        Some(v) => {
            starts = starts.max(4);
            Some(viscous_start(&req, v)?)
        }
        // (only where the fit's parameters are the law's, in its order)
        None => admissible_start(&req.law, &req.fixed)?.filter(|p| {
            objective.space().names()
                == req
                    .law
                    .params()
                    .iter()
                    .map(|s| s.name.clone())
                    .collect::<Vec<_>>()
                && p.len() == objective.space().len()
        }),
    };
    // An FE model's force carries its solver's tolerance (~1e-9 relative)
    // and is costly: forward differences (one run per parameter instead of
    // two) with a step (1e-4) well above that noise, as the staged Q1 fit.
    // (Exact sensitivities, when a model gives them, replace both.)
    let fd = if expensive {
        FdOptions {
            relative_step: 1e-4,
            central: false,
            parallel: true,
        }
    } else {
        FdOptions::default()
    };
    let options = FitOptions {
        method: req.method,
        fd,
        multistart: MultiStart {
            starts,
            spread: 1.0,
        },
        observer: req.observer.clone(),
        start,
    };
    let report = fit(&objective, &options).with_context(|| format!("fitting {}", req.law))?;
    let theta = report.theta();
    let mut predictions = Vec::new();
    for (d, fitted) in req
        .fitted
        .iter()
        .map(|d| (d, true))
        .chain(req.predict.iter().map(|d| (d, false)))
    {
        if fitted && req.predict.iter().any(|p| p.name == d.name) {
            continue;
        }
        let predicted = req
            .model_of(d)?
            .predict(&theta, &d.loading)
            .with_context(|| format!("predicting {}", d.name))?;
        let (r2, rms) = r2_rms(&d.observed, &predicted);
        predictions.push(Prediction {
            data: d.name.clone(),
            test: d.test,
            time: d.loading.time.clone(),
            fitted: fitted || req.fitted.iter().any(|f| f.name == d.name),
            r2,
            rms,
            stretch_or_displacement: d.loading.drive.clone(),
            observed: d.observed.clone(),
            predicted,
        });
    }
    let params = report
        .parameters
        .iter()
        .map(|p| {
            (
                p.name.clone(),
                ParamValue {
                    value: p.value,
                    standard_error: p.standard_error,
                    unit: p.unit.clone(),
                    fixed: p.fixed,
                },
            )
        })
        .collect::<Vec<_>>();
    let params = NamedParams(params);
    let degenerate = degeneracy(&req.law, &theta, &predictions);
    Ok(Calibration {
        law: req.law.to_string(),
        data: req.fitted.iter().map(|d| d.name.clone()).collect(),
        residual: req.residual,
        estimator: report.method.clone(),
        params,
        r2: report.r_squared,
        rms: report.rms,
        sse: report.sse,
        iterations: report.iterations,
        evaluations: report.evaluations,
        converged: report.converged,
        identifiable: report.identifiability.identifiable,
        degenerate,
        // A viscoelastic fit appends Prony terms: the law is the leading part.
        drucker: drucker(&req.law, &theta[..req.law.param_count().min(theta.len())]),
        predictions,
        fit: report,
    })
}

/// Relative size below which a shear modulus or a prediction counts as 0.
const DEGENERATE: f64 = 1e-6;

/// What makes a fitted law degenerate: its initial shear modulus is ~0
/// (below 1e-6 of the sum of its moduli' magnitudes: Mooney-Rivlin held on
/// `C01 = -C10`), or it predicts ~0 (below 1e-6 of the data's largest
/// magnitude) at every sample of a data set (Mooney-Rivlin with
/// `C01 = -C10` in planar tension). One phrase each; empty when neither.
pub fn degeneracy(law: &Law, theta: &[f64], predictions: &[Prediction]) -> Vec<String> {
    let mut out = Vec::new();
    let n = law.param_count().min(theta.len());
    let moduli: f64 = law
        .params()
        .iter()
        .zip(&theta[..n])
        .filter(|(s, _)| s.unit == "MPa")
        .map(|(_, v)| v.abs())
        .sum();
    let mu0 = law.shear_modulus(&theta[..n]);
    if moduli > 0.0 && mu0.abs() <= DEGENERATE * moduli {
        out.push(format!("initial shear modulus {mu0:.1e} MPa ~ 0"));
    }
    for p in predictions {
        let scale = p.observed.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if scale > 0.0 && p.predicted.iter().all(|v| v.abs() <= DEGENERATE * scale) {
            out.push(format!("predicts ~0 throughout `{}`", p.data));
        }
    }
    out
}

/// A start inside the law's domain when fixed values push the default one
/// out of it (`--fix C01=-0.1` on Mooney-Rivlin: C10 + C01 > 0 needs
/// C10 > 0.1 MPa, the default start is C10 = 1e-3): the free moduli (MPa,
/// those that raise the initial shear modulus) are raised by the fixed moduli's
/// magnitude. `None`: the default start is admissible (or the law has no
/// fixed value). An error names the fixed values when no such start exists.
pub(crate) fn admissible_start(
    law: &Law,
    fixed: &[(String, f64)],
) -> anyhow::Result<Option<Vec<f64>>> {
    if fixed.is_empty() {
        return Ok(None);
    }
    let specs = law.params();
    let value = |s: &palpate_material::MaterialParam| {
        fixed.iter().find(|(n, _)| n == &s.name).map(|(_, v)| *v)
    };
    let mut p: Vec<f64> = specs
        .iter()
        .map(|s| value(s).unwrap_or(s.initial))
        .collect();
    if law.check(&p).is_ok() {
        return Ok(None);
    }
    let shift: f64 = specs
        .iter()
        .filter(|s| s.unit == "MPa")
        .filter_map(value)
        .map(f64::abs)
        .sum();
    // the free moduli: bounded below by 0, an Ogden mu_i, or one that
    // raises the initial shear modulus (C10 and C01 of Mooney-Rivlin; not
    // a higher polynomial term)
    let base = p.clone();
    for (k, s) in specs.iter().enumerate() {
        let raises = {
            let mut q = base.clone();
            q[k] += 1.0;
            law.shear_modulus(&q) > law.shear_modulus(&base)
        };
        let modulus = s.lower == 0.0 || s.name.starts_with("mu") || raises;
        if value(s).is_none() && s.unit == "MPa" && modulus {
            p[k] = s.initial.abs().max(1e-3) + shift;
        }
    }
    match law.check(&p) {
        Ok(()) => Ok(Some(p)),
        Err(e) => {
            let given: Vec<String> = fixed.iter().map(|(n, v)| format!("{n}={v}")).collect();
            anyhow::bail!(
                "fixed {}: no start of {law} with these values is admissible ({e}); free a parameter or change the fixed value",
                given.join(" ")
            )
        }
    }
}

/// The start of a viscoelastic fit: the law's parameters from an elastic
/// fit to the same records (time ignored), then `g_i = 0.5 / N` and
/// relaxation times log-spaced between ten times the shortest sampling step
/// and half the longest record (the decades the data can resolve).
fn viscous_start(req: &Request<'_>, viscous: Viscous) -> anyhow::Result<Vec<f64>> {
    let elastic = calibrate(Request {
        law: req.law,
        model: None,
        fitted: req.fitted,
        predict: &[],
        residual: req.residual,
        method: req.method,
        fixed: req
            .fixed
            .iter()
            .filter(|(n, _)| req.law.params().iter().any(|p| &p.name == n))
            .cloned()
            .collect(),
        observer: None,
        viscous: None,
    })
    .context("the elastic fit that starts the viscoelastic one")?;
    let mut theta: Vec<f64> = elastic.params.iter().map(|(_, p)| p.value).collect();
    let (mut dt_min, mut span) = (f64::INFINITY, 0.0f64);
    for d in req.fitted {
        let t = d.loading.time.as_deref().ok_or_else(|| {
            anyhow::anyhow!(
                "data set `{}` ({}) has no `time_s` column: a viscoelastic fit needs timed records",
                d.name,
                d.file
            )
        })?;
        for w in t.windows(2) {
            if w[1] > w[0] {
                dt_min = dt_min.min(w[1] - w[0]);
            }
        }
        span = span.max(t.last().copied().unwrap_or(0.0) - t[0]);
    }
    let n = match viscous {
        Viscous::Qlv(n) | Viscous::Finite(n) => n,
    };
    let (lo, hi) = (
        (10.0 * dt_min).min(span / 4.0).max(1e-6),
        (span / 2.0).max(1e-6),
    );
    for i in 1..=n {
        let x = i as f64 / (n + 1) as f64;
        theta.push(0.5 / n as f64);
        theta.push(lo * (hi / lo).powf(x));
    }
    Ok(theta)
}

/// R^2 = 1 - SS_res / SS_tot and the RMS of absolute residuals.
pub fn r2_rms(observed: &[f64], predicted: &[f64]) -> (f64, f64) {
    let n = observed.len().max(1) as f64;
    let mean = observed.iter().sum::<f64>() / n;
    let ss_res: f64 = observed
        .iter()
        .zip(predicted)
        .map(|(y, f)| (y - f).powi(2))
        .sum();
    let ss_tot: f64 = observed.iter().map(|y| (y - mean).powi(2)).sum();
    (1.0 - ss_res / ss_tot, (ss_res / n).sqrt())
}
