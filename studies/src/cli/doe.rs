//! `palpate doe`: generate a factorial design from a TOML manifest and, when
//! the manifest names a response palpate can compute, run it and analyse it.
//!
//! Manifest (serde, unknown fields rejected; paths relative to the manifest):
//!
//! ```toml
//! [design]
//! seed = 2024             # run order randomised from this seed (omit: standard order)
//! replicates = 1
//! generators = []         # two-level fractions, e.g. ["D=ABC"]
//!
//! [[factors]]
//! name = "law"
//! levels = ["neo-hookean", "mooney-rivlin", "yeoh", "arruda-boyce"]
//!
//! [[factors]]
//! name = "residual"
//! levels = ["absolute", "relative"]
//!
//! [response.calibration]  # optional: each run is an analytic calibration
//! metric = "r2"           # r2 or rms of the fit
//! data = { uniaxial = "../data/treloar/uniaxial.csv" }
//!
//! [analysis]              # optional
//! max_order = 1
//! alpha = 0.05
//! ```
//!
//! Calibration factors: `law` (a law name), `residual` (absolute, relative,
//! normalised), `data` (a data-set name of `response.calibration.data`, or
//! several joined by `+`), `estimator` (lm, bfgs, lbfgs). Factors of the FE
//! benchmarks (`friction`, `space`, `mesh`) are not supported yet.
//!
//! With `--experiment FILE`, a `[response.simulation]` runs that lab's own
//! experiment (docs/guide/experiment.md) instead of N1: its factors are
//! parameters of the description (numeric levels, e.g. `name = "C10"`,
//! `levels = ["2e-3", "5e-3"]`), the other parameters at the description's
//! starts; `benchmark`, `law`, `friction`, `mesh` and `params` are refused
//! (the description holds the model).

use super::anova::{format_analysis, write_outputs};
use crate::model::calibration::{calibrate, parse_method, Request};
use crate::records::{TestData, TestKind};
use crate::run::output::write_atomic;
use anyhow::Context;
use palpate_inverse::ResidualKind;
use palpate_material::Law;
use palpate_uq::anova::{analyse, AnovaOptions, FactorColumn};
use palpate_uq::doe::{Design, Factor};
use rayon::prelude::*;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Generate and run a designed experiment (factorial design) from a TOML manifest
///
/// Writes design.csv (run order, standard order, replicate, levels and the
/// response), design.json (with defining relation, resolution and aliases)
/// and, when the response is computed, anova.json and plots/ into --out.
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment, allow_negative_numbers = true)]
pub struct Args {
    /// The design manifest (TOML).
    #[arg(long)]
    pub manifest: PathBuf,
    /// Output directory (default: print only).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// A lab's own experiment (an experiment file, a preset's name or the
    /// description as JSON) that each run of `[response.simulation]`
    /// simulates; the factors are its parameters.
    #[arg(long, value_name = "FILE|PRESET")]
    pub experiment: Option<String>,
}

/// A design manifest.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    #[serde(default)]
    design: DesignSpec,
    factors: Vec<Factor>,
    response: Option<ResponseSpec>,
    #[serde(default)]
    analysis: AnalysisSpec,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DesignSpec {
    seed: Option<u64>,
    #[serde(default = "one")]
    replicates: usize,
    #[serde(default)]
    generators: Vec<String>,
}

fn one() -> usize {
    1
}

