//! The `calibrate` step of a study ([`crate::manifest::CalibrateStep`]):
//! each fit a unit of the run folder, cached under its inputs, and the
//! step's tables and plots in the report. Split from [`crate::runner`].

use crate::calibration::{calibrate, parse_method, Request, TestData};
use crate::manifest::{CalibrateStep, ModelForm};
use crate::output::write_atomic;
use crate::report::{calibrate_tables, fit_plot, fit_row, r2_cells};
use crate::runner::{FitEntry, Run, StepResult};
use anyhow::Context;
use palpate_inverse::ResidualKind;
use palpate_material::Law;
use serde::{Deserialize, Serialize};

/// A finished fit as cached: its results entry, its report rows and its plot.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct FitUnit {
    entry: serde_json::Value,
    /// The row of the fit table.
    row: String,
    /// (data set, R^2 cell) of the prediction table.
    r2: Vec<(String, String)>,
    plot: String,
}

pub(crate) fn run_calibrate(
    run: &Run,
    step: &CalibrateStep,
    report: &mut String,
) -> anyhow::Result<StepResult> {
    let (manifest, data) = (run.manifest, run.data);
    let method = parse_method(&step.estimator)?;
    let predict: Vec<TestData> = step.predict.iter().map(|n| data[n].clone()).collect();
    let mut units = Vec::new();
    for model_name in &step.models {
        let entry = &manifest.models[model_name];
        let law: Law = entry
            .law_text()
            .parse()
            .map_err(|e| anyhow::anyhow!("models.{model_name}.law: {e}"))?;
        let spec = match &entry.model {
            ModelForm::Law(_) => None,
            ModelForm::Spec(s) => Some(s),
        };
        for (group, sets) in &step.fits {
            let fitted: Vec<TestData> = sets.iter().map(|n| data[n].clone()).collect();
            for residual in &step.residuals {
                let kind: ResidualKind = residual.parse().map_err(|e| anyhow::anyhow!("{e}"))?;
                let label = format!("{}: {model_name} on {group} ({residual})", step.name);
                let inputs = (
                    "calibrate",
                    &step.name,
                    model_name,
                    entry,
                    group,
                    &fitted,
                    &predict,
                    residual,
                    &step.estimator,
                );
                let Some(unit): Option<FitUnit> = run.unit(&label, &inputs, || {
                    let calibration = calibrate(Request {
                        law,
                        model: spec,
                        fitted: &fitted,
                        predict: &predict,
                        residual: kind,
                        method,
                        fixed: entry.fixed.iter().map(|(k, v)| (k.clone(), *v)).collect(),
                        observer: None,
                        viscous: entry
                            .viscoelastic
                            .as_deref()
                            .map(crate::models::Viscous::parse)
                            .transpose()
                            .map_err(|e| {
                                anyhow::anyhow!("models.{model_name}.viscoelastic: {e}")
                            })?,
                    })
                    .with_context(|| {
                        format!(
                            "step `{}`: model `{model_name}` on `{group}` ({residual})",
                            step.name
                        )
                    })?;
                    let fit = FitEntry {
                        model: model_name.clone(),
                        group: group.clone(),
                        residual: residual.clone(),
                        calibration,
                    };
                    Ok(FitUnit {
                        row: fit_row(&fit.model, &fit.group, &fit.residual, &fit.calibration),
                        r2: r2_cells(&fit.calibration),
                        plot: fit_plot(&fit.calibration).to_svg(),
                        entry: serde_json::to_value(&fit)?,
                    })
                })?
                else {
                    continue;
                };
                let file = format!("{}-{model_name}-{group}-{residual}.svg", step.name);
                write_atomic(&run.out.join("plots").join(&file), unit.plot.as_bytes())?;
                units.push(((model_name, group, residual), unit));
            }
        }
    }
    let rows: Vec<_> = units
        .iter()
        .map(|((m, g, r), u)| {
            (
                (m.as_str(), g.as_str(), r.as_str()),
                u.row.as_str(),
                &u.r2[..],
            )
        })
        .collect();
    report.push_str(&calibrate_tables(&step.name, &step.estimator, &rows));
    Ok(StepResult::Calibrate {
        name: step.name.clone(),
        fits: units.into_iter().map(|(_, u)| u.entry).collect(),
    })
}
