//! `palpate simulate`: run a finite-element forward model (N1 needle
//! indentation, N3 needle indentation in 3D, C1 compression, Q1 flat-punch
//! ramp-and-hold or R2 rolling over nodules, docs/benchmarks.md) and write its
//! force curve, with the volumetric treatment used and, unless `--error-estimate off`, an
//! estimate of its discretisation error from one coarser solve (Richardson
//! extrapolation with the model's documented order of convergence,
//! `palpate_fe::discretisation`), printed and written as `#` lines and an
//! `error_estimate_N` column of the CSV.

use std::path::PathBuf;

use anyhow::{anyhow, bail, Context};
use indicatif::{ProgressBar, ProgressStyle};
use palpate_core::ForwardModel;
use palpate_core::{Drive, Loading};
use palpate_fe::{Bulk, Progress, Simulation};
use palpate_material::Law;

use super::simulate_estimate::estimate;
use crate::model::{
    C1FeSpec, Model, ModelSpec, N1NeedleSpec, N3NeedleSpec, Q1Spec, R2Spec, Q1_STOP_HINT,
};
use crate::report::plot::{Plot, Series};
use crate::run::output::write_atomic;

/// Run a finite-element forward model (N1, N3, C1, Q1, R2 of docs/benchmarks.md) and write its force curve
///
/// The benchmark's geometry, boundary conditions and loading are those of
/// docs/benchmarks.md; the material is --law with one --param per parameter
/// (MPa), optionally viscoelastic (--prony, with --ramp and --hold). The
/// force curve is printed and written with --csv (and --plot, --vtu).
///
/// Unless --error-estimate off, the model is solved once more on a coarser
/// mesh and the discretisation error is estimated by Richardson
/// extrapolation with the model's documented order of convergence (--order
/// to change it); the estimate is printed and written as `#` lines and an
/// error_estimate_N column of the CSV.
///
/// Every option is checked before solving: options of another benchmark are
/// refused by name, and sizes (--depth / --step, --mesh) are checked against
/// what the machine can hold.
///
/// Examples:
///   palpate simulate --benchmark C1 --law neo-hookean --param C10=0.0011 --csv c1.csv
///   palpate simulate --benchmark N1 --law yeoh --param C10=0.001 --param C20=0 --param C30=0 --mesh medium --plot n1.svg
///   palpate simulate --benchmark R2 --rd 6 --nodules 75:15 --csv r2.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment, allow_negative_numbers = true)]
pub struct Args {
    /// Benchmark: N1 (needle indentation of a 70 x 80 mm cylinder), N3 (the same needle into a 70 x 80 x 80 mm block, 3D quarter model), C1 (compression of a 38 x 9 mm cylinder), Q1 (ramp-and-hold of a flat punch of radius 2 mm, edge rounded 0.2 mm, frictionless, on a cylinder of radius 50 and height 60 mm) or R2 (a wheel of diameter 8 mm pressed to --rd at x = 10 mm and rolled to x = 140 mm over a 150 x 30 mm block, 50 mm thick, with bonded nodules of diameter 10 mm; plane stress).
    #[arg(long, value_parser = ["N1", "N3", "C1", "Q1", "R2", "n1", "n3", "c1", "q1", "r2"], required_unless_present = "experiment")]
    pub benchmark: Option<String>,
    /// A lab's own experiment instead of a benchmark: an experiment file (TOML) or a preset's name (palpate experiment list; docs/guide/experiment.md). The description holds the specimen, materials, tool, supports, protocol and mesh, so the benchmark options are refused with it; --param NAME=VALUE sets a parameter (default: its start in the description).
    #[arg(long, value_name = "FILE|PRESET", conflicts_with_all = EXPERIMENT_HOLDS)]
    pub experiment: Option<String>,
    /// Material law: neo-hookean, mooney-rivlin, reduced-polynomial:N, yeoh, arruda-boyce, ogden:N, gent, veronda-westmann, humphrey (required, except R2: the tissue law, default arruda-boyce with rtv6166-ab's mu=0.00498, lambda_m=1.05).
    #[arg(long)]
    pub law: Option<String>,
    /// A law parameter in MPa (or 1), e.g. --param C10=0.001101295; repeat for each parameter of the law.
    #[arg(long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// N1, N3: Coulomb friction coefficient between needle and material [default: 0.8]; R2: between wheel and block [default: 0, frictionless].
    #[arg(long)]
    pub friction: Option<f64>,
    /// R2: rolling depth of the wheel in mm (required; 0 < RD < 8, the wheel diameter).
    #[arg(long, value_name = "RD")]
    pub rd: Option<f64>,
    /// R2: the nodules as X:DEPTH,... in mm (centre position along the block, centre depth below the surface), or none [default: 37.5:10,75:15,112.5:20]; 75:15 alone is R2-1.
    #[arg(long, value_name = "X:DEPTH,...", allow_hyphen_values = true)]
    pub nodules: Option<String>,
    /// R2: the nodules' law [default: arruda-boyce with rubber-ab's mu=0.0734, lambda_m=1.01].
    #[arg(long)]
    pub nodule_law: Option<String>,
    /// R2: a parameter of the nodule law, e.g. --nodule-param mu=0.0734; repeat for each.
    #[arg(long = "nodule-param", value_name = "NAME=VALUE")]
    pub nodule_params: Vec<String>,
    /// C1: bonded (no-slip) platens instead of frictionless ones.
    #[arg(long)]
    pub bonded: bool,
    /// N1: bottom face free to slide radially instead of fixed.
    #[arg(long)]
    pub sliding_base: bool,
    /// N1, N3 tool: needle (docs/benchmarks.md), sphere:RADIUS, punch:RADIUS (flat, edge rounded 0.1 mm) or platen [default: needle].
    #[arg(long)]
    pub tool: Option<String>,
    /// N1 and Q1 element: quad4 (4-node, constant pressure) or quad9 (9-node, linear discontinuous pressure, on the same grading made quadratic: more accurate per unknown) [default: quad4; N1 needle without --mesh: quad9 on the bench mesh]. N3: hex8 (8-node, constant pressure, on the graded box) or hex27 (27-node, linear discontinuous pressure, on the quarter O-grid with cells of 1.6/N mm: the accurate choice with friction; accuracy and cost: docs/validation/fe.md "N3") [default without --mesh: hex27 with friction, hex8 frictionless; with --mesh: hex8].
    #[arg(long, value_name = "quad4|quad9")]
    pub element: Option<String>,
    /// Q1: radius of the punch's rounded edge in mm, > 0 and below the punch radius 2 [default: 0.2]. The default runs the 5 mm ramp; a larger edge is a rounded punch, no longer the flat one (its force and accuracy against depth: docs/validation/fe.md "Q1").
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub edge_radius: Option<f64>,
    /// Final tool displacement in mm (default: 10 for N1, 2 for C1, 5 for Q1).
    #[arg(long)]
    pub depth: Option<f64>,
    /// Spacing of the output samples in mm (default: 0.25 for N1, 0.1 for C1, depth/100 for Q1, 0.5 mm of wheel travel for R2).
    #[arg(long)]
    pub step: Option<f64>,
    /// Mesh density: coarse, medium, fine or a refinement level N = 1..12 (N1: 4-node elements of 0.4/N mm under the tool, or bench: the benchmark mesh, 9-node cells of 0.5 mm in a 2 mm zone, the default for the needle, within 0.5 % of the converged force; C1: 19N x 9N elements; Q1: 0.2/N mm under the punch; N3: hexahedra of 0.8/N mm, levels 1..2, default: 27-node cells of 1.6 mm on the O-grid with friction, the coarse box frictionless; R2: 9-node elements of 2/N mm at the surface and around the nodules, levels 1..3, default coarse) [default: medium; N1 needle: bench]. --accuracy chooses it for a stated error instead.
    #[arg(long)]
    pub mesh: Option<String>,
    /// N1, N3: choose the mesh for this relative discretisation error of the force at the deepest sample (e.g. 0.01 for 1 %) instead of --mesh: the model is solved on a ladder of refinement levels, each error estimated by Richardson from a mesh with elements twice as large, and the first level that meets it is used; the level is cached (in $XDG_CACHE_HOME/palpate or ~/.cache/palpate) so the search is paid once per model, depth and accuracy.
    #[arg(long, value_name = "FRACTION")]
    pub accuracy: Option<f64>,
    /// Incompressibility: exact (Lagrange multiplier per element) or a bulk-to-shear modulus ratio K/mu such as 1000 [default: exact].
    #[arg(long)]
    pub bulk: Option<String>,
    /// Discretisation error estimate: `on` solves once more on a coarser mesh (elements twice as large: N1 h_fine and growth-1 doubled, C1 half the elements each way) and states the Richardson estimate of the error with the model's documented order of convergence; `off` skips the second solve.
    #[arg(long, value_name = "on|off", value_parser = ["on", "off"], default_value = "on")]
    pub error_estimate: String,
    /// Order of convergence P for the error estimate instead of the model's documented one (N1 1.22, C1 bonded 0.58); a smaller P gives a larger estimate.
    #[arg(long, value_name = "P")]
    pub order: Option<f64>,
    /// N1, C1 and Q1: viscoelastic material, a Prony series g1=..,tau1=..,g2=..,tau2=.. on the law's isochoric stress (G(t) = 1 - sum g_i (1 - exp(-t/tau_i)), tau in s); the history becomes timed: ramp to --depth in --ramp seconds, then hold --hold seconds.
    #[arg(long, value_name = "g1=..,tau1=..")]
    pub prony: Option<String>,
    /// With --prony (N1, C1) or Q1: duration of the ramp to --depth in s [default: C1 1; N1 depth / 0.4 mm/s (docs/benchmarks.md); Q1 0.5].
    #[arg(long, value_name = "SECONDS")]
    pub ramp: Option<f64>,
    /// With --prony (N1, C1) or Q1: hold at --depth for this many seconds after the ramp, in 200 samples [default: 0; Q1: 60].
    #[arg(long, value_name = "SECONDS")]
    pub hold: Option<f64>,
    /// Write the force curve as CSV (columns [time_s,]displacement_mm,force_N[,error_estimate_N], time_s with --prony and for Q1; R2: position_mm,force_N,force_x_N[,error_estimate_N] for the rolled pass and the pressing phase in OUT.press.csv as displacement_mm,force_N,force_x_N; `#` lines state the model, the volumetric treatment and the error estimate).
    #[arg(long, value_name = "OUT.csv")]
    pub csv: Option<PathBuf>,
    /// Write the final deformed state as a VTK .vtu file for ParaView.
    #[arg(long, value_name = "OUT.vtu")]
    pub vtu: Option<PathBuf>,
    /// Write an SVG plot of force against displacement.
    #[arg(long, value_name = "OUT.svg")]
    pub plot: Option<PathBuf>,
}