/// A manifest without `[design]`: one replicate in standard order (a derived
/// Default would give 0 replicates, rejected by the design).
impl Default for DesignSpec {
    fn default() -> Self {
        DesignSpec {
            seed: None,
            replicates: one(),
            generators: Vec::new(),
        }
    }
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct AnalysisSpec {
    max_order: Option<usize>,
    alpha: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
enum ResponseSpec {
    Calibration(CalibrationResponse),
    Simulation(SimulationResponse),
}

/// A finite-element response: each run simulates benchmark N1 (needle
/// indentation) with the run's law, friction and mesh, and is scored against
/// a reference curve (columns displacement_mm, force_N) by R^2 or RMS.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SimulationResponse {
    /// `N1` (the needle-indentation benchmark); not with `--experiment`.
    benchmark: Option<String>,
    /// `r2` or `rms` (N) of the simulated force against the reference.
    metric: String,
    /// The reference curve (relative to the manifest).
    reference: String,
    /// Material parameters of each law level, by law spelling, e.g.
    /// `{ "neo-hookean" = { C10 = 1.101295e-3 } }` (MPa). Defaults: the
    /// ecoflex-nh and ecoflex-rp2 materials of docs/benchmarks.md.
    #[serde(default)]
    params: BTreeMap<String, BTreeMap<String, f64>>,
    /// Score only the reference samples up to this depth (mm); default: the
    /// whole reference curve.
    max_depth_mm: Option<f64>,
    /// Defaults for settings that are not factors (absent: neo-hookean and
    /// the N1 model's defaults, friction 0.8 and the medium mesh).
    law: Option<String>,
    friction: Option<f64>,
    #[serde(default, deserialize_with = "crate::model::text_or_number")]
    mesh: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CalibrationResponse {
    /// `r2` or `rms`.
    metric: String,
    /// Data-set name -> homogeneous-test file (columns stretch, stress_MPa);
    /// the name is also the test mode unless it is given as `NAME:MODE`.
    data: BTreeMap<String, String>,
    /// Defaults for settings that are not factors.
    law: Option<String>,
    residual: Option<String>,
    estimator: Option<String>,
}

const FE_FACTORS: [&str; 4] = ["friction", "space", "mesh", "benchmark"];

/// The docs/benchmarks.md material of a law for the N1 design (MPa).
fn default_params(law: &Law) -> Option<Vec<(String, f64)>> {
    match law.to_string().as_str() {
        "neo-hookean" => Some(vec![("C10".into(), 1.101295e-3)]),
        "reduced-polynomial:2" => Some(vec![
            ("C10".into(), 0.686428e-3),
            ("C20".into(), 1.929606e-3),
        ]),
        _ => None,
    }
}

/// Reads a design manifest's text (named `path` in errors) and builds its
/// design, checking its size, analysis options and generators before any
/// allocation; the response is checked later, against its files. The
/// design-manifest reader of `palpate doe`, also fuzzed (fuzz/).
pub fn read_design(path: &Path, text: &str) -> anyhow::Result<(Manifest, Design)> {
    let m = path.display();
    let manifest: Manifest = toml::from_str(text).map_err(|e| anyhow::anyhow!("{m}: {e}"))?;
    let gens: Vec<&str> = manifest
        .design
        .generators
        .iter()
        .map(String::as_str)
        .collect();
    let levels: Vec<usize> = manifest.factors.iter().map(|f| f.levels.len()).collect();
    crate::run::limits::check_runs(
        &format!(
            "{m}: [[factors]] and design.replicates = {}",
            manifest.design.replicates
        ),
        &levels,
        gens.len(),
        manifest.design.replicates,
    )?;
    let mut design = if gens.is_empty() {
        Design::full_factorial(manifest.factors.clone(), manifest.design.replicates)
    } else {
        Design::fractional(manifest.factors.clone(), &gens, manifest.design.replicates)
    }
    .map_err(|e| anyhow::anyhow!("{m}: {e}"))?;
    crate::run::limits::check_anova(
        &format!("{m}: analysis.max_order ="),
        manifest.analysis.max_order,
        design.factors.len(),
        design.runs.len(),
    )?;
    if let Some(a) = manifest.analysis.alpha {
        crate::run::checks::check_alpha(&format!("{m}: analysis.alpha ="), a)?;
    }
    if let Some(seed) = manifest.design.seed {
        design = design.randomised(seed);
    }
    Ok((manifest, design))
}

/// Runs `palpate doe`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(&args.manifest)
        .with_context(|| format!("cannot read {}", args.manifest.display()))?;
    let (manifest, design) = read_design(&args.manifest, &text)?;
    let base_dir = args
        .manifest
        .parent()
        .unwrap_or(Path::new("."))
        .to_path_buf();
    let m = args.manifest.display();
    let experiment = args
        .experiment
        .as_deref()
        .map(crate::model::ExperimentSpec::from_option)
        .transpose()?;
    if experiment.is_some() && !matches!(manifest.response, Some(ResponseSpec::Simulation(_))) {
        anyhow::bail!(
            "--experiment: {m} has no [response.simulation] to run it (each run simulates the experiment)"
        );
    }
    if let Some(out) = &args.out {
        check_out(out, &args.manifest, &manifest, &base_dir)?;
    }
    // Every input of the response (its fields, its data, each run's model)
    // is checked before anything is written or run; errors name the manifest.
    let plan = match &manifest.response {
        Some(ResponseSpec::Calibration(c)) => {
            Some(prepare_calibrations(&design, c, &base_dir).map(Plan::Calibration))
        }
        Some(ResponseSpec::Simulation(s)) => Some(
            match experiment {
                Some(e) => prepare_experiment(&design, s, &base_dir, e),
                None => prepare_simulations(&design, s, &base_dir),
            }
            .map(Plan::Simulation),
        ),
        None => None,
    }
    .transpose()
    .map_err(|e| anyhow::anyhow!("{m}: {e:#}"))?;
    println!("{}", describe(&design));
    if let Some(out) = &args.out {
        // The design alone first, so it is there even if a run fails.
        write_atomic(
            &out.join("design.csv"),
            design_csv(&design, "", None).as_bytes(),
        )?;
    }
    let response = match (&manifest.response, plan) {
        (Some(ResponseSpec::Calibration(c)), Some(Plan::Calibration(sets))) => {
            Some(run_calibrations(&design, c, &sets))
        }
        (Some(ResponseSpec::Simulation(s)), Some(Plan::Simulation(plan))) => {
            Some(run_simulations(&design, s, plan))
        }
        _ => None,
    }
    .transpose()
    .map_err(|e| anyhow::anyhow!("{m}: {e:#}"))?;
    let metric = match &manifest.response {
        Some(ResponseSpec::Calibration(c)) => c.metric.clone(),
        Some(ResponseSpec::Simulation(s)) => s.metric.clone(),
        None => "response".into(),
    };
    if let Some(out) = &args.out {
        write_atomic(
            &out.join("design.csv"),
            design_csv(&design, &metric, response.as_deref()).as_bytes(),
        )?;
        crate::run::output::write_json(&out.join("design.json"), &design_record(&design))?;
        println!("wrote {}", out.join("design.csv").display());
    }
    if let Some(y) = response {
        let factors: Vec<FactorColumn> = (0..design.factors.len())
            .map(|f| FactorColumn {
                name: design.factors[f].name.clone(),
                levels: design.factors[f].levels.clone(),
                codes: design.runs.iter().map(|r| r.levels[f]).collect(),
            })
            .collect();
        let options = AnovaOptions {
            max_order: manifest.analysis.max_order,
            alpha: manifest.analysis.alpha.unwrap_or(0.05),
            ..Default::default()
        };
        let analysis = analyse(&metric, &factors, &y, &options)?;
        print!("{}", format_analysis(&analysis));
        if let Some(out) = &args.out {
            write_outputs(
                &analysis,
                Some(&out.join("anova.json")),
                Some(&out.join("plots")),
            )?;
        }
    }
    Ok(())
}

/// Checks `--out` and the files written into it before any run: none is
/// the manifest or a data file it names, and the folder can be written.
fn check_out(out: &Path, path: &Path, manifest: &Manifest, base: &Path) -> anyhow::Result<()> {
    let mut inputs: Vec<PathBuf> = vec![path.to_path_buf()];
    match &manifest.response {
        Some(ResponseSpec::Calibration(c)) => {
            inputs.extend(c.data.values().map(|f| base.join(f)));
        }
        Some(ResponseSpec::Simulation(s)) => inputs.push(base.join(&s.reference)),
        None => {}
    }
    let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
    let files: Vec<(String, PathBuf)> = ["design.csv", "design.json", "anova.json"]
        .iter()
        .map(|f| (format!("--out (its {f})"), out.join(f)))
        .collect();
    let plots = out.join("plots");
    crate::run::output::check_outputs_and_dirs(
        &inputs,
        &files
            .iter()
            .map(|(o, p)| (o.as_str(), p.as_path()))
            .collect::<Vec<_>>(),
        &[("--out", out), ("--out (its plots/)", &plots)],
    )
}

fn describe(d: &Design) -> String {
    let mut s = String::new();
    let levels: Vec<String> = d
        .factors
        .iter()
        .map(|f| format!("{} ({})", f.name, f.levels.join("/")))
        .collect();
    let _ = writeln!(s, "Design: {} runs; factors {}", d.len(), levels.join(", "));
    if !d.generators.is_empty() {
        let g: Vec<String> = d.generators.iter().map(|g| g.to_string()).collect();
        let w: Vec<String> = d
            .defining_relation()
            .iter()
            .map(|w| w.to_string())
            .collect();
        let _ = writeln!(
            s,
            "Generators {}; I = {}; resolution {}",
            g.join(", "),
            w.join(" = "),
            d.resolution().unwrap_or(0)
        );
        for c in d.alias_chains(2) {
            let _ = writeln!(s, "  {c}");
        }
    }
    s
}

#[derive(serde::Serialize)]
struct DesignRecord<'a> {
    design: &'a Design,
    defining_relation: Vec<String>,
    resolution: Option<usize>,
    alias_chains: Vec<String>,
}

