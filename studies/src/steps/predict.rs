//! The `predict` step of a study: run models with the parameters a
//! calibrate step found, on the loading of some records, and compare.
//!
//! ```toml
//! [[steps]]
//! [steps.predict]
//! name = "needle"
//! calibration = "compression"   # an earlier calibrate step
//! models = ["nh-axisymmetric", "nh-3d"]   # [models.NAME.<kind>] entries
//! data = ["needle-1", "needle-2"]         # records compared with each prediction
//! ```
//!
//! Each model runs once, with the parameters of the one fit of the
//! calibrate step whose law is the model's law, on the union of the
//! records' displacements; each (model, record) pair gets R^2 = 1 -
//! SS_res/SS_tot and the RMS residual ([`crate::model::calibration::r2_rms`]).
//! The runs are units of the run folder's cache keyed by (model, parameters,
//! loading), so an edit of any other step does not run them again; runs not
//! cached are computed in parallel (one per thread) with a progress report
//! over their load steps.

use crate::model::calibration::r2_rms;
use crate::model::ModelForm;
use crate::steps::calibrate::CalibrateStep;
use crate::model::{Model, ModelSpec};
use crate::run::output::write_atomic;
use crate::report::plot::{Plot, Series};
use crate::run::step::{At, Run, Step, StepResult, Study};
use crate::run::step::{find_list, Sharding};
use anyhow::Context;
use palpate_core::{Drive, Loading};
use palpate_material::Law;
use serde::{Deserialize, Serialize};
use std::fmt::Write;

/// `[steps.predict]`: models run with calibrated parameters against records.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PredictStep {
    pub name: String,
    /// The calibrate step (earlier in the manifest) whose fits give the
    /// parameters: each model takes those of the one fit of its own law.
    pub calibration: String,
    /// Models to run (`[models.NAME.<kind>]` entries; a bare `law = ...` has no kind).
    pub models: Vec<String>,
    /// Records compared with each prediction.
    pub data: Vec<String>,
}

impl PredictStep {
    /// Checks the step (step `i` of `manifest`); errors name the manifest
    /// file (`where_`) and the field.
    pub(crate) fn check(&self, manifest: &Study, i: usize, where_: &str) -> anyhow::Result<()> {
        let at = format!("steps[{i}].predict (\"{}\")", self.name);
        let calibrate = match manifest
            .steps
            .iter()
            .position(|s| s.name() == self.calibration)
        {
            None => anyhow::bail!(
                "{where_}: {at}.calibration: no step named \"{}\" (a calibrate step before this one)",
                self.calibration
            ),
            Some(j) if j >= i => anyhow::bail!(
                "{where_}: {at}.calibration: step \"{}\" is steps[{j}], not before this one; steps run in order",
                self.calibration
            ),
            Some(j) => match manifest.steps[j].get::<CalibrateStep>() {
                Some(c) => c,
                None => anyhow::bail!(
                    "{where_}: {at}.calibration: step \"{}\" is a {} step; expected a calibrate step",
                    self.calibration,
                    manifest.steps[j].kind
                ),
            },
        };
        for (field, list) in [("models", &self.models), ("data", &self.data)] {
            anyhow::ensure!(
                !list.is_empty(),
                "{where_}: {at}.{field} = []: give at least one"
            );
            if let Some(d) = list
                .iter()
                .enumerate()
                .find(|(k, x)| list[..*k].contains(x))
            {
                anyhow::bail!("{where_}: {at}.{field}: \"{}\" is listed twice", d.1);
            }
        }
        for m in &self.models {
            let spec = match manifest.models.get(m).map(|e| &e.model) {
                None => anyhow::bail!(
                    "{where_}: {at}.models: unknown model \"{m}\" (defined: {})",
                    crate::run::step::keys(manifest.models)
                ),
                Some(ModelForm::Law(_)) => anyhow::bail!(
                    "{where_}: {at}.models: \"{m}\" is a law alone; a prediction needs a model kind, e.g. [models.{m}.n1_needle]"
                ),
                Some(ModelForm::Spec(s)) => s,
            };
            let Ok(law) = spec.law() else {
                continue; // reported with the model
            };
            let fits = fits_of_law(manifest, calibrate, law);
            match fits.len() {
                1 => {}
                0 => anyhow::bail!(
                    "{where_}: {at}.models: \"{m}\" is {law}, and step \"{}\" fits no model of that law (its models: {})",
                    self.calibration,
                    calibrate.models.join(", ")
                ),
                n => anyhow::bail!(
                    "{where_}: {at}.models: \"{m}\" is {law}, and step \"{}\" has {n} fits of that law ({}); a prediction takes the parameters of exactly one",
                    self.calibration,
                    fits.join(", ")
                ),
            }
            for d in &self.data {
                if !manifest.data.contains_key(d) {
                    anyhow::bail!(
                        "{where_}: {at}.data: unknown data set \"{d}\" (defined: {})",
                        crate::run::step::keys(manifest.data)
                    );
                }
                manifest.check_predicts(where_.to_string(), &at, m, spec, d)?;
            }
        }
        Ok(())
    }
}

