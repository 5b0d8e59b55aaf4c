//! Simulate a finite-element forward model (N1 needle indentation, N3 in
//! 3D, C1 compression, Q1 flat-punch ramp-and-hold, docs/benchmarks.md) or
//! a lab's own experiment, and return its force curve with the volumetric
//! treatment used and, when asked, an estimate of its discretisation error
//! from one coarser solve (Richardson extrapolation with the model's
//! documented order of convergence, [`super::estimate`]). `palpate
//! simulate` and the Python package's `simulate` call [`simulate`]; the R2
//! scan is the command line's (`cli/simulate_r2.rs`).
//!
//! The errors name the command line's options (`--param`, `--depth`, ...),
//! so that the command line and Python say the same.

use anyhow::{anyhow, bail};
use indicatif::{ProgressBar, ProgressStyle};
use palpate_core::ForwardModel;
use palpate_core::{Drive, Loading};
use palpate_fe::experiment::ExperimentModel;
use palpate_fe::{Bulk, Progress, Simulation};
use palpate_material::Law;

use super::estimate::estimate;
use super::Observer;
use crate::model::{
    C1FeSpec, ExperimentSpec, Model, ModelSpec, N1NeedleSpec, N3NeedleSpec, Q1Spec, R2Spec,
    Q1_STOP_HINT,
};

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

/// The model the options describe: N1 -> `n1_needle`, N3 -> `n3_needle`,
/// C1 -> `c1_fe`, Q1 -> `q1`; an option of another benchmark is refused by name, since it
/// would be neither used nor visible in the result.
pub fn model_spec(o: &SimulateOptions) -> anyhow::Result<ModelSpec> {
    let kind = if o.is_q1() {
        "Q1"
    } else if o.benchmark().eq_ignore_ascii_case("r2") {
        "R2"
    } else if o.benchmark().eq_ignore_ascii_case("n3") {
        "N3"
    } else if o.benchmark().eq_ignore_ascii_case("n1") {
        "N1"
    } else {
        "C1"
    };
    // (option, value shown, the benchmarks that use it)
    let options: [(bool, &str, String, &[&str]); 14] = [
        (
            o.rd.is_some(),
            "--rd",
            o.rd.map(|f| f.to_string()).unwrap_or_default(),
            &["R2"],
        ),
        (
            o.nodules.is_some(),
            "--nodules",
            o.nodules.clone().unwrap_or_default(),
            &["R2"],
        ),
        (
            o.nodule_law.is_some(),
            "--nodule-law",
            o.nodule_law.clone().unwrap_or_default(),
            &["R2"],
        ),
        (
            !o.nodule_params.is_empty(),
            "--nodule-param",
            o.nodule_params
                .iter()
                .map(|(n, v)| format!("{n}={v}"))
                .collect::<Vec<_>>()
                .join(" "),
            &["R2"],
        ),
        (
            o.depth.is_some(),
            "--depth",
            format!("{:?}", o.depth.unwrap_or(0.0)),
            &["N1", "N3", "C1", "Q1"],
        ),
        (o.bonded, "--bonded", String::new(), &["C1"]),
        (
            o.prony.is_some(),
            "--prony",
            o.prony.clone().unwrap_or_default(),
            &["N1", "C1", "Q1"],
        ),
        (
            o.ramp.is_some(),
            "--ramp",
            format!("{:?}", o.ramp.unwrap_or(0.0)),
            &["N1", "C1", "Q1"],
        ),
        (
            o.hold.is_some(),
            "--hold",
            format!("{:?}", o.hold.unwrap_or(0.0)),
            &["N1", "C1", "Q1"],
        ),
        (
            o.friction.is_some(),
            "--friction",
            o.friction.map(|f| f.to_string()).unwrap_or_default(),
            &["N1", "N3", "R2"],
        ),
        (o.sliding_base, "--sliding-base", String::new(), &["N1"]),
        (
            o.tool.is_some(),
            "--tool",
            o.tool.clone().unwrap_or_default(),
            &["N1", "N3"],
        ),
        (
            o.element.is_some(),
            "--element",
            o.element.clone().unwrap_or_default(),
            &["N1", "Q1", "N3"],
        ),
        (
            o.edge_radius.is_some(),
            "--edge-radius",
            format!("{:?}", o.edge_radius.unwrap_or(0.0)),
            &["Q1"],
        ),
    ];
    if let Some((_, name, value, users)) = options
        .iter()
        .find(|(given, _, _, users)| *given && !users.contains(&kind))
    {
        bail!(
            "{name}{}{value}: an option of benchmark {}; --benchmark {kind} does not use it",
            if value.is_empty() { "" } else { " " },
            users.join(" and ")
        );
    }
    if kind == "R2" {
        let rd = o.rd.ok_or_else(|| {
            anyhow!("--benchmark R2 needs --rd RD (the rolling depth in mm, e.g. 6)")
        })?;
        return Ok(ModelSpec::R2(R2Spec {
            law: o.law.clone().unwrap_or_else(|| "arruda-boyce".into()),
            nodule_law: o.nodule_law.clone(),
            rd,
            nodules: o.nodules.clone(),
            friction: o.friction,
            mesh: o.mesh.clone(),
            bulk: o.bulk.clone(),
        }));
    }
    let law = o
        .law
        .clone()
        .ok_or_else(|| anyhow!("--benchmark {kind} needs --law (e.g. --law neo-hookean)"))?;
    Ok(if kind == "Q1" {
        ModelSpec::Q1(Q1Spec {
            law: law.clone(),
            mesh: o.mesh.clone(),
            bulk: o.bulk.clone(),
            element: o.element.clone(),
            prony: o.prony.clone(),
            edge_radius: o.edge_radius,
        })
    } else if kind == "N3" {
        ModelSpec::N3Needle(N3NeedleSpec {
            law: law.clone(),
            friction: o.friction,
            mesh: o.mesh.clone(),
            bulk: o.bulk.clone(),
            tool: o.tool.clone(),
            element: o.element.clone(),
        })
    } else if kind == "N1" {
        ModelSpec::N1Needle(N1NeedleSpec {
            law: law.clone(),
            friction: o.friction,
            mesh: o.mesh.clone(),
            bulk: o.bulk.clone(),
            base: o.sliding_base.then(|| "sliding".into()),
            tool: o.tool.clone(),
            element: o.element.clone(),
            prony: o.prony.clone(),
        })
    } else {
        ModelSpec::C1Fe(C1FeSpec {
            law,
            platens: o.bonded.then(|| "bonded".into()),
            mesh: o.mesh.clone(),
            bulk: o.bulk.clone(),
            prony: o.prony.clone(),
        })
    })
}