fn design_record(d: &Design) -> DesignRecord<'_> {
    DesignRecord {
        design: d,
        defining_relation: d
            .defining_relation()
            .iter()
            .map(|w| w.to_string())
            .collect(),
        resolution: d.resolution(),
        alias_chains: d
            .alias_chains(d.factors.len())
            .iter()
            .map(|c| c.to_string())
            .collect(),
    }
}

fn design_csv(d: &Design, metric: &str, y: Option<&[f64]>) -> String {
    let mut s = String::from("run_order,standard_order,replicate");
    for f in &d.factors {
        let _ = write!(s, ",{}", f.name);
    }
    if y.is_some() {
        let _ = write!(s, ",{metric}");
    }
    s.push('\n');
    for (i, r) in d.runs.iter().enumerate() {
        let _ = write!(s, "{},{},{}", r.run_order, r.standard_order, r.replicate);
        for f in 0..d.factors.len() {
            let _ = write!(s, ",{}", d.level_name(r, f));
        }
        if let Some(y) = y {
            let _ = write!(s, ",{}", y[i]);
        }
        s.push('\n');
    }
    s
}

/// What a response needs, checked and read before any run.
enum Plan {
    Calibration(BTreeMap<String, TestData>),
    Simulation(SimulationPlan),
}

/// Checks a calibration response (factors, metric) and reads its data sets.
fn prepare_calibrations(
    d: &Design,
    spec: &CalibrationResponse,
    base: &Path,
) -> anyhow::Result<BTreeMap<String, TestData>> {
    for f in &d.factors {
        if FE_FACTORS.contains(&f.name.as_str()) {
            anyhow::bail!("factor `{}` needs a finite-element response: use [response.simulation] (benchmark N1)", f.name);
        }
        if !["law", "residual", "data", "estimator"].contains(&f.name.as_str()) {
            anyhow::bail!("factor `{}` has no meaning for a calibration response; known factors: law, residual, data, estimator", f.name);
        }
    }
    if !["r2", "rms"].contains(&spec.metric.as_str()) {
        anyhow::bail!(
            "response.calibration.metric = `{}`; expected r2 or rms",
            spec.metric
        );
    }
    let mut sets = BTreeMap::new();
    for (name, file) in &spec.data {
        let (set, mode) = name.split_once(':').unwrap_or((name, name));
        let test =
            TestKind::parse(mode).with_context(|| format!("response.calibration.data `{name}`"))?;
        sets.insert(
            set.to_string(),
            TestData::read(set, test, &base.join(file))?,
        );
    }
    Ok(sets)
}

