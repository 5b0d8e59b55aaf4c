//! The staged Q1 identification as a study step (`[[steps]] two_stage =
//! {...}` in a manifest, `studies/two-stage-q1.toml`): its fields, their
//! checks and its run, cached as a unit of the run folder. The
//! identification itself is [`crate::apps::two_stage`].

use crate::apps::two_stage::{identify, report, Q1Record, TwoStageOptions};
use crate::run::step::{At, Run, Step, StepResult, Study};
use std::path::PathBuf;
use palpate_core::ForwardModel;
use palpate_material::Law;
use serde::Serialize;

/// A study step (`[[steps]] two_stage = {...}` in a manifest): the staged
/// identification of one Q1 record, cached as a unit of the run folder.
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwoStageStep {
    pub name: String,
    /// The record (`time_s,displacement_mm,force_N`), relative to the manifest.
    pub record: String,
    pub law: String,
    /// `elastic,relaxation` (default).
    #[serde(default)]
    pub stages: Option<String>,
    #[serde(default)]
    pub prony_terms: Option<usize>,
    /// Element size under the punch of the fits' mesh (mm, default 0.3).
    #[serde(default)]
    pub fit_mesh: Option<f64>,
    /// Element size under the punch of the mesh that corrects the fits (mm,
    /// finer than `fit_mesh`; default none: `--correct-mesh`).
    #[serde(default)]
    pub correct_mesh: Option<f64>,
    /// Time step of the viscoelastic runs (s, default 1).
    #[serde(default)]
    pub time_step: Option<f64>,
    /// Radius of the punch's rounded edge (mm, default 0.2).
    #[serde(default)]
    pub edge_radius: Option<f64>,
    /// Radius of the edge of the fit mesh's punch (mm; needs
    /// `correct_mesh`, which keeps `edge_radius`; default `edge_radius`).
    #[serde(default)]
    pub fit_edge_radius: Option<f64>,
    /// Element size under the punch of a mesh the polish is checked on (mm;
    /// default none: `--mesh-check`).
    #[serde(default)]
    pub mesh_check: Option<f64>,
    /// The one-stage comparison (default true).
    #[serde(default)]
    pub compare: Option<bool>,
    /// Profile-likelihood intervals (default true).
    #[serde(default)]
    pub profile: Option<bool>,
    /// The true parameters, in the model's order, when the record is synthetic.
    #[serde(default)]
    pub truth: Option<Vec<f64>>,
}

impl TwoStageStep {
    /// The options; errors name the field.
    pub fn options(&self) -> anyhow::Result<TwoStageOptions> {
        let law: Law = self
            .law
            .parse()
            .map_err(|e| anyhow::anyhow!("law = {:?}: {e}", self.law))?;
        let mut o = TwoStageOptions::new(law);
        if let Some(s) = &self.stages {
            o.stages =
                TwoStageOptions::parse_stages(s).map_err(|e| anyhow::anyhow!("stages: {e}"))?;
        }
        if let Some(n) = self.prony_terms {
            o.set_terms(n)
                .map_err(|e| anyhow::anyhow!("prony_terms = {n}: {e}"))?;
        }
        if let Some(h) = self.fit_mesh {
            o.set_fit_mesh(h)
                .map_err(|e| anyhow::anyhow!("fit_mesh = {h}: {e}"))?;
        }
        if let Some(h) = self.correct_mesh {
            o.set_correct_mesh(h)
                .map_err(|e| anyhow::anyhow!("correct_mesh = {h}: {e}"))?;
        }
        if let Some(dt) = self.time_step {
            o.set_time_step(dt)
                .map_err(|e| anyhow::anyhow!("time_step = {dt}: {e}"))?;
        }
        if let Some(rho) = self.edge_radius {
            o.set_edge_radius(rho)
                .map_err(|e| anyhow::anyhow!("edge_radius = {rho}: {e}"))?;
        }
        if let Some(rho) = self.fit_edge_radius {
            o.set_fit_edge_radius(rho)
                .map_err(|e| anyhow::anyhow!("fit_edge_radius = {rho}: {e}"))?;
        }
        if let Some(h) = self.mesh_check {
            o.set_mesh_check(h)
                .map_err(|e| anyhow::anyhow!("mesh_check = {h}: {e}"))?;
        }
        o.one_stage = self.compare.unwrap_or(true);
        o.profile = self.profile.unwrap_or(true);
        if let Some(t) = &self.truth {
            let n = o.viscoelastic_model().space().len();
            anyhow::ensure!(
                t.len() == n,
                "truth: {} values for the {n} parameters of the model",
                t.len()
            );
        }
        Ok(o)
    }

    /// Checks the step before any run (the manifest's validation).
    pub(crate) fn check(&self, where_: &str, at: &str, dir: &std::path::Path) -> anyhow::Result<()> {
        self.options()
            .map_err(|e| anyhow::anyhow!("{where_}: {at}.{e}"))?;
        let f = dir.join(&self.record);
        anyhow::ensure!(
            f.is_file(),
            "{where_}: {at}.record: no such file {}",
            f.display()
        );
        Ok(())
    }
}

/// A finished step as cached: the result as JSON and its report.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub(crate) struct TwoStageUnit {
    pub result: serde_json::Value,
    pub report: String,
}

/// Runs the step (cached under the record's bytes and the options).
pub(crate) fn run_two_stage(
    run: &Run<'_>,
    step: &TwoStageStep,
    report_md: &mut String,
) -> anyhow::Result<serde_json::Value> {
    use std::fmt::Write;
    let path = run.manifest_dir.join(&step.record);
    let bytes = std::fs::read(&path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let options = step.options()?;
    let inputs = (
        "two_stage",
        format!("{step:?}"),
        bytes,
        crate::run::surrogate::code_version(),
    );
    let label = format!("{}: two-stage identification of {}", step.name, step.record);
    let Some(unit): Option<TwoStageUnit> = run.unit(&label, &inputs, || {
        let mut record = Q1Record::read(&path)?;
        record.name = step.record.clone();
        let say = |s: &str| eprintln!("{s}");
        let result = identify(&record, &options, &say)?;
        Ok(TwoStageUnit {
            report: report(&result, step.truth.as_deref()),
            result: serde_json::to_value(&result)?,
        })
    })?
    else {
        // Another shard's unit: the runner defers the step.
        return Ok(serde_json::json!({
            "name": step.name.clone(),
            "result": serde_json::Value::Null,
        }));
    };
    let _ = writeln!(
        report_md,
        "## {} (two-stage inverse FE, Q1)\n\n{}",
        step.name, unit.report
    );
    Ok(serde_json::json!({
        "name": step.name.clone(),
        "result": unit.result,
    }))
}

impl Step for TwoStageStep {
    fn name(&self) -> &str {
        &self.name
    }

    fn validate(&self, study: &Study, at: &At) -> anyhow::Result<()> {
        let _ = study;
        self.check(&at.file, &at.step(&self.name), at.dir)
    }

    fn inputs(&self) -> Vec<PathBuf> {
        vec![PathBuf::from(&self.record)]
    }

    fn run(
        &self,
        run: &Run,
        done: &[StepResult],
        report: &mut String,
    ) -> anyhow::Result<serde_json::Value> {
        let _ = done;
        run_two_stage(run, self, report)
    }
}