/// The fits of a calibrate step whose model has `law`, as `model/group/residual`.
fn fits_of_law(
    manifest: &Study,
    step: &CalibrateStep,
    law: Law,
) -> Vec<String> {
    let mut out = Vec::new();
    for m in &step.models {
        let same = manifest
            .models
            .get(m)
            .and_then(|e| e.law_text().parse::<Law>().ok())
            == Some(law);
        if same {
            for g in step.fits.keys() {
                for r in &step.residuals {
                    out.push(format!("{m}/{g}/{r}"));
                }
            }
        }
    }
    out
}

/// One finished FE (or analytic) run as cached: the force at each
/// displacement of the step's loading.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct RunUnit {
    forces: Vec<f64>,
}

/// A prediction of one model compared with one record (`results.json`).
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    pub model: String,
    pub data: String,
    pub r2: f64,
    pub rms: f64,
}

/// One model's prediction (`results.json`).
#[derive(Debug, Clone, Serialize)]
pub struct PredictionRun {
    pub model: String,
    pub kind: String,
    pub law: String,
    /// The parameters, from the calibrate step's fit, in the law's order.
    pub params: serde_json::Map<String, serde_json::Value>,
    pub displacement_mm: Vec<f64>,
    pub force_n: Vec<f64>,
}

/// The parameters (names and values, the law's order) of the fit of `law`
/// in a calibrate step's results.
fn params_of(fits: &[serde_json::Value], law: Law) -> Option<Vec<(String, f64)>> {
    let fit = fits.iter().find(|f| {
        f["calibration"]["law"]
            .as_str()
            .and_then(|l| l.parse::<Law>().ok())
            == Some(law)
    })?;
    fit["calibration"]["params"]
        .as_object()?
        .iter()
        .map(|(n, p)| Some((n.clone(), p["value"].as_f64()?)))
        .collect()
}