/// One calibration per run, in parallel (each run is independent; results
/// do not depend on the thread count). Returns the metric per run.
fn run_calibrations(
    d: &Design,
    spec: &CalibrationResponse,
    sets: &BTreeMap<String, TestData>,
) -> anyhow::Result<Vec<f64>> {
    let setting = |run: &palpate_uq::doe::Run, factor: &str| -> Option<String> {
        d.factors
            .iter()
            .position(|f| f.name == factor)
            .map(|k| d.level_name(run, k).to_string())
    };
    d.runs
        .par_iter()
        .map(|run| {
            let law_text = setting(run, "law")
                .or_else(|| spec.law.clone())
                .unwrap_or_else(|| "neo-hookean".into());
            let law: Law = law_text
                .parse()
                .map_err(|e| anyhow::anyhow!("law `{law_text}`: {e}"))?;
            let residual_text = setting(run, "residual")
                .or_else(|| spec.residual.clone())
                .unwrap_or_else(|| "absolute".into());
            let residual: ResidualKind = residual_text
                .parse()
                .map_err(|e| anyhow::anyhow!("residual `{residual_text}`: {e}"))?;
            let method = parse_method(
                &setting(run, "estimator")
                    .or_else(|| spec.estimator.clone())
                    .unwrap_or_else(|| "lm".into()),
            )?;
            let fitted: Vec<TestData> = match setting(run, "data") {
                Some(names) => names
                    .split('+')
                    .map(|n| {
                        sets.get(n.trim()).cloned().ok_or_else(|| {
                            anyhow::anyhow!("data set `{n}` is not in response.calibration.data")
                        })
                    })
                    .collect::<anyhow::Result<_>>()?,
                None => sets.values().cloned().collect(),
            };
            let c = calibrate(Request {
                law,
                model: None,
                fitted: &fitted,
                predict: &[],
                residual,
                method,
                fixed: Vec::new(),
                observer: None,
                viscous: None,
            })
            .with_context(|| {
                format!(
                    "run {} (standard order {})",
                    run.run_order, run.standard_order
                )
            })?;
            Ok(if spec.metric == "r2" { c.r2 } else { c.rms })
        })
        .collect()
}

