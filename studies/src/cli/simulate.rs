//! `palpate simulate`: run a finite-element forward model (N1 needle
//! indentation, N3 needle indentation in 3D, C1 compression, Q1 flat-punch
//! ramp-and-hold or R2 rolling over nodules, docs/benchmarks.md) and write its
//! force curve, with the volumetric treatment used and, unless `--error-estimate off`, an
//! estimate of its discretisation error from one coarser solve (Richardson
//! extrapolation with the model's documented order of convergence,
//! `palpate_fe::discretisation`), printed and written as `#` lines and an
//! `error_estimate_N` column of the CSV.

//!
//! The run itself is [`crate::api::simulate`] (the R2 scan:
//! [`crate::api::simulate::r2`]); this module reads the options into
//! [`SimulateOptions`] and writes or prints the curve (the R2 scan's files:
//! `simulate_r2.rs`).

use std::path::PathBuf;

use anyhow::{anyhow, Context};
use palpate_material::Law;

use crate::api::simulate::{curve_text, Curve, NotConverged, SimulateOptions};
use crate::model::{Model, ModelSpec};
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
    /// Mesh density: coarse, medium, fine or a refinement level N = 1..12 (N1: 4-node elements of 0.4/N mm under the tool, or bench: the benchmark mesh, 9-node cells of 0.5 mm in a 2 mm zone, the default for the needle (its accuracy: docs/validation/fe.md, "N1 speed"); C1: 19N x 9N elements; Q1: 0.2/N mm under the punch; N3: hexahedra of 0.8/N mm, levels 1..2, default: 27-node cells of 1.6 mm on the O-grid with friction, the coarse box frictionless; R2: 9-node elements of 2/N mm at the surface and around the nodules, levels 1..3, default coarse) [default: medium; N1 needle: bench]. --accuracy chooses it for a stated error instead.
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

/// `--param NAME=VALUE` options as pairs (a number each).
fn param_pairs(given: &[String]) -> anyhow::Result<Vec<(String, f64)>> {
    given
        .iter()
        .map(|g| {
            let (name, value) = g
                .split_once('=')
                .ok_or_else(|| anyhow!("--param `{g}`: expected NAME=VALUE"))?;
            let v: f64 = value
                .trim()
                .parse()
                .map_err(|_| anyhow!("--param `{g}`: `{value}` is not a number"))?;
            Ok((name.trim().to_string(), v))
        })
        .collect()
}

/// The law's parameter vector from `--param NAME=VALUE` options
/// ([`crate::api::simulate::law_params`]).
pub(crate) fn parse_params(law: &Law, given: &[String]) -> anyhow::Result<Vec<f64>> {
    crate::api::simulate::law_params(law, &param_pairs(given)?)
}

/// The options of the run (what [`crate::api::simulate`] takes).
pub fn options(args: &Args) -> anyhow::Result<SimulateOptions> {
    let params = if args.experiment.is_some() {
        // an experiment's parameters: finite numbers
        let mut out = Vec::new();
        for g in &args.params {
            let (n, v) = super::calibrate::split_pair(g, "NAME=VALUE, e.g. C10=0.002")
                .map_err(|e| anyhow!("--param {e}"))?;
            let v: f64 = v
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| anyhow!("--param {g}: `{v}` is not a finite number"))?;
            out.push((n.to_string(), v));
        }
        out
    } else {
        param_pairs(&args.params)?
    };
    let nodule_params = param_pairs(&args.nodule_params)
        .map_err(|e| anyhow!("{}", e.to_string().replace("--param", "--nodule-param")))?;
    Ok(SimulateOptions {
        params,
        nodule_params,
        ..spec_options(args)
    })
}

/// The options that choose the model (no `--param`; R2's own parameters,
/// read by `simulate_r2.rs`, as given or NaN when not a number).
fn spec_options(args: &Args) -> SimulateOptions {
    let nodule_params = args
        .nodule_params
        .iter()
        .map(|g| match g.split_once('=') {
            Some((n, v)) => (n.trim().to_string(), v.trim().parse().unwrap_or(f64::NAN)),
            None => (g.clone(), f64::NAN),
        })
        .collect();
    SimulateOptions {
        benchmark: args.benchmark.clone(),
        experiment: args.experiment.clone(),
        law: args.law.clone(),
        params: Vec::new(),
        friction: args.friction,
        rd: args.rd,
        nodules: args.nodules.clone(),
        nodule_law: args.nodule_law.clone(),
        nodule_params,
        bonded: args.bonded,
        sliding_base: args.sliding_base,
        tool: args.tool.clone(),
        element: args.element.clone(),
        edge_radius: args.edge_radius,
        depth: args.depth,
        step: args.step,
        mesh: args.mesh.clone(),
        accuracy: args.accuracy,
        bulk: args.bulk.clone(),
        error_estimate: args.error_estimate == "on",
        order: args.order,
        prony: args.prony.clone(),
        ramp: args.ramp,
        hold: args.hold,
    }
}

/// The model the options describe ([`crate::api::simulate::model_spec`]).
pub fn model_spec(args: &Args) -> anyhow::Result<ModelSpec> {
    crate::api::simulate::model_spec(&spec_options(args))
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

/// Runs `palpate simulate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.experiment.is_none() {
        let model = model_spec(&args)?
            .validate()
            .map_err(|e| anyhow!("{}", e.as_option()))?;
        if let Model::R2(_) = model {
            return super::simulate_r2::run(&args, &options(&args)?);
        }
    }
    let options = options(&args)?;
    crate::run::output::check_outputs(
        &[],
        &crate::run::output::given(&[
            ("--csv", &args.csv),
            ("--vtu", &args.vtu),
            ("--plot", &args.plot),
        ]),
    )?;
    match crate::api::simulate::simulate(&options, &crate::api::Stderr) {
        Ok(s) => write_outputs(&args, &s.curve, s.system.as_ref()),
        Err(e) => {
            if let (Some(path), Some(stop)) = (&args.csv, e.downcast_ref::<NotConverged>()) {
                write_curve(path, &stop.partial)?;
                eprintln!(
                    "wrote the {} converged samples to {}",
                    stop.partial.force_n.len(),
                    path.display()
                );
            }
            Err(e)
        }
    }
}

/// Writes a curve as the options ask (--csv, --vtu, --plot; printed
/// without --csv).
fn write_outputs(
    args: &Args,
    c: &Curve,
    solver: Option<&palpate_fe::system::System>,
) -> anyhow::Result<()> {
    if let Some(path) = &args.csv {
        write_curve(path, c)?;
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

fn write_curve(path: &std::path::Path, c: &Curve) -> anyhow::Result<()> {
    write_atomic(
        path,
        curve_text(
            &c.comments,
            c.time_s.as_deref(),
            &c.displacement_mm,
            &c.force_n,
            c.error_estimate_n.as_deref(),
        )
        .as_bytes(),
    )
}
