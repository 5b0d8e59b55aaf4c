//! The `calibrate` step of a study ([`CalibrateStep`]): each fit a unit of
//! the run folder, cached under its inputs, and the step's tables and plots
//! in the report.

use crate::model::calibration::{calibrate, parse_method, Calibration, Request};
use crate::records::TestData;
use crate::model::ModelForm;
use crate::run::output::write_atomic;
use crate::report::{calibrate_tables, fit_plot, fit_row, r2_cells};
use crate::run::step::{duplicate, keys, At, Run, Step, StepResult, Study};
use std::collections::BTreeMap;
use anyhow::Context;
use palpate_inverse::ResidualKind;
use palpate_material::Law;
use serde::{Deserialize, Serialize};

/// Fit every model to every group of data sets, with every residual kind.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrateStep {
    pub name: String,
    /// Model names (keys of `[models]`).
    pub models: Vec<String>,
    /// Named groups of data sets fitted jointly, e.g. `{ all = ["uniaxial", "biaxial", "planar"] }`.
    pub fits: BTreeMap<String, Vec<String>>,
    /// Residual kinds: `absolute`, `relative`, `normalised`.
    #[serde(default = "default_residuals")]
    pub residuals: Vec<String>,
    /// `lm`, `bfgs` or `lbfgs`.
    #[serde(default = "default_estimator")]
    pub estimator: String,
    /// Data sets on which every fit is also evaluated (predictions of other modes).
    #[serde(default)]
    pub predict: Vec<String>,
}

fn default_residuals() -> Vec<String> {
    vec!["absolute".into()]
}
fn default_estimator() -> String {
    "lm".into()
}

/// One fit of a calibrate step.
#[derive(Debug, Clone, Serialize)]
pub struct FitEntry {
    pub model: String,
    pub group: String,
    pub residual: String,
    pub calibration: Calibration,
}

impl Step for CalibrateStep {
    fn name(&self) -> &str {
        &self.name
    }

    fn validate(&self, study: &Study, site: &At) -> anyhow::Result<()> {
        let where_ = &site.file;
        let at = site.step(&self.name);
        for (field, list) in [
            ("models", &self.models),
            ("residuals", &self.residuals),
            ("predict", &self.predict),
        ] {
            if list.is_empty() && field != "predict" {
                anyhow::bail!("{where_}: {at}.{field} = []: give at least one");
            }
            if let Some(d) = duplicate(list) {
                anyhow::bail!("{where_}: {at}.{field}: \"{d}\" is listed twice");
            }
        }
        for m in &self.models {
            if !study.models.contains_key(m) {
                anyhow::bail!(
                    "{where_}: {at}.models: unknown model \"{m}\" (defined: {})",
                    keys(study.models)
                );
            }
        }
        if self.fits.is_empty() {
            anyhow::bail!(
                "{where_}: {at}.fits: at least one group of data sets is needed"
            );
        }
        for (g, sets) in &self.fits {
            if sets.is_empty() {
                anyhow::bail!("{where_}: {at}.fits.{g}: empty group");
            }
            for s in sets {
                if !study.data.contains_key(s) {
                    anyhow::bail!("{where_}: {at}.fits.{g}: unknown data set \"{s}\" (defined: {})", keys(study.data));
                }
            }
        }
        for s in &self.predict {
            if !study.data.contains_key(s) {
                anyhow::bail!(
                    "{where_}: {at}.predict: unknown data set \"{s}\" (defined: {})",
                    keys(study.data)
                );
            }
        }
        for m in &self.models {
            let ModelForm::Spec(spec) = &study.models[m].model else {
                continue;
            };
            for s in self.fits.values().flatten().chain(&self.predict) {
                study.check_predicts(where_.to_string(), &at, m, spec, s)?;
            }
        }
        for r in &self.residuals {
            if !["absolute", "relative", "normalised"].contains(&r.as_str()) {
                anyhow::bail!("{where_}: {at}.residuals: \"{r}\" is not one of absolute, relative, normalised");
            }
        }
        if !["lm", "bfgs", "lbfgs"].contains(&self.estimator.as_str()) {
            anyhow::bail!(
                "{where_}: {at}.estimator: \"{}\" is not one of lm, bfgs, lbfgs",
                self.estimator
            );
        }
        Ok(())
    }

    fn run(
        &self,
        run: &Run,
        _done: &[StepResult],
        report: &mut String,
    ) -> anyhow::Result<serde_json::Value> {
        run_calibrate(run, self, report)
    }
}


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
) -> anyhow::Result<serde_json::Value> {
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
                        viscous: entry.viscoelastic,
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
    Ok(serde_json::json!({
        "name": step.name.clone(),
        "fits": units.into_iter().map(|(_, u)| u.entry).collect::<Vec<_>>(),
    }))
}
