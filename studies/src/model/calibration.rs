//! The calibration service behind `palpate calibrate` and the manifests'
//! `calibrate` step: reads data files into data sets, builds the forward
//! model each test needs, fits, and adds what a material-model user expects
//! beside the fit (Drucker stability range, predictions of other tests).

use crate::models::{ModelSpec, Viscous};
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
    /// A homogeneous test driven by one stretch: uniaxial (tension and
    /// compression), equibiaxial or planar; columns `stretch` (or `strain`,
    /// `true_strain`) and `stress_MPa` (or `true_stress_MPa`, kPa, Pa),
    /// and `time_s` for a timed (viscoelastic) record ([`crate::columns`]).
    Homogeneous(Mode),
    /// General biaxial extension: `lambda1`, `lambda2`, `stress1_MPa`,
    /// `stress2_MPa` (two stretches and two stresses per row; `--data
    /// biaxial=FILE` becomes this when the file has two stretch columns).
    GeneralBiaxial,
    /// Simple shear, optionally superposed on an axial stretch:
    /// `amount_of_shear`, `shear_stress_MPa`.
    SimpleShear,
    /// Benchmark C1: columns `displacement_mm`, `force_N` (and `time_s` when timed).
    C1,
    /// Benchmark N1 (FE needle indentation; by default friction 0.8, coarse mesh): same columns as C1.
    N1,
}

impl TestKind {
    /// Parses `uniaxial`, `biaxial` (equibiaxial, or general from the
    /// columns), `planar` (`pure_shear`), `general_biaxial`, `simple_shear`
    /// (and their aliases), `C1` or `N1`.
    pub fn parse(s: &str) -> anyhow::Result<TestKind> {
        if s.eq_ignore_ascii_case("c1") {
            return Ok(TestKind::C1);
        }
        if s.eq_ignore_ascii_case("n1") {
            return Ok(TestKind::N1);
        }
        match s.trim().to_ascii_lowercase().replace('-', "_").as_str() {
            "simple_shear" => return Ok(TestKind::SimpleShear),
            "shear" => anyhow::bail!(
                "test `{s}` is ambiguous: simple_shear (amount of shear, shear stress) or planar (pure shear: stretch, stress)"
            ),
            "general_biaxial" => return Ok(TestKind::GeneralBiaxial),
            _ => {}
        }
        s.parse::<Mode>().map(TestKind::Homogeneous).map_err(|_| {
            anyhow::anyhow!(
                "unknown test `{s}`; expected uniaxial, biaxial, planar, simple_shear, general_biaxial, C1 or N1"
            )
        })
    }

    /// Whether records of this kind are homogeneous stress records (not force records).
    pub fn is_homogeneous(self) -> bool {
        !matches!(self, TestKind::C1 | TestKind::N1)
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
    /// Weight of this record's residuals in a joint fit (default 1).
    pub weight: f64,
    /// Simple shear: the axial stretch the shear is superposed on (default 1).
    pub axial_stretch: f64,
}

/// How to read a data file beyond its test kind (all optional).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReadOptions {
    /// Weight of the record in a joint fit (> 0).
    pub weight: f64,
    /// Simple shear superposed on this axial stretch (> 0).
    pub axial_stretch: f64,
    /// The unit the stress columns are really in, in MPa per unit,
    /// overriding the unit in their names (for a file whose header is
    /// known to be wrong).
    pub stress_unit: Option<f64>,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            weight: 1.0,
            axial_stretch: 1.0,
            stress_unit: None,
        }
    }
}

impl ReadOptions {
    /// Parses the options of a `--data KIND[key=value,...]=FILE` or a
    /// manifest data set: `weight`, `axial_stretch`, `stress_unit` (MPa, kPa, Pa).
    pub fn set(&mut self, key: &str, value: &str) -> anyhow::Result<()> {
        let number = |what: &str| -> anyhow::Result<f64> {
            value
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| *v > 0.0 && v.is_finite())
                .ok_or_else(|| anyhow::anyhow!("{what} `{value}`: expected a positive number"))
        };
        match key.trim() {
            "weight" => self.weight = number("weight")?,
            "axial_stretch" => self.axial_stretch = number("axial_stretch")?,
            "stress_unit" => {
                self.stress_unit = Some(match value.trim() {
                    "MPa" => 1.0,
                    "kPa" => 1e-3,
                    "Pa" => 1e-6,
                    other => anyhow::bail!("stress_unit `{other}`: expected MPa, kPa or Pa"),
                })
            }
            other => anyhow::bail!(
                "unknown data option `{other}`; expected weight, axial_stretch or stress_unit"
            ),
        }
        Ok(())
    }
}

