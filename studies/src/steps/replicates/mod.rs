//! Replicates of one material: the law fitted to all records pooled and to
//! each record alone ([`analyse`], which `palpate calibrate` uses too), and
//! the study step `replicates` ([`ReplicatesStep`]) that adds the fit to
//! their mean curve on a common strain grid and its comparison with a
//! published table of fits to that curve; the per-record parameters' mean and SD beside the
//! pooled fit's standard errors, and the batch-to-batch difference (batch A
//! against batch B) by Welch's t-test on the per-record parameters.
//!
//! The pooled standard errors say how well the pooled curve pins the
//! parameters given its residuals; the replicate SD says how much the
//! material differs from specimen to specimen. On dense records the first
//! is far smaller than the second: a parameter is known to the replicate
//! SD over the square root of the number of replicates, not to its pooled
//! standard error.

use crate::model::calibration::{calibrate, Calibration, Request};
use crate::records::published::PublishedFit;
use crate::records::replicates::{batches_from_names, mean_curve, stem, MeanCurve};
use crate::records::{ReadOptions, TestData, TestKind};
use crate::report::plot::{thinned, Plot, Series, PALETTE};
use crate::run::output::write_atomic;
use crate::run::step::{duplicate, At, Run, Step, StepResult, Study};

mod hierarchical;
use anyhow::Context;
pub use hierarchical::{hierarchical, hierarchical_table};
use palpate_analytic::Mode;
use palpate_material::{homogeneous, Law};
use serde::Deserialize;
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, StudentsT};
use std::path::PathBuf;

/// One record's own fit.
#[derive(Debug, Clone, Serialize)]
pub struct ReplicateFit {
    /// The file's stem (`EF10_0T_A1`).
    pub record: String,
    pub batch: Option<String>,
    /// Fitted parameters, in the law's order.
    pub values: Vec<f64>,
    /// Their standard errors (from the record's residuals).
    pub standard_errors: Vec<Option<f64>>,
    pub r2: f64,
    pub rms: f64,
    pub converged: bool,
}

/// Welch's t-test of one parameter between two batches.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct Welch {
    pub mean_a: f64,
    pub mean_b: f64,
    /// mean_b - mean_a.
    pub difference: f64,
    pub t: f64,
    /// Welch-Satterthwaite degrees of freedom.
    pub df: f64,
    /// Two-sided p-value.
    pub p: f64,
}

/// Welch's t-test (unequal variances) of the means of `a` and `b`;
/// `None` with fewer than two values in either or no spread in both.
pub fn welch(a: &[f64], b: &[f64]) -> Option<Welch> {
    if a.len() < 2 || b.len() < 2 {
        return None;
    }
    let (ma, va) = mean_var(a);
    let (mb, vb) = mean_var(b);
    let (sa, sb) = (va / a.len() as f64, vb / b.len() as f64);
    let se2 = sa + sb;
    if se2 <= 0.0 || !se2.is_finite() {
        return None;
    }
    let t = (mb - ma) / se2.sqrt();
    let df = se2 * se2 / (sa * sa / (a.len() as f64 - 1.0) + sb * sb / (b.len() as f64 - 1.0));
    let dist = StudentsT::new(0.0, 1.0, df).ok()?;
    Some(Welch {
        mean_a: ma,
        mean_b: mb,
        difference: mb - ma,
        t,
        df,
        p: 2.0 * dist.sf(t.abs()),
    })
}

/// Mean and sample variance (n - 1).
fn mean_var(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = if v.len() > 1 {
        v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0)
    } else {
        f64::NAN
    };
    (m, var)
}

/// The batch comparison of one pair of batches.
#[derive(Debug, Clone, Serialize)]
pub struct BatchComparison {
    pub a: String,
    pub b: String,
    pub n_a: usize,
    pub n_b: usize,
    /// Where the batches come from: `declared` or `file names`.
    pub source: String,
    /// One test per parameter (law order); `None` where it cannot be made.
    pub tests: Vec<Option<Welch>>,
}

/// Pooled and per-record fits of replicates.
#[derive(Debug, Clone, Serialize)]
pub struct Replicates {
    pub law: String,
    pub names: Vec<String>,
    pub units: Vec<String>,
    /// The pooled fit's values and standard errors.
    pub pooled: Vec<f64>,
    pub pooled_se: Vec<Option<f64>>,
    pub pooled_r2: f64,
    pub fits: Vec<ReplicateFit>,
    /// Mean and SD (n - 1) of the per-record values.
    pub mean: Vec<f64>,
    pub sd: Vec<f64>,
    /// Batch A against batch B, when the records come in two batches.
    pub batches: Option<BatchComparison>,
    /// Batches found but not compared (more than two), for the report.
    pub note: Option<String>,
}

