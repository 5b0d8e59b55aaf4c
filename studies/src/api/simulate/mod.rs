//! Simulate a finite-element forward model (N1 needle indentation, N3 in
//! 3D, C1 compression, Q1 flat-punch ramp-and-hold, docs/benchmarks.md) or
//! a lab's own experiment, and return its force curve with the volumetric
//! treatment used and, when asked, an estimate of its discretisation error
//! from one coarser solve (Richardson extrapolation with the model's
//! documented order of convergence, `super::estimate`). `palpate
//! simulate` and the Python package's `simulate` call [`simulate`], and
//! [`r2::scan`] for the R2 scan.
//!
//! Files: this one (the options, the curve, the entry point and what the
//! others share), `spec.rs` (the model the options describe), `benchmark.rs`
//! (a benchmark's run), `experiment.rs` (an experiment description's run),
//! `r2.rs` (the R2 scan: the pressing phase and the rolled pass).
//!
//! The errors name the command line's options (`--param`, `--depth`, ...),
//! so that the command line and Python say the same.

use anyhow::{anyhow, bail};
use indicatif::{ProgressBar, ProgressStyle};
use palpate_fe::{Bulk, Progress};
use palpate_material::Law;

use super::Observer;
use crate::model::Model;

mod benchmark;
mod experiment;
pub mod r2;
mod spec;

use benchmark::compute;
use experiment::experiment;
pub use spec::model_spec;

/// What to simulate: a benchmark (`benchmark`, with `law` and `params` and
/// the benchmark's options) or an experiment description (`experiment`:
/// a file, a preset's name or JSON text, with `params` only). `None` is the
/// benchmark's default (`palpate simulate --help` gives each); an option of
/// another benchmark is refused by name.
#[derive(Debug, Clone, Default)]
pub struct SimulateOptions {
    /// N1, N3, C1, Q1 (or R2, whose scan is the command line's).
    pub benchmark: Option<String>,
    /// An experiment description instead of a benchmark.
    pub experiment: Option<String>,
    /// The material law (R2: the tissue's).
    pub law: Option<String>,
    /// The law's parameters by name (MPa or 1); an experiment's parameters
    /// replace their starts.
    pub params: Vec<(String, f64)>,
    pub friction: Option<f64>,
    /// R2: rolling depth (mm).
    pub rd: Option<f64>,
    /// R2: the nodules as X:DEPTH,... in mm, or none.
    pub nodules: Option<String>,
    pub nodule_law: Option<String>,
    pub nodule_params: Vec<(String, f64)>,
    /// C1: bonded platens.
    pub bonded: bool,
    /// N1: the bottom face slides radially.
    pub sliding_base: bool,
    /// N1, N3: needle, sphere:R, punch:R or platen.
    pub tool: Option<String>,
    /// quad4, quad9 (N1, Q1); hex8, hex27 (N3).
    pub element: Option<String>,
    /// Q1: radius of the punch's rounded edge (mm).
    pub edge_radius: Option<f64>,
    /// Final tool displacement (mm).
    pub depth: Option<f64>,
    /// Spacing of the output samples (mm).
    pub step: Option<f64>,
    /// coarse, medium, fine or a level.
    pub mesh: Option<String>,
    /// N1, N3: the mesh for this relative error instead of `mesh`.
    pub accuracy: Option<f64>,
    /// exact or a bulk-to-shear ratio.
    pub bulk: Option<String>,
    /// Solve once more on a coarser mesh for the discretisation error.
    pub error_estimate: bool,
    /// The order of convergence of the estimate instead of the model's.
    pub order: Option<f64>,
    /// A Prony series g1=..,tau1=.. (N1, C1, Q1).
    pub prony: Option<String>,
    /// Ramp and hold durations (s).
    pub ramp: Option<f64>,
    pub hold: Option<f64>,
}