/// Runs a predict step; `done` holds the results of the steps before it.
pub(crate) fn run_predict(
    run: &Run,
    step: &PredictStep,
    done: &[StepResult],
    report: &mut String,
) -> anyhow::Result<serde_json::Value> {
    let fits = find_list(done, "calibrate", &step.calibration, "fits")
        .with_context(|| {
            format!(
                "step `{}`: no results of calibrate step `{}`",
                step.name, step.calibration
            )
        })?;
    // The loading: every displacement of every record, in order.
    let mut drive: Vec<f64> = step
        .data
        .iter()
        .flat_map(|d| run.data[d].loading.drive.iter().copied())
        .collect();
    drive.sort_by(f64::total_cmp);
    drive.dedup();
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive.clone());

    struct Job {
        model: String,
        spec: ModelSpec,
        law: Law,
        params: Vec<(String, f64)>,
        key: String,
    }
    let mut jobs = Vec::new();
    for m in &step.models {
        let ModelForm::Spec(spec) = &run.manifest.models[m].model else {
            anyhow::bail!("step `{}`: model `{m}` is a law alone", step.name);
        };
        let law = spec.law().map_err(|e| anyhow::anyhow!("models.{m}.{e}"))?;
        let params = params_of(fits, law).with_context(|| {
            format!(
                "step `{}`: no fit of {law} in step `{}`",
                step.name, step.calibration
            )
        })?;
        let theta: Vec<f64> = params.iter().map(|p| p.1).collect();
        // Keyed by what the run depends on, not by names: a renamed step
        // or model reuses it.
        let key = crate::run::run_folder::RunFolder::key(&("predict", spec, &theta, &drive));
        jobs.push(Job {
            model: m.clone(),
            spec: spec.clone(),
            law,
            params,
            key,
        });
    }
    // Each run is a unit: cached, this process's to compute, or (a shard
    // run) another shard's.
    let claims: Vec<Option<bool>> = jobs.iter().map(|j| run.claim(&j.key)).collect();
    let mut forces: Vec<Option<Vec<f64>>> = jobs
        .iter()
        .map(|j| {
            run.folder
                .cached::<RunUnit>(&j.key)
                .map(|u| u.forces)
                .filter(|f| f.len() == drive.len())
        })
        .collect();
    for (j, f) in jobs.iter().zip(&forces) {
        if f.is_some() {
            run.observer
                .message(&format!("{}: {} (cached)", step.name, j.model));
        }
    }
    let todo: Vec<usize> = (0..jobs.len())
        .filter(|&k| forces[k].is_none() && claims[k] != Some(false))
        .collect();
    let others = (0..jobs.len()).any(|k| forces[k].is_none() && claims[k] == Some(false));
    if !todo.is_empty() {
        let names: Vec<&str> = todo.iter().map(|&k| jobs[k].model.as_str()).collect();
        run.observer.message(&format!(
            "{}: running {} ({} load steps each)",
            step.name,
            names.join(", "),
            drive.len()
        ));
        let label = format!("{}: {} runs", step.name, todo.len());
        let inputs: Vec<(ModelSpec, Vec<f64>)> = todo
            .iter()
            .map(|&k| {
                (
                    jobs[k].spec.clone(),
                    jobs[k].params.iter().map(|p| p.1).collect(),
                )
            })
            .collect();
        let results = run_parallel(&inputs, &loading, &|done, total| {
            run.observer.progress(&label, done, total)
        });
        for (&k, r) in todo.iter().zip(results) {
            let f = r.with_context(|| {
                format!(
                    "step `{}`: model `{}` ({})",
                    step.name,
                    jobs[k].model,
                    jobs[k].spec.kind()
                )
            })?;
            run.folder
                .store(&jobs[k].key, &RunUnit { forces: f.clone() })?;
            forces[k] = Some(f);
        }
    }
    if others {
        // Runs of other shards are missing: the runner defers the step.
        return Ok(serde_json::json!({
            "name": step.name.clone(),
            "runs": Vec::<serde_json::Value>::new(),
            "comparisons": Vec::<serde_json::Value>::new(),
        }));
    }
    let forces: Vec<Vec<f64>> = forces.into_iter().map(Option::unwrap_or_default).collect();

    // Compare each prediction with each record at the record's own displacements.
    let mut comparisons = Vec::new();
    for (j, f) in jobs.iter().zip(&forces) {
        for d in &step.data {
            let rec = &run.data[d];
            let predicted: Vec<f64> = rec
                .loading
                .drive
                .iter()
                .map(|x| f[drive.partition_point(|v| v < x)])
                .collect();
            let (r2, rms) = r2_rms(&rec.observed, &predicted);
            comparisons.push(Comparison {
                model: j.model.clone(),
                data: d.clone(),
                r2,
                rms,
            });
        }
    }
    let runs: Vec<PredictionRun> = jobs
        .iter()
        .zip(&forces)
        .map(|(j, f)| PredictionRun {
            model: j.model.clone(),
            kind: j.spec.kind().to_string(),
            law: j.law.to_string(),
            params: j
                .params
                .iter()
                .map(|(n, v)| (n.clone(), serde_json::json!(v)))
                .collect(),
            displacement_mm: drive.clone(),
            force_n: f.clone(),
        })
        .collect();
    write_report(step, &runs, &comparisons, report);
    let svg = plot(step, run, &runs).to_svg();
    write_atomic(
        &run.out.join("plots").join(format!("{}.svg", step.name)),
        svg.as_bytes(),
    )?;
    Ok(serde_json::json!({
        "name": step.name.clone(),
        "runs": runs
            .iter()
            .map(serde_json::to_value)
            .collect::<Result<Vec<serde_json::Value>, _>>()?,
        "comparisons": comparisons
            .iter()
            .map(serde_json::to_value)
            .collect::<Result<Vec<serde_json::Value>, _>>()?,
    }))
}

/// Runs each (model, parameters) on `loading`, as many at once as there are
/// threads; `progress(done, total)` counts load steps over all runs and is
/// called on this thread only.
fn run_parallel(
    inputs: &[(ModelSpec, Vec<f64>)],
    loading: &Loading,
    progress: &dyn Fn(u64, u64),
) -> Vec<anyhow::Result<Vec<f64>>> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::mpsc;
    let samples = loading.drive.len() as u64;
    let total = samples * inputs.len() as u64;
    let workers = rayon::current_num_threads().clamp(1, inputs.len().max(1));
    let next = AtomicUsize::new(0);
    let (tx, rx) = mpsc::channel::<(usize, Option<u64>, Option<anyhow::Result<Vec<f64>>>)>();
    let mut out: Vec<Option<anyhow::Result<Vec<f64>>>> = inputs.iter().map(|_| None).collect();
    std::thread::scope(|s| {
        for _ in 0..workers {
            let tx = tx.clone();
            let next = &next;
            s.spawn(move || loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some((spec, theta)) = inputs.get(k) else {
                    break;
                };
                let r = run_one(spec, theta, loading, &mut |station| {
                    tx.send((k, Some(station), None)).ok();
                });
                tx.send((k, Some(samples), Some(r))).ok();
            });
        }
        drop(tx);
        let mut at = vec![0u64; inputs.len()];
        progress(0, total);
        for (k, station, result) in rx {
            if let Some(st) = station {
                if st > at[k] {
                    at[k] = st;
                    progress(at.iter().sum(), total);
                }
            }
            if let Some(r) = result {
                out[k] = Some(r);
            }
        }
    });
    out.into_iter()
        .map(|r| r.unwrap_or_else(|| Err(anyhow::anyhow!("the run did not finish"))))
        .collect()
}