/// `--accuracy`: the N1 or N3 model at the level of its mesh family that
/// meets the target (`palpate_fe::accuracy::choose`, cached in the user's
/// cache directory), and the line stating it.
fn choose_mesh(
    o: &SimulateOptions,
    model: &Model,
    target: f64,
    theta: &[f64],
    loading: &Loading,
    observer: &dyn Observer,
) -> anyhow::Result<(Model, String)> {
    use palpate_fe::accuracy::{choose, AccuracyOptions, Refinable};
    if let Some(mesh) = &o.mesh {
        bail!(
            "--accuracy {target} with --mesh {mesh}: --accuracy chooses the mesh; give one of them"
        );
    }
    let mut opts = AccuracyOptions::new(target);
    opts.cache_dir = crate::run::surrogate::mesh_cache_dir();
    let bar = if observer.bars() {
        ProgressBar::new_spinner()
    } else {
        ProgressBar::hidden()
    };
    bar.set_message(format!(
        "choosing the mesh for {} % accuracy",
        100.0 * target
    ));
    let result = match model {
        Model::N1Needle(m) => choose(m, loading, &opts, |m, l| m.predict(theta, l))
            .map(|c| (Model::N1Needle(m.at_level(c.level)), c)),
        Model::N3Needle(m) => choose(m, loading, &opts, |m, l| m.predict(theta, l))
            .map(|c| (Model::N3Needle(m.at_level(c.level)), c)),
        _ => bail!(
            "--accuracy: N1 and N3 choose their mesh for an accuracy; --benchmark {} takes --mesh",
            o.benchmark()
        ),
    };
    bar.finish_and_clear();
    let (m, choice) = result.map_err(|e| anyhow!("--accuracy {target}: {e}"))?;
    let line = choice.line();
    observer.message(&line);
    Ok((m, line))
}

/// The volumetric treatment in words.
pub fn volumetric(bulk: Bulk) -> String {
    match bulk {
        Bulk::Exact => "exact incompressibility (Lagrange multiplier per element)".into(),
        Bulk::Ratio(r) => format!("nearly incompressible, K = {r} x mu (mean-dilatation penalty)"),
    }
}

