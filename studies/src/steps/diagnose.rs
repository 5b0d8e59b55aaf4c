//! The `diagnose` step of a study ([`DiagnoseStep`]): the gap diagnosis of
//! each record, a unit of the run folder cached under its inputs, and its
//! table and plots in the report.

use crate::model::{build, default_effects, gap_base_for, parse_effects};
use crate::model::{ExperimentSpec, ModelForm, ModelSpec};
use crate::records::{TestData, TestKind};
use crate::report::{data_unit, gap_svg, gap_table_header};
use crate::run::output::write_atomic;
use crate::run::step::{duplicate, keys, At, Run, Step, StepResult, Study};
use crate::steps::replicates::sig4;
use anyhow::Context;
use palpate_core::{Effect, ForwardModel, Loading};
use palpate_material::Law;
use palpate_uq::gap::NoisePaths;
use serde::{Deserialize, Serialize};
use std::fmt::Write;

/// Diagnose the sim-to-real gap of a base model on C1 or N1 records.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiagnoseStep {
    pub name: String,
    /// Data set names (each diagnosed separately).
    pub data: Vec<String>,
    /// Base law, e.g. `neo-hookean`, in the base model of each record's test
    /// ([`crate::model::gap_base`]: C1 analytic; N1 frictionless, coarse mesh).
    #[serde(default)]
    pub base: Option<String>,
    /// Or the base model by name (a `[models.NAME.<kind>]` entry).
    #[serde(default)]
    pub model: Option<String>,
    /// Candidate effects (GAP.md names); default: C1 every effect its model
    /// offers, N1 `friction` and `boundary_condition`, an experiment's model
    /// (`model` naming a `[models.NAME] experiment = ..`) every effect it
    /// offers that the record can show.
    #[serde(default)]
    pub effects: Option<Vec<String>>,
}

/// One diagnosed data set.
#[derive(Debug, Clone, Serialize)]
pub struct DiagnoseEntry {
    pub data: String,
    pub report: serde_json::Value,
}

impl Step for DiagnoseStep {
    fn name(&self) -> &str {
        &self.name
    }

    fn validate(&self, study: &Study, site: &At) -> anyhow::Result<()> {
        let where_ = &site.file;
        let at = site.step(&self.name);
        for s in &self.data {
            match study.data.get(s) {
                None => anyhow::bail!(
                    "{where_}: {at}.data: unknown data set \"{s}\" (defined: {})",
                    keys(study.data)
                ),
                Some(spec) if spec.test != "C1" && spec.test != "N1" => {
                    anyhow::bail!("{where_}: {at}.data: \"{s}\" is a {} test; the gap diagnosis needs a C1 or N1 force record", spec.test)
                }
                _ => {}
            }
        }
        match (&self.base, &self.model) {
            (Some(base), None) => {
                if let Err(e) = base.parse::<palpate_material::Law>() {
                    anyhow::bail!("{where_}: {at}.base = \"{base}\": {e}");
                }
            }
            (None, Some(m)) => match study.models.get(m).map(|e| &e.model) {
                None => anyhow::bail!(
                    "{where_}: {at}.model: unknown model \"{m}\" (defined: {})",
                    keys(study.models)
                ),
                Some(ModelForm::Law(_)) => anyhow::bail!(
                    "{where_}: {at}.model: \"{m}\" is a law alone; give the law as `base` or define models.{m}.c1 / models.{m}.n1_needle"
                ),
                Some(ModelForm::Spec(spec)) => {
                    for s in &self.data {
                        study.check_predicts(where_.to_string(), &at, m, spec, s)?;
                    }
                }
            },
            _ => anyhow::bail!(
                "{where_}: {at}: give exactly one of `base` (a law) and `model` (a model name)"
            ),
        }
        anyhow::ensure!(
            !self.data.is_empty(),
            "{where_}: {at}.data = []: give at least one record"
        );
        let mut effects = Vec::new();
        for e in self.effects.iter().flatten() {
            match e.parse::<palpate_core::Effect>() {
                Ok(e) => effects.push(e),
                Err(m) => anyhow::bail!("{where_}: {at}.effects: \"{e}\": {m}"),
            }
        }
        if let Some(list) = &self.effects {
            anyhow::ensure!(
                !list.is_empty(),
                "{where_}: {at}.effects = []: give at least one effect, or leave `effects` out for the default candidates"
            );
            if let Some(e) = duplicate(list) {
                anyhow::bail!("{where_}: {at}.effects: \"{e}\" is listed twice");
            }
        }
        for s in &self.data {
            let Some(spec) = diagnose_model(study, self, s) else {
                continue;
            };
            if let Ok(model) = crate::model::build(&spec) {
                crate::model::check_effects(model.as_ref(), &effects)
                    .map_err(|e| anyhow::anyhow!("{where_}: {at}.effects: {e}"))?;
            }
        }
        Ok(())
    }

