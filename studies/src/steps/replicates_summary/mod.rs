//! The `replicates_summary` step: what several `replicates` steps (one
//! material each) say together. The verdicts of their fits beside the
//! published table, law by law; the initial shear modulus of one law per
//! material (its fit to the mean curve, and each record's own fit) against
//! a numeric factor (plot); and a factorial ANOVA of the per-record moduli
//! with the records as replicates, on the materials whose levels cross
//! completely, with the batch effect (batch nested in the cells) tested
//! against the records within a batch.
//!
//! ```toml
//! [[steps]]
//! [steps.replicates_summary]
//! name = "modulus"
//! steps = ["EF10_0T", "EF30_0T", ...]     # replicates steps before this one
//! law = "reduced-polynomial:3"            # fitted per record in each of them
//! factors.family = { EF10_0T = "00-10", EF30_0T = "00-30", ... }
//! factors.thinner = { EF10_0T = "0", EF30_0T = "0", ... }
//! x = "thinner"                           # a numeric factor: the plot's axis
//! ```

use crate::report::anova::plots;
use crate::report::plot::{Plot, Series, PALETTE};
use crate::run::checks::check_alpha;
use crate::run::output::write_atomic;
use crate::run::step::{duplicate, At, Run, Sharding, Step, StepResult, Study};
use crate::steps::replicates::{sig4, ReplicatesStep};
use anyhow::Context;
use palpate_material::Law;
use palpate_uq::anova::{analyse, Analysis, AnovaOptions, FactorColumn};
use palpate_uq::stats::PBound;
use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, FisherSnedecor};
use std::collections::BTreeMap;
use std::fmt::Write;

/// `[steps.replicates_summary]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReplicatesSummaryStep {
    pub name: String,
    /// The `replicates` steps (before this one), one material each.
    pub steps: Vec<String>,
    /// The law whose initial shear modulus is the response; each step must
    /// fit it per record.
    pub law: String,
    /// Each factor: the level of each step.
    pub factors: BTreeMap<String, BTreeMap<String, String>>,
    /// A factor with numeric levels: the x axis of the modulus plot.
    #[serde(default)]
    pub x: Option<String>,
    /// Significance level (default 0.05).
    #[serde(default = "default_alpha")]
    pub alpha: f64,
}

fn default_alpha() -> f64 {
    0.05
}

impl Step for ReplicatesSummaryStep {
    fn name(&self) -> &str {
        &self.name
    }

    fn validate(&self, study: &Study, site: &At) -> anyhow::Result<()> {
        let at = format!("{}: {}", site.file, site.step(&self.name));
        let law: Law = self
            .law
            .parse()
            .map_err(|e| anyhow::anyhow!("{at}.law: \"{}\": {e}", self.law))?;
        anyhow::ensure!(
            self.steps.len() >= 2,
            "{at}.steps: {} step; a summary needs two replicates steps at least",
            self.steps.len()
        );
        if let Some(d) = duplicate(&self.steps) {
            anyhow::bail!("{at}.steps: \"{d}\" is listed twice");
        }
        for s in &self.steps {
            let Some(j) = study.steps.iter().position(|r| r.name() == s) else {
                anyhow::bail!(
                    "{at}.steps: no step named \"{s}\" (a replicates step before this one)"
                );
            };
            anyhow::ensure!(
                j < site.index,
                "{at}.steps: step \"{s}\" is steps[{j}], not before this one; steps run in order"
            );
            let Some(r) = study.steps[j].get::<ReplicatesStep>() else {
                anyhow::bail!(
                    "{at}.steps: step \"{s}\" is a {} step; expected a replicates step",
                    study.steps[j].kind
                );
            };
            let fitted = r.laws.iter().any(|l| l.parse::<Law>().ok() == Some(law));
            let per_record = r
                .per_record_laws
                .as_ref()
                .is_none_or(|p| p.iter().any(|l| l.parse::<Law>().ok() == Some(law)));
            anyhow::ensure!(
                fitted && per_record,
                "{at}.law = \"{}\": step \"{s}\" does not fit it per record (add it to its laws and per_record_laws)",
                self.law
            );
        }
        check_alpha(&format!("{at}.alpha ="), self.alpha)?;
        anyhow::ensure!(
            !self.factors.is_empty(),
            "{at}.factors: give at least one factor, e.g. factors.family = {{ STEP = \"level\", ... }}"
        );
        for (f, levels) in &self.factors {
            anyhow::ensure!(
                f != "batch" && f != "mu0",
                "{at}.factors.{f}: `batch` and `mu0` are the summary's own names; name the factor otherwise"
            );
            for s in &self.steps {
                anyhow::ensure!(
                    levels.contains_key(s),
                    "{at}.factors.{f}: no level for step \"{s}\""
                );
            }
            if let Some(s) = levels.keys().find(|s| !self.steps.contains(s)) {
                anyhow::bail!(
                    "{at}.factors.{f}: \"{s}\" is not one of steps ({})",
                    self.steps.join(", ")
                );
            }
        }
        if let Some(x) = &self.x {
            let Some(levels) = self.factors.get(x) else {
                anyhow::bail!(
                    "{at}.x = \"{x}\": not a factor (factors: {})",
                    self.factors.keys().cloned().collect::<Vec<_>>().join(", ")
                );
            };
            if let Some((s, l)) = levels.iter().find(|(_, l)| l.parse::<f64>().is_err()) {
                anyhow::bail!("{at}.factors.{x}.{s} = \"{l}\": the plot's x factor needs numbers");
            }
        }
        Ok(())
    }

