//! The ANOVA of the per-record moduli on one scale (kPa, or ln of the
//! modulus: multiplicative effects), with the cast (batch) nested in the
//! cells, and its report tables.

use super::checks::checks;
use super::ReplicatesSummaryStep;
use crate::steps::replicates::sig4;
use anyhow::Context;
use palpate_uq::anova::{analyse, Analysis, AnovaOptions, FactorColumn};
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, FisherSnedecor};
use std::fmt::Write;

/// The batch effect: batch nested in the cells of the factors.
#[derive(Debug, Clone, Serialize)]
pub(super) struct BatchEffect {
    ss: f64,
    df: usize,
    f: f64,
    p: f64,
    /// The records within a batch (the error).
    error_df: usize,
    error_ms: f64,
    /// Each factor term tested against the batches instead of the records
    /// (the batch as the experimental unit): (term, F, p).
    against_batches: Vec<(String, f64, f64)>,
}

/// The batch terms of `nested` (factors x batch, every interaction) pooled:
/// the batch nested in the cells of the factors, tested against the
/// records within a batch. (`palpate_uq::anova` has crossed terms only; on
/// a balanced design the terms that hold `batch` sum to the nested term.)
fn batch_effect(crossed: &Analysis, nested: &Analysis) -> Option<BatchEffect> {
    let terms: Vec<_> = nested
        .table
        .terms
        .iter()
        .filter(|t| t.name.split(':').any(|f| f == "batch"))
        .collect();
    let ss: f64 = terms.iter().map(|t| t.ss).sum();
    let df: usize = terms.iter().map(|t| t.df).sum();
    let error_df = nested.table.residual.df;
    let error_ms = nested.table.residual.ms?;
    if df == 0 || error_df == 0 || error_ms <= 0.0 {
        return None;
    }
    let f = ss / df as f64 / error_ms;
    let p = FisherSnedecor::new(df as f64, error_df as f64).ok()?.sf(f);
    let ms_batch = ss / df as f64;
    let against_batches = crossed
        .table
        .terms
        .iter()
        .filter_map(|t| {
            let ms = t.ms?;
            let f = ms / ms_batch;
            let p = FisherSnedecor::new(t.df as f64, df as f64).ok()?.sf(f);
            Some((t.name.clone(), f, p))
        })
        .collect();
    Some(BatchEffect {
        ss,
        df,
        f,
        p,
        error_df,
        error_ms,
        against_batches,
    })
}

/// The analysis of one scale of the response (mu0, or ln mu0): the crossed
/// ANOVA and, when every record has a batch, the batch effect.
#[derive(Debug, Clone)]
pub(super) struct ScaleAnalysis {
    pub(super) analysis: Analysis,
    pub(super) batch: Option<BatchEffect>,
}

pub(super) fn analyse_scale(
    response: &str,
    factors: &[FactorColumn],
    batches: Option<&[String]>,
    y: &[f64],
    options: &AnovaOptions,
) -> anyhow::Result<ScaleAnalysis> {
    let analysis =
        analyse(response, factors, y, options).with_context(|| format!("ANOVA of {response}"))?;
    let batch = match batches {
        Some(b) => {
            let mut with_batch = factors.to_vec();
            with_batch.push(FactorColumn::from_names("batch", b));
            let nested = analyse(response, &with_batch, y, options)
                .with_context(|| format!("ANOVA of {response} with the batches"))?;
            batch_effect(&analysis, &nested)
        }
        None => None,
    };
    Ok(ScaleAnalysis { analysis, batch })
}

fn p_text(p: f64) -> String {
    if p < 1e-3 {
        format!("{p:.2e}")
    } else {
        format!("{p:.3}")
    }
}

