//! Sizes a user can type (samples of a simulated history, MCMC draws and
//! chains, DoE runs, ANOVA terms), checked against what the machine can hold
//! before anything is allocated: the one helper every command uses, so that
//! an absurd size is an error naming the option and the estimate, never a
//! capacity-overflow panic or an allocation abort.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Memory a command may plan to use: the `MemAvailable` of /proc/meminfo
/// where there is one, else 8 GiB.
pub fn available_bytes() -> f64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("MemAvailable:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<f64>().ok())
        })
        .map(|kb| kb * 1024.0)
        .unwrap_or(8.0 * 1024f64.powi(3))
}

/// Checks that `count` items of `bytes_each` bytes fit in memory, `count`
/// computed in floating point from what the user typed (`what`, e.g.
/// "--depth 2 / --step 1e-300") so that it cannot overflow. The error states
/// the count, the largest count that fits and the memory that is free.
pub fn check_count(what: &str, count: f64, noun: &str, bytes_each: f64) -> anyhow::Result<usize> {
    check_count_within(what, count, noun, bytes_each, available_bytes())
}

/// [`check_count`] against a given memory (for tests).
pub fn check_count_within(
    what: &str,
    count: f64,
    noun: &str,
    bytes_each: f64,
    available: f64,
) -> anyhow::Result<usize> {
    let bytes_each = bytes_each.max(1.0);
    let max = (available / bytes_each)
        .floor()
        .min(usize::MAX as f64 / 2.0);
    if !(count.is_finite() && count >= 0.0) || count > max {
        anyhow::bail!(
            "{what} gives {} {noun}; at most {} fit in memory (~{:.1} GiB free, ~{} bytes each)",
            fmt_count(count),
            fmt_count(max),
            available / 1024f64.powi(3),
            bytes_each
        );
    }
    Ok(count as usize)
}

/// A count as an integer when small, in scientific notation when large.
fn fmt_count(x: f64) -> String {
    if !x.is_finite() {
        "an unbounded number of".into()
    } else if x < 1e9 {
        format!("{}", x.round() as u64)
    } else {
        format!("{x:.3e}")
    }
}

/// Progress of a long loop: an indicatif bar when stderr is a terminal,
/// otherwise a plain line every 10 % or every 10 s (whichever comes first),
/// so that a run logged to a file still shows it is alive.
pub struct Progress {
    bar: Option<indicatif::ProgressBar>,
    label: String,
    total: u64,
    done: AtomicU64,
    last: Mutex<(Instant, u64)>,
}

impl Progress {
    /// A progress report of `total` steps named `label`.
    pub fn new(total: u64, label: &str, template: &str) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = indicatif::ProgressBar::new(total);
            b.set_style(
                indicatif::ProgressStyle::with_template(template)
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            b.set_message(label.to_string());
            b
        });
        Progress {
            bar,
            label: label.to_string(),
            total,
            done: AtomicU64::new(0),
            last: Mutex::new((Instant::now(), 0)),
        }
    }

    /// `n` more steps done.
    pub fn inc(&self, n: u64) {
        if let Some(b) = &self.bar {
            b.inc(n);
            return;
        }
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        let tenth = (self.total / 10).max(1);
        if let Ok(mut last) = self.last.lock() {
            let due = done / tenth > last.1 / tenth || last.0.elapsed() >= Duration::from_secs(10);
            if due && done < self.total {
                eprintln!(
                    "{}: {done}/{} ({:.0} %)",
                    self.label,
                    self.total,
                    100.0 * done as f64 / self.total.max(1) as f64
                );
                *last = (Instant::now(), done);
            }
        }
    }

    /// Clears the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// Checks an ANOVA model's highest interaction order (1..=number of
/// factors) and that its design matrix (runs x terms) fits in memory.
/// `what` names the setting (`--max-order` or `analysis.max_order`).
pub fn check_anova(
    what: &str,
    max_order: Option<usize>,
    factors: usize,
    runs: usize,
) -> anyhow::Result<()> {
    if let Some(m) = max_order {
        anyhow::ensure!(
            (1..=factors.max(1)).contains(&m),
            "{what} {m}: expected an interaction order from 1 (main effects only) to {} (the number of factors)",
            factors.max(1)
        );
    }
    let m = max_order.unwrap_or(factors).min(factors);
    // Terms of order <= m among k factors: sum of C(k, i), in floating point.
    let mut c = 1.0f64;
    let mut terms = 1.0f64;
    for i in 1..=m {
        c = c * (factors + 1 - i) as f64 / i as f64;
        terms += c;
    }
    check_count(
        &format!("{what} {m} with {factors} factors and {runs} runs"),
        terms * runs as f64,
        "design-matrix entries",
        8.0,
    )?;
    Ok(())
}

/// Checks the number of runs of a designed experiment (the product of the
/// factors' level counts and the replicates, divided by 2 per generator)
/// against the design's limit and the memory, before it is built.
pub fn check_runs(
    what: &str,
    levels: &[usize],
    generators: usize,
    replicates: usize,
) -> anyhow::Result<usize> {
    let runs = levels.iter().map(|&l| l as f64).product::<f64>() * replicates as f64
        / 2f64.powi(generators.min(1000) as i32);
    let max = palpate_uq::doe::MAX_RUNS;
    anyhow::ensure!(
        runs <= max as f64,
        "{what} gives {} runs ({}); at most {max} (2^20) runs are supported",
        runs_formula(levels, generators, replicates, runs),
        design_size(levels, replicates),
    );
    check_count(what, runs, "runs", 64.0 + 8.0 * levels.len() as f64)
}