/// Every run's N1 model with its parameters, the reference loading and the
/// reference forces it is scored against.
struct SimulationPlan {
    models: Vec<(Arc<dyn palpate_core::ForwardModel>, Vec<f64>)>,
    loading: palpate_core::Loading,
    y: Vec<f64>,
}

/// Checks an N1 simulation response, reads its reference and builds (and
/// checks) every run's model.
fn prepare_simulations(
    d: &Design,
    spec: &SimulationResponse,
    base: &Path,
) -> anyhow::Result<SimulationPlan> {
    use crate::model::{ModelSpec, N1NeedleSpec};
    use palpate_core::ForwardModel;
    match spec.benchmark.as_deref() {
        Some(b) if b.eq_ignore_ascii_case("n1") => {}
        Some(b) => anyhow::bail!(
            "response.simulation.benchmark = `{b}`: only N1 is supported (or run a lab's own experiment with --experiment FILE)"
        ),
        None => anyhow::bail!(
            "response.simulation.benchmark: give N1, or run a lab's own experiment with --experiment FILE"
        ),
    }
    for f in &d.factors {
        if !["law", "friction", "mesh"].contains(&f.name.as_str()) {
            anyhow::bail!("factor `{}` has no meaning for an N1 simulation; known factors: law, friction, mesh", f.name);
        }
    }
    let (loading, y) = reference_curve(spec, base)?;
    let setting = |run: &palpate_uq::doe::Run, factor: &str| -> Option<String> {
        d.factors
            .iter()
            .position(|f| f.name == factor)
            .map(|k| d.level_name(run, k).to_string())
    };
    // Every run's model is built and checked before anything runs.
    let models: Vec<(Arc<dyn ForwardModel>, Vec<f64>)> = d
        .runs
        .iter()
        .map(|run| {
            let at = || {
                format!(
                    "run {} (standard order {})",
                    run.run_order, run.standard_order
                )
            };
            let law_text = setting(run, "law")
                .or_else(|| spec.law.clone())
                .unwrap_or_else(|| "neo-hookean".into());
            let friction = match setting(run, "friction") {
                Some(t) => Some(t.parse::<f64>().map_err(|_| {
                    anyhow::anyhow!("{}: friction level `{t}` is not a number", at())
                })?),
                None => spec.friction,
            };
            let model_spec = ModelSpec::N1Needle(N1NeedleSpec {
                law: law_text.clone(),
                friction,
                mesh: crate::model::parse_setting(
                    "n1_needle",
                    setting(run, "mesh")
                        .or_else(|| spec.mesh.clone())
                        .as_deref(),
                )
                .map_err(|e| anyhow::anyhow!("{}: {e}", at()))?,
                ..Default::default()
            });
            let checked = model_spec
                .validate()
                .map_err(|e| anyhow::anyhow!("{}: {e}", at()))?;
            let law = model_spec
                .law()
                .map_err(|e| anyhow::anyhow!("{}: {e}", at()))?;
            let model: Arc<dyn ForwardModel> = Arc::from(checked.into_forward());
            let theta: Vec<f64> = match spec.params.get(&law_text) {
                Some(p) => model
                    .space()
                    .names()
                    .iter()
                    .map(|n| {
                        p.get(n).copied().ok_or_else(|| {
                            anyhow::anyhow!(
                                "response.simulation.params.\"{law_text}\": parameter `{n}` missing"
                            )
                        })
                    })
                    .collect::<anyhow::Result<_>>()?,
                None => {
                    let p = default_params(&law).ok_or_else(|| {
                        anyhow::anyhow!(
                            "law `{law_text}`: give its parameters in response.simulation.params"
                        )
                    })?;
                    p.into_iter().map(|(_, v)| v).collect()
                }
            };
            Ok((model, theta))
        })
        .collect::<anyhow::Result<_>>()?;
    Ok(SimulationPlan { models, loading, y })
}

