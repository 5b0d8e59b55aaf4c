//! Runs a study manifest into a run folder:
//!
//! * `results.json` — every number, byte-identical on a rerun (no times, no
//!   paths outside the manifest's own names);
//! * `report.md` — a readable report with comparison tables;
//! * `plots/*.svg`;
//! * `provenance.json` — hashes, git commit, crate versions, seed, threads, timings.

use crate::calibration::{calibrate, parse_method, Calibration, Request, TestData, TestKind};
use crate::manifest::{CalibrateStep, DiagnoseStep, Manifest, ModelForm, Step};
use crate::models::{build, default_effects, gap_base, parse_effects};
use crate::output::{write_atomic, write_json};
use crate::provenance::{crate_versions, git_state, hash_file, Provenance};
use crate::report::{fit_plot, gap_svg};
use anyhow::Context;
use palpate_inverse::ResidualKind;
use palpate_material::Law;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// The results of a whole study (`results.json`).
#[derive(Debug, Clone, Serialize)]
pub struct StudyResults {
    pub study: String,
    pub description: String,
    pub seed: u64,
    pub steps: Vec<StepResult>,
}

/// The results of one step.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StepResult {
    Calibrate {
        name: String,
        fits: Vec<FitEntry>,
    },
    Diagnose {
        name: String,
        cases: Vec<DiagnoseEntry>,
    },
}

/// One fit of a calibrate step.
#[derive(Debug, Clone, Serialize)]
pub struct FitEntry {
    pub model: String,
    pub group: String,
    pub residual: String,
    pub calibration: Calibration,
}

/// One diagnosed data set.
#[derive(Debug, Clone, Serialize)]
pub struct DiagnoseEntry {
    pub data: String,
    pub report: serde_json::Value,
}

/// Progress messages of a run (the CLI shows them; tests ignore them).
pub trait RunObserver {
    fn message(&self, text: &str);
}

impl<F: Fn(&str)> RunObserver for F {
    fn message(&self, text: &str) {
        self(text)
    }
}

/// Runs the manifest at `path` into `out_dir` (default `runs/<study name>`).
pub fn run_study(
    path: &Path,
    out_dir: Option<&Path>,
    observer: &dyn RunObserver,
) -> anyhow::Result<PathBuf> {
    let started = std::time::Instant::now();
    let started_unix_s = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    let manifest = Manifest::read(path)?;
    manifest.validate(path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let out = out_dir
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("runs").join(&manifest.study.name));
    std::fs::create_dir_all(out.join("plots"))
        .with_context(|| format!("cannot create run folder {}", out.display()))?;

    let mut data = BTreeMap::new();
    for (name, spec) in &manifest.data {
        let kind = TestKind::parse(&spec.test).with_context(|| format!("data.{name}.test"))?;
        data.insert(
            name.clone(),
            TestData::read(name, kind, &dir.join(&spec.file))?,
        );
    }
    let mut results = StudyResults {
        study: manifest.study.name.clone(),
        description: manifest.study.description.clone(),
        seed: manifest.study.seed,
        steps: Vec::new(),
    };
    let mut report = String::new();
    let _ = writeln!(report, "# Study `{}`\n", manifest.study.name);
    if !manifest.study.description.is_empty() {
        let _ = writeln!(report, "{}\n", manifest.study.description.trim());
    }
    for step in &manifest.steps {
        match step {
            Step::Calibrate(c) => {
                let r = run_calibrate(&manifest, c, &data, &out, observer, &mut report)?;
                results.steps.push(r);
            }
            Step::Diagnose(d) => {
                let r = run_diagnose(&manifest, d, &data, &out, observer, &mut report)?;
                results.steps.push(r);
            }
        }
    }
    write_json(&out.join("results.json"), &results)?;
    write_atomic(&out.join("report.md"), report.as_bytes())?;
    let (git_commit, git_dirty) = git_state();
    let provenance = Provenance {
        palpate_version: env!("CARGO_PKG_VERSION").to_string(),
        manifest: hash_file(path)?,
        data: manifest
            .data
            .values()
            .map(|d| hash_file(&dir.join(&d.file)))
            .collect::<anyhow::Result<_>>()?,
        git_commit,
        git_dirty,
        crate_versions: crate_versions(),
        seed: manifest.study.seed,
        threads: rayon::current_num_threads(),
        started_unix_s,
        wall_time_s: started.elapsed().as_secs_f64(),
        command_line: std::env::args().collect(),
    };
    write_json(&out.join("provenance.json"), &provenance)?;
    Ok(out)
}

fn run_calibrate(
    manifest: &Manifest,
    step: &CalibrateStep,
    data: &BTreeMap<String, TestData>,
    out: &Path,
    observer: &dyn RunObserver,
    report: &mut String,
) -> anyhow::Result<StepResult> {
    let method = parse_method(&step.estimator)?;
    let predict: Vec<TestData> = step.predict.iter().map(|n| data[n].clone()).collect();
    let mut fits = Vec::new();
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
                observer.message(&format!(
                    "{}: {model_name} on {group} ({residual})",
                    step.name
                ));
                let calibration = calibrate(Request {
                    law,
                    model: spec,
                    fitted: &fitted,
                    predict: &predict,
                    residual: kind,
                    method,
                    fixed: entry.fixed.iter().map(|(k, v)| (k.clone(), *v)).collect(),
                    observer: None,
                })
                .with_context(|| {
                    format!(
                        "step `{}`: model `{model_name}` on `{group}` ({residual})",
                        step.name
                    )
                })?;
                let plot = fit_plot(&calibration);
                let file = format!("{}-{model_name}-{group}-{residual}.svg", step.name);
                write_atomic(&out.join("plots").join(&file), plot.to_svg().as_bytes())?;
                fits.push(FitEntry {
                    model: model_name.clone(),
                    group: group.clone(),
                    residual: residual.clone(),
                    calibration,
                });
            }
        }
    }
    write_calibrate_report(step, &fits, report);
    Ok(StepResult::Calibrate {
        name: step.name.clone(),
        fits,
    })
}

