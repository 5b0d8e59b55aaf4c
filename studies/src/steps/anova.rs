//! The `anova` step of a study: a factorial analysis of the comparisons of
//! a predict step (one run per model and record), optionally beside the
//! same analysis of a published table of the same experiment.
//!
//! ```toml
//! [[steps]]
//! [steps.anova]
//! name = "factorial"
//! predictions = "needle"           # an earlier predict step
//! response = "r2"                  # r2 (default) | rms
//! factors.material = { nh-axi = "NH", rp-axi = "RP" }        # level of each model
//! factors.space = { nh-axi = "axisymmetric", rp-axi = "axisymmetric" }
//! published = "table1.csv"         # optional: columns = the factors, `replicate`, the response
//! source = "Mesa-Munera et al. 2011, Table 1"
//! ```
//!
//! The model has every interaction of the factors (factors in alphabetical
//! order of their names; sequential SS equal Type III on balanced designs):
//! F, p, eta^2 = SS_term / SS_total for each term, the Ryan-Joiner test of
//! the residuals' normality and Bartlett's test of equal variances across
//! cells ([`palpate_uq::anova::analyse`], as `palpate anova`), main-effect
//! and interaction plots. The report lays the responses out as a table of
//! cells by replicates (ours, then the published ones) and states in words
//! which term matters, how much, and whether the two analyses agree.

use crate::report::anova::plots;
use crate::run::checks::check_alpha;
use crate::steps::predict::PredictStep;
use crate::run::output::write_atomic;
use crate::run::step::{At, Run, Step, StepResult, Study};
use crate::run::step::{find_list, Sharding};
use anyhow::Context;
use palpate_uq::anova::{analyse, Analysis, AnovaOptions, FactorColumn, RunsTable};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::PathBuf;

/// `[steps.anova]`: a factorial ANOVA over a predict step's comparisons.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnovaStep {
    pub name: String,
    /// The predict step (earlier in the manifest) whose comparisons are the runs.
    pub predictions: String,
    /// `r2` (default) or `rms`.
    #[serde(default = "default_response")]
    pub response: String,
    /// Each factor: the level of each model of the predict step.
    pub factors: BTreeMap<String, BTreeMap<String, String>>,
    /// Significance level (default 0.05).
    #[serde(default = "default_alpha")]
    pub alpha: f64,
    /// A published table of the same experiment (CSV, relative to the
    /// manifest): the factor columns, `replicate` and the response column.
    #[serde(default)]
    pub published: Option<PathBuf>,
    /// Where the published table comes from (shown in the report).
    #[serde(default)]
    pub source: Option<String>,
}

fn default_response() -> String {
    "r2".into()
}
fn default_alpha() -> f64 {
    0.05
}

/// The responses a predict step offers.
const RESPONSES: [&str; 2] = ["r2", "rms"];