pub(super) fn anova_report(
    report: &mut String,
    step: &ReplicatesSummaryStep,
    law: &str,
    kept: &[String],
    dropped: &[String],
    raw: Option<&ScaleAnalysis>,
    log: Option<&ScaleAnalysis>,
) {
    let names = step.factors.keys().cloned().collect::<Vec<_>>().join(" x ");
    let _ = writeln!(
        report,
        "\n### ANOVA of mu0 ({law}, kPa) on {names}, the records as replicates\n"
    );
    let _ = writeln!(
        report,
        "Materials in the complete crossing: {}.",
        kept.join(", ")
    );
    if !dropped.is_empty() {
        let _ = writeln!(
            report,
            "Outside it (their levels do not cross with every level of the other factors; in the table and plot above only): {}.",
            dropped.join(", ")
        );
    }
    let Some(raw) = raw else {
        let _ = writeln!(
            report,
            "\nNo ANOVA: the crossing has a factor with one level, or no replicates."
        );
        return;
    };
    scale_report(
        report,
        step,
        &raw.analysis,
        raw.batch.as_ref(),
        "kPa",
        |v| v,
    );
    let _ = writeln!(
        report,
        "\nPlots: `plots/{n}-main_effects.svg`, `plots/{n}-interaction.svg`, `plots/{n}-normal_probability.svg`, `plots/{n}-residuals_vs_fits.svg`.\n",
        n = step.name
    );
    let Some(log) = log else {
        let _ = writeln!(report, "No ANOVA of ln mu0: a modulus is not positive.\n");
        return;
    };
    let _ = writeln!(
        report,
        "### ANOVA of ln mu0 ({law}) on {names}: multiplicative effects\n\n\
         The same ANOVA on the natural log of the modulus: each effect is then a ratio of moduli (a thinner \
         fraction that halves the modulus of both families is no interaction here, though it is one in kPa), \
         and a spread in proportion to the modulus is one spread. Means are geometric means, exp(mean of ln mu0)."
    );
    scale_report(
        report,
        step,
        &log.analysis,
        log.batch.as_ref(),
        "kPa, geometric",
        f64::exp,
    );
    let _ = writeln!(
        report,
        "\nPlots: `plots/{n}-log-main_effects.svg`, `plots/{n}-log-interaction.svg`, `plots/{n}-log-normal_probability.svg`, `plots/{n}-log-residuals_vs_fits.svg`.\n",
        n = step.name
    );
    let _ = writeln!(
        report,
        "### Residual checks on each scale (alpha = {})\n\n\
         | response | Ryan-Joiner p | Anderson-Darling p | normal residuals | Bartlett p | Levene (median) p | equal variances |\n\
         |---|---|---|---|---|---|---|",
        step.alpha
    );
    let c = [
        checks(&raw.analysis, step.alpha),
        checks(&log.analysis, step.alpha),
    ];
    let yes = |b: bool| if b { "yes" } else { "no" };
    for (k, (x, a)) in c.iter().zip([&raw.analysis, &log.analysis]).enumerate() {
        let rj = a
            .ryan_joiner
            .as_ref()
            .map(|t| t.p_text())
            .unwrap_or_else(|| "-".into());
        let p = |v: Option<f64>| v.map(p_text).unwrap_or_else(|| "-".into());
        let _ = writeln!(
            report,
            "| {} | {rj} | {} | {} | {} | {} | {} |",
            ["mu0 (kPa)", "ln mu0"][k],
            p(x.anderson_darling_p),
            yes(x.normal),
            p(x.bartlett_p),
            p(x.levene_p),
            yes(x.equal_variances)
        );
    }
    let verdict: Vec<String> = c
        .iter()
        .zip(["mu0", "ln mu0"])
        .map(|(x, n)| {
            let failed = x.failed();
            if failed.is_empty() {
                format!("{n} passes the four checks")
            } else {
                format!("{n} fails {}", failed.join(", "))
            }
        })
        .collect();
    let verdict = verdict.join("; ");
    let _ = writeln!(report, "\nVerdict: {verdict}.\n");
}

