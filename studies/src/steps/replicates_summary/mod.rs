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
//!
//! Here the step and the crossing it analyses; `anova.rs` the ANOVA of
//! each scale (kPa and ln) with the nested cast test and its report
//! tables, `checks.rs` the residual checks, `tables.rs` the verdict and
//! modulus tables, `plot.rs` the modulus plot.

mod anova;
mod checks;
mod plot;
mod tables;

use crate::report::anova::plots;
use crate::run::checks::check_alpha;
use crate::run::output::write_atomic;
use crate::run::step::{duplicate, At, Run, Sharding, Step, StepResult, Study};
use crate::steps::replicates::ReplicatesStep;
use anova::{analyse_scale, anova_report};
use anyhow::Context;
use checks::checks;
use palpate_material::Law;
use palpate_uq::anova::{AnovaOptions, FactorColumn};
use plot::modulus_plot;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write;
use tables::{modulus_table, verdict_table};

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
