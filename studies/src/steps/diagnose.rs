//! The `diagnose` step of a study ([`crate::manifest::DiagnoseStep`]): the
//! gap diagnosis of each record, a unit of the run folder cached under its
//! inputs, and its table and plots in the report. Split from
//! [`crate::runner`].

use crate::manifest::{DiagnoseStep, ModelForm};
use crate::models::{build, default_effects, gap_base_for, parse_effects};
use crate::output::write_atomic;
use crate::report::gap_svg;
use crate::runner::{DiagnoseEntry, Run, StepResult};
use anyhow::Context;
use palpate_material::Law;
use serde::{Deserialize, Serialize};
use std::fmt::Write;

/// A diagnosed record as cached.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct DiagnoseUnit {
    entry: serde_json::Value,
    row: String,
    plot: String,
}

pub(crate) fn run_diagnose(
    run: &Run,
    step: &DiagnoseStep,
    report: &mut String,
) -> anyhow::Result<StepResult> {
    let (manifest, data) = (run.manifest, run.data);
    // The base model: a named model spec, or the base law in the gap base
    // model of each record's test (models::gap_base).
    let (base_name, named) = match (&step.base, &step.model) {
        (Some(base), _) => (base.clone(), None),
        (None, Some(m)) => match &manifest.models[m].model {
            ModelForm::Spec(s) => (m.clone(), Some(s)),
            ModelForm::Law(_) => anyhow::bail!("step `{}`: model `{m}` is a law alone", step.name),
        },
        (None, None) => anyhow::bail!("step `{}`: no base model", step.name),
    };
    let mut cases = Vec::new();
    let _ = writeln!(
        report,
        "## Gap diagnosis `{}` (base `{}`)\n",
        step.name, base_name
    );
    let _ = writeln!(report, "| data | verdict | noise SD (N) | base misfit (N) | best effect | misfit after (N) | held-out before / after (N) |");
    let _ = writeln!(report, "|---|---|---|---|---|---|---|");
    for name in &step.data {
        let d = &data[name];
        let spec = match named {
            Some(s) => s.clone(),
            None => {
                let law: Law = base_name
                    .parse()
                    .map_err(|e| anyhow::anyhow!("step `{}`: base: {e}", step.name))?;
                gap_base_for(d, law).with_context(|| format!("step `{}`: `{name}`", step.name))?
            }
        };
        let label = format!("{}: diagnosing {name}", step.name);
        let inputs = (
            "diagnose",
            &step.name,
            &base_name,
            &spec,
            &step.effects,
            name,
            d,
        );
        let Some(unit): Option<DiagnoseUnit> = run.unit(&label, &inputs, || {
            let model = build(&spec).map_err(|e| anyhow::anyhow!("step `{}`: {e}", step.name))?;
            let options = palpate_uq::gap::GapOptions {
                effects: match &step.effects {
                    Some(list) => Some(
                        parse_effects(list)
                            .with_context(|| format!("step `{}`: effects", step.name))?,
                    ),
                    None => default_effects(&spec, model.as_ref(), &d.loading),
                },
                ..Default::default()
            };
            let gap = palpate_uq::gap::diagnose(model.as_ref(), &d.loading, &d.observed, &options)
                .with_context(|| format!("step `{}`: diagnosing `{name}`", step.name))?;
            let best = gap.ranking.first();
            let row = format!(
                "| {name} | **{}**{} | {:.4} | {:.4} | {} | {} | {} |",
                gap.verdict,
                if gap.confounded.is_empty() {
                    String::new()
                } else {
                    let names: Vec<&str> = gap.confounded.iter().map(|e| e.name()).collect();
                    format!(" (confounded with {})", names.join(", "))
                },
                gap.noise_sd,
                gap.base.misfit,
                best.map(|b| b.effect.to_string()).unwrap_or_default(),
                best.map(|b| format!("{:.4}", b.misfit_after))
                    .unwrap_or_default(),
                best.map(|b| format!("{:.4} / {:.4}", b.heldout_before, b.heldout_after))
                    .unwrap_or_default(),
            );
            Ok(DiagnoseUnit {
                row,
                plot: gap_svg(&gap, name),
                entry: serde_json::to_value(DiagnoseEntry {
                    data: name.clone(),
                    report: serde_json::to_value(&gap)?,
                })?,
            })
        })?
        else {
            continue;
        };
        let _ = writeln!(report, "{}", unit.row);
        write_atomic(
            &run.out
                .join("plots")
                .join(format!("{}-{name}.svg", step.name)),
            unit.plot.as_bytes(),
        )?;
        cases.push(unit.entry);
    }
    let _ = writeln!(report, "\nPlots: `plots/{}-<data>.svg` (data, base and enriched fits, residuals with the flagged windows).\n", step.name);
    Ok(StepResult::Diagnose {
        name: step.name.clone(),
        cases,
    })
}