/// The sample times of a viscoelastic (`--prony`) run or of any Q1 run
/// (ramp-and-hold, docs/benchmarks.md): the drive samples spread over `--ramp`
/// seconds, then `--hold` seconds at `depth` in 200 samples appended to
/// `drive`; `None` for an elastic C1 or N1 run.
fn timed_history(
    o: &SimulateOptions,
    depth: f64,
    drive: &mut Vec<f64>,
) -> anyhow::Result<Option<Vec<f64>>> {
    let q1 = o.is_q1();
    if o.prony.is_none() && !q1 {
        if o.ramp.is_some() || o.hold.is_some() {
            bail!("--ramp and --hold time a viscoelastic run: they need --prony");
        }
        return Ok(None);
    }
    if !(o.benchmark().eq_ignore_ascii_case("c1") || o.benchmark().eq_ignore_ascii_case("n1") || q1)
    {
        bail!("--prony: only N1, C1 and Q1 have the viscoelastic material so far");
    }
    // N1: the needle's 0.4 mm/s (docs/benchmarks.md), C1: 1 s, Q1: 0.5 s
    let ramp = o.ramp.unwrap_or(if q1 {
        0.5
    } else if o.benchmark().eq_ignore_ascii_case("n1") {
        depth / 0.4
    } else {
        1.0
    });
    let hold = o.hold.unwrap_or(if q1 { 60.0 } else { 0.0 });
    if !(ramp > 0.0 && ramp.is_finite()) {
        bail!("--ramp {ramp}: must be a positive duration in s");
    }
    if !(hold >= 0.0 && hold.is_finite()) {
        bail!("--hold {hold}: must be a duration in s, zero or more");
    }
    // one ramp sample lasts ramp x step / depth: a shorter hold is a typo
    let one_step = ramp * (drive.get(1).copied().unwrap_or(depth)) / depth;
    if hold > 0.0 && hold < one_step {
        bail!(
            "--hold {hold}: shorter than one step of the ramp ({one_step} s); give 0 for no hold or at least {one_step} s"
        );
    }
    let mut time: Vec<f64> = drive.iter().map(|d| ramp * d / depth).collect();
    if hold > 0.0 {
        const HOLD_SAMPLES: usize = 200;
        for k in 1..=HOLD_SAMPLES {
            time.push(ramp + hold * k as f64 / HOLD_SAMPLES as f64);
            drive.push(depth);
        }
    }
    Ok(Some(time))
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

/// The FE run of `palpate simulate` for a validated N1, N3, C1 or Q1 model:
/// its curve and the solved system (for `--vtu`).
fn compute(
    o: &SimulateOptions,
    model: Model,
    observer: &dyn Observer,
) -> anyhow::Result<(Curve, palpate_fe::system::System)> {
    let law_text = o.law.clone().unwrap_or_default();
    let law: Law = law_text
        .parse()
        .map_err(|e| anyhow!("--law `{law_text}`: {e}"))?;
    let theta = law_params(&law, &o.params)?;
    // needle benchmarks (N1, N3): 10 mm every 0.25 mm
    let n1 = o.benchmark().eq_ignore_ascii_case("n1") || o.benchmark().eq_ignore_ascii_case("n3");
    let q1 = o.is_q1();
    let depth = o.depth.unwrap_or(if n1 {
        10.0
    } else if q1 {
        5.0
    } else {
        2.0
    });
    // Q1: at least 100 samples in the ramp (docs/benchmarks.md)
    let step = o.step.unwrap_or(if n1 {
        0.25
    } else if q1 {
        depth / 100.0
    } else {
        0.1
    });
    if !(depth > 0.0 && depth.is_finite() && step > 0.0 && step.is_finite()) {
        bail!("--depth and --step must be positive (got {depth} and {step})");
    }
    if let Some(p) = o.order {
        if !(p > 0.0 && p.is_finite()) {
            bail!("--order {p}: must be a positive order of convergence");
        }
    }
    // Each sample keeps its drive, time, force and estimate, and a solve.
    let n = crate::run::limits::check_count(
        &format!(
            "--depth {} / --step {}",
            crate::run::limits::fmt_value(depth),
            crate::run::limits::fmt_value(step)
        ),
        (depth / step).ceil() + 1.0,
        "samples",
        256.0,
    )? - 1;
    crate::run::checks::check_travel("--depth", depth, &model)?;
    crate::run::checks::check_tool(
        &format!("--tool {}", o.tool.as_deref().unwrap_or("needle")),
        &model,
    )?;
    let mut drive: Vec<f64> = (0..=n).map(|k| (k as f64 * step).min(depth)).collect();
    let time = timed_history(o, depth, &mut drive)?;
    if let Some(end) = time.as_ref().and_then(|t| t.last()) {
        crate::run::checks::check_increments(&model, *end)?;
    }
    let loading = match &time {
        Some(t) => Loading::timed(Drive::DisplacementMm, t.clone(), drive.clone()),
        None => Loading::quasi_static(Drive::DisplacementMm, drive.clone()),
    };

    let chosen = match o.accuracy {
        Some(target) => Some(choose_mesh(o, &model, target, &theta, &loading, observer)?),
        None => None,
    };
    let (model, chosen_line) = match chosen {
        Some((m, line)) => (m, Some(line)),
        None => (model, None),
    };

    let (bar, mut cb) = progress_bar(drive.len(), "", observer.bars());
    let (title, bulk, result) = match &model {
        Model::N1Needle(m) => (
            m.name(),
            m.bulk,
            m.simulate(&theta, &loading, Some(&mut cb)),
        ),
        Model::N3Needle(m) => (
            m.name(),
            m.bulk,
            m.simulate(&theta, &loading, Some(&mut cb)),
        ),
        Model::C1Fe(m) => (
            m.name(),
            m.bulk,
            m.simulate(&theta, &loading, Some(&mut cb)),
        ),
        Model::Q1(m) => (
            m.name(),
            m.bulk,
            m.simulate(&theta, &loading, Some(&mut cb)),
        ),
        _ => bail!("--benchmark {}: expected N1, N3, C1 or Q1", o.benchmark()),
    };
    drop(cb);
    bar.finish_and_clear();
    let mut comments = vec![
        format!("palpate simulate: {title}"),
        format!("volumetric: {}", volumetric(bulk)),
    ];
    comments.extend(chosen_line);
    let (sim, solver): (Simulation, _) = match result {
        Ok(r) => r,
        Err(palpate_core::ForwardError::NotConverged {
            sample,
            drive: d,
            cuts,
            reason,
            completed,
        }) => {
            comments.push(format!(
                "did not converge at sample {sample} (drive {d} mm): partial curve, no error estimate"
            ));
            let hint = if o.is_q1() && d > 0.0 {
                format!("\nhint: {Q1_STOP_HINT}")
            } else {
                String::new()
            };
            let k = completed.len();
            return Err(NotConverged {
                message: format!("{title}: did not converge at sample {sample} (drive {d} mm) after {cuts} step cuts: {reason}{hint}"),
                partial: Curve {
                    title: title.to_string(),
                    comments,
                    time_s: time.as_ref().map(|t| t[..k].to_vec()),
                    displacement_mm: drive[..k].to_vec(),
                    force_n: completed,
                    error_estimate_n: None,
                },
            }
            .into());
        }
        Err(e) => bail!("{title}: {e}"),
    };
    observer.message(&format!(
        "{title}: {} elements, {} unknowns, {} increments, {} Newton iterations ({} factorisations), F({depth} mm) = {:.6} N",
        solver.mesh.cell_count(),
        solver.equations(),
        sim.stats.increments,
        sim.stats.iterations,
        sim.stats.factorisations,
        sim.forces.last().copied().unwrap_or(0.0)
    ));
    if sim.stats.loose > 0 {
        observer.message(&format!(
            "warning: {} increments were accepted at the looser stagnation tolerance (SolverOptions::stagnation_tolerance), not the full one",
            sim.stats.loose
        ));
    }
    observer.message(&format!("volumetric: {}", volumetric(bulk)));
    let errors = if o.error_estimate {
        let est = estimate(
            &model,
            &theta,
            &loading,
            o.order,
            &sim.forces,
            observer.bars(),
        )?;
        observer.message(&est.line);
        comments.push(est.line);
        if est.errors.is_some() {
            comments.push(
                "error_estimate_N: force_N minus the estimated converged force, per sample".into(),
            );
        }
        est.errors
    } else {
        comments.push("discretisation error: not estimated (--error-estimate off)".into());
        None
    };
    Ok((
        Curve {
            title: title.to_string(),
            comments,
            time_s: time,
            displacement_mm: drive,
            force_n: sim.forces,
            error_estimate_n: errors,
        },
        solver,
    ))
}

/// The parameter values of a run: the description's starts (and fixed
/// values), each given (name, value) replacing one by name.
fn theta(model: &dyn ForwardModel, given: &[(String, f64)]) -> anyhow::Result<Vec<f64>> {
    let space = model.space();
    let mut theta: Vec<f64> = space.params.iter().map(|s| s.initial).collect();
    let names = space.names();
    for (n, v) in given {
        let (n, v) = (n.as_str(), *v);
        let g = format!("{n}={v}");
        let k = names.iter().position(|m| m == n).ok_or_else(|| {
            anyhow!(
                "--param {g}: the experiment has no parameter `{n}`; its parameters: {}",
                names.join(", ")
            )
        })?;
        if !v.is_finite() {
            bail!("--param {g}: `{v}` is not a finite number");
        }
        let s = &space.params[k];
        if !(v >= s.lower && v <= s.upper) {
            bail!(
                "--param {g}: outside {n}'s bounds [{}, {}]",
                s.lower,
                s.upper
            );
        }
        theta[k] = v;
    }
    Ok(theta)
}

/// The curve of an experiment description `arg` (and its solved system
/// when the model has one to write as a `.vtu`).
fn experiment(
    o: &SimulateOptions,
    arg: &str,
    observer: &dyn Observer,
) -> anyhow::Result<(Curve, Option<palpate_fe::system::System>)> {
    let spec = ExperimentSpec::from_option(arg)?;
    let source = spec.source.to_string();

    let Model::Experiment(built) = ModelSpec::Experiment(spec)
        .validate()
        .map_err(|e| anyhow!("--experiment {source}: {}", e.expected))?
    else {
        bail!("--experiment {source}: not an experiment model");
    };
    if let Some(p) = o.order {
        if !(p > 0.0 && p.is_finite()) {
            bail!("--order {p}: must be a positive order of convergence");
        }
    }
    let loading: Loading = built.model.loading().ok_or_else(|| {
        anyhow!(
            "--experiment {source}: its protocol is a record's; give the record with --data, or protocol.segments (e.g. [{{ ramp_to = 2.0 }}])"
        )
    })?;
    let model = built.model;
    let theta = theta(model.as_forward(), &o.params)?;
    let title = model.as_forward().name();
    let mut comments = vec![
        format!("palpate simulate: {title}"),
        format!("experiment: {source}"),
    ];
    let (bar, mut cb) = progress_bar(loading.len(), "", observer.bars());
    #[allow(unreachable_patterns)]
    let (forces, solver, as_model) = match &model {
        ExperimentModel::Cylinder(m) => {
            let (sim, solver) = m
                .simulate(&theta, &loading, Some(&mut cb))
                .map_err(|e| anyhow!("{title}: {e}"))?;
            comments.push(format!(
                "mesh: level {}, {:?} elements ({} cells, {} unknowns)",
                m.sizing.map_or(m.mesh.level as f64, |s| s.level),
                m.element,
                solver.mesh.cell_count(),
                solver.equations()
            ));
            comments.push(format!("volumetric: {}", volumetric(m.bulk)));
            (
                sim.forces,
                Some(solver),
                Some(Model::N1Needle(m.model().clone())),
            )
        }
        other => {
            let f = other
                .as_forward()
                .predict(&theta, &loading)
                .map_err(|e| anyhow!("{title}: {e}"))?;
            (f, None, None)
        }
    };
    drop(cb);
    bar.finish_and_clear();
    for c in &comments[2..] {
        observer.message(c);
    }
    let errors = match (&as_model, o.error_estimate) {
        (_, false) => {
            comments.push("discretisation error: not estimated (--error-estimate off)".into());
            None
        }
        (Some(m), true) => {
            let est = estimate(m, &theta, &loading, o.order, &forces, observer.bars())?;
            observer.message(&est.line);
            comments.push(est.line);
            if est.errors.is_some() {
                comments.push(
                    "error_estimate_N: force_N minus the estimated converged force, per sample"
                        .into(),
                );
            }
            est.errors
        }
        (None, true) => {
            comments.push("discretisation error: no estimate for this model".into());
            None
        }
    };
    Ok((
        Curve {
            title,
            comments,
            time_s: loading.time.clone(),
            displacement_mm: loading.drive.clone(),
            force_n: forces,
            error_estimate_n: errors,
        },
        solver,
    ))
}