/// Fits `law` to `records` pooled (`pooled`, already made: the joint fit
/// of every record) and to each alone, and compares the batches (declared
/// with `batch=`, else read from the file names).
pub fn analyse(law: Law, records: &[TestData], pooled: &Calibration) -> anyhow::Result<Replicates> {
    anyhow::ensure!(
        records.len() >= 2,
        "replicates: {} record; replicates need two files at least",
        records.len()
    );
    let names: Vec<String> = pooled.params.iter().map(|(n, _)| n.clone()).collect();
    let units: Vec<String> = pooled.params.iter().map(|(_, v)| v.unit.clone()).collect();
    let stems: Vec<String> = records.iter().map(|r| stem(&r.file)).collect();
    let declared = records.iter().any(|r| r.batch.is_some());
    let (batch_of, source): (Vec<Option<String>>, &str) = if declared {
        if let Some(r) = records.iter().find(|r| r.batch.is_none()) {
            anyhow::bail!(
                "replicates: {} has no batch while others do (batch=...); declare the batch of every file or of none",
                r.file
            );
        }
        (
            records.iter().map(|r| r.batch.clone()).collect(),
            "declared",
        )
    } else {
        match batches_from_names(&stems) {
            Some(b) => (b.into_iter().map(Some).collect(), "file names"),
            None => (vec![None; records.len()], ""),
        }
    };
    let mut fits = Vec::with_capacity(records.len());
    for (k, r) in records.iter().enumerate() {
        let c = calibrate(Request::least_squares(law, std::slice::from_ref(r)))
            .with_context(|| format!("replicate {}", r.file))?;
        fits.push(ReplicateFit {
            record: stems[k].clone(),
            batch: batch_of[k].clone(),
            values: c.params.iter().map(|(_, v)| v.value).collect(),
            standard_errors: c.params.iter().map(|(_, v)| v.standard_error).collect(),
            r2: c.r2,
            rms: c.rms,
            converged: c.converged,
        });
    }
    let column = |j: usize, keep: &dyn Fn(&ReplicateFit) -> bool| -> Vec<f64> {
        fits.iter()
            .filter(|f| keep(f))
            .map(|f| f.values[j])
            .collect()
    };
    let (mean, sd): (Vec<f64>, Vec<f64>) = (0..names.len())
        .map(|j| {
            let (m, v) = mean_var(&column(j, &|_| true));
            (m, v.sqrt())
        })
        .unzip();
    let mut labels: Vec<String> = batch_of.iter().flatten().cloned().collect();
    labels.sort();
    labels.dedup();
    let (batches, note) = match labels.len() {
        2 => {
            let (a, b) = (labels[0].clone(), labels[1].clone());
            let in_a = |f: &ReplicateFit| f.batch.as_deref() == Some(a.as_str());
            let in_b = |f: &ReplicateFit| f.batch.as_deref() == Some(b.as_str());
            let tests = (0..names.len())
                .map(|j| welch(&column(j, &in_a), &column(j, &in_b)))
                .collect();
            (
                Some(BatchComparison {
                    n_a: fits.iter().filter(|f| in_a(f)).count(),
                    n_b: fits.iter().filter(|f| in_b(f)).count(),
                    a,
                    b,
                    source: source.to_string(),
                    tests,
                }),
                None,
            )
        }
        0 | 1 => (None, None),
        n => (
            None,
            Some(format!(
                "{n} batches ({}): the batch test compares two",
                labels.join(", ")
            )),
        ),
    };
    Ok(Replicates {
        law: law.to_string(),
        pooled: pooled.params.iter().map(|(_, v)| v.value).collect(),
        pooled_se: pooled
            .params
            .iter()
            .map(|(_, v)| v.standard_error)
            .collect(),
        pooled_r2: pooled.r2,
        names,
        units,
        fits,
        mean,
        sd,
        batches,
        note,
    })
}

/// A number with 4 significant digits (`1.234e-5`, `0.02213`), never `0.0000`.
pub fn sig4(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if (1e-3..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.3e}")
    }
}