impl AnovaStep {
    /// Checks the step (step `i` of `manifest`, read from `dir`); errors
    /// name the manifest file (`where_`) and the field.
    pub(crate) fn check(
        &self,
        manifest: &Study,
        i: usize,
        where_: &str,
        dir: &std::path::Path,
    ) -> anyhow::Result<()> {
        let at = format!("steps[{i}].anova (\"{}\")", self.name);
        let predict = match manifest
            .steps
            .iter()
            .position(|s| s.name() == self.predictions)
        {
            None => anyhow::bail!(
                "{where_}: {at}.predictions: no step named \"{}\" (a predict step before this one)",
                self.predictions
            ),
            Some(j) if j >= i => anyhow::bail!(
                "{where_}: {at}.predictions: step \"{}\" is steps[{j}], not before this one; steps run in order",
                self.predictions
            ),
            Some(j) => match manifest.steps[j].get::<PredictStep>() {
                Some(p) => p,
                None => anyhow::bail!(
                    "{where_}: {at}.predictions: step \"{}\" is a {} step; expected a predict step",
                    self.predictions,
                    manifest.steps[j].kind
                ),
            },
        };
        anyhow::ensure!(
            RESPONSES.contains(&self.response.as_str()),
            "{where_}: {at}.response = \"{}\": expected one of {}",
            self.response,
            RESPONSES.join(", ")
        );
        check_alpha(&format!("{where_}: {at}.alpha ="), self.alpha)?;
        anyhow::ensure!(
            !self.factors.is_empty(),
            "{where_}: {at}.factors: give at least one factor, e.g. factors.material = {{ model = \"level\", ... }}"
        );
        for (f, levels) in &self.factors {
            anyhow::ensure!(
                f != &self.response && f != "replicate",
                "{where_}: {at}.factors.{f}: a factor cannot be named like the response or `replicate`"
            );
            for m in &predict.models {
                anyhow::ensure!(
                    levels.contains_key(m),
                    "{where_}: {at}.factors.{f}: no level for model \"{m}\" of step \"{}\"",
                    self.predictions
                );
            }
            if let Some(m) = levels.keys().find(|m| !predict.models.contains(m)) {
                anyhow::bail!(
                    "{where_}: {at}.factors.{f}: \"{m}\" is not a model of step \"{}\" (its models: {})",
                    self.predictions,
                    predict.models.join(", ")
                );
            }
            let mut distinct: Vec<&String> = levels.values().collect();
            distinct.sort();
            distinct.dedup();
            anyhow::ensure!(
                distinct.len() >= 2,
                "{where_}: {at}.factors.{f}: one level ({}) for every model; a factor needs two levels at least",
                distinct.first().map(|s| s.as_str()).unwrap_or("none")
            );
        }
        if let Some(p) = &self.published {
            let f = dir.join(p);
            anyhow::ensure!(
                f.is_file(),
                "{where_}: {at}.published: no such file {}",
                f.display()
            );
        }
        Ok(())
    }
}

/// One run of the factorial (`results.json`).
#[derive(Debug, Clone, serde::Serialize)]
struct FactorialRun {
    model: String,
    data: String,
    levels: BTreeMap<String, String>,
    response: f64,
}

/// A response table: cell (levels in factor order) -> replicate values.
type Cells = Vec<(Vec<String>, Vec<f64>)>;

fn cells_of(factors: &[FactorColumn], y: &[f64]) -> Cells {
    let mut cells: Cells = Vec::new();
    for (k, v) in y.iter().enumerate() {
        let key: Vec<String> = factors
            .iter()
            .map(|f| f.levels[f.codes[k]].clone())
            .collect();
        match cells.iter_mut().find(|(c, _)| *c == key) {
            Some((_, vals)) => vals.push(*v),
            None => cells.push((key, vec![*v])),
        }
    }
    cells
}

