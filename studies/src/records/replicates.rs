//! Replicates: several files recording one material, named by a pattern
//! with wildcards (`tests/EF10_0T_*.csv`), and the batch each belongs to,
//! declared (`batch=A`) or read from the file names (`EF10_0T_A1` ...
//! `EF10_0T_B5`: batches `A` and `B`), and their mean curve on a common
//! strain grid ([`mean_curve`]).

use super::{TestData, TestKind};
use palpate_core::{Drive, Loading};
use std::path::{Path, PathBuf};

/// Whether `pattern` has wildcards (`*` or `?`).
pub fn is_pattern(pattern: &str) -> bool {
    pattern.contains(['*', '?'])
}

/// Whether `name` matches `pattern` (`*` any run of characters, `?` one
/// character). Written here: one directory level of two wildcards needs no
/// glob crate.
pub fn matches(pattern: &str, name: &str) -> bool {
    let p: Vec<char> = pattern.chars().collect();
    let n: Vec<char> = name.chars().collect();
    // Iterative matching with the last `*` as the backtrack point.
    let (mut i, mut j) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while j < n.len() {
        if i < p.len() && (p[i] == '?' || p[i] == n[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some((i, j));
            i += 1;
        } else if let Some((si, sj)) = star {
            i = si + 1;
            j = sj + 1;
            star = Some((si, sj + 1));
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

/// The files `pattern` names, sorted by name: the file itself when it has
/// no wildcard; wildcards only in the file name, not in its folders. `Err`
/// when nothing matches, listing the folder's files.
pub fn expand(pattern: &str) -> anyhow::Result<Vec<PathBuf>> {
    if !is_pattern(pattern) {
        return Ok(vec![PathBuf::from(pattern)]);
    }
    let path = Path::new(pattern);
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let file = path
        .file_name()
        .and_then(|f| f.to_str())
        .unwrap_or_default();
    anyhow::ensure!(
        !is_pattern(&dir.to_string_lossy()),
        "{pattern}: wildcards only in the file name, not in its folders ({})",
        dir.display()
    );
    let entries = std::fs::read_dir(dir)
        .map_err(|e| anyhow::anyhow!("{pattern}: cannot list {}: {e}", dir.display()))?;
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok())
        .filter(|e| e.file_type().map(|t| t.is_file()).unwrap_or(false))
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .collect();
    names.sort();
    let found: Vec<PathBuf> = names
        .iter()
        .filter(|n| matches(file, n))
        .map(|n| dir.join(n))
        .collect();
    if found.is_empty() {
        let shown: Vec<&str> = names.iter().take(8).map(String::as_str).collect();
        anyhow::bail!(
            "{pattern}: no file of {} matches `{file}` (it has {}{})",
            dir.display(),
            if shown.is_empty() {
                "no files".to_string()
            } else {
                shown.join(", ")
            },
            if names.len() > shown.len() {
                ", ..."
            } else {
                ""
            }
        );
    }
    Ok(found)
}

/// The batch of each file read from the names (stems) of replicate files:
/// each stem without its trailing test number (`EF10_0T_A3` ->
/// `EF10_0T_A`), then what differs after the part all share (`A`, `B`).
/// `None` when the names make fewer than two batches, or a batch of one
/// file.
pub fn batches_from_names(stems: &[String]) -> Option<Vec<String>> {
    let cut: Vec<&str> = stems
        .iter()
        .map(|s| s.trim_end_matches(|c: char| c.is_ascii_digit()))
        .map(|s| s.trim_end_matches(['_', '-', ' ', '.']))
        .collect();
    let mut distinct: Vec<&str> = cut.clone();
    distinct.sort();
    distinct.dedup();
    if distinct.len() < 2 || distinct.iter().any(|d| d.is_empty()) {
        return None;
    }
    if distinct
        .iter()
        .any(|d| cut.iter().filter(|c| *c == d).count() < 2)
    {
        return None;
    }
    // The longest common prefix, in characters.
    let first: Vec<char> = distinct[0].chars().collect();
    let common = distinct.iter().skip(1).fold(first.len(), |n, d| {
        d.chars()
            .zip(&first)
            .take(n)
            .take_while(|(a, b)| a == *b)
            .count()
    });
    let label = |c: &str| -> String {
        let rest: String = c.chars().skip(common).collect();
        let rest = rest.trim_start_matches(['_', '-', ' ', '.']);
        if rest.is_empty() {
            c.to_string()
        } else {
            rest.to_string()
        }
    };
    let labels: Vec<String> = cut.iter().map(|c| label(c)).collect();
    Some(labels)
}

/// The stem of a file path (`dir/EF10_0T_A1.csv` -> `EF10_0T_A1`).
pub fn stem(file: &str) -> String {
    Path::new(file)
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| file.to_string())
}

/// The mean curve of replicate records: each record's stress interpolated
/// linearly at the same engineering strains, then averaged point by point.
#[derive(Debug, Clone)]
pub struct MeanCurve {
    /// The mean curve as a record (stretch drive, mean stress; no time).
    pub record: TestData,
    /// The grid: `points` strains evenly spaced from 0 to `strain_max`.
    pub points: usize,
    /// The largest strain every record reaches (the grid's end), as a
    /// magnitude.
    pub strain_max: f64,
    /// The number of records averaged.
    pub records: usize,
}

impl MeanCurve {
    /// How the curve was made, for reports.
    pub fn describe(&self) -> String {
        format!(
            "mean of {} records at {} engineering strains evenly spaced from 0 to {:.6} \
             (the largest strain every record reaches), each record interpolated linearly",
            self.records, self.points, self.strain_max
        )
    }
}

/// The mean curve of homogeneous records of one test on a common strain
/// grid: `points` engineering strains `|stretch - 1|` evenly spaced from 0
/// to the largest strain every record reaches, each record's stress
/// interpolated linearly there (held at its first value below its first
/// sample) and averaged. This is how a published table of fits to "the mean
/// curve of the tests" is usually made. `Err` naming the file when the
/// records are not of one homogeneous test, mix tension and compression, or
/// a record's strain does not grow monotonically.
pub fn mean_curve(records: &[TestData], points: usize) -> anyhow::Result<MeanCurve> {
    anyhow::ensure!(
        !records.is_empty(),
        "mean curve: no records; give one file at least"
    );
    anyhow::ensure!(
        points >= 2,
        "mean curve: {points} grid points; give 2 at least"
    );
    let first = &records[0];
    anyhow::ensure!(
        matches!(first.test, TestKind::Homogeneous(_)) && first.loading.drive_kind == Drive::Stretch,
        "mean curve: {} is a {:?} record; a mean curve is made of homogeneous stretch records (uniaxial, biaxial, planar)",
        first.file,
        first.test
    );
    // each record as (strain magnitude, stress), strain growing
    let mut direction = 0.0;
    let mut curves = Vec::with_capacity(records.len());
    for r in records {
        anyhow::ensure!(
            r.test == first.test,
            "mean curve: {} is a {:?} record and {} a {:?} record; the replicates of a mean curve record one test",
            first.file,
            first.test,
            r.file,
            r.test
        );
        let end = r
            .loading
            .drive
            .iter()
            .map(|l| l - 1.0)
            .fold(0.0_f64, |a, e| if e.abs() > a.abs() { e } else { a });
        anyhow::ensure!(end != 0.0, "mean curve: {} never leaves stretch 1", r.file);
        let sign = end.signum();
        if direction == 0.0 {
            direction = sign;
        }
        anyhow::ensure!(
            sign == direction,
            "mean curve: {} is stretched in {} while {} is in {}; average records of one direction",
            r.file,
            if sign < 0.0 { "compression" } else { "tension" },
            first.file,
            if direction < 0.0 {
                "compression"
            } else {
                "tension"
            }
        );
        let strain: Vec<f64> = r.loading.drive.iter().map(|l| (l - 1.0) * sign).collect();
        if let Some(k) = strain.windows(2).position(|w| w[1] <= w[0]) {
            anyhow::bail!(
                "mean curve: {}: the strain does not grow at sample {} ({} then {}); \
                 a mean curve needs each record loaded monotonically (cut an unloading branch off first)",
                r.file,
                k + 2,
                strain[k],
                strain[k + 1]
            );
        }
        curves.push((strain, &r.observed));
    }
    let strain_max = curves
        .iter()
        .map(|(e, _)| e[e.len() - 1])
        .fold(f64::INFINITY, f64::min);
    // numpy's linspace: start + k step, the last point the end itself
    let step = strain_max / (points - 1) as f64;
    let grid: Vec<f64> = (0..points)
        .map(|k| {
            if k == points - 1 {
                strain_max
            } else {
                k as f64 * step
            }
        })
        .collect();
    let mut mean = vec![0.0; points];
    for (strain, stress) in &curves {
        for (m, &g) in mean.iter_mut().zip(&grid) {
            *m += interpolate(strain, stress, g);
        }
    }
    let n = curves.len() as f64;
    let observed: Vec<f64> = mean.iter().map(|m| m / n).collect();
    let drive: Vec<f64> = grid.iter().map(|e| 1.0 + direction * e).collect();
    let record = TestData {
        name: format!("mean of {}", records.len()),
        test: first.test,
        file: format!("mean of {} records ({} ...)", records.len(), first.file),
        loading: Loading::quasi_static(Drive::Stretch, drive),
        observed,
        weight: 1.0,
        axial_stretch: 1.0,
        metadata: Default::default(),
        columns_read: Vec::new(),
        sign: first.sign.clone(),
        batch: None,
    };
    Ok(MeanCurve {
        record,
        points,
        strain_max,
        records: records.len(),
    })
}

/// Linear interpolation of `y(x)` at `at` (`x` strictly growing), held at
/// the end values outside `x` (as numpy's `interp`). Written here: one
/// bracket search per point needs no crate.
fn interpolate(x: &[f64], y: &[f64], at: f64) -> f64 {
    let n = x.len();
    if at <= x[0] {
        return y[0];
    }
    if at >= x[n - 1] {
        return y[n - 1];
    }
    // the last k with x[k] <= at
    let k = x.partition_point(|&v| v <= at) - 1;
    let t = (at - x[k]) / (x[k + 1] - x[k]);
    y[k] + t * (y[k + 1] - y[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(file: &str, stretch: Vec<f64>, stress: Vec<f64>) -> TestData {
        TestData {
            name: file.into(),
            test: TestKind::Homogeneous(palpate_analytic::Mode::Uniaxial),
            file: file.into(),
            loading: Loading::quasi_static(Drive::Stretch, stretch),
            observed: stress,
            weight: 1.0,
            axial_stretch: 1.0,
            metadata: Default::default(),
            columns_read: Vec::new(),
            sign: String::new(),
            batch: None,
        }
    }

    /// Two compression records sampled at different strains, stresses
    /// linear in strain (-2 e and -4 e): their mean on the grid is -3 e,
    /// exactly, up to the smaller record's end.
    #[test]
    fn mean_curve_averages_records_on_a_common_grid() {
        let a = record(
            "a",
            (0..=40).map(|k| 1.0 - 0.5 * k as f64 / 40.0).collect(),
            (0..=40).map(|k| -2.0 * 0.5 * k as f64 / 40.0).collect(),
        );
        let b = record(
            "b",
            (0..=7).map(|k| 1.0 - 0.06 * k as f64).collect(),
            (0..=7).map(|k| -4.0 * 0.06 * k as f64).collect(),
        );
        let m = mean_curve(&[a.clone(), b.clone()], 11).unwrap();
        assert!((m.strain_max - 0.42).abs() < 1e-14);
        assert_eq!(m.points, 11);
        assert_eq!(m.record.loading.drive.len(), 11);
        for (l, s) in m.record.loading.drive.iter().zip(&m.record.observed) {
            let e = 1.0 - l;
            assert!((s + 3.0 * e).abs() < 1e-12, "strain {e}: {s}");
        }
        assert!((m.record.loading.drive.last().unwrap() - 0.58).abs() < 1e-15);
        assert!(m.describe().contains("11 engineering strains"));
        // a tension record among compression ones
        let t = record("t", vec![1.0, 1.1, 1.2], vec![0.0, 0.1, 0.2]);
        let e = mean_curve(&[a.clone(), t], 11).unwrap_err().to_string();
        assert!(
            e.contains("t is stretched in tension while a is in compression"),
            "{e}"
        );
        // a record that unloads
        let u = record("u", vec![1.0, 0.9, 0.8, 0.85], vec![0.0, -0.1, -0.2, -0.15]);
        let e = mean_curve(&[a.clone(), u], 11).unwrap_err().to_string();
        assert!(e.contains("u: the strain does not grow at sample 4"), "{e}");
        let e = mean_curve(&[a, b], 1).unwrap_err().to_string();
        assert!(e.contains("1 grid points; give 2 at least"), "{e}");
    }

    #[test]
    fn wildcards_match_as_a_shell_does() {
        assert!(matches("*.csv", "EF10_0T_A1.csv"));
        assert!(matches("EF10_0T_?1.csv", "EF10_0T_B1.csv"));
        assert!(!matches("EF10_0T_?1.csv", "EF10_0T_B2.csv"));
        assert!(matches("*_A*", "EF10_0T_A1.csv"));
        assert!(!matches("*_A*", "EF10_0T_B1.csv"));
        assert!(matches("a*b*c", "aXXbYYc"));
        assert!(!matches("a*b*c", "aXXbYY"));
        assert!(matches("*", ""));
    }

    #[test]
    fn batches_are_read_from_the_names_or_not_at_all() {
        let stems = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        assert_eq!(
            batches_from_names(&stems(&[
                "EF10_0T_A1",
                "EF10_0T_A2",
                "EF10_0T_B1",
                "EF10_0T_B2"
            ])),
            Some(stems(&["A", "A", "B", "B"]))
        );
        assert_eq!(
            batches_from_names(&stems(&["run_x_1", "run_x_2", "run_yy_1", "run_yy_2"])),
            Some(stems(&["x", "x", "yy", "yy"]))
        );
        // One batch, or a batch of a single file: none.
        assert_eq!(batches_from_names(&stems(&["s1", "s2", "s3"])), None);
        assert_eq!(batches_from_names(&stems(&["A1", "A2", "B1"])), None);
    }
}