impl Replicates {
    /// The report: per-record fits, then per parameter the pooled value
    /// and standard error beside the replicate mean and SD, then the batch
    /// test.
    pub fn table(&self) -> String {
        let mut out = format!(
            "\nreplicates: {} records, {} fitted pooled and one by one\n",
            self.fits.len(),
            self.law
        );
        out.push_str(&format!("{:<24} {:>6}", "record", "batch"));
        for n in &self.names {
            out.push_str(&format!(" {n:>12}"));
        }
        out.push_str(&format!(" {:>8}\n", "R^2"));
        for f in &self.fits {
            out.push_str(&format!(
                "{:<24} {:>6}",
                f.record,
                f.batch.as_deref().unwrap_or("-")
            ));
            for v in &f.values {
                out.push_str(&format!(" {:>12}", sig4(*v)));
            }
            out.push_str(&format!(
                " {:>8.5}{}\n",
                f.r2,
                if f.converged { "" } else { " (not converged)" }
            ));
        }
        out.push_str(&format!(
            "\n{:<10} {:>6} {:>12} {:>11} {:>12} {:>11} {:>9}\n",
            "parameter", "unit", "pooled", "pooled SE", "rep. mean", "rep. SD", "SD/SE"
        ));
        for j in 0..self.names.len() {
            let se = self.pooled_se[j];
            out.push_str(&format!(
                "{:<10} {:>6} {:>12} {:>11} {:>12} {:>11} {:>9}\n",
                self.names[j],
                self.units[j],
                sig4(self.pooled[j]),
                se.map(sig4).unwrap_or_else(|| "-".into()),
                sig4(self.mean[j]),
                sig4(self.sd[j]),
                se.filter(|s| *s > 0.0)
                    .map(|s| format!("{:.1}", self.sd[j] / s))
                    .unwrap_or_else(|| "-".into()),
            ));
        }
        out.push_str(
            "(pooled SE: from the pooled fit's residuals; rep. SD: the spread of the per-record fits, \
             the specimen-to-specimen variation the pooled SE does not hold)\n",
        );
        if let Some(b) = &self.batches {
            out.push_str(&format!(
                "\nbatch {} ({} records) against batch {} ({} records), batches from the {}; Welch's t-test:\n",
                b.a, b.n_a, b.b, b.n_b, b.source
            ));
            out.push_str(&format!(
                "{:<10} {:>12} {:>12} {:>12} {:>8} {:>6} {:>9}\n",
                "parameter",
                format!("mean {}", b.a),
                format!("mean {}", b.b),
                "B - A",
                "t",
                "df",
                "p"
            ));
            for (j, t) in b.tests.iter().enumerate() {
                match t {
                    Some(w) => out.push_str(&format!(
                        "{:<10} {:>12} {:>12} {:>12} {:>8.3} {:>6.1} {:>9.3e}\n",
                        self.names[j],
                        sig4(w.mean_a),
                        sig4(w.mean_b),
                        sig4(w.difference),
                        w.t,
                        w.df,
                        w.p
                    )),
                    None => out.push_str(&format!(
                        "{:<10} (no test: fewer than two records in a batch or no spread)\n",
                        self.names[j]
                    )),
                }
            }
        }
        if let Some(n) = &self.note {
            out.push_str(&format!("\n{n}\n"));
        }
        out
    }
}

/// The replicate files of a step: a pattern with wildcards in the file
/// name, or a list of files (relative to the manifest).
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum Files {
    Pattern(String),
    List(Vec<String>),
}

/// A published table to compare the mean-curve fits with.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PublishedTable {
    /// The table, relative to the manifest.
    pub file: String,
    /// Its format ([`crate::records::published::FORMATS`]).
    pub format: String,
    /// The material's key in the table.
    pub material: String,
    /// `engineering` (default) or `true`.
    #[serde(default = "engineering")]
    pub measure: String,
}

fn engineering() -> String {
    "engineering".into()
}
fn uniaxial() -> String {
    "uniaxial".into()
}
fn thousand() -> usize {
    1000
}

/// A study step (`[[steps]] [steps.replicates]`): replicate records of one
/// material, their mean curve on a common strain grid, each law fitted to
/// the mean curve (beside a published table's fits to it, when given), to
/// the records pooled and to each record alone, with the batch test.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReplicatesStep {
    pub name: String,
    /// The replicate files: `"folder/EF10_0T_*.csv"` or a list.
    pub data: Files,
    /// The test they record (default `uniaxial`).
    #[serde(default = "uniaxial")]
    pub test: String,
    /// The laws (`--law` names).
    pub laws: Vec<String>,
    /// Points of the mean curve's strain grid (default 1000).
    #[serde(default = "thousand")]
    pub grid_points: usize,
    /// The laws also fitted to the records pooled and one by one (default:
    /// every law; `[]`: none).
    #[serde(default)]
    pub per_record_laws: Option<Vec<String>>,
    /// The published table of fits to the same curve.
    #[serde(default)]
    pub published: Option<PublishedTable>,
}

impl ReplicatesStep {
    fn laws(&self) -> anyhow::Result<Vec<Law>> {
        self.laws
            .iter()
            .map(|l| {
                l.parse::<Law>()
                    .map_err(|e| anyhow::anyhow!("laws: \"{l}\": {e}"))
            })
            .collect()
    }