pub(crate) fn parse_params(law: &Law, given: &[String]) -> anyhow::Result<Vec<f64>> {
    let specs = law.params();
    let mut values = vec![None; specs.len()];
    for g in given {
        let (name, value) = g
            .split_once('=')
            .ok_or_else(|| anyhow!("--param `{g}`: expected NAME=VALUE"))?;
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
        let v: f64 = value
            .trim()
            .parse()
            .map_err(|_| anyhow!("--param `{g}`: `{value}` is not a number"))?;
        if values[k].is_some() {
            bail!(
                "--param `{g}`: {} is given twice; give each parameter once",
                specs[k].name
            );
        }
        values[k] = Some(v);
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
    let shown: Vec<String> = given.iter().map(|g| format!("--param {g}")).collect();
    law.check(&p)
        .map_err(|e| anyhow!("{} ({law}): {e}", shown.join(" ")))?;
    crate::run::checks::check_law_values(law, &p, |n, v| format!("--param {n}={v}"))?;
    Ok(p)
}

/// The model the options describe: N1 -> `n1_needle`, N3 -> `n3_needle`,
/// C1 -> `c1_fe`, Q1 -> `q1`; an option of another benchmark is refused by name, since it
/// would be neither used nor visible in the result.
pub fn model_spec(args: &Args) -> anyhow::Result<ModelSpec> {
    let kind = if is_q1(args) {
        "Q1"
    } else if args.benchmark().eq_ignore_ascii_case("r2") {
        "R2"
    } else if args.benchmark().eq_ignore_ascii_case("n3") {
        "N3"
    } else if args.benchmark().eq_ignore_ascii_case("n1") {
        "N1"
    } else {
        "C1"
    };
    // (option, value shown, the benchmarks that use it)
    let options: [(bool, &str, String, &[&str]); 14] = [
        (
            args.rd.is_some(),
            "--rd",
            args.rd.map(|f| f.to_string()).unwrap_or_default(),
            &["R2"],
        ),
        (
            args.nodules.is_some(),
            "--nodules",
            args.nodules.clone().unwrap_or_default(),
            &["R2"],
        ),
        (
            args.nodule_law.is_some(),
            "--nodule-law",
            args.nodule_law.clone().unwrap_or_default(),
            &["R2"],
        ),
        (
            !args.nodule_params.is_empty(),
            "--nodule-param",
            args.nodule_params.join(" "),
            &["R2"],
        ),
        (
            args.depth.is_some(),
            "--depth",
            format!("{:?}", args.depth.unwrap_or(0.0)),
            &["N1", "N3", "C1", "Q1"],
        ),
        (args.bonded, "--bonded", String::new(), &["C1"]),
        (
            args.prony.is_some(),
            "--prony",
            args.prony.clone().unwrap_or_default(),
            &["N1", "C1", "Q1"],
        ),
        (
            args.ramp.is_some(),
            "--ramp",
            format!("{:?}", args.ramp.unwrap_or(0.0)),
            &["N1", "C1", "Q1"],
        ),
        (
            args.hold.is_some(),
            "--hold",
            format!("{:?}", args.hold.unwrap_or(0.0)),
            &["N1", "C1", "Q1"],
        ),
        (
            args.friction.is_some(),
            "--friction",
            args.friction.map(|f| f.to_string()).unwrap_or_default(),
            &["N1", "N3", "R2"],
        ),
        (args.sliding_base, "--sliding-base", String::new(), &["N1"]),
        (
            args.tool.is_some(),
            "--tool",
            args.tool.clone().unwrap_or_default(),
            &["N1", "N3"],
        ),
        (
            args.element.is_some(),
            "--element",
            args.element.clone().unwrap_or_default(),
            &["N1", "Q1", "N3"],
        ),
        (
            args.edge_radius.is_some(),
            "--edge-radius",
            format!("{:?}", args.edge_radius.unwrap_or(0.0)),
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
        let rd = args.rd.ok_or_else(|| {
            anyhow!("--benchmark R2 needs --rd RD (the rolling depth in mm, e.g. 6)")
        })?;
        return Ok(ModelSpec::R2(R2Spec {
            law: args.law.clone().unwrap_or_else(|| "arruda-boyce".into()),
            nodule_law: args.nodule_law.clone(),
            rd,
            nodules: args.nodules.clone(),
            friction: args.friction,
            mesh: args.mesh.clone(),
            bulk: args.bulk.clone(),
        }));
    }
    let law = args
        .law
        .clone()
        .ok_or_else(|| anyhow!("--benchmark {kind} needs --law (e.g. --law neo-hookean)"))?;
    Ok(if kind == "Q1" {
        ModelSpec::Q1(Q1Spec {
            law: law.clone(),
            mesh: args.mesh.clone(),
            bulk: args.bulk.clone(),
            element: args.element.clone(),
            prony: args.prony.clone(),
            edge_radius: args.edge_radius,
        })
    } else if kind == "N3" {
        ModelSpec::N3Needle(N3NeedleSpec {
            law: law.clone(),
            friction: args.friction,
            mesh: args.mesh.clone(),
            bulk: args.bulk.clone(),
            tool: args.tool.clone(),
            element: args.element.clone(),
        })
    } else if kind == "N1" {
        ModelSpec::N1Needle(N1NeedleSpec {
            law: law.clone(),
            friction: args.friction,
            mesh: args.mesh.clone(),
            bulk: args.bulk.clone(),
            base: args.sliding_base.then(|| "sliding".into()),
            tool: args.tool.clone(),
            element: args.element.clone(),
            prony: args.prony.clone(),
        })
    } else {
        ModelSpec::C1Fe(C1FeSpec {
            law,
            platens: args.bonded.then(|| "bonded".into()),
            mesh: args.mesh.clone(),
            bulk: args.bulk.clone(),
            prony: args.prony.clone(),
        })
    })
}

fn is_q1(args: &Args) -> bool {
    args.benchmark().eq_ignore_ascii_case("q1")
}

/// The options an experiment description holds itself (its specimen,
/// materials, tool, supports, protocol and mesh): refused with --experiment.
const EXPERIMENT_HOLDS: [&str; 19] = [
    "benchmark",
    "law",
    "friction",
    "rd",
    "nodules",
    "nodule_law",
    "nodule_params",
    "bonded",
    "sliding_base",
    "tool",
    "element",
    "edge_radius",
    "depth",
    "step",
    "mesh",
    "bulk",
    "prony",
    "ramp",
    "hold",
];

impl Args {
    /// The benchmark's name (empty with --experiment).
    pub fn benchmark(&self) -> &str {
        self.benchmark.as_deref().unwrap_or("")
    }
}

/// A force curve of `palpate simulate` (N1, N3, C1, Q1), as its CSV holds
/// it but at full precision: the columns are the vectors the solver filled.
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
    /// `error_estimate_N` when `--error-estimate on` could estimate it.
    pub error_estimate_n: Option<Vec<f64>>,
}

/// Runs `palpate simulate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if let Some(e) = &args.experiment {
        let (c, solver) = super::simulate_experiment::compute(&args, e)?;
        return write_outputs(&args, &c, solver.as_ref());
    }
    let model = model_spec(&args)?
        .validate()
        .map_err(|e| anyhow!("{}", e.as_option()))?;
    if let Model::R2(m) = model {
        return super::simulate_r2::run(&args, m);
    }
    let (c, solver) = compute(&args, model)?;
    write_outputs(&args, &c, Some(&solver))
}

