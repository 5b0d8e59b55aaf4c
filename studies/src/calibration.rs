//! The calibration service behind `palpate calibrate` and the manifests'
//! `calibrate` step: reads data files into data sets, builds the forward
//! model each test needs, fits, and adds what a material-model user expects
//! beside the fit (Drucker stability range, predictions of other tests).

use crate::models::ModelSpec;
use anyhow::Context;
use palpate_analytic::Mode;
use palpate_core::data::{Column, Table};
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_inverse::{
    fit, DataSet, FitOptions, FitReport, Method, MultiStart, Objective, ResidualKind,
    SharedObserver,
};
use palpate_material::stability::{drucker, DruckerReport};
use palpate_material::Law;
use serde::Serialize;
use std::path::Path;
use std::sync::Arc;

/// The kind of experiment a data file records.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TestKind {
    /// A homogeneous test: columns `stretch`, `stress_MPa` (nominal).
    Homogeneous(Mode),
    /// Benchmark C1: columns `displacement_mm`, `force_N` (and `time_s` when timed).
    C1,
    /// Benchmark N1 (FE needle indentation; by default friction 0.8, coarse mesh): same columns as C1.
    N1,
}

impl TestKind {
    /// Parses `uniaxial`, `biaxial`, `planar` (and their aliases), `C1` or `N1`.
    pub fn parse(s: &str) -> anyhow::Result<TestKind> {
        if s.eq_ignore_ascii_case("c1") {
            return Ok(TestKind::C1);
        }
        if s.eq_ignore_ascii_case("n1") {
            return Ok(TestKind::N1);
        }
        s.parse::<Mode>().map(TestKind::Homogeneous).map_err(|_| {
            anyhow::anyhow!("unknown test `{s}`; expected uniaxial, biaxial, planar, C1 or N1")
        })
    }

    /// The forward model of this test for a law ([`crate::models::for_test`]).
    pub fn model(self, law: Law) -> anyhow::Result<Arc<dyn ForwardModel>> {
        let m = crate::models::build(&crate::models::for_test(self, law))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        Ok(Arc::from(m))
    }
}

/// A data file read for one test.
#[derive(Debug, Clone)]
pub struct TestData {
    /// Name in reports (`uniaxial`, or the manifest's data-set name).
    pub name: String,
    pub test: TestKind,
    pub file: String,
    pub loading: Loading,
    pub observed: Vec<f64>,
}

impl TestData {
    /// Reads a data file for a test; errors name the file, line and column.
    pub fn read(name: &str, test: TestKind, path: &Path) -> anyhow::Result<TestData> {
        let table = Table::read(path)?;
        let (loading, observed) = match test {
            TestKind::Homogeneous(_) => {
                table.require(&[Column::STRETCH, Column::STRESS])?;
                let stretch = table.column(Column::STRETCH)?.to_vec();
                if let Some(k) = stretch.iter().position(|&s| s <= 0.0) {
                    anyhow::bail!(
                        "{}:{}: column `stretch` must be positive, found {}",
                        path.display(),
                        table.lines[k],
                        stretch[k]
                    );
                }
                (
                    Loading::quasi_static(Drive::Stretch, stretch),
                    table.column(Column::STRESS)?.to_vec(),
                )
            }
            TestKind::C1 | TestKind::N1 => {
                table.require(&[Column::DISPLACEMENT, Column::FORCE])?;
                let d = table.column(Column::DISPLACEMENT)?.to_vec();
                let loading = if table.has(Column::TIME) {
                    Loading::timed(
                        Drive::DisplacementMm,
                        table.column(Column::TIME)?.to_vec(),
                        d,
                    )
                } else {
                    Loading::quasi_static(Drive::DisplacementMm, d)
                };
                (loading, table.column(Column::FORCE)?.to_vec())
            }
        };
        // A record must carry a curve: two samples at least, and not zero
        // everywhere (a fit to zeros "converges" to nothing with R^2 -inf).
        let column = match test {
            TestKind::Homogeneous(_) => Column::STRESS,
            _ => Column::FORCE,
        };
        if observed.len() < 2 {
            anyhow::bail!(
                "{}:{}: a single data row; a record needs at least 2 rows of `{column}`",
                path.display(),
                table.lines[0]
            );
        }
        if observed.iter().all(|&v| v == 0.0) {
            anyhow::bail!(
                "{}: column `{column}` is zero on every row (lines {}-{}): nothing to fit",
                path.display(),
                table.lines[0],
                table.lines[table.lines.len() - 1]
            );
        }
        Ok(TestData {
            name: name.to_string(),
            test,
            file: path.display().to_string(),
            loading,
            observed,
        })
    }

    /// The data set of this record predicted by `model`.
    pub fn dataset(&self, model: Arc<dyn ForwardModel>) -> DataSet {
        DataSet::new(
            self.name.clone(),
            model,
            self.loading.clone(),
            self.observed.clone(),
        )
    }
}

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
    pub fitted: bool,
    pub r2: f64,
    pub rms: f64,
    pub stretch_or_displacement: Vec<f64>,
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
    /// test for `law` ([`crate::models::for_test`]).
    pub model: Option<&'a ModelSpec>,
    pub fitted: &'a [TestData],
    /// Further data sets on which the fit is evaluated.
    pub predict: &'a [TestData],
    pub residual: ResidualKind,
    pub method: Method,
    pub fixed: Vec<(String, f64)>,
    pub observer: Option<SharedObserver>,
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

impl Request<'_> {
    /// The forward model of a data set.
    fn model_of(&self, d: &TestData) -> anyhow::Result<Arc<dyn ForwardModel>> {
        match self.model {
            None => d.test.model(self.law),
            Some(spec) => {
                anyhow::ensure!(
                    spec.test().ok() == Some(d.test),
                    "data set `{}` is a {:?} record; a {} model does not predict it",
                    d.name,
                    d.test,
                    spec.kind()
                );
                let m = crate::models::build(spec).map_err(|e| anyhow::anyhow!("{e}"))?;
                Ok(Arc::from(m))
            }
        }
    }
}

/// Fits a law and evaluates it on the fitted and the extra data sets.
pub fn calibrate(req: Request<'_>) -> anyhow::Result<Calibration> {
    let sets: Vec<DataSet> = req
        .fitted
        .iter()
        .map(|d| Ok(d.dataset(req.model_of(d)?)))
        .collect::<anyhow::Result<_>>()?;
    let objective = Objective::new(sets, req.residual, &req.fixed).context("setting up the fit")?;
    // Laws with exponents (Ogden, Arruda-Boyce) have several local minima: start from several points.
    let starts = match req.law {
        Law::Ogden(n) => 6 * n,
        Law::ArrudaBoyce => 4,
        _ => 1,
    };
    let options = FitOptions {
        method: req.method,
        multistart: MultiStart {
            starts,
            spread: 1.0,
        },
        observer: req.observer.clone(),
        ..FitOptions::default()
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
        drucker: drucker(&req.law, &theta),
        predictions,
        fit: report,
    })
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
