//! Replicates of one material: the law fitted to all records pooled and to
//! each record alone, the per-record parameters' mean and SD beside the
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
use crate::records::replicates::{batches_from_names, stem};
use crate::records::TestData;
use anyhow::Context;
use palpate_inverse::{Method, ResidualKind};
use palpate_material::Law;
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, StudentsT};

/// One record's own fit.
#[derive(Debug, Clone, Serialize)]
pub struct ReplicateFit {
    /// The file's stem (`EF10_0T_A1`).
    pub record: String,
    pub batch: Option<String>,
    /// Fitted parameters, in the law's order.
    pub values: Vec<f64>,
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
        let c = calibrate(Request {
            law,
            model: None,
            fitted: std::slice::from_ref(r),
            predict: &[],
            residual: ResidualKind::Absolute,
            method: Method::LevenbergMarquardt(Default::default()),
            fixed: Vec::new(),
            observer: None,
            viscous: None,
        })
        .with_context(|| format!("replicate {}", r.file))?;
        fits.push(ReplicateFit {
            record: stems[k].clone(),
            batch: batch_of[k].clone(),
            values: c.params.iter().map(|(_, v)| v.value).collect(),
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