impl SimulateOptions {
    /// The benchmark's name (empty for an experiment).
    pub fn benchmark(&self) -> &str {
        self.benchmark.as_deref().unwrap_or("")
    }

    fn is_q1(&self) -> bool {
        self.benchmark().eq_ignore_ascii_case("q1")
    }
}

/// A force curve (N1, N3, C1, Q1, an experiment), as the CSV of `palpate
/// simulate` holds it but at full precision: the columns are the vectors
/// the solver filled.
#[derive(Debug, Clone)]
pub struct Curve {
    /// The model's name.
    pub title: String,
    /// The CSV's comment lines (model, volumetric treatment, error estimate).
    pub comments: Vec<String>,
    /// `time_s` (Q1 and timed histories), else `None`.
    pub time_s: Option<Vec<f64>>,
    pub displacement_mm: Vec<f64>,
    pub force_n: Vec<f64>,
    /// `error_estimate_N` when the error estimate was asked and could be made.
    pub error_estimate_n: Option<Vec<f64>>,
}

/// A simulation: the curve and the solved system (for a `.vtu`; `None` for
/// an experiment model without one).
pub struct Simulated {
    pub curve: Curve,
    pub system: Option<palpate_fe::system::System>,
}

/// The error of a run that stopped before its last sample, with the curve
/// of the samples that converged (its comments say so).
#[derive(Debug)]
pub struct NotConverged {
    pub message: String,
    pub partial: Curve,
}

impl std::fmt::Display for NotConverged {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for NotConverged {}

/// Runs the benchmark or experiment of `options`; lines (FE summary,
/// error estimate) and progress bars go to `observer`. Every option is
/// checked before solving. A run that stops early is a [`NotConverged`]
/// error holding the converged samples. R2 (a scan, not a force curve) is
/// refused with the command to use.
pub fn simulate(options: &SimulateOptions, observer: &dyn Observer) -> anyhow::Result<Simulated> {
    if let Some(e) = &options.experiment {
        if let Some(name) = held_by_experiment(options).next() {
            bail!("{name}: not an option with --experiment {e}; the description holds the specimen, materials, tool, supports, protocol and mesh (edit it, or palpate experiment show NAME for a preset)");
        }
        let (curve, system) = experiment(options, e, observer)?;
        return Ok(Simulated { curve, system });
    }
    let model = model_spec(options)?
        .validate()
        .map_err(|e| anyhow!("{}", e.as_option()))?;
    if let Model::R2(_) = model {
        bail!("--benchmark R2: a scan (position_mm, force_N, force_x_N), not a force curve; run it with palpate simulate --benchmark R2 --csv FILE");
    }
    let (curve, system) = compute(options, model, observer)?;
    Ok(Simulated {
        curve,
        system: Some(system),
    })
}

/// The options given that an experiment description holds itself (its
/// specimen, materials, tool, supports, protocol and mesh).
fn held_by_experiment(o: &SimulateOptions) -> impl Iterator<Item = &'static str> {
    [
        (o.benchmark.is_some(), "--benchmark"),
        (o.law.is_some(), "--law"),
        (o.friction.is_some(), "--friction"),
        (o.rd.is_some(), "--rd"),
        (o.nodules.is_some(), "--nodules"),
        (o.nodule_law.is_some(), "--nodule-law"),
        (!o.nodule_params.is_empty(), "--nodule-param"),
        (o.bonded, "--bonded"),
        (o.sliding_base, "--sliding-base"),
        (o.tool.is_some(), "--tool"),
        (o.element.is_some(), "--element"),
        (o.edge_radius.is_some(), "--edge-radius"),
        (o.depth.is_some(), "--depth"),
        (o.step.is_some(), "--step"),
        (o.mesh.is_some(), "--mesh"),
        (o.bulk.is_some(), "--bulk"),
        (o.prony.is_some(), "--prony"),
        (o.ramp.is_some(), "--ramp"),
        (o.hold.is_some(), "--hold"),
    ]
    .into_iter()
    .filter_map(|(given, name)| given.then_some(name))
}