/// Writes a curve as the options ask (--csv, --vtu, --plot; printed
/// without --csv).
fn write_outputs(
    args: &Args,
    c: &Curve,
    solver: Option<&palpate_fe::system::System>,
) -> anyhow::Result<()> {
    if let Some(path) = &args.csv {
        write_curve(
            path,
            &c.comments,
            c.time_s.as_deref(),
            &c.displacement_mm,
            &c.force_n,
            c.error_estimate_n.as_deref(),
        )?;
    }
    if let (Some(path), Some(solver)) = (&args.vtu, solver) {
        let vtu = palpate_fe::vtu::to_vtu(solver).map_err(|e| anyhow!("{e}"))?;
        write_atomic(path, vtu.as_bytes())?;
    }
    if let Some(path) = &args.plot {
        let plot = match &c.time_s {
            Some(t) => {
                Plot::new(&c.title, "time (s)", "force (N)").with(Series::line("FE", t, &c.force_n))
            }
            None => Plot::new(&c.title, "displacement (mm)", "force (N)").with(Series::line(
                "FE",
                &c.displacement_mm,
                &c.force_n,
            )),
        };
        write_atomic(path, plot.to_svg().as_bytes())
            .with_context(|| format!("plot {}", path.display()))?;
    }
    if args.csv.is_none() {
        print!(
            "{}",
            curve_text(
                &c.comments,
                c.time_s.as_deref(),
                &c.displacement_mm,
                &c.force_n,
                c.error_estimate_n.as_deref()
            )
        );
    }
    Ok(())
}