/// One run; `station(n)` says `n` load steps are done.
fn run_one(
    spec: &ModelSpec,
    theta: &[f64],
    loading: &Loading,
    station: &mut dyn FnMut(u64),
) -> anyhow::Result<Vec<f64>> {
    let model = spec.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut cb = |p: &palpate_fe::Progress| station(p.sample as u64 + 1);
    let forces = match model {
        Model::N1Needle(m) => m.simulate(theta, loading, Some(&mut cb))?.0.forces,
        Model::N3Needle(m) => m.simulate(theta, loading, Some(&mut cb))?.0.forces,
        other => other.into_forward().predict(theta, loading)?,
    };
    Ok(forces)
}

fn write_report(
    step: &PredictStep,
    runs: &[PredictionRun],
    comparisons: &[Comparison],
    r: &mut String,
) {
    let _ = writeln!(
        r,
        "## Predictions `{}` (parameters of `{}`)\n",
        step.name, step.calibration
    );
    let _ = writeln!(r, "Each model runs once with the parameters of the fit of its law; R^2 = 1 - SS_res/SS_tot against each record at the record's displacements.\n");
    let _ = writeln!(
        r,
        "| model | kind | law | parameters (MPa) | F at {} mm (N) | {} | mean R^2 |",
        runs.first()
            .and_then(|x| x.displacement_mm.last())
            .copied()
            .unwrap_or(0.0),
        step.data
            .iter()
            .map(|d| format!("R^2 {d}"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let _ = writeln!(
        r,
        "|---|---|---|---|---|{}---|",
        "---|".repeat(step.data.len())
    );
    for run in runs {
        let r2: Vec<f64> = comparisons
            .iter()
            .filter(|c| c.model == run.model)
            .map(|c| c.r2)
            .collect();
        let params: Vec<String> = run
            .params
            .iter()
            .map(|(n, v)| format!("{n} = {:.6e}", v.as_f64().unwrap_or(f64::NAN)))
            .collect();
        let _ = writeln!(
            r,
            "| {} | {} | {} | {} | {:.6} | {} | {:.5} |",
            run.model,
            run.kind,
            run.law,
            params.join(", "),
            run.force_n.last().copied().unwrap_or(0.0),
            r2.iter()
                .map(|v| format!("{v:.5}"))
                .collect::<Vec<_>>()
                .join(" | "),
            r2.iter().sum::<f64>() / r2.len().max(1) as f64
        );
    }
    let _ = writeln!(
        r,
        "\nPlot: `plots/{}.svg` (records and predictions).\n",
        step.name
    );
}

fn plot(step: &PredictStep, run: &Run, runs: &[PredictionRun]) -> Plot {
    let mut p = Plot::new(
        format!(
            "{}: predictions with the parameters of {}",
            step.name, step.calibration
        ),
        "displacement (mm)",
        "force (N)",
    );
    for d in &step.data {
        let rec = &run.data[d];
        p.push(Series::markers(
            d.clone(),
            &rec.loading.drive,
            &rec.observed,
        ));
    }
    for r in runs {
        p.push(Series::line(
            format!("{} ({})", r.model, r.kind),
            &r.displacement_mm,
            &r.force_n,
        ));
    }
    p
}

impl Step for PredictStep {
    fn name(&self) -> &str {
        &self.name
    }

    fn validate(&self, study: &Study, at: &At) -> anyhow::Result<()> {
        self.check(study, at.index, &at.file)
    }

    fn sharding(&self) -> Sharding {
        Sharding::AfterEarlierSteps
    }

    fn run(
        &self,
        run: &Run,
        done: &[StepResult],
        report: &mut String,
    ) -> anyhow::Result<serde_json::Value> {
        run_predict(run, self, done, report)
    }
}