fn write_calibrate_report(step: &CalibrateStep, fits: &[FitEntry], r: &mut String) {
    let _ = writeln!(r, "## Calibration `{}`\n", step.name);
    let _ = writeln!(r, "Estimator `{}`. R^2 = 1 - SS_res/SS_tot on the fitted data; predictions of the other tests use the fitted parameters.\n", step.estimator);
    let _ = writeln!(r, "| model | fitted to | residual | SSE | R^2 (fit) | identifiable | parameters | Drucker stable (uniaxial / biaxial / planar) |");
    let _ = writeln!(r, "|---|---|---|---|---|---|---|---|");
    for f in fits {
        let c = &f.calibration;
        let params: Vec<String> = c
            .params
            .iter()
            .map(|(n, p)| match p.standard_error {
                Some(se) if c.identifiable => format!("{n} = {:.5e} ± {:.2e}", p.value, se),
                _ => format!("{n} = {:.5e}", p.value),
            })
            .collect();
        let d = &c.drucker;
        let _ = writeln!(
            r,
            "| {} (`{}`) | {} | {} | {:.6e} | {:.5} | {} | {} | [{:.2}, {:.2}] / [{:.2}, {:.2}] / [{:.2}, {:.2}] |",
            f.model,
            c.law,
            f.group,
            f.residual,
            c.sse,
            c.r2,
            if c.identifiable { "yes".to_string() } else { format!("**no** ({})", c.fit.identifiability.involved.join(", ")) },
            params.join("<br>"),
            d.uniaxial.lower,
            d.uniaxial.upper,
            d.biaxial.lower,
            d.biaxial.upper,
            d.planar.lower,
            d.planar.upper
        );
    }
    let names: Vec<String> = {
        let mut v: Vec<String> = fits
            .iter()
            .flat_map(|f| f.calibration.predictions.iter().map(|p| p.data.clone()))
            .collect();
        v.dedup();
        let mut seen = Vec::new();
        v.retain(|x| {
            let new = !seen.contains(x);
            seen.push(x.clone());
            new
        });
        v
    };
    let _ = writeln!(
        r,
        "\nR^2 on each data set (*italic*: predicted, not fitted):\n"
    );
    let _ = writeln!(
        r,
        "| model | fitted to | residual | {} |",
        names.join(" | ")
    );
    let _ = writeln!(r, "|---|---|---|{}", "---|".repeat(names.len()));
    for f in fits {
        let cells: Vec<String> = names
            .iter()
            .map(
                |n| match f.calibration.predictions.iter().find(|p| &p.data == n) {
                    Some(p) if p.fitted => format!("{:.4}", p.r2),
                    Some(p) => format!("*{:.4}*", p.r2),
                    None => "".into(),
                },
            )
            .collect();
        let _ = writeln!(
            r,
            "| {} | {} | {} | {} |",
            f.model,
            f.group,
            f.residual,
            cells.join(" | ")
        );
    }
    let _ = writeln!(
        r,
        "\nPlots: `plots/{}-<model>-<group>-<residual>.svg`.\n",
        step.name
    );
}

fn run_diagnose(
    manifest: &Manifest,
    step: &DiagnoseStep,
    data: &BTreeMap<String, TestData>,
    out: &Path,
    observer: &dyn RunObserver,
    report: &mut String,
) -> anyhow::Result<StepResult> {
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
        observer.message(&format!("{}: diagnosing {name}", step.name));
        let d = &data[name];
        let spec = match named {
            Some(s) => s.clone(),
            None => {
                let law: Law = base_name
                    .parse()
                    .map_err(|e| anyhow::anyhow!("step `{}`: base: {e}", step.name))?;
                gap_base(d.test, law).with_context(|| format!("step `{}`: `{name}`", step.name))?
            }
        };
        let model = build(&spec).map_err(|e| anyhow::anyhow!("step `{}`: {e}", step.name))?;
        let options = palpate_uq::gap::GapOptions {
            effects: match &step.effects {
                Some(list) => Some(
                    parse_effects(list)
                        .with_context(|| format!("step `{}`: effects", step.name))?,
                ),
                None => default_effects(&spec),
            },
            ..Default::default()
        };
        let gap = palpate_uq::gap::diagnose(model.as_ref(), &d.loading, &d.observed, &options)
            .with_context(|| format!("step `{}`: diagnosing `{name}`", step.name))?;
        let best = gap.ranking.first();
        let _ = writeln!(
            report,
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
        let svg = gap_svg(&gap, name);
        write_atomic(
            &out.join("plots").join(format!("{}-{name}.svg", step.name)),
            svg.as_bytes(),
        )?;
        cases.push(DiagnoseEntry {
            data: name.clone(),
            report: serde_json::to_value(&gap)?,
        });
    }
    let _ = writeln!(report, "\nPlots: `plots/{}-<data>.svg` (data, base and enriched fits, residuals with the flagged windows).\n", step.name);
    Ok(StepResult::Diagnose {
        name: step.name.clone(),
        cases,
    })
}