    /// The files, in order (a pattern expanded and sorted by name).
    fn files(&self, dir: &std::path::Path) -> anyhow::Result<Vec<PathBuf>> {
        match &self.data {
            Files::Pattern(p) => {
                let full = dir.join(p);
                crate::records::replicates::expand(&full.to_string_lossy())
                    .map_err(|e| anyhow::anyhow!("data: {e}"))
            }
            Files::List(l) => {
                anyhow::ensure!(!l.is_empty(), "data = []: list two files at least");
                Ok(l.iter().map(|f| dir.join(f)).collect())
            }
        }
    }
}

impl Step for ReplicatesStep {
    fn name(&self) -> &str {
        &self.name
    }

    fn validate(&self, _study: &Study, site: &At) -> anyhow::Result<()> {
        let at = format!("{}: {}", site.file, site.step(&self.name));
        self.laws().map_err(|e| anyhow::anyhow!("{at}.{e}"))?;
        anyhow::ensure!(!self.laws.is_empty(), "{at}.laws = []: give at least one");
        if let Some(d) = duplicate(&self.laws) {
            anyhow::bail!("{at}.laws: \"{d}\" is listed twice");
        }
        for l in self.per_record_laws.iter().flatten() {
            anyhow::ensure!(
                self.laws.contains(l),
                "{at}.per_record_laws: \"{l}\" is not one of laws ({})",
                self.laws.join(", ")
            );
        }
        let test = TestKind::parse(&self.test).map_err(|e| anyhow::anyhow!("{at}.test: {e}"))?;
        anyhow::ensure!(
            matches!(test, TestKind::Homogeneous(_)),
            "{at}.test = \"{}\": replicates take uniaxial, biaxial or planar records",
            self.test
        );
        anyhow::ensure!(
            self.grid_points >= 2,
            "{at}.grid_points = {}: give 2 at least",
            self.grid_points
        );
        let files = self
            .files(site.dir)
            .map_err(|e| anyhow::anyhow!("{at}.{e}"))?;
        anyhow::ensure!(
            files.len() >= 2,
            "{at}.data: {} file; replicates need two files at least",
            files.len()
        );
        for f in &files {
            anyhow::ensure!(f.is_file(), "{at}.data: {} does not exist", f.display());
        }
        if let Some(p) = &self.published {
            crate::records::published::read(
                &site.dir.join(&p.file),
                &p.format,
                &p.material,
                &p.measure,
            )
            .map_err(|e| anyhow::anyhow!("{at}.published: {e}"))?;
        }
        Ok(())
    }

    fn inputs(&self) -> Vec<PathBuf> {
        // a pattern as it is: the runner hashes the files it matches
        let mut out: Vec<PathBuf> = match &self.data {
            Files::Pattern(p) => vec![PathBuf::from(p)],
            Files::List(l) => l.iter().map(PathBuf::from).collect(),
        };
        out.extend(self.published.iter().map(|p| PathBuf::from(&p.file)));
        out
    }

    fn run(
        &self,
        run: &Run,
        _done: &[StepResult],
        report: &mut String,
    ) -> anyhow::Result<serde_json::Value> {
        run_replicates(run, self, report)
    }
}

/// One law's fits to the mean curve, pooled and per record.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct LawFits {
    pub law: String,
    pub names: Vec<String>,
    pub units: Vec<String>,
    /// The fit to the mean curve: values, SSE (MPa^2) and the database's AIC
    /// (`n ln(SSE / n) + 2 k`, SSE in the published table's unit, kPa^2 by
    /// default).
    pub mean_curve: Vec<f64>,
    pub mean_curve_sse: f64,
    pub mean_curve_aic: f64,
    pub mean_curve_converged: bool,
    /// The mean-curve fit's Drucker-stable stretches in each mode.
    pub mean_curve_drucker: palpate_material::stability::DruckerReport,
    /// The initial shear modulus of each fit (MPa).
    pub mu0_mean_curve: f64,
    pub mu0_pooled: Option<f64>,
    /// The per-record fits' mu0: mean and SD.
    pub mu0_records_mean: Option<f64>,
    pub mu0_records_sd: Option<f64>,
    /// The published fit of this law, when the table has it.
    pub published: Option<PublishedComparison>,
    /// Pooled and per-record fits ([`Replicates`]), as serialised.
    pub replicates: Option<serde_json::Value>,
    /// The replicates' report table.
    pub replicates_table: Option<String>,
}

/// A published fit beside palpate's fit to the same curve.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PublishedComparison {
    /// The table's name of the law.
    pub name: String,
    /// Its parameters in palpate's convention (MPa).
    pub values: Vec<f64>,
    /// Its SSE as published, in the table's unit squared.
    pub sse: f64,
    /// Its AIC as published.
    pub aic: Option<f64>,
    /// Its parameters' SSE on palpate's mean curve, in the table's unit squared.
    pub sse_here: f64,
    /// palpate's SSE in the table's unit squared.
    pub sse_palpate: f64,
    /// The largest relative difference of a parameter.
    pub max_relative_difference: f64,
    /// `same` (every parameter to 4 significant digits, SSE within 1e-4),
    /// `lower SSE` (palpate's optimum is better on the same curve) or
    /// `higher SSE` (palpate missed the published optimum).
    pub verdict: String,
}