/// One scale's table, means (through `back`, e.g. exp for ln mu0), residual
/// checks and batch effect.
fn scale_report(
    report: &mut String,
    step: &ReplicatesSummaryStep,
    a: &Analysis,
    batch: Option<&BatchEffect>,
    unit: &str,
    back: impl Fn(f64) -> f64,
) {
    let t = &a.table;
    let _ = writeln!(
        report,
        "\n| source | DF | SS | MS | F | p | eta^2 |\n|---|---|---|---|---|---|---|"
    );
    for r in &t.terms {
        let _ = writeln!(
            report,
            "| {} | {} | {} | {} | {} | {} | {:.4} |",
            r.name,
            r.df,
            sig4(r.ss),
            r.ms.map(sig4).unwrap_or_else(|| "-".into()),
            r.f.map(|f| format!("{f:.2}")).unwrap_or_else(|| "-".into()),
            r.p.map(p_text).unwrap_or_else(|| "-".into()),
            r.eta_sq
        );
    }
    let _ = writeln!(
        report,
        "| error (records) | {} | {} | {} | | | {:.4} |",
        t.residual.df,
        sig4(t.residual.ss),
        t.residual.ms.map(sig4).unwrap_or_else(|| "-".into()),
        t.residual.ss / t.total.ss.max(f64::MIN_POSITIVE)
    );
    let _ = writeln!(
        report,
        "| total | {} | {} | | | | |",
        t.total.df,
        sig4(t.total.ss)
    );
    let _ = writeln!(report);
    for m in &a.main_effects {
        let means: Vec<String> = m
            .levels
            .iter()
            .zip(&m.means)
            .map(|(l, v)| format!("{l}: {}", sig4(back(*v))))
            .collect();
        let _ = writeln!(
            report,
            "* means of `{}` ({unit}): {}",
            m.factor,
            means.join(", ")
        );
    }
    let rj = a
        .ryan_joiner
        .as_ref()
        .map(|t| format!("Ryan-Joiner R = {:.4}, p {}", t.r, t.p_text()))
        .unwrap_or_else(|| "Ryan-Joiner: not available".into());
    let b = a
        .bartlett
        .as_ref()
        .map(|t| {
            format!(
                "Bartlett statistic = {:.2}, p = {}",
                t.statistic,
                p_text(t.p)
            )
        })
        .unwrap_or_else(|| "Bartlett: not available".into());
    let _ = writeln!(
        report,
        "* residuals: {rj}; equal variances across cells: {b}"
    );
    for n in &a.notes {
        let _ = writeln!(report, "  * note: {n}");
    }
    match batch {
        Some(b) => {
            let _ = writeln!(
                report,
                "\n**Batch effect** (the batches nested in the cells, against the records within a batch): \
                 SS {}, DF {}, F = {:.2} on ({}, {}) DF, p = {}: {}.",
                sig4(b.ss),
                b.df,
                b.f,
                b.df,
                b.error_df,
                p_text(b.p),
                if b.p < step.alpha {
                    "the casts differ more than the tests of one cast"
                } else {
                    "no evidence that the casts differ beyond the tests of one cast"
                }
            );
            let terms: Vec<String> = b
                .against_batches
                .iter()
                .map(|(t, f, p)| format!("`{t}` F = {f:.2}, p = {}", p_text(*p)))
                .collect();
            let _ = writeln!(
                report,
                "With the batch as the experimental unit (each term against the batches, {} DF): {}.",
                b.df,
                terms.join("; ")
            );
        }
        None => {
            let _ = writeln!(report, "\nNo batch test: the records have no batches.");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nested batch term equals its definition: the batch means about
    /// their cell's mean (SS, one DF per cell), against the records about
    /// their batch's mean.
    #[test]
    fn the_batch_effect_is_the_nested_term() {
        // 2 x 2 cells, 2 batches each, 3 records per batch
        let mut rows = Vec::new();
        for (c, (f, t)) in [("x", "0"), ("x", "1"), ("y", "0"), ("y", "1")]
            .iter()
            .enumerate()
        {
            for (b, batch) in ["A", "B"].iter().enumerate() {
                for k in 0..3 {
                    let y = 10.0 * c as f64
                        + 0.7 * b as f64 * (c as f64 - 1.5)
                        + [0.31, -0.12, 0.05][k] * (1.0 + 0.2 * (c + b) as f64);
                    rows.push((f.to_string(), t.to_string(), batch.to_string(), y));
                }
            }
        }
        let col = |name: &str, k: usize| {
            let v: Vec<String> = rows.iter().map(|r| [&r.0, &r.1, &r.2][k].clone()).collect();
            FactorColumn::from_names(name, &v)
        };
        let y: Vec<f64> = rows.iter().map(|r| r.3).collect();
        let o = AnovaOptions::default();
        let crossed = analyse("y", &[col("f", 0), col("t", 1)], &y, &o).unwrap();
        let nested = analyse("y", &[col("f", 0), col("t", 1), col("batch", 2)], &y, &o).unwrap();
        let b = batch_effect(&crossed, &nested).unwrap();
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let (mut ss_b, mut ss_e) = (0.0, 0.0);
        for cell in y.chunks(6) {
            let m = mean(cell);
            for batch in cell.chunks(3) {
                let mb = mean(batch);
                ss_b += 3.0 * (mb - m) * (mb - m);
                ss_e += batch.iter().map(|v| (v - mb) * (v - mb)).sum::<f64>();
            }
        }
        assert_eq!((b.df, b.error_df), (4, 16));
        assert!((b.ss - ss_b).abs() <= 1e-9 * ss_b, "{} {ss_b}", b.ss);
        assert!(
            (b.error_ms - ss_e / 16.0).abs() <= 1e-9 * ss_e,
            "{} {ss_e}",
            b.error_ms
        );
        let f = (ss_b / 4.0) / (ss_e / 16.0);
        assert!((b.f - f).abs() <= 1e-9 * f);
        let p = FisherSnedecor::new(4.0, 16.0).unwrap().sf(f);
        assert!((b.p - p).abs() <= 1e-12, "{} {p}", b.p);
        assert_eq!(b.against_batches.len(), 3);
    }

    /// Agreement to 6 significant digits (p-values below 1e-10, far in
    /// the F distribution's tail, to 4).
    fn close(got: f64, want: f64, what: &str) {
        let rel = if want.abs() < 1e-10 { 5e-5 } else { 5e-7 };
        assert!(
            (got - want).abs() <= rel * want.abs(),
            "{what}: palpate {got}, statsmodels/scipy {want}"
        );
    }

    /// The ANOVA of mu0 and of ln mu0 on the study's per-record moduli
    /// (the complete crossing, 100 records in 20 batches), the nested batch
    /// term and the residual checks, against statsmodels and scipy
    /// (docs/validation/phantom_database_anova_statsmodels.py wrote
    /// docs/validation/phantom_database_anova_reference.json). On these data
    /// the log scale passes both normality checks and Levene's test where
    /// the kPa scale fails all four; Bartlett's test fails on both.
    #[test]
    fn both_scales_agree_with_statsmodels() {
        let r: serde_json::Value = serde_json::from_str(include_str!(
            "../../../../docs/validation/phantom_database_anova_reference.json"
        ))
        .unwrap();
        let col = |k: &str| -> Vec<String> {
            r["data"][k]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_str().unwrap().to_string())
                .collect()
        };
        let factors = [
            FactorColumn::from_names("family", &col("family")),
            FactorColumn::from_names("thinner", &col("thinner")),
        ];
        let batches = col("batch");
        let mu0: Vec<f64> = r["data"]["mu0_kPa"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(mu0.len(), 100);
        let ln: Vec<f64> = mu0.iter().map(|v| v.ln()).collect();
        let o = AnovaOptions::default();
        let mut verdicts = Vec::new();
        for (name, y) in [("mu0", &mu0), ("ln_mu0", &ln)] {
            let want = &r[name];
            let s = analyse_scale(name, &factors, Some(&batches), y, &o).unwrap();
            let t = &s.analysis.table;
            for w in want["terms"].as_array().unwrap() {
                let n = w["name"].as_str().unwrap();
                let got = t.terms.iter().find(|x| x.name == n).unwrap();
                assert_eq!(got.df as u64, w["df"].as_u64().unwrap(), "{name} {n} df");
                close(got.ss, w["ss"].as_f64().unwrap(), &format!("{name} {n} SS"));
                close(
                    got.f.unwrap(),
                    w["f"].as_f64().unwrap(),
                    &format!("{name} {n} F"),
                );
                close(
                    got.p.unwrap(),
                    w["p"].as_f64().unwrap(),
                    &format!("{name} {n} p"),
                );
            }
            assert_eq!(
                t.residual.df as u64,
                want["residual"]["df"].as_u64().unwrap()
            );
            close(
                t.residual.ss,
                want["residual"]["ss"].as_f64().unwrap(),
                "residual SS",
            );
            let b = s.batch.as_ref().unwrap();
            let wb = &want["batch"];
            assert_eq!(
                (b.df as u64, b.error_df as u64),
                (wb["df"].as_u64().unwrap(), wb["error_df"].as_u64().unwrap())
            );
            close(
                b.ss,
                wb["ss"].as_f64().unwrap(),
                &format!("{name} batch SS"),
            );
            close(b.f, wb["f"].as_f64().unwrap(), &format!("{name} batch F"));
            close(b.p, wb["p"].as_f64().unwrap(), &format!("{name} batch p"));
            close(
                b.error_ms,
                wb["error_ms"].as_f64().unwrap(),
                &format!("{name} batch error MS"),
            );
            for (w, (n, f, p)) in wb["against_batches"]
                .as_array()
                .unwrap()
                .iter()
                .zip(&b.against_batches)
            {
                assert_eq!(n, w["name"].as_str().unwrap());
                close(
                    *f,
                    w["f"].as_f64().unwrap(),
                    &format!("{name} {n} F against batches"),
                );
                close(
                    *p,
                    w["p"].as_f64().unwrap(),
                    &format!("{name} {n} p against batches"),
                );
            }
            let a = &s.analysis;
            close(
                a.bartlett.as_ref().unwrap().p,
                want["bartlett_p"].as_f64().unwrap(),
                "Bartlett p",
            );
            close(
                a.levene.as_ref().unwrap().p,
                want["levene_median_p"].as_f64().unwrap(),
                "Levene p",
            );
            close(
                a.anderson_darling.as_ref().unwrap().p,
                want["anderson_darling_p"].as_f64().unwrap(),
                "Anderson-Darling p",
            );
            close(
                a.ryan_joiner.as_ref().unwrap().r,
                want["ryan_joiner_r"].as_f64().unwrap(),
                "Ryan-Joiner R",
            );
            verdicts.push(checks(a, 0.05).failed());
        }
        assert_eq!(
            verdicts,
            [
                vec!["Ryan-Joiner", "Anderson-Darling", "Bartlett", "Levene"],
                vec!["Bartlett"]
            ]
        );
    }
}