/// The curve of `palpate simulate` without writing it (the outputs
/// `--csv`, `--vtu`, `--plot` are left to [`run`]): for callers that want
/// the vectors, such as the Python package. R2 (a scan, not a force curve)
/// is refused with the command to use.
pub fn curve(args: &Args) -> anyhow::Result<Curve> {
    if let Some(e) = &args.experiment {
        return super::simulate_experiment::compute(args, e).map(|(c, _)| c);
    }
    let model = model_spec(args)?
        .validate()
        .map_err(|e| anyhow!("{}", e.as_option()))?;
    if let Model::R2(_) = model {
        bail!("--benchmark R2: a scan (position_mm, force_N, force_x_N), not a force curve; run it with palpate simulate --benchmark R2 --csv FILE");
    }
    compute(args, model).map(|(c, _)| c)
}

/// The FE run of `palpate simulate` for a validated N1, N3, C1 or Q1 model:
/// its curve and the solved system (for `--vtu`).
fn compute(args: &Args, model: Model) -> anyhow::Result<(Curve, palpate_fe::system::System)> {
    let law_text = args.law.clone().unwrap_or_default();
    let law: Law = law_text
        .parse()
        .map_err(|e| anyhow!("--law `{law_text}`: {e}"))?;
    let theta = parse_params(&law, &args.params)?;
    crate::run::output::check_outputs(
        &[],
        &crate::run::output::given(&[
            ("--csv", &args.csv),
            ("--vtu", &args.vtu),
            ("--plot", &args.plot),
        ]),
    )?;
    // needle benchmarks (N1, N3): 10 mm every 0.25 mm
    let n1 =
        args.benchmark().eq_ignore_ascii_case("n1") || args.benchmark().eq_ignore_ascii_case("n3");
    let q1 = is_q1(args);
    let depth = args.depth.unwrap_or(if n1 {
        10.0
    } else if q1 {
        5.0
    } else {
        2.0
    });
    // Q1: at least 100 samples in the ramp (docs/benchmarks.md)
    let step = args.step.unwrap_or(if n1 {
        0.25
    } else if q1 {
        depth / 100.0
    } else {
        0.1
    });
    if !(depth > 0.0 && depth.is_finite() && step > 0.0 && step.is_finite()) {
        bail!("--depth and --step must be positive (got {depth} and {step})");
    }
    if let Some(p) = args.order {
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
        &format!("--tool {}", args.tool.as_deref().unwrap_or("needle")),
        &model,
    )?;
    let mut drive: Vec<f64> = (0..=n).map(|k| (k as f64 * step).min(depth)).collect();
    let time = timed_history(args, depth, &mut drive)?;
    if let Some(end) = time.as_ref().and_then(|t| t.last()) {
        crate::run::checks::check_increments(&model, *end)?;
    }
    let loading = match &time {
        Some(t) => Loading::timed(Drive::DisplacementMm, t.clone(), drive.clone()),
        None => Loading::quasi_static(Drive::DisplacementMm, drive.clone()),
    };

    let chosen = match args.accuracy {
        Some(target) => Some(choose_mesh(args, &model, target, &theta, &loading)?),
        None => None,
    };
    let (model, chosen_line) = match chosen {
        Some((m, line)) => (m, Some(line)),
        None => (model, None),
    };

    let (bar, mut cb) = progress_bar(drive.len(), "");
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
        _ => bail!(
            "--benchmark {}: expected N1, N3, C1 or Q1",
            args.benchmark()
        ),
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
            if let Some(path) = &args.csv {
                comments.push(format!(
                    "did not converge at sample {sample} (drive {d} mm): partial curve, no error estimate"
                ));
                write_curve(
                    path,
                    &comments,
                    time.as_ref().map(|t| &t[..completed.len()]),
                    &drive[..completed.len()],
                    &completed,
                    None,
                )?;
                eprintln!(
                    "wrote the {} converged samples to {}",
                    completed.len(),
                    path.display()
                );
            }
            let hint = if is_q1(args) && d > 0.0 {
                format!("\nhint: {Q1_STOP_HINT}")
            } else {
                String::new()
            };
            bail!("{title}: did not converge at sample {sample} (drive {d} mm) after {cuts} step cuts: {reason}{hint}");
        }
        Err(e) => bail!("{title}: {e}"),
    };
    eprintln!(
        "{title}: {} elements, {} unknowns, {} increments, {} Newton iterations ({} factorisations), F({depth} mm) = {:.6} N",
        solver.mesh.cell_count(),
        solver.equations(),
        sim.stats.increments,
        sim.stats.iterations,
        sim.stats.factorisations,
        sim.forces.last().copied().unwrap_or(0.0)
    );
    if sim.stats.loose > 0 {
        eprintln!(
            "warning: {} increments were accepted at the looser stagnation tolerance (SolverOptions::stagnation_tolerance), not the full one",
            sim.stats.loose
        );
    }
    eprintln!("volumetric: {}", volumetric(bulk));
    let errors = if args.error_estimate == "on" {
        let est = estimate(&model, &theta, &loading, args.order, &sim.forces)?;
        eprintln!("{}", est.line);
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

/// `--accuracy`: the N1 or N3 model at the level of its mesh family that
/// meets the target (`palpate_fe::accuracy::choose`, cached in the user's
/// cache directory), and the line stating it.
fn choose_mesh(
    args: &Args,
    model: &Model,
    target: f64,
    theta: &[f64],
    loading: &Loading,
) -> anyhow::Result<(Model, String)> {
    use palpate_fe::accuracy::{choose, AccuracyOptions, Refinable};
    if let Some(mesh) = &args.mesh {
        bail!(
            "--accuracy {target} with --mesh {mesh}: --accuracy chooses the mesh; give one of them"
        );
    }
    let mut opts = AccuracyOptions::new(target);
    opts.cache_dir = crate::run::surrogate::mesh_cache_dir();
    let bar = ProgressBar::new_spinner();
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
            args.benchmark()
        ),
    };
    bar.finish_and_clear();
    let (m, choice) = result.map_err(|e| anyhow!("--accuracy {target}: {e}"))?;
    let line = choice.line();
    eprintln!("{line}");
    Ok((m, line))
}