impl TestData {
    /// Reads a data file for a test; errors name the file, line and column.
    pub fn read(name: &str, test: TestKind, path: &Path) -> anyhow::Result<TestData> {
        Self::read_with(name, test, path, ReadOptions::default())
    }

    /// [`TestData::read`] with a weight, an axial stretch or a stress unit.
    pub fn read_with(
        name: &str,
        test: TestKind,
        path: &Path,
        options: ReadOptions,
    ) -> anyhow::Result<TestData> {
        Self::from_table(name, test, Table::read(path)?, options)
    }

    /// A record from a table already read (a file's, or the columns of an
    /// [`crate::arrays::ArrayRecord`]); messages name `table.file`.
    pub fn from_table(
        name: &str,
        test: TestKind,
        table: Table,
        options: ReadOptions,
    ) -> anyhow::Result<TestData> {
        let path = table.file.clone();
        let path = path.as_path();
        if options.axial_stretch != 1.0 && test != TestKind::SimpleShear {
            anyhow::bail!(
                "{}: axial_stretch = {} is for simple-shear records, not {test:?}",
                path.display(),
                options.axial_stretch
            );
        }
        let mut test = test;
        let mut stress_column = String::from("stress_MPa");
        let (loading, observed) = match test {
            TestKind::Homogeneous(_) | TestKind::GeneralBiaxial | TestKind::SimpleShear => {
                let h =
                    crate::columns::read(&table, test, options.axial_stretch, options.stress_unit)?;
                test = h.test;
                if let Some(c) = h.used.last() {
                    stress_column = c.clone();
                }
                let loading = match (table.has(Column::TIME), test) {
                    (true, TestKind::GeneralBiaxial) | (false, _) => {
                        Loading::quasi_static(h.drive_kind, h.drive)
                    }
                    (true, _) => {
                        Loading::timed(h.drive_kind, table.column(Column::TIME)?.to_vec(), h.drive)
                    }
                };
                (loading, h.stress)
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
        let column = if test.is_homogeneous() {
            stress_column.as_str()
        } else {
            Column::FORCE
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
            weight: options.weight,
            axial_stretch: options.axial_stretch,
        })
    }

    /// The model of this record's test for `law` ([`crate::models::for_test`]),
    /// with its axial stretch and, if given, a viscoelastic form.
    pub fn spec(&self, law: Law, viscous: Option<Viscous>) -> ModelSpec {
        let mut spec = crate::models::for_test(self.test, law);
        if let ModelSpec::Homogeneous(h) = &mut spec {
            if self.test == TestKind::SimpleShear && self.axial_stretch != 1.0 {
                h.axial_stretch = Some(self.axial_stretch);
            }
            h.viscoelastic = viscous.map(|v| v.to_string());
        }
        spec
    }

    /// The data set of this record predicted by `model`.
    pub fn dataset(&self, model: Arc<dyn ForwardModel>) -> DataSet {
        let mut d = DataSet::new(
            self.name.clone(),
            model,
            self.loading.clone(),
            self.observed.clone(),
        );
        d.weight = self.weight;
        d
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

impl Request<'_> {
    /// The forward model of a data set.
    fn model_of(&self, d: &TestData) -> anyhow::Result<Arc<dyn ForwardModel>> {
        match self.model {
            None if d.test.is_homogeneous() => {
                let m = crate::models::build(&d.spec(self.law, self.viscous))
                    .map_err(|e| anyhow::anyhow!("data set `{}`: {e}", d.name))?;
                Ok(Arc::from(m))
            }
            None => {
                anyhow::ensure!(
                    self.viscous.is_none(),
                    "data set `{}`: a viscoelastic form applies to homogeneous records only",
                    d.name
                );
                d.test.model(self.law)
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
                let m = crate::models::build(&spec).map_err(|e| anyhow::anyhow!("{e}"))?;
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
    let options = FitOptions {
        method: req.method,
        multistart: MultiStart {
            starts,
            spread: 1.0,
        },
        observer: req.observer.clone(),
        start,
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
        // A viscoelastic fit appends Prony terms: the law is the leading part.
        drucker: drucker(&req.law, &theta[..req.law.param_count().min(theta.len())]),
        predictions,
        fit: report,
    })
}

/// A start inside the law's domain when fixed values push the default one
/// out of it (`--fix C01=-0.1` on Mooney-Rivlin: C10 + C01 > 0 needs
/// C10 > 0.1 MPa, the default start is C10 = 1e-3): the free moduli (MPa,
/// lower bound 0, or Ogden's mu_i) are raised by the fixed moduli's
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
    for (k, s) in specs.iter().enumerate() {
        let modulus = s.unit == "MPa" && (s.lower == 0.0 || s.name.starts_with("mu"));
        if value(s).is_none() && modulus {
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