/// The metric checked and the reference curve of a simulation response
/// (up to `max_depth_mm`): the loading of its displacements and its forces.
fn reference_curve(
    spec: &SimulationResponse,
    base: &Path,
) -> anyhow::Result<(palpate_core::Loading, Vec<f64>)> {
    use palpate_core::{data::Table, Drive, Loading};
    if !["r2", "rms"].contains(&spec.metric.as_str()) {
        anyhow::bail!(
            "response.simulation.metric = `{}`; expected r2 or rms",
            spec.metric
        );
    }
    let reference = Table::read(base.join(&spec.reference))?;
    let depth = spec.max_depth_mm.unwrap_or(f64::INFINITY);
    if depth.is_nan() || depth <= 0.0 {
        anyhow::bail!("response.simulation.max_depth_mm = {depth}: must be positive");
    }
    let keep: Vec<usize> = (0..reference.len())
        .filter(|&i| {
            reference
                .column("displacement_mm")
                .map(|x| x[i] <= depth)
                .unwrap_or(false)
        })
        .collect();
    let x: Vec<f64> = keep
        .iter()
        .map(|&i| reference.column("displacement_mm").map(|c| c[i]))
        .collect::<Result<_, _>>()?;
    let y: Vec<f64> = keep
        .iter()
        .map(|&i| reference.column("force_N").map(|c| c[i]))
        .collect::<Result<_, _>>()?;
    if x.len() < 3 {
        anyhow::bail!("response.simulation: fewer than 3 reference samples up to {depth} mm");
    }
    Ok((Loading::quasi_static(Drive::DisplacementMm, x), y))
}