/// palpate's fit against a published one on the same curve: every
/// parameter within half a unit of the 4th significant digit and SSE within
/// 1e-4 relative is `same`; a lower SSE (by more than 1e-4 relative) than
/// the published parameters' on the same curve is `lower SSE`.
pub fn verdict(
    law: Law,
    palpate: &[f64],
    published: &[f64],
    sse_palpate: f64,
    sse_published_here: f64,
) -> (f64, String) {
    let max_rel = palpate
        .iter()
        .zip(published)
        .map(|(a, b)| (a - b).abs() / b.abs().max(f64::MIN_POSITIVE))
        .fold(0.0_f64, f64::max);
    let same_sse = (sse_palpate - sse_published_here).abs() <= 1e-4 * sse_published_here;
    let outside: Vec<String> = law
        .params()
        .iter()
        .zip(published)
        .filter(|(b, v)| **v < b.lower || **v > b.upper)
        .map(|(b, v)| {
            format!(
                "{} = {} outside [{}, {}]",
                b.name,
                sig4(*v),
                b.lower,
                b.upper
            )
        })
        .collect();
    let text = if max_rel <= 5e-4 && same_sse {
        "same".to_string()
    } else if sse_palpate < sse_published_here * (1.0 - 1e-4) {
        "lower SSE".to_string()
    } else if same_sse {
        "same SSE, other parameters".to_string()
    } else if !outside.is_empty() {
        format!(
            "higher SSE: the published optimum has {}, palpate's bounds",
            outside.join(", ")
        )
    } else {
        "higher SSE".to_string()
    };
    (max_rel, text)
}

fn run_replicates(
    run: &Run,
    step: &ReplicatesStep,
    report: &mut String,
) -> anyhow::Result<serde_json::Value> {
    let test = TestKind::parse(&step.test)?;
    let files = step.files(run.manifest_dir)?;
    let records: Vec<TestData> = files
        .iter()
        .map(|f| {
            let mut r = TestData::read_with(&step.test, test, f, ReadOptions::default())?;
            // names relative to the manifest, so that reports and cache keys
            // do not depend on where the study is run from
            r.file = f
                .strip_prefix(run.manifest_dir)
                .unwrap_or(f)
                .display()
                .to_string();
            r.name = stem(&r.file);
            Ok(r)
        })
        .collect::<anyhow::Result<_>>()
        .with_context(|| format!("step `{}`", step.name))?;
    let curve =
        mean_curve(&records, step.grid_points).with_context(|| format!("step `{}`", step.name))?;
    let published = match &step.published {
        Some(p) => crate::records::published::read(
            &run.manifest_dir.join(&p.file),
            &p.format,
            &p.material,
            &p.measure,
        )?,
        None => Vec::new(),
    };
    // the table's stress unit (kPa by default) for SSE and AIC
    let unit = published.first().map(|p| p.stress_unit).unwrap_or(1e-3);
    let mut fits = Vec::new();
    for (text, law) in step.laws.iter().zip(step.laws()?) {
        let per_record = step
            .per_record_laws
            .as_ref()
            .is_none_or(|l| l.contains(text));
        let label = format!("{}: {law}", step.name);
        let inputs = (
            "replicates",
            &step.name,
            law.to_string(),
            &records,
            step.grid_points,
            per_record,
            &published,
        );
        let Some(f): Option<LawFits> = run.unit(&label, &inputs, || {
            fit_law(law, &records, &curve, &published, unit, per_record)
                .with_context(|| format!("step `{}`: {law}", step.name))
        })?
        else {
            continue;
        };
        fits.push(f);
    }
    report.push_str(&replicates_report(
        step, &records, &curve, &published, unit, &fits,
    ));
    if let TestKind::Homogeneous(mode) = test {
        let file = format!("{}-fits.svg", step.name);
        let svg = fits_plot(&step.name, mode, &records, &curve, &fits);
        write_atomic(&run.out.join("plots").join(&file), svg.as_bytes())?;
        report.push_str(&format!(
            "
![the fits of {}](plots/{file})
",
            step.name
        ));
    }
    let table = fits_csv(&fits, unit);
    write_atomic(
        &run.out.join(format!("{}-fits.csv", step.name)),
        table.as_bytes(),
    )?;
    Ok(serde_json::json!({
        "name": step.name.clone(),
        "records": records.iter().map(|r| r.file.clone()).collect::<Vec<_>>(),
        "mean_curve": { "points": curve.points, "strain_max": curve.strain_max, "records": curve.records },
        "laws": fits,
    }))
}