/// The volumetric treatment in words.
pub(crate) fn volumetric(bulk: Bulk) -> String {
    match bulk {
        Bulk::Exact => "exact incompressibility (Lagrange multiplier per element)".into(),
        Bulk::Ratio(r) => format!("nearly incompressible, K = {r} x mu (mean-dilatation penalty)"),
    }
}

pub(crate) fn progress_bar(len: usize, prefix: &str) -> (ProgressBar, impl FnMut(&Progress)) {
    let bar = ProgressBar::new(len as u64);
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

/// The sample times of a viscoelastic (`--prony`) run or of any Q1 run
/// (ramp-and-hold, docs/benchmarks.md): the drive samples spread over `--ramp`
/// seconds, then `--hold` seconds at `depth` in 200 samples appended to
/// `drive`; `None` for an elastic C1 or N1 run.
fn timed_history(
    args: &Args,
    depth: f64,
    drive: &mut Vec<f64>,
) -> anyhow::Result<Option<Vec<f64>>> {
    let q1 = is_q1(args);
    if args.prony.is_none() && !q1 {
        if args.ramp.is_some() || args.hold.is_some() {
            bail!("--ramp and --hold time a viscoelastic run: they need --prony");
        }
        return Ok(None);
    }
    if !(args.benchmark().eq_ignore_ascii_case("c1")
        || args.benchmark().eq_ignore_ascii_case("n1")
        || q1)
    {
        bail!("--prony: only N1, C1 and Q1 have the viscoelastic material so far");
    }
    // N1: the needle's 0.4 mm/s (docs/benchmarks.md), C1: 1 s, Q1: 0.5 s
    let ramp = args.ramp.unwrap_or(if q1 {
        0.5
    } else if args.benchmark().eq_ignore_ascii_case("n1") {
        depth / 0.4
    } else {
        1.0
    });
    let hold = args.hold.unwrap_or(if q1 { 60.0 } else { 0.0 });
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

pub(crate) fn curve_text(
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

fn write_curve(
    path: &std::path::Path,
    comments: &[String],
    time: Option<&[f64]>,
    d: &[f64],
    f: &[f64],
    errors: Option<&[f64]>,
) -> anyhow::Result<()> {
    write_atomic(path, curve_text(comments, time, d, f, errors).as_bytes())
}