/// Checks a simulation response of `--experiment`, reads its reference and
/// builds the experiment's model (meshed for the reference's deepest
/// displacement when its protocol is the record's) and every run's
/// parameters: the factors' levels, the others at the description's starts.
fn prepare_experiment(
    d: &Design,
    spec: &SimulationResponse,
    base: &Path,
    mut experiment: crate::model::ExperimentSpec,
) -> anyhow::Result<SimulationPlan> {
    use crate::model::ModelSpec;
    let given: [(bool, &str); 5] = [
        (spec.benchmark.is_some(), "benchmark"),
        (spec.law.is_some(), "law"),
        (spec.friction.is_some(), "friction"),
        (spec.mesh.is_some(), "mesh"),
        (!spec.params.is_empty(), "params"),
    ];
    if let Some((_, field)) = given.iter().find(|g| g.0) {
        anyhow::bail!(
            "response.simulation.{field}: not with --experiment: the description holds the model (its laws, tool friction, [mesh] and parameter starts)"
        );
    }
    let (loading, y) = reference_curve(spec, base)?;
    let space = experiment
        .experiment
        .param_space()
        .map_err(|e| anyhow::anyhow!("{}: {e}", experiment.source))?;
    for f in &d.factors {
        if space.index_of(&f.name).is_none() {
            anyhow::bail!(
                "factor `{}` is not a parameter of the experiment {} (its parameters: {})",
                f.name,
                experiment.source,
                space.names().join(", ")
            );
        }
    }
    let deepest = loading.drive.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    experiment.experiment.size_for_depth(deepest);
    experiment.check()?;
    let model: Arc<dyn palpate_core::ForwardModel> = Arc::from(
        ModelSpec::Experiment(experiment)
            .validate()
            .map_err(|e| anyhow::anyhow!("{}", e.expected))?
            .into_forward(),
    );
    let start: Vec<f64> = space.params.iter().map(|p| p.initial).collect();
    let models = d
        .runs
        .iter()
        .map(|run| {
            let at = format!(
                "run {} (standard order {})",
                run.run_order, run.standard_order
            );
            let mut theta = start.clone();
            for (k, f) in d.factors.iter().enumerate() {
                let text = d.level_name(run, k);
                let v: f64 = text.trim().parse().map_err(|_| {
                    anyhow::anyhow!("{at}: factor `{}` level `{text}` is not a number", f.name)
                })?;
                if let Some(j) = space.index_of(&f.name) {
                    theta[j] = v;
                }
            }
            space
                .check(&theta)
                .map_err(|e| anyhow::anyhow!("{at}: {e}"))?;
            Ok((model.clone(), theta))
        })
        .collect::<anyhow::Result<_>>()?;
    Ok(SimulationPlan { models, loading, y })
}

/// One N1 simulation per run (in parallel over runs; each run's numbers do
/// not depend on the thread count), scored against the reference curve.
fn run_simulations(
    d: &Design,
    spec: &SimulationResponse,
    plan: SimulationPlan,
) -> anyhow::Result<Vec<f64>> {
    let SimulationPlan { models, loading, y } = plan;
    let bar = crate::run::limits::Progress::new(
        d.runs.len() as u64,
        "N1 runs",
        "{bar:30} {pos}/{len} N1 runs [{elapsed_precise}, eta {eta}]",
    );
    let out = d
        .runs
        .par_iter()
        .zip(&models)
        .map(|(run, (model, theta))| {
            let at = || {
                format!(
                    "run {} (standard order {})",
                    run.run_order, run.standard_order
                )
            };
            let f = model.predict(theta, &loading).with_context(at)?;
            bar.inc(1);
            let (r2, rms) = crate::model::calibration::r2_rms(&y, &f);
            Ok(if spec.metric == "r2" { r2 } else { rms })
        })
        .collect();
    bar.finish();
    out
}