    fn sharding(&self) -> Sharding {
        Sharding::AtMerge
    }

    fn run(
        &self,
        run: &Run,
        done: &[StepResult],
        report: &mut String,
    ) -> anyhow::Result<serde_json::Value> {
        run_summary(run, self, done, report).with_context(|| format!("step `{}`", self.name))
    }
}

/// One record's modulus.
#[derive(Debug, Clone, Serialize)]
struct RecordModulus {
    step: String,
    record: String,
    batch: Option<String>,
    /// Initial shear modulus, kPa.
    mu0_kpa: f64,
}

/// One material's modulus.
#[derive(Debug, Clone, Serialize)]
struct MaterialModulus {
    step: String,
    levels: BTreeMap<String, String>,
    /// Of the fit to the mean curve, kPa.
    mean_curve_kpa: f64,
    /// Mean and SD of the per-record fits, kPa.
    records_mean_kpa: f64,
    records_sd_kpa: f64,
    records: usize,
}

/// The batch effect: batch nested in the cells of the factors.
#[derive(Debug, Clone, Serialize)]
struct BatchEffect {
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

fn run_summary(
    run: &Run,
    step: &ReplicatesSummaryStep,
    done: &[StepResult],
    report: &mut String,
) -> anyhow::Result<serde_json::Value> {
    let law: Law = step.law.parse().map_err(|e| anyhow::anyhow!("law: {e}"))?;
    let law_name = law.to_string();
    let mut materials = Vec::new();
    let mut records = Vec::new();
    // verdicts[law][verdict] = steps
    let mut verdicts: BTreeMap<String, BTreeMap<String, Vec<String>>> = BTreeMap::new();
    let mut law_order: Vec<String> = Vec::new();
    for s in &step.steps {
        let body = done
            .iter()
            .find(|r| r.kind == "replicates" && r.name() == s)
            .map(|r| &r.body)
            .with_context(|| format!("no results of replicates step `{s}`"))?;
        let laws = body["laws"].as_array().cloned().unwrap_or_default();
        for l in &laws {
            let name = l["law"].as_str().unwrap_or_default().to_string();
            if !law_order.contains(&name) {
                law_order.push(name.clone());
            }
            let v = l["published"]["verdict"]
                .as_str()
                .map(|v| v.split(':').next().unwrap_or(v).to_string())
                .unwrap_or_else(|| "not in the table".into());
            verdicts
                .entry(name)
                .or_default()
                .entry(v)
                .or_default()
                .push(s.clone());
        }
        let entry = laws
            .iter()
            .find(|l| l["law"].as_str() == Some(law_name.as_str()))
            .with_context(|| format!("step `{s}` has no fit of {law_name}"))?;
        let fits = entry["replicates"]["fits"]
            .as_array()
            .with_context(|| format!("step `{s}`: {law_name} was not fitted per record"))?;
        let mut mu0s = Vec::new();
        for f in fits {
            let values: Vec<f64> = f["values"]
                .as_array()
                .map(|v| v.iter().filter_map(|x| x.as_f64()).collect())
                .unwrap_or_default();
            let mu0 = 1e3 * law.shear_modulus(&values);
            mu0s.push(mu0);
            records.push(RecordModulus {
                step: s.clone(),
                record: f["record"].as_str().unwrap_or_default().to_string(),
                batch: f["batch"].as_str().map(str::to_string),
                mu0_kpa: mu0,
            });
        }
        let n = mu0s.len() as f64;
        let mean = mu0s.iter().sum::<f64>() / n;
        let sd =
            (mu0s.iter().map(|m| (m - mean) * (m - mean)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
        materials.push(MaterialModulus {
            step: s.clone(),
            levels: step
                .factors
                .iter()
                .map(|(f, l)| (f.clone(), l[s].clone()))
                .collect(),
            mean_curve_kpa: 1e3 * entry["mu0_mean_curve"].as_f64().unwrap_or(f64::NAN),
            records_mean_kpa: mean,
            records_sd_kpa: sd,
            records: mu0s.len(),
        });
    }
    let _ = writeln!(
        report,
        "\n## Summary `{}` over {} replicates steps\n",
        step.name,
        step.steps.len()
    );
    verdict_table(report, &law_order, &verdicts);
    modulus_table(report, step, &law_name, &materials);
    if let Some(x) = &step.x {
        let svg = modulus_plot(step, x, &law_name, &materials, &records);
        let file = format!("{}-modulus.svg", step.name);
        write_atomic(&run.out.join("plots").join(&file), svg.as_bytes())?;
        let _ = writeln!(report, "\n![mu0 against {x}](plots/{file})\n");
    }
    // the factorial on the complete crossing
    let (kept, dropped) = complete_crossing(step, &materials);
    let rows: Vec<&RecordModulus> = records.iter().filter(|r| kept.contains(&r.step)).collect();
    let level = |f: &str, r: &RecordModulus| step.factors[f][&r.step].clone();
    let factors: Vec<FactorColumn> = step
        .factors
        .keys()
        .map(|f| {
            let v: Vec<String> = rows.iter().map(|r| level(f, r)).collect();
            FactorColumn::from_names(f.as_str(), &v)
        })
        .collect();
    let y: Vec<f64> = rows.iter().map(|r| r.mu0_kpa).collect();
    let batches: Option<Vec<String>> = rows
        .iter()
        .map(|r| r.batch.clone())
        .collect::<Option<Vec<String>>>();
    let options = AnovaOptions {
        alpha: step.alpha,
        ..Default::default()
    };
    let usable = factors.iter().filter(|f| f.levels.len() >= 2).count() == factors.len();
    let (raw, log) = if usable && rows.len() > kept.len() {
        let raw = analyse_scale("mu0", &factors, batches.as_deref(), &y, &options)?;
        for (file, svg) in plots(&raw.analysis) {
            write_atomic(
                &run.out.join("plots").join(format!("{}-{file}", step.name)),
                svg.as_bytes(),
            )?;
        }
        // multiplicative effects: the same ANOVA of ln mu0 (every modulus
        // is positive, else the log scale is left out)
        let log = if y.iter().all(|v| *v > 0.0 && v.is_finite()) {
            let ln: Vec<f64> = y.iter().map(|v| v.ln()).collect();
            let log = analyse_scale("ln_mu0", &factors, batches.as_deref(), &ln, &options)?;
            for (file, svg) in plots(&log.analysis) {
                write_atomic(
                    &run.out
                        .join("plots")
                        .join(format!("{}-log-{file}", step.name)),
                    svg.as_bytes(),
                )?;
            }
            Some(log)
        } else {
            None
        };
        (Some(raw), log)
    } else {
        (None, None)
    };
    anova_report(
        report,
        step,
        &law_name,
        &kept,
        &dropped,
        raw.as_ref(),
        log.as_ref(),
    );
    let mut csv = String::from("step");
    for f in step.factors.keys() {
        let _ = write!(csv, ",{f}");
    }
    csv.push_str(",record,batch,mu0_kPa\n");
    for r in &records {
        let _ = write!(csv, "{}", r.step);
        for f in step.factors.keys() {
            let _ = write!(csv, ",{}", level(f, r));
        }
        let _ = writeln!(
            csv,
            ",{},{},{:.9e}",
            r.record,
            r.batch.as_deref().unwrap_or(""),
            r.mu0_kpa
        );
    }
    write_atomic(
        &run.out.join(format!("{}-modulus.csv", step.name)),
        csv.as_bytes(),
    )?;
    Ok(serde_json::json!({
        "name": step.name.clone(),
        "law": law_name,
        "verdicts": verdicts,
        "materials": materials,
        "records": records,
        "crossed": kept,
        "outside_the_crossing": dropped,
        "analysis": raw.as_ref().map(|s| &s.analysis),
        "batch": raw.as_ref().and_then(|s| s.batch.as_ref()),
        "analysis_log": log.as_ref().map(|s| &s.analysis),
        "batch_log": log.as_ref().and_then(|s| s.batch.as_ref()),
        "residual_checks": [
            raw.as_ref().map(|s| checks(&s.analysis, step.alpha)),
            log.as_ref().map(|s| checks(&s.analysis, step.alpha)),
        ],
    }))
}

/// The steps whose levels cross completely: levels dropped one at a time
/// (the one with the fewest records first) until every combination of the
/// remaining levels has a step. Returns (kept steps, dropped steps).
fn complete_crossing(
    step: &ReplicatesSummaryStep,
    materials: &[MaterialModulus],
) -> (Vec<String>, Vec<String>) {
    let mut kept: Vec<&MaterialModulus> = materials.iter().collect();
    loop {
        let levels: Vec<(&String, Vec<String>)> = step
            .factors
            .keys()
            .map(|f| {
                let mut l: Vec<String> = kept.iter().map(|m| m.levels[f].clone()).collect();
                l.sort();
                l.dedup();
                (f, l)
            })
            .collect();
        let cells: usize = levels.iter().map(|(_, l)| l.len()).product();
        let mut present: Vec<Vec<&String>> = kept
            .iter()
            .map(|m| step.factors.keys().map(|f| &m.levels[f]).collect())
            .collect();
        present.sort();
        present.dedup();
        if present.len() == cells || kept.is_empty() {
            break;
        }
        // a level is incomplete when it misses a combination of the others
        let mut worst: Option<(usize, &String, String)> = None;
        for (f, ls) in &levels {
            let others: usize = levels
                .iter()
                .filter(|(g, _)| g != f)
                .map(|(_, l)| l.len())
                .product();
            for l in ls {
                let with: Vec<&&MaterialModulus> =
                    kept.iter().filter(|m| &m.levels[*f] == l).collect();
                let mut combos: Vec<Vec<&String>> = with
                    .iter()
                    .map(|m| {
                        step.factors
                            .keys()
                            .filter(|g| g != f)
                            .map(|g| &m.levels[g])
                            .collect()
                    })
                    .collect();
                combos.sort();
                combos.dedup();
                if combos.len() < others {
                    let n: usize = with.iter().map(|m| m.records).sum();
                    if worst.as_ref().is_none_or(|(w, _, _)| n < *w) {
                        worst = Some((n, f, l.clone()));
                    }
                }
            }
        }
        match worst {
            Some((_, f, l)) => kept.retain(|m| m.levels[f] != l),
            None => break,
        }
    }
    let names: Vec<String> = kept.iter().map(|m| m.step.clone()).collect();
    let dropped = materials
        .iter()
        .filter(|m| !names.contains(&m.step))
        .map(|m| m.step.clone())
        .collect();
    (names, dropped)
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
struct ScaleAnalysis {
    analysis: Analysis,
    batch: Option<BatchEffect>,
}

fn analyse_scale(
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

/// The residual checks of one scale at `alpha`: normality (Ryan-Joiner and
/// Anderson-Darling) and equal variances across the cells (Bartlett and
/// Levene); a check passes when its p-value is at least `alpha`, and one
/// that is undefined does not pass.
#[derive(Debug, Clone, PartialEq, Serialize)]
struct ResidualChecks {
    response: String,
    ryan_joiner_p: Option<f64>,
    anderson_darling_p: Option<f64>,
    bartlett_p: Option<f64>,
    levene_p: Option<f64>,
    ryan_joiner_pass: bool,
    anderson_darling_pass: bool,
    bartlett_pass: bool,
    levene_pass: bool,
    normal: bool,
    equal_variances: bool,
}

impl ResidualChecks {
    /// The checks that do not pass.
    fn failed(&self) -> Vec<&'static str> {
        [
            ("Ryan-Joiner", self.ryan_joiner_pass),
            ("Anderson-Darling", self.anderson_darling_pass),
            ("Bartlett", self.bartlett_pass),
            ("Levene", self.levene_pass),
        ]
        .into_iter()
        .filter(|(_, pass)| !pass)
        .map(|(n, _)| n)
        .collect()
    }
}

fn checks(a: &Analysis, alpha: f64) -> ResidualChecks {
    // Ryan-Joiner's p is a bound outside its table (< 0.01 or > 0.10)
    let rj = a.ryan_joiner.as_ref().map(|t| match t.p_bound {
        PBound::Below => t.p.min(alpha * (1.0 - 1e-12)),
        _ => t.p,
    });
    let ad = a.anderson_darling.as_ref().map(|t| t.p);
    let b = a.bartlett.as_ref().map(|t| t.p);
    let l = a.levene.as_ref().map(|t| t.p);
    let pass = |p: Option<f64>| p.is_some_and(|p| p >= alpha);
    ResidualChecks {
        response: a.table.response.clone(),
        ryan_joiner_p: a.ryan_joiner.as_ref().map(|t| t.p),
        anderson_darling_p: ad,
        bartlett_p: b,
        levene_p: l,
        ryan_joiner_pass: pass(rj),
        anderson_darling_pass: pass(ad),
        bartlett_pass: pass(b),
        levene_pass: pass(l),
        normal: pass(rj) && pass(ad),
        equal_variances: pass(b) && pass(l),
    }
}

fn p_text(p: f64) -> String {
    if p < 1e-3 {
        format!("{p:.2e}")
    } else {
        format!("{p:.3}")
    }
}

fn verdict_table(
    report: &mut String,
    laws: &[String],
    verdicts: &BTreeMap<String, BTreeMap<String, Vec<String>>>,
) {
    let columns = [
        "same",
        "lower SSE",
        "same SSE, other parameters",
        "higher SSE",
        "not in the table",
    ];
    let _ = writeln!(
        report,
        "Fits to the mean curves beside the published table, per law: how many materials give each verdict \
         (`same`: every parameter within 5e-4 relative and the SSE within 1e-4; `lower SSE`: palpate's optimum \
         is better on the same curve).\n"
    );
    let _ = writeln!(
        report,
        "| law | {} | materials with `higher SSE` |",
        columns.join(" | ")
    );
    let _ = writeln!(report, "|---|{}---|", "---|".repeat(columns.len()));
    for l in laws {
        let v = &verdicts[l];
        let counts: Vec<String> = columns
            .iter()
            .map(|c| v.get(*c).map(|s| s.len().to_string()).unwrap_or_default())
            .collect();
        let higher = v
            .get("higher SSE")
            .map(|s| s.join(", "))
            .unwrap_or_default();
        let _ = writeln!(report, "| {l} | {} | {higher} |", counts.join(" | "));
    }
}

fn modulus_table(
    report: &mut String,
    step: &ReplicatesSummaryStep,
    law: &str,
    m: &[MaterialModulus],
) {
    let _ = writeln!(
        report,
        "\nInitial shear modulus mu0 of {law} (kPa): its fit to the mean curve, and the mean and SD of the \
         per-record fits.\n"
    );
    let f: Vec<&String> = step.factors.keys().collect();
    let _ = writeln!(
        report,
        "| material | {} | mean curve | per-record mean | per-record SD | records |",
        f.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(" | ")
    );
    let _ = writeln!(report, "|---|{}---|---|---|---|", "---|".repeat(f.len()));
    for x in m {
        let levels: Vec<&str> = f.iter().map(|k| x.levels[*k].as_str()).collect();
        let _ = writeln!(
            report,
            "| {} | {} | {} | {} | {} | {} |",
            x.step,
            levels.join(" | "),
            sig4(x.mean_curve_kpa),
            sig4(x.records_mean_kpa),
            sig4(x.records_sd_kpa),
            x.records
        );
    }
}

/// mu0 against the numeric factor `x`, one colour per combination of the
/// other factors: each record's fit (markers) and the mean-curve fit (line).
fn modulus_plot(
    step: &ReplicatesSummaryStep,
    x: &str,
    law: &str,
    materials: &[MaterialModulus],
    records: &[RecordModulus],
) -> String {
    let group = |levels: &BTreeMap<String, String>| -> String {
        levels
            .iter()
            .filter(|(f, _)| f.as_str() != x)
            .map(|(f, l)| format!("{f} {l}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut groups: Vec<String> = materials.iter().map(|m| group(&m.levels)).collect();
    groups.dedup();
    let mut unique = Vec::new();
    for g in groups {
        if !unique.contains(&g) {
            unique.push(g);
        }
    }
    let value = |m: &MaterialModulus| m.levels[x].parse::<f64>().unwrap_or(f64::NAN);
    let mut plot = Plot::new(
        format!("initial shear modulus of {law} against {x}"),
        x.to_string(),
        "mu0 (kPa)",
    );
    for (k, g) in unique.iter().enumerate() {
        let color = PALETTE[k % PALETTE.len()];
        let mut line: Vec<(f64, f64)> = materials
            .iter()
            .filter(|m| &group(&m.levels) == g)
            .map(|m| (value(m), m.mean_curve_kpa))
            .collect();
        line.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (lx, ly): (Vec<f64>, Vec<f64>) = line.into_iter().unzip();
        let (px, py): (Vec<f64>, Vec<f64>) = records
            .iter()
            .filter_map(|r| {
                let m = materials.iter().find(|m| m.step == r.step)?;
                (&group(&m.levels) == g).then(|| (value(m), r.mu0_kpa))
            })
            .unzip();
        let name = if g.is_empty() {
            step.name.clone()
        } else {
            g.clone()
        };
        plot.push(Series::line(format!("{name}: mean curve"), &lx, &ly).color(color));
        plot.push(Series::markers(format!("{name}: each record"), &px, &py).color(color));
    }
    plot.to_svg()
}

fn anova_report(
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

    fn material(step: &str, family: &str, thinner: &str) -> MaterialModulus {
        MaterialModulus {
            step: step.into(),
            levels: [("family", family), ("thinner", thinner)]
                .into_iter()
                .map(|(f, l)| (f.to_string(), l.to_string()))
                .collect(),
            mean_curve_kpa: 1.0,
            records_mean_kpa: 1.0,
            records_sd_kpa: 0.1,
            records: 10,
        }
    }

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
            "../../../docs/validation/phantom_database_anova_reference.json"
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

    /// Family 00-10 at thinner 0, 50 and 100, family 00-30 at 0 and 50: the
    /// crossing keeps 0 and 50 of both and drops 00-10 at 100.
    #[test]
    fn the_complete_crossing_drops_the_levels_without_partners() {
        let m = vec![
            material("a0", "00-10", "0"),
            material("a50", "00-10", "50"),
            material("a100", "00-10", "100"),
            material("b0", "00-30", "0"),
            material("b50", "00-30", "50"),
        ];
        let levels = |l: &[(&str, &str)]| -> BTreeMap<String, String> {
            l.iter()
                .map(|(s, v)| (s.to_string(), v.to_string()))
                .collect()
        };
        let step = ReplicatesSummaryStep {
            name: "s".into(),
            steps: m.iter().map(|x| x.step.clone()).collect(),
            law: "neo-hookean".into(),
            factors: [
                (
                    "family".to_string(),
                    levels(&[
                        ("a0", "00-10"),
                        ("a50", "00-10"),
                        ("a100", "00-10"),
                        ("b0", "00-30"),
                        ("b50", "00-30"),
                    ]),
                ),
                (
                    "thinner".to_string(),
                    levels(&[
                        ("a0", "0"),
                        ("a50", "50"),
                        ("a100", "100"),
                        ("b0", "0"),
                        ("b50", "50"),
                    ]),
                ),
            ]
            .into_iter()
            .collect(),
            x: Some("thinner".into()),
            alpha: 0.05,
        };
        let (kept, dropped) = complete_crossing(&step, &m);
        assert_eq!(kept, ["a0", "a50", "b0", "b50"]);
        assert_eq!(dropped, ["a100"]);
    }
}