/// The law's parameter vector from `given` (name, value) pairs: each
/// parameter once, all of them, admissible for the law.
pub fn law_params(law: &Law, given: &[(String, f64)]) -> anyhow::Result<Vec<f64>> {
    let specs = law.params();
    let mut values = vec![None; specs.len()];
    for (name, v) in given {
        let g = format!("{name}={v}");
        let k = specs
            .iter()
            .position(|p| p.name == name.trim())
            .ok_or_else(|| {
                let names: Vec<_> = specs.iter().map(|p| p.name.as_str()).collect();
                anyhow!(
                    "--param `{g}`: {law} has no parameter `{name}` (its parameters: {})",
                    names.join(", ")
                )
            })?;
        if values[k].is_some() {
            bail!(
                "--param `{g}`: {} is given twice; give each parameter once",
                specs[k].name
            );
        }
        values[k] = Some(*v);
    }
    let missing: Vec<_> = specs
        .iter()
        .zip(&values)
        .filter(|(_, v)| v.is_none())
        .map(|(p, _)| format!("{} ({}, e.g. {})", p.name, p.unit, p.initial))
        .collect();
    if !missing.is_empty() {
        bail!("missing --param for {}", missing.join(", "));
    }
    let p: Vec<f64> = values.into_iter().flatten().collect();
    let shown: Vec<String> = given
        .iter()
        .map(|(n, v)| format!("--param {n}={v}"))
        .collect();
    law.check(&p)
        .map_err(|e| anyhow!("{} ({law}): {e}", shown.join(" ")))?;
    crate::run::checks::check_law_values(law, &p, |n, v| format!("--param {n}={v}"))?;
    Ok(p)
}

/// A progress bar of `len` samples (hidden unless `show`) and the callback
/// that moves it.
pub fn progress_bar(len: usize, prefix: &str, show: bool) -> (ProgressBar, impl FnMut(&Progress)) {
    let bar = if show {
        ProgressBar::new(len as u64)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} samples  {msg}  [{elapsed_precise}]")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let b = bar.clone();
    let prefix = prefix.to_string();
    let cb = move |p: &Progress| {
        b.set_position(p.sample as u64 + 1);
        b.set_message(format!(
            "{prefix}d = {:.3} mm  F = {:.5} N  ({} increments, {} iterations)",
            p.drive,
            p.outputs.first().copied().unwrap_or(0.0),
            p.increments,
            p.iterations
        ));
    };
    (bar, cb)
}

/// The volumetric treatment in words.
pub fn volumetric(bulk: Bulk) -> String {
    match bulk {
        Bulk::Exact => "exact incompressibility (Lagrange multiplier per element)".into(),
        Bulk::Ratio(r) => format!("nearly incompressible, K = {r} x mu (mean-dilatation penalty)"),
    }
}

/// A curve as the CSV of `palpate simulate --csv` writes it.
pub fn curve_text(
    comments: &[String],
    time: Option<&[f64]>,
    d: &[f64],
    f: &[f64],
    errors: Option<&[f64]>,
) -> String {
    let mut s = String::new();
    for c in comments {
        s.push_str(&format!("# {c}\n"));
    }
    if time.is_some() {
        s.push_str("time_s,");
    }
    s.push_str("displacement_mm,force_N");
    s.push_str(if errors.is_some() {
        ",error_estimate_N\n"
    } else {
        "\n"
    });
    for (k, (d, f)) in d.iter().zip(f).enumerate() {
        if let Some(t) = time {
            s.push_str(&format!("{:.6},", t[k]));
        }
        s.push_str(&format!("{d:.6},{f:.9e}"));
        if let Some(e) = errors {
            s.push_str(&format!(",{:.9e}", e[k]));
        }
        s.push('\n');
    }
    s
}