/// The fits of one law.
fn fit_law(
    law: Law,
    records: &[TestData],
    curve: &MeanCurve,
    published: &[PublishedFit],
    unit: f64,
    per_record: bool,
) -> anyhow::Result<LawFits> {
    let request = |fitted: &[TestData]| -> anyhow::Result<Calibration> {
        calibrate(Request::least_squares(law, fitted))
    };
    let mean = request(std::slice::from_ref(&curve.record)).context("the mean-curve fit")?;
    let values: Vec<f64> = mean.params.iter().map(|(_, v)| v.value).collect();
    // the stress of the law itself (its own checks, not the fit's bounds:
    // a published fit may lie outside palpate's search box)
    let TestKind::Homogeneous(mode) = curve.record.test else {
        anyhow::bail!("the mean curve is not a homogeneous record");
    };
    let sse_of = |theta: &[f64]| -> anyhow::Result<f64> {
        law.check(theta)?;
        let mut sse = 0.0;
        for (&l, o) in curve
            .record
            .loading
            .drive
            .iter()
            .zip(&curve.record.observed)
        {
            let p = match mode {
                Mode::Uniaxial => homogeneous::uniaxial(&law, theta, l),
                Mode::Equibiaxial => homogeneous::equibiaxial(&law, theta, l),
                Mode::Planar => homogeneous::planar(&law, theta, l),
            };
            sse += (p - o) * (p - o);
        }
        anyhow::ensure!(
            sse.is_finite(),
            "{law} {theta:?}: the stress is not finite on the curve"
        );
        Ok(sse)
    };
    let sse = sse_of(&values)?;
    let to_table = |s: f64| s / (unit * unit);
    let k = law.param_count();
    let comparison = match published.iter().find(|p| p.law == Some(law)) {
        Some(p) => {
            let theirs = p.params.clone().unwrap_or_default();
            let here = to_table(sse_of(&theirs)?);
            let (max_rel, verdict) = verdict(law, &values, &theirs, to_table(sse), here);
            Some(PublishedComparison {
                name: p.name.clone(),
                values: theirs,
                sse: p.sse,
                aic: p.aic,
                sse_here: here,
                sse_palpate: to_table(sse),
                max_relative_difference: max_rel,
                verdict,
            })
        }
        None => None,
    };
    let (mu0_pooled, mu0_mean, mu0_sd, reps, table) = if per_record && records.len() >= 2 {
        let pooled = request(records).context("the pooled fit")?;
        let reps = analyse(law, records, &pooled)?;
        let theta: Vec<f64> = pooled.params.iter().map(|(_, v)| v.value).collect();
        let mu0s: Vec<f64> = reps
            .fits
            .iter()
            .map(|f| law.shear_modulus(&f.values))
            .collect();
        let (m, v) = mean_var(&mu0s);
        (
            Some(law.shear_modulus(&theta)),
            Some(m),
            Some(v.sqrt()),
            Some(serde_json::to_value(&reps)?),
            Some(reps.table()),
        )
    } else {
        (None, None, None, None, None)
    };
    Ok(LawFits {
        law: law.to_string(),
        names: mean.params.iter().map(|(n, _)| n.clone()).collect(),
        units: mean.params.iter().map(|(_, v)| v.unit.clone()).collect(),
        mean_curve_aic: crate::records::published::aic(to_table(sse), curve.points, k),
        mean_curve: values.clone(),
        mean_curve_sse: sse,
        mean_curve_converged: mean.converged,
        mean_curve_drucker: mean.drucker,
        mu0_mean_curve: law.shear_modulus(&values),
        mu0_pooled,
        mu0_records_mean: mu0_mean,
        mu0_records_sd: mu0_sd,
        published: comparison,
        replicates: reps,
        replicates_table: table,
    })
}

fn unit_name(unit: f64) -> &'static str {
    if unit == 1.0 {
        "MPa"
    } else if unit == 1e-6 {
        "Pa"
    } else {
        "kPa"
    }
}