    fn run(
        &self,
        run: &Run,
        _done: &[StepResult],
        report: &mut String,
    ) -> anyhow::Result<serde_json::Value> {
        run_diagnose(run, self, report)
    }
}

/// The base model a diagnose step uses on data set `data` (None when
/// the step or the data set is wrong: reported elsewhere).
fn diagnose_model(study: &Study, d: &DiagnoseStep, data: &str) -> Option<ModelSpec> {
    match (&d.base, &d.model) {
        (Some(base), None) => {
            let test = crate::records::TestKind::parse(&study.data.get(data)?.test).ok()?;
            crate::model::gap_base(test, base.parse().ok()?).ok()
        }
        (None, Some(m)) => match &study.models.get(m)?.model {
            ModelForm::Spec(s) => Some(s.clone()),
            ModelForm::Law(_) => None,
        },
        _ => None,
    }
}

/// The base of an experiment's diagnosis on `record`: its description with
/// the law of its one material replaced by `law` when given (the law's
/// parameters then start at their defaults), meshed for the record's
/// deepest displacement when the protocol is the record's
/// ([`palpate_fe::experiment::Experiment::size_for_depth`]). Parameters the
/// description holds at their start (`fit = false`) are refused: the
/// diagnosis (and `palpate sample`) vary every parameter of the model.
pub fn experiment_base(
    mut spec: ExperimentSpec,
    law: Option<&str>,
    record: &TestData,
) -> anyhow::Result<ModelSpec> {
    if let Some(law) = law {
        law.parse::<Law>()
            .map_err(|e| anyhow::anyhow!("--base {law}: {e}"))?;
        let materials = &mut spec.experiment.materials;
        anyhow::ensure!(
            materials.len() == 1,
            "--base {law}: {} has {} materials; give their laws in the description",
            spec.source,
            materials.len()
        );
        for m in materials.values_mut() {
            if m.law != law {
                m.law = law.to_string();
                m.params.clear();
            }
        }
    }
    let fixed = spec.fixed()?;
    if let Some((name, _)) = fixed.first() {
        anyhow::bail!(
            "{}: parameter `{name}` is held at its start (fit = false); diagnose and sample vary every parameter of the description: give it as a number to hold it, or let it be fitted",
            spec.source
        );
    }
    let deepest = record
        .loading
        .drive
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    spec.experiment.size_for_depth(deepest);
    spec.check()?;
    Ok(ModelSpec::Experiment(spec))
}

/// The candidates of an experiment's diagnosis: every effect its model
/// offers (the description's type decides, `Setup::effects`), but
/// `viscoelasticity` on a record without times.
pub fn experiment_effects(model: &dyn ForwardModel, loading: &Loading) -> Vec<Effect> {
    palpate_core::enrichable::effects_of(model)
        .into_iter()
        .filter(|e| *e != Effect::Viscoelasticity || loading.time.is_some())
        .collect()
}