/// Runs an anova step; `done` holds the results of the steps before it.
pub(crate) fn run_anova(
    run: &Run,
    step: &AnovaStep,
    done: &[StepResult],
    report: &mut String,
) -> anyhow::Result<serde_json::Value> {
    let comparisons = find_list(done, "predict", &step.predictions, "comparisons")
        .with_context(|| {
            format!(
                "step `{}`: no results of predict step `{}`",
                step.name, step.predictions
            )
        })?;
    let mut runs = Vec::new();
    for c in comparisons {
        let model = c["model"].as_str().unwrap_or_default().to_string();
        let levels: BTreeMap<String, String> = step
            .factors
            .iter()
            .map(|(f, l)| (f.clone(), l.get(&model).cloned().unwrap_or_default()))
            .collect();
        runs.push(FactorialRun {
            response: c[step.response.as_str()].as_f64().unwrap_or(f64::NAN),
            data: c["data"].as_str().unwrap_or_default().to_string(),
            model,
            levels,
        });
    }
    let names: Vec<&String> = step.factors.keys().collect();
    let factors: Vec<FactorColumn> = names
        .iter()
        .map(|f| {
            let values: Vec<&str> = runs.iter().map(|r| r.levels[*f].as_str()).collect();
            FactorColumn::from_names(f.as_str(), &values)
        })
        .collect();
    let y: Vec<f64> = runs.iter().map(|r| r.response).collect();
    let options = AnovaOptions {
        alpha: step.alpha,
        ..Default::default()
    };
    let ours = analyse(&step.response, &factors, &y, &options)
        .with_context(|| format!("step `{}`: ANOVA of {}", step.name, step.response))?;
    let dir = run.manifest_dir;
    let published = match &step.published {
        None => None,
        Some(p) => {
            let path = dir.join(p);
            let table = RunsTable::read(&path)
                .with_context(|| format!("step `{}`: published", step.name))?;
            let pf = names
                .iter()
                .map(|f| table.factor(f))
                .collect::<Result<Vec<_>, _>>()
                .with_context(|| format!("step `{}`: published", step.name))?;
            let py = table
                .numeric(&step.response)
                .with_context(|| format!("step `{}`: published", step.name))?;
            let a = analyse(&step.response, &pf, &py, &options)
                .with_context(|| format!("step `{}`: ANOVA of the published table", step.name))?;
            Some((cells_of(&pf, &py), a))
        }
    };
    write_report(step, &factors, &y, &ours, published.as_ref(), report);
    for (prefix, a) in std::iter::once((step.name.clone(), &ours)).chain(
        published
            .as_ref()
            .map(|(_, a)| (format!("{}-published", step.name), a)),
    ) {
        for (file, svg) in plots(a) {
            write_atomic(
                &run.out.join("plots").join(format!("{prefix}-{file}")),
                svg.as_bytes(),
            )?;
        }
    }
    Ok(serde_json::json!({
        "name": step.name.clone(),
        "runs": serde_json::to_value(&runs)?,
        "analysis": serde_json::to_value(&ours)?,
        "published": published
            .as_ref()
            .map(|(_, a)| serde_json::to_value(a))
            .transpose()?,
    }))
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

fn p_text(p: Option<f64>) -> String {
    match p {
        Some(p) if p < 0.001 => "< 0.001".into(),
        Some(p) => format!("{p:.3}"),
        None => "-".into(),
    }
}

fn write_report(
    step: &AnovaStep,
    factors: &[FactorColumn],
    y: &[f64],
    ours: &Analysis,
    published: Option<&(Cells, Analysis)>,
    r: &mut String,
) {
    let source = step.source.as_deref().unwrap_or("published");
    let _ = writeln!(
        r,
        "## Factorial `{}`: {} of `{}` on {}\n",
        step.name,
        step.response,
        step.predictions,
        step.factors.keys().cloned().collect::<Vec<_>>().join(" x ")
    );
    // Table 1 layout: one row per cell, the replicates side by side.
    let cells = cells_of(factors, y);
    let n_ours = cells.iter().map(|c| c.1.len()).max().unwrap_or(0);
    let n_pub = published
        .map(|(c, _)| c.iter().map(|c| c.1.len()).max().unwrap_or(0))
        .unwrap_or(0);
    let mut head: Vec<String> = step.factors.keys().cloned().collect();
    head.extend((1..=n_ours).map(|k| format!("ours {k}")));
    head.push("ours mean".into());
    if published.is_some() {
        head.extend((1..=n_pub).map(|k| format!("{source} {k}")));
        head.push(format!("{source} mean"));
    }
    let _ = writeln!(
        r,
        "{} of each prediction against each record (replicate):\n",
        step.response
    );
    let _ = writeln!(r, "| {} |", head.join(" | "));
    let _ = writeln!(r, "|{}", "---|".repeat(head.len()));
    let pub_cell = |key: &Vec<String>| -> Option<&Vec<f64>> {
        published.and_then(|(c, _)| c.iter().find(|(k, _)| k == key).map(|(_, v)| v))
    };
    for (key, vals) in &cells {
        let mut row: Vec<String> = key.clone();
        row.extend((0..n_ours).map(|k| vals.get(k).map(|v| format!("{v:.5}")).unwrap_or_default()));
        row.push(format!("**{:.5}**", mean(vals)));
        if published.is_some() {
            let pv = pub_cell(key);
            row.extend((0..n_pub).map(|k| {
                pv.and_then(|v| v.get(k))
                    .map(|v| format!("{v:.5}"))
                    .unwrap_or_default()
            }));
            row.push(
                pv.map(|v| format!("**{:.5}**", mean(v)))
                    .unwrap_or_else(|| "(not in the table)".into()),
            );
        }
        let _ = writeln!(r, "| {} |", row.join(" | "));
    }
    // The ANOVA tables side by side.
    let _ = writeln!(
        r,
        "\nANOVA (all interactions; eta^2 = SS_term / SS_total):\n"
    );
    if published.is_some() {
        let _ = writeln!(r, "| source | DF | F | p | eta^2 | DF ({source}) | F ({source}) | p ({source}) | eta^2 ({source}) |");
        let _ = writeln!(r, "|---|---|---|---|---|---|---|---|---|");
    } else {
        let _ = writeln!(r, "| source | DF | F | p | eta^2 |");
        let _ = writeln!(r, "|---|---|---|---|---|");
    }
    let fmt_f = |f: Option<f64>| f.map(|v| format!("{v:.3}")).unwrap_or("-".into());
    for t in &ours.table.terms {
        let mut row = format!(
            "| {} | {} | {} | {} | {:.4} |",
            t.name,
            t.df,
            fmt_f(t.f),
            p_text(t.p),
            t.eta_sq
        );
        if let Some((_, a)) = published {
            match a.table.term(&t.name) {
                Some(u) => {
                    let _ = write!(
                        row,
                        " {} | {} | {} | {:.4} |",
                        u.df,
                        fmt_f(u.f),
                        p_text(u.p),
                        u.eta_sq
                    );
                }
                None => row.push_str(" | | | |"),
            }
        }
        let _ = writeln!(r, "{row}");
    }
    let res = |a: &Analysis| {
        format!(
            "{} | | | {:.4} |",
            a.table.residual.df,
            a.table.residual.ss / a.table.total.ss.max(f64::MIN_POSITIVE)
        )
    };
    let _ = write!(r, "| error | {}", res(ours));
    if let Some((_, a)) = published {
        let _ = write!(r, " {}", res(a));
    }
    let _ = writeln!(r);
    let _ = writeln!(r, "\nResidual checks:\n");
    let checks = |a: &Analysis| {
        let rj = a
            .ryan_joiner
            .as_ref()
            .map(|t| format!("Ryan-Joiner R = {:.4}, p {}", t.r, t.p_text()))
            .unwrap_or_else(|| "Ryan-Joiner: not available".into());
        let b = a
            .bartlett
            .as_ref()
            .map(|t| format!("Bartlett statistic = {:.3}, p = {:.3}", t.statistic, t.p))
            .unwrap_or_else(|| "Bartlett: not available".into());
        format!("{rj}; {b}")
    };
    let _ = writeln!(r, "* ours: {}", checks(ours));
    for n in &ours.notes {
        let _ = writeln!(r, "  * note: {n}");
    }
    if let Some((_, a)) = published {
        let _ = writeln!(r, "* {source}: {}", checks(a));
        for n in &a.notes {
            let _ = writeln!(r, "  * note: {n}");
        }
    }
    let _ = writeln!(r, "\n### Conclusion\n");
    let _ = writeln!(r, "{}", conclusion(step, ours, published.map(|p| &p.1)));
    let _ = writeln!(
        r,
        "\nPlots: `plots/{n}-main_effects.svg`, `plots/{n}-interaction.svg`, `plots/{n}-normal_probability.svg`, `plots/{n}-residuals_vs_fits.svg`, `plots/{n}-pareto.svg`{}.\n",
        if published.is_some() { format!(" and the same with `{n}-published-`", n = step.name) } else { String::new() },
        n = step.name
    );
}

/// The conclusion in words: the terms by eta^2, whether each is
/// significant, the better level of each factor, the residual checks, and
/// the agreement with the published analysis.
pub fn conclusion(step: &AnovaStep, ours: &Analysis, published: Option<&Analysis>) -> String {
    let alpha = step.alpha;
    let source = step.source.as_deref().unwrap_or("the published table");
    let higher_is_better = step.response == "r2";
    let describe = |a: &Analysis| -> String {
        let mut terms: Vec<_> = a.table.terms.iter().collect();
        terms.sort_by(|x, y| y.eta_sq.total_cmp(&x.eta_sq));
        let parts: Vec<String> = terms
            .iter()
            .map(|t| {
                let sig = match t.p {
                    Some(p) if p < alpha => format!("significant, p {}", p_text(Some(p))),
                    Some(p) => format!("not significant, p = {p:.3}"),
                    None => "untested".into(),
                };
                format!("`{}` {:.1} % ({sig})", t.name, 100.0 * t.eta_sq)
            })
            .collect();
        let err = a.table.residual.ss / a.table.total.ss.max(f64::MIN_POSITIVE);
        let mut s = format!(
            "{} of the variance of {}; the replicates (error) {:.1} %.",
            parts.join(", "),
            step.response,
            100.0 * err
        );
        for m in &a.main_effects {
            let best = m
                .means
                .iter()
                .enumerate()
                .max_by(|x, y| {
                    if higher_is_better {
                        x.1.total_cmp(y.1)
                    } else {
                        y.1.total_cmp(x.1)
                    }
                })
                .map(|(k, _)| k)
                .unwrap_or(0);
            let means: Vec<String> = m
                .levels
                .iter()
                .zip(&m.means)
                .map(|(l, v)| format!("{l} {v:.5}"))
                .collect();
            let _ = write!(
                s,
                " `{}`: {} is better (means {}).",
                m.factor,
                m.levels[best],
                means.join(", ")
            );
        }
        s
    };
    let mut s = format!("**Ours**: {}", describe(ours));
    let top = |a: &Analysis| {
        a.table
            .terms
            .iter()
            .max_by(|x, y| x.eta_sq.total_cmp(&y.eta_sq))
            .map(|t| t.name.clone())
    };
    let significant = |a: &Analysis| -> Vec<String> {
        a.table
            .terms
            .iter()
            .filter(|t| t.p.is_some_and(|p| p < alpha))
            .map(|t| t.name.clone())
            .collect()
    };
    let best_levels = |a: &Analysis| -> Vec<(String, String)> {
        a.main_effects
            .iter()
            .map(|m| {
                let k = m
                    .means
                    .iter()
                    .enumerate()
                    .max_by(|x, y| {
                        if higher_is_better {
                            x.1.total_cmp(y.1)
                        } else {
                            y.1.total_cmp(x.1)
                        }
                    })
                    .map(|(k, _)| k)
                    .unwrap_or(0);
                (m.factor.clone(), m.levels[k].clone())
            })
            .collect()
    };
    if let Some(p) = published {
        let _ = write!(s, "\n\n**{source}**: {}", describe(p));
        let same_top = top(ours) == top(p);
        let (so, sp) = (significant(ours), significant(p));
        let same_sig = so == sp;
        let same_best = best_levels(ours) == best_levels(p);
        let _ = write!(
            s,
            "\n\n**Agreement**: the dominant term is {} ({} in ours, {} in {source}); \
             the terms significant at alpha = {alpha} are {} ({} in ours, {} in {source}); \
             the better level of every factor is {}.",
            if same_top { "the same" } else { "not the same" },
            top(ours).unwrap_or_default(),
            top(p).unwrap_or_default(),
            if same_sig { "the same" } else { "not the same" },
            if so.is_empty() {
                "none".into()
            } else {
                so.join(", ")
            },
            if sp.is_empty() {
                "none".into()
            } else {
                sp.join(", ")
            },
            if same_best {
                "the same"
            } else {
                "not the same in both"
            }
        );
    }
    s
}

impl Step for AnovaStep {
    fn name(&self) -> &str {
        &self.name
    }

    fn validate(&self, study: &Study, at: &At) -> anyhow::Result<()> {
        self.check(study, at.index, &at.file, at.dir)
    }

    fn inputs(&self) -> Vec<PathBuf> {
        self.published.iter().cloned().collect()
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
        run_anova(run, self, done, report)
    }
}