/// The step's section of the report.
fn replicates_report(
    step: &ReplicatesStep,
    records: &[TestData],
    curve: &MeanCurve,
    published: &[PublishedFit],
    unit: f64,
    fits: &[LawFits],
) -> String {
    let u = unit_name(unit);
    let mut out = format!("\n## replicates `{}`\n\n", step.name);
    out.push_str(&format!(
        "{} records: {}\n\nmean curve: {}\n",
        records.len(),
        records
            .iter()
            .map(|r| stem(&r.file))
            .collect::<Vec<_>>()
            .join(", "),
        curve.describe()
    ));
    if let Some(p) = &step.published {
        out.push_str(&format!(
            "\n### fits to the mean curve beside the published table ({}, {} `{}`, {})\n\n",
            p.file, p.format, p.material, p.measure
        ));
    } else {
        out.push_str("\n### fits to the mean curve\n\n");
    }
    out.push_str(&format!(
        "SSE in {u}^2 over the {} grid points; AIC = n ln(SSE / n) + 2 k; parameters in palpate's convention (MPa)\n\n",
        curve.points
    ));
    out.push_str("| law | parameters (palpate) | SSE | AIC | published (converted) | published SSE | its SSE here | published AIC | max rel. diff. | verdict |\n");
    out.push_str("|---|---|---|---|---|---|---|---|---|---|\n");
    for f in fits {
        let ours = params_text(&f.names, &f.mean_curve);
        match &f.published {
            Some(c) => out.push_str(&format!(
                "| {} | {} | {:.4} | {:.3} | {} | {:.4} | {:.4} | {} | {:.1e} | {} |\n",
                f.law,
                ours,
                f.mean_curve_sse / (unit * unit),
                f.mean_curve_aic,
                params_text(&f.names, &c.values),
                c.sse,
                c.sse_here,
                c.aic
                    .map(|a| format!("{a:.3}"))
                    .unwrap_or_else(|| "-".into()),
                c.max_relative_difference,
                c.verdict
            )),
            None => out.push_str(&format!(
                "| {} | {} | {:.4} | {:.3} | - | - | - | - | - | not in the table |\n",
                f.law,
                ours,
                f.mean_curve_sse / (unit * unit),
                f.mean_curve_aic
            )),
        }
    }
    // fits that lose Drucker stability somewhere in the scanned stretches
    for f in fits {
        let d = &f.mean_curve_drucker;
        let full = |r: &palpate_material::stability::StableRange| r.lower <= 0.1 && r.upper >= 10.0;
        if !(full(&d.uniaxial) && full(&d.biaxial) && full(&d.planar)) {
            let range = |r: &palpate_material::stability::StableRange| {
                format!("[{:.3}, {:.3}]", r.lower, r.upper)
            };
            let drive = &curve.record.loading.drive;
            let lo = drive.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = drive.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let own = match curve.record.test {
                TestKind::Homogeneous(Mode::Equibiaxial) => &d.biaxial,
                TestKind::Homogeneous(Mode::Planar) => &d.planar,
                _ => &d.uniaxial,
            };
            out.push_str(&format!(
                "\n{}: Drucker-stable for stretches uniaxial {}, equibiaxial {}, planar {} (of 0.1 to 10); the curve's stretches {lo:.3} to {hi:.3} are {}.\n",
                f.law,
                range(&d.uniaxial),
                range(&d.biaxial),
                range(&d.planar),
                if own.contains(lo) && own.contains(hi) { "inside" } else { "not all inside" }
            ));
        }
    }
    let missing: Vec<&str> = published
        .iter()
        .filter(|p| p.law.is_none())
        .map(|p| p.name.as_str())
        .collect();
    if !missing.is_empty() {
        out.push_str(&format!(
            "\npublished laws palpate does not have: {}\n",
            missing.join(", ")
        ));
    }
    if fits.iter().any(|f| f.mu0_pooled.is_some()) {
        out.push_str("\n### initial shear modulus mu0 (MPa): mean curve, pooled records, per-record fits\n\n");
        out.push_str("| law | mean curve | pooled | pooled / mean curve - 1 | per-record mean | SD | per-record mean / mean curve - 1 |\n|---|---|---|---|---|---|---|\n");
        for f in fits {
            if let (Some(p), Some(m), Some(s)) =
                (f.mu0_pooled, f.mu0_records_mean, f.mu0_records_sd)
            {
                out.push_str(&format!(
                    "| {} | {} | {} | {:+.2} % | {} | {} | {:+.2} % |\n",
                    f.law,
                    sig4(f.mu0_mean_curve),
                    sig4(p),
                    100.0 * (p / f.mu0_mean_curve - 1.0),
                    sig4(m),
                    sig4(s),
                    100.0 * (m / f.mu0_mean_curve - 1.0)
                ));
            }
        }
        for f in fits {
            if let Some(t) = &f.replicates_table {
                out.push_str(&format!("\n```{t}```\n"));
            }
        }
    }
    out
}