/// The run count as a product of powers, e.g. `2^40 = 1.100e12`,
/// `2^3 x 3 x 5 replicates / 2^1 = 60`.
fn runs_formula(levels: &[usize], generators: usize, replicates: usize, runs: f64) -> String {
    let mut terms: Vec<String> = grouped(levels)
        .into_iter()
        .map(|(l, n)| {
            if n == 1 {
                format!("{l}")
            } else {
                format!("{l}^{n}")
            }
        })
        .collect();
    if replicates != 1 {
        terms.push(format!("{replicates} replicates"));
    }
    let mut f = terms.join(" x ");
    if f.is_empty() {
        f = "1".into();
    }
    if generators > 0 {
        f = format!("{f} / 2^{generators}");
    }
    if f == fmt_count(runs) {
        f
    } else {
        format!("{f} = {}", fmt_count(runs))
    }
}

/// The factors grouped by level count, e.g. `40 factors of 2 levels, 1 replicate`.
fn design_size(levels: &[usize], replicates: usize) -> String {
    let mut parts: Vec<String> = grouped(levels)
        .into_iter()
        .map(|(l, n)| format!("{n} factor{} of {l} levels", if n == 1 { "" } else { "s" }))
        .collect();
    parts.push(format!(
        "{replicates} replicate{}",
        if replicates == 1 { "" } else { "s" }
    ));
    parts.join(", ")
}

/// (level count, number of factors with it), in order of first appearance.
fn grouped(levels: &[usize]) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for &l in levels {
        match out.iter_mut().find(|(m, _)| *m == l) {
            Some((_, n)) => *n += 1,
            None => out.push((l, 1)),
        }
    }
    out
}

/// Parses a count typed on the command line (clap `value_parser`): a whole
/// number, 0 or more, also as `1e3` or `10_000`; the message says what is
/// valid instead of clap's "invalid digit found in string".
pub fn parse_count<T: TryFrom<u64>>(text: &str) -> Result<T, String> {
    let t = text.trim().replace('_', "");
    let value: u64 = match t.parse::<u64>() {
        Ok(v) => v,
        Err(_) => match t.parse::<f64>() {
            Ok(x) if x.is_finite() && x >= 0.0 && x.fract() == 0.0 && x <= 2f64.powi(53) => {
                x as u64
            }
            Ok(x) if x < 0.0 => {
                return Err(
                    "a count cannot be negative; expected a whole number 0 or more, e.g. 1000"
                        .into(),
                )
            }
            Ok(x) if x.is_finite() && x.fract() != 0.0 => {
                return Err("expected a whole number, e.g. 1000".into())
            }
            Ok(_) => {
                return Err(format!(
                    "too large; expected a whole number up to {}",
                    u64::MAX
                ))
            }
            Err(_) => {
                return Err(
                    "not a number; expected a whole number 0 or more, e.g. 1000 or 1e3".into(),
                )
            }
        },
    };
    T::try_from(value).map_err(|_| format!("{value} is too large for this option"))
}

/// A number as a user would type it: `1e-300`, `0.1`, `2`.
pub fn fmt_value(x: f64) -> String {
    if x != 0.0 && (x.abs() < 1e-4 || x.abs() >= 1e9) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_parse_as_a_user_types_them() {
        assert_eq!(parse_count::<usize>("1000"), Ok(1000));
        assert_eq!(parse_count::<usize>("1e3"), Ok(1000));
        assert_eq!(parse_count::<usize>("10_000"), Ok(10_000));
        assert_eq!(parse_count::<u64>("18446744073709551615"), Ok(u64::MAX));
        for (bad, says) in [
            ("-3", "negative"),
            ("2.5", "whole number"),
            ("ten", "not a number"),
            ("1e30", "too large"),
        ] {
            let e = parse_count::<usize>(bad).unwrap_err();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }

    #[test]
    fn a_run_count_is_stated_as_the_product_it_is() {
        let e = check_runs("d.toml: [[factors]]", &[2; 40], 0, 1)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("2^40 = 1.100e12 runs (40 factors of 2 levels, 1 replicate)"),
            "{e}"
        );
        let e = check_runs("d.toml", &[2, 2, 3], 0, usize::MAX)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("2^2 x 3 x 18446744073709551615 replicates = 2.214e20 runs")
                && e.contains("2 factors of 2 levels, 1 factor of 3 levels"),
            "{e}"
        );
        assert!(!e.contains("18446744073709551615 runs"), "{e}");
    }

    #[test]
    fn every_absurd_count_is_refused_with_its_estimate() {
        let gib = 1024f64.powi(3);
        assert_eq!(
            check_count_within("--n 3", 3.0, "samples", 8.0, gib).unwrap(),
            3
        );
        for bad in [
            2e300,
            f64::INFINITY,
            f64::NAN,
            1e18,
            -1.0,
            18446744073709551615.0,
        ] {
            let e = check_count_within("--step 1e-300", bad, "samples", 64.0, gib)
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("--step 1e-300 gives "), "{e}");
            assert!(e.contains("at most 16777216 fit in memory"), "{e}");
            assert!(e.contains("1.0 GiB"), "{e}");
        }
        assert!(available_bytes() > 0.0);
    }
}