/// The loading paths of a record whose noise must be estimated path by
/// path: a general biaxial record holds two stresses per row (one per
/// direction) and runs of rows at one fixed stretch (Kawabata's paths:
/// lambda1 held, lambda2 varied), so neighbouring samples of the record
/// belong to different curves. A path is a run of rows that keep lambda1
/// (or, when lambda1 changes from row to row, lambda2), each direction's
/// stress its own path, placed along the stretch that varies. `None` for
/// every other record (one path, in order).
pub fn noise_paths(record: &TestData) -> Option<NoisePaths> {
    if record.test != TestKind::GeneralBiaxial {
        return None;
    }
    let rows: Vec<(f64, f64)> = record
        .loading
        .drive
        .chunks_exact(2)
        .map(|r| (r[0], r[1]))
        .collect();
    if rows.len() < 2 {
        return None;
    }
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0);
    let runs = |first: bool| {
        rows.windows(2)
            .filter(|w| {
                let (a, b) = if first {
                    (w[0].0, w[1].0)
                } else {
                    (w[0].1, w[1].1)
                };
                !same(a, b)
            })
            .count()
    };
    // The stretch held on a path changes least often from row to row.
    let held_first = runs(true) <= runs(false);
    let (mut path, mut along) = (Vec::new(), Vec::new());
    let mut id = 0;
    for (i, &(l1, l2)) in rows.iter().enumerate() {
        let (held, varied) = if held_first { (l1, l2) } else { (l2, l1) };
        if i > 0 {
            let prev = if held_first {
                rows[i - 1].0
            } else {
                rows[i - 1].1
            };
            if !same(prev, held) {
                id += 1;
            }
        }
        for k in 0..2 {
            path.push(2 * id + k);
            along.push(varied);
        }
    }
    Some(NoisePaths { path, along })
}

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
) -> anyhow::Result<serde_json::Value> {
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
    let units: Vec<&str> = step.data.iter().map(|n| data_unit(data[n].test)).collect();
    report.push_str(&gap_table_header(&units));
    for name in &step.data {
        let d = &data[name];
        let spec = match named {
            Some(ModelSpec::Experiment(e)) => experiment_base(e.clone(), None, d)
                .with_context(|| format!("step `{}`: `{name}`", step.name))?,
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
                    None if matches!(spec, ModelSpec::Experiment(_)) => {
                        Some(experiment_effects(model.as_ref(), &d.loading))
                    }
                    None => default_effects(&spec, model.as_ref(), &d.loading),
                },
                paths: noise_paths(d),
                ..Default::default()
            };
            let gap = palpate_uq::gap::diagnose(model.as_ref(), &d.loading, &d.observed, &options)
                .with_context(|| format!("step `{}`: diagnosing `{name}`", step.name))?;
            let best = gap.ranking.first();
            let row = format!(
                "| {name} | **{}**{} | {} | {} | {} | {} | {} |",
                gap.verdict,
                if gap.confounded.is_empty() {
                    String::new()
                } else {
                    let names: Vec<&str> = gap.confounded.iter().map(|e| e.name()).collect();
                    format!(" (confounded with {})", names.join(", "))
                },
                sig4(gap.noise_sd),
                sig4(gap.base.misfit),
                best.map(|b| b.effect.to_string()).unwrap_or_default(),
                best.map(|b| sig4(b.misfit_after)).unwrap_or_default(),
                best.map(|b| format!("{} / {}", sig4(b.heldout_before), sig4(b.heldout_after)))
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
    Ok(serde_json::json!({
        "name": step.name.clone(),
        "cases": cases,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_general_biaxial_record_gets_its_noise_path_by_path() {
        // Kawabata's record: paths at fixed lambda1, lambda2 varied, two
        // stresses per row. Differenced across the interleaved paths the
        // "noise" is the jump between curves; within each path it is what
        // the digitised data scatter by.
        let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data/real/kawabata1981/biaxial.csv");
        let d = TestData::read("biaxial", TestKind::GeneralBiaxial, &file).unwrap();
        let paths = noise_paths(&d).unwrap();
        let labels: std::collections::BTreeSet<usize> = paths.path.iter().copied().collect();
        let rows = d.loading.len() / 2;
        assert!(
            labels.len() >= 20 && labels.len() < rows,
            "{} paths",
            labels.len()
        );
        // within a path the position (lambda2) increases
        for w in paths.path.windows(3).zip(paths.along.windows(3)) {
            if w.0[0] == w.0[2] {
                assert!(w.1[2] >= w.1[0]);
            }
        }
        let across = palpate_uq::gap::difference_noise_sd(&d.observed, None).unwrap();
        let within = palpate_uq::gap::path_noise_sd(&d.observed, &paths).unwrap();
        assert!(within.sd < 0.2 * across.sd, "{within:?} against {across:?}");
        // other records are one path
        let uni = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data/real/meunier2008_silicone/uniaxial.csv");
        let u = TestData::read(
            "uniaxial",
            TestKind::Homogeneous(palpate_analytic::Mode::Uniaxial),
            &uni,
        )
        .unwrap();
        assert!(noise_paths(&u).is_none());
    }

    #[test]
    fn small_numbers_keep_their_digits() {
        // a dense record's noise of ~1e-5 MPa is not printed as 0.0000
        assert_eq!(sig4(1.234e-5), "1.234e-5");
        assert_eq!(sig4(0.02213), "0.02213");
    }
}