/// The records (grey), their mean curve (markers) and each law's fit to
/// it (lines): stress (kPa) against strain, compression positive when the
/// records are compressions.
fn fits_plot(
    name: &str,
    mode: Mode,
    records: &[TestData],
    curve: &MeanCurve,
    fits: &[LawFits],
) -> String {
    let compression = curve.record.loading.drive.iter().any(|&l| l < 1.0);
    let sign = if compression { -1.0 } else { 1.0 };
    let strain = |l: &[f64]| -> Vec<f64> { l.iter().map(|l| sign * (l - 1.0)).collect() };
    let stress = |s: &[f64]| -> Vec<f64> { s.iter().map(|s| sign * 1e3 * s).collect() };
    let what = if compression {
        "compressive"
    } else {
        "tensile"
    };
    let mut plot = Plot::new(
        format!("{name}: records, mean curve and the fits to it"),
        format!("{what} engineering strain"),
        format!("{what} engineering stress (kPa)"),
    );
    for (k, r) in records.iter().enumerate() {
        let (x, y) = thinned(&strain(&r.loading.drive), &stress(&r.observed), 150);
        let label = if k == 0 {
            format!("{} records", records.len())
        } else {
            String::new()
        };
        plot.push(Series::line(label, &x, &y).color("#c8c8c8"));
    }
    let grid = &curve.record.loading.drive;
    let (x, y) = thinned(&strain(grid), &stress(&curve.record.observed), 40);
    plot.push(Series::markers("mean curve", &x, &y).color("#000000"));
    for (k, f) in fits.iter().enumerate() {
        let Ok(law) = f.law.parse::<Law>() else {
            continue;
        };
        let (gx, gl) = thinned(grid, grid, 200);
        let p: Vec<f64> = gl
            .iter()
            .map(|&l| match mode {
                Mode::Uniaxial => homogeneous::uniaxial(&law, &f.mean_curve, l),
                Mode::Equibiaxial => homogeneous::equibiaxial(&law, &f.mean_curve, l),
                Mode::Planar => homogeneous::planar(&law, &f.mean_curve, l),
            })
            .collect();
        plot.push(
            Series::line(f.law.clone(), &strain(&gx), &stress(&p))
                .color(PALETTE[k % PALETTE.len()]),
        );
    }
    plot.to_svg()
}

fn params_text(names: &[String], values: &[f64]) -> String {
    names
        .iter()
        .zip(values)
        .map(|(n, v)| format!("{n} {}", sig4(*v)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The table of fits: one row per law and kind of fit (the parameters in
/// palpate's convention, MPa).
fn fits_csv(fits: &[LawFits], unit: f64) -> String {
    let mut out = format!(
        "law,fit,parameters,values,sse_{u}2,aic,mu0_MPa\n",
        u = unit_name(unit)
    );
    for f in fits {
        let join = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x:.9e}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let names = f.names.join(" ");
        out.push_str(&format!(
            "{},mean curve,{names},{},{:.6},{:.4},{:.9e}\n",
            f.law,
            join(&f.mean_curve),
            f.mean_curve_sse / (unit * unit),
            f.mean_curve_aic,
            f.mu0_mean_curve
        ));
        if let Some(c) = &f.published {
            out.push_str(&format!(
                "{},published ({}),{names},{},{:.6},{},{:.9e}\n",
                f.law,
                c.name,
                join(&c.values),
                c.sse,
                c.aic.map(|a| format!("{a:.4}")).unwrap_or_default(),
                f.law
                    .parse::<Law>()
                    .map(|l| l.shear_modulus(&c.values))
                    .unwrap_or(f64::NAN)
            ));
        }
        if let Some(p) = f.mu0_pooled {
            out.push_str(&format!("{},pooled,,,,,{p:.9e}\n", f.law));
        }
        if let (Some(m), Some(s)) = (f.mu0_records_mean, f.mu0_records_sd) {
            out.push_str(&format!("{},per-record mean,,,,,{m:.9e}\n", f.law));
            out.push_str(&format!("{},per-record SD,,,,,{s:.9e}\n", f.law));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against scipy 1.x, `scipy.stats.ttest_ind(b, a, equal_var=False)`:
    /// t = 2.5887392067622947, df = 8.973974220210568, p = 0.029340424936550855.
    #[test]
    fn welch_matches_scipy() {
        let a = [1.0, 2.0, 3.0, 4.0, 5.0];
        let b = [3.0, 4.5, 5.0, 6.5, 7.0, 8.0];
        let w = welch(&a, &b).unwrap();
        assert!((w.t - 2.588_739_206_762_294_7).abs() < 1e-12, "{}", w.t);
        assert!((w.df - 8.973_974_220_210_568).abs() < 1e-10, "{}", w.df);
        assert!((w.p - 0.029_340_424_936_550_855).abs() < 1e-9, "{}", w.p);
        assert!(welch(&a, &[1.0]).is_none());
        assert!(welch(&[1.0, 1.0], &[1.0, 1.0]).is_none());
    }

    #[test]
    fn four_significant_digits_never_print_zero() {
        assert_eq!(sig4(1.4406e-5), "1.441e-5");
        assert_eq!(sig4(0.022123), "0.02212");
        assert_eq!(sig4(12.3456), "12.35");
        assert_eq!(sig4(-0.5), "-0.5000");
        assert_eq!(sig4(0.0), "0");
    }
}
