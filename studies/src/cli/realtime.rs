//! `palpate realtime build|query`: the real-time force model of the Q1
//! (or N1) benchmark ([`palpate_realtime`]): built once from FE runs (an
//! elastic ramp for the force curve, training histories for its memory
//! kernel, random held-out histories for its error table) with a progress
//! bar, stored as a JSON file, queried on a CSV of depths. `palpate
//! surrogate` is a hidden alias of the command (its former name).

use crate::run::limits::Progress;
use crate::run::output::{check_outputs, given, write_atomic};
use anyhow::{anyhow, bail, Context};
use palpate_core::ForwardModel;
use palpate_fe::{N1Needle, Prony, Q1Punch};
use palpate_material::Law;
use palpate_realtime::report::{error_table, target_warning};
use palpate_realtime::{RealTimeModel, RealTimeRequest};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Build (from FE runs) or query the real-time force model of Q1 or N1
///
/// `build` runs the FE model of the benchmark (an elastic ramp to
/// --depth-max for the force curve, --train histories its memory is fitted
/// to, and random held-out histories of ramps, holds and unloadings for its
/// error table) for one material (--law, --param, --prony) and stores the
/// model as JSON; `query` answers any depth history, sample by sample,
/// in microseconds per sample.
/// The model is valid only for that material, benchmark and depth range.
/// Its measured accuracy, build by build: docs/validation/realtime.md.
///
/// Examples:
///   palpate realtime build --benchmark Q1 --law neo-hookean --param C10=0.0016 --prony g1=0.3,tau1=0.5 --depth-max 1 --out q1-rt.json
///   palpate realtime query --model q1-rt.json --csv depths.csv --out forces.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(subcommand)]
    pub command: Sub,
}

/// The realtime subcommands (their help is their `Args` doc comment).
#[derive(Debug, clap::Subcommand)]
pub enum Sub {
    // Build from FE runs and store it (BuildArgs).
    Build(BuildArgs),
    // Answer a depth history (QueryArgs).
    Query(QueryArgs),
}

/// Build the real-time model from FE runs and store it
///
/// Runs the benchmark's FE model for the material given (--law, --param,
/// --prony): one elastic ramp to --depth-max; --train histories (a ramp and
/// hold, then random ones) to which the model's memory is fitted (a
/// relaxation read through the present depth, with the contact form and
/// optional stop operators (a rate-independent hysteresis) chosen by
/// cross-validation; 0: plain QLV on the force curve with the material's
/// terms); then --holdout other random histories
/// of --segments ramps, holds and unloadings, whose FE forces are compared
/// with the model's (and plain QLV's) in a printed error table (max
/// error at the segment ends and 16 points inside each ramp, 12 inside each
/// hold, as a percentage of the history's peak force).
/// Measured tables of the benchmarks' builds: docs/validation/realtime.md.
///
/// Example: palpate realtime build --benchmark Q1 --law neo-hookean --param C10=0.0016
///   --prony g1=0.3,tau1=0.5,g2=0.2,tau2=10 --depth-max 1 --out q1-rt.json
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct BuildArgs {
    /// Q1 (flat punch) or N1 (needle, friction 0.8 unless --friction).
    #[arg(long)]
    pub benchmark: String,
    /// N1: the needle's Coulomb friction [default: 0.8]. How the fitted
    /// memory's held-out error depends on it and on the depth:
    /// docs/validation/realtime.md.
    #[arg(long)]
    pub friction: Option<f64>,
    /// Material law: neo-hookean, mooney-rivlin, reduced-polynomial:N, yeoh, arruda-boyce, ogden:N,
    /// gent, veronda-westmann, humphrey.
    #[arg(long)]
    pub law: String,
    /// A law parameter, e.g. --param C10=0.0016 (MPa); repeat for each.
    #[arg(long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// The material's Prony series g1=..,tau1=..,...
    #[arg(long)]
    pub prony: String,
    /// The deepest depth it answers for (mm). Q1's FE runs to 5 mm with the default edge; past about 2 mm mesh 1 is stiff against finer meshes (docs/validation/fe.md, "Q1"), and the model follows the FE of the mesh it is built on.
    #[arg(long, value_name = "MM")]
    pub depth_max: f64,
    /// Q1: radius of the punch's rounded edge in mm [default: 0.2], as `palpate simulate --edge-radius`: a larger edge is a rounded punch, no longer the flat one.
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub edge_radius: Option<f64>,
    /// Mesh level of the FE runs (default 1).
    #[arg(long, default_value_t = 1)]
    pub mesh: usize,
    /// FE training histories for the fitted memory (default 12; 0: plain
    /// QLV, no training runs; otherwise at least 5).
    #[arg(long, default_value_t = 12)]
    pub train: usize,
    /// Held-out random histories run by FE for the error table (default 4).
    #[arg(long, default_value_t = 4)]
    pub holdout: usize,
    /// Segments (ramps, holds, unloadings) per held-out history (default 6).
    #[arg(long, default_value_t = 6)]
    pub segments: usize,
    /// The error the model is meant to keep on held-out histories, as
    /// the largest station error over the history's peak force, in per cent
    /// [default: 2]. A build that misses it is still stored, with a warning
    /// naming the histories over it.
    #[arg(long, value_name = "PCT", default_value_t = 2.0)]
    pub target: f64,
    /// Where to store the model (JSON).
    #[arg(long, value_name = "OUT.json")]
    pub out: PathBuf,
}

/// Answer a depth history (CSV time_s,displacement_mm) sample by sample
///
/// Writes time_s,displacement_mm,force_N; a depth beyond the model's
/// --depth-max is refused, naming its row (it does not extrapolate).
/// How far a model's forces are from the FE's: docs/validation/realtime.md.
///
/// Example: palpate realtime query --model q1-rt.json --csv depths.csv --out forces.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct QueryArgs {
    /// The model written by `palpate realtime build`.
    #[arg(long, value_name = "FILE.json", alias = "surrogate")]
    pub model: PathBuf,
    /// Columns time_s,displacement_mm (header line; # comments).
    #[arg(long, value_name = "FILE.csv")]
    pub csv: PathBuf,
    /// Output CSV time_s,displacement_mm,force_N (default: standard output).
    #[arg(long, value_name = "OUT.csv")]
    pub out: Option<PathBuf>,
}

/// Runs `palpate realtime`.
pub fn run(args: Args) -> anyhow::Result<()> {
    match args.command {
        Sub::Build(a) => build(a),
        Sub::Query(a) => query(a),
    }
}

fn build(a: BuildArgs) -> anyhow::Result<()> {
    let law: Law = a.law.parse().map_err(|e| anyhow!("--law {}: {e}", a.law))?;
    let theta = super::simulate::parse_params(&law, &a.params)?;
    let prony: Prony = a
        .prony
        .parse()
        .map_err(|e| anyhow!("--prony {}: {e}", a.prony))?;
    if !(a.depth_max > 0.0 && a.depth_max.is_finite() && a.depth_max <= 20.0) {
        bail!(
            "--depth-max {}: give a depth in mm, > 0 and <= 20",
            a.depth_max
        );
    }
    if !(1..=6).contains(&a.mesh) {
        bail!("--mesh {}: give a level 1..6", a.mesh);
    }
    if a.train != 0 && !(5..=64).contains(&a.train) {
        bail!(
            "--train {}: give 0 (plain QLV) or 5..64 FE training histories",
            a.train
        );
    }
    if !(1..=64).contains(&a.holdout) || !(1..=50).contains(&a.segments) {
        bail!(
            "--holdout {} / --segments {}: give 1..64 histories of 1..50 segments",
            a.holdout,
            a.segments
        );
    }
    if !(a.target > 0.0 && a.target.is_finite()) {
        bail!("--target {}: give a per cent > 0", a.target);
    }
    check_outputs(&[], &given(&[("--out", &Some(a.out.clone()))]))?;
    if a.friction.is_some() && !a.benchmark.eq_ignore_ascii_case("N1") {
        bail!("--friction applies to --benchmark N1 only (Q1's punch is frictionless)");
    }
    if a.edge_radius.is_some() && !a.benchmark.eq_ignore_ascii_case("Q1") {
        bail!("--edge-radius applies to --benchmark Q1 only (the flat punch's edge)");
    }
    let (elastic, visco): (Box<dyn ForwardModel>, Box<dyn ForwardModel>) =
        match a.benchmark.to_ascii_uppercase().as_str() {
            "Q1" => {
                let mut e = Q1Punch::new(law);
                e.level = a.mesh;
                if let Some(rho) = a.edge_radius {
                    e.set_edge_radius(rho)
                        .map_err(|why| anyhow::anyhow!("--edge-radius {rho}: {why}"))?;
                }
                let mut v = e.clone();
                v.prony = Some(prony.clone());
                (Box::new(e), Box::new(v))
            }
            "N1" => {
                let mut e = N1Needle::new(law);
                e.mesh.level = a.mesh;
                if let Some(mu) = a.friction {
                    if !(mu >= 0.0 && mu.is_finite()) {
                        bail!("--friction {mu}: give a coefficient >= 0");
                    }
                    e.friction = mu;
                }
                let mut v = e.clone();
                v.prony = Some(prony.clone());
                (Box::new(e), Box::new(v))
            }
            b => bail!("--benchmark {b}: the real-time model is built for Q1 or N1"),
        };
    let extra = |m: &dyn ForwardModel| -> Vec<f64> {
        let mut t = theta.clone();
        t.extend(m.space().params[theta.len()..].iter().map(|p| p.initial));
        t
    };
    let (te, tv) = (extra(elastic.as_ref()), extra(visco.as_ref()));
    let req = RealTimeRequest {
        elastic: elastic.as_ref(),
        elastic_theta: &te,
        viscoelastic: visco.as_ref(),
        viscoelastic_theta: &tv,
        prony: prony.terms().to_vec(),
        depth_max: a.depth_max,
        knots: 20,
        validation_histories: a.holdout,
        segments: a.segments,
        training_histories: a.train,
        kernel_knots: 10,
    };
    if a.benchmark.eq_ignore_ascii_case("Q1")
        && a.mesh <= 1
        && a.depth_max > 2.0
        && a.edge_radius.is_none_or(|r| r < 0.5)
    {
        eprintln!(
            "note: on mesh {} the Q1 force past 2 mm is stiff against finer meshes and drops where the surface snaps round the punch's edge; the model follows this mesh's FE (--mesh 2 is smoother at about 9 x the FE time; docs/validation/realtime.md)",
            a.mesh
        );
    }
    let total = (1 + a.train + a.holdout) as u64;
    let bar = Progress::new(
        total,
        "real-time model",
        "{msg} [{bar:40}] {pos}/{len} FE runs ({elapsed}, eta {eta})",
    );
    let tick = |_d: usize, _t: usize| bar.inc(1);
    let built = RealTimeModel::build(&req, Some(&tick));
    bar.finish();
    let s = built.map_err(|e| anyhow!("building the real-time model of {}: {e}", visco.name()))?;
    write_atomic(&a.out, s.to_json().as_bytes())?;
    println!("{}", error_table(&s));
    if let Some(w) = target_warning(&s, a.target) {
        eprintln!("{w}");
    }
    eprintln!(
        "built from {} FE runs in {:.1} s, stored in {}",
        s.fe_runs,
        s.build_time_s,
        a.out.display()
    );
    Ok(())
}

fn query(a: QueryArgs) -> anyhow::Result<()> {
    let outputs = given(&[("--out", &a.out)]);
    check_outputs(&[a.model.as_path(), a.csv.as_path()], &outputs)?;
    let text = std::fs::read_to_string(&a.model)
        .with_context(|| format!("--model {}", a.model.display()))?;
    let mut s = RealTimeModel::from_json(&text)
        .map_err(|e| anyhow!("--model {}: not a real-time model: {e}", a.model.display()))?;
    let (time, depth) = read_depths(&a.csv)?;
    let mut out = String::from("time_s,displacement_mm,force_N\n");
    let mut prev = 0.0;
    for (k, (&t, &d)) in time.iter().zip(&depth).enumerate() {
        let f = s
            .force(d, t - prev)
            .map_err(|e| anyhow!("{}: row {} (time_s {t}): {e}", a.csv.display(), k + 2))?;
        prev = t;
        let _ = writeln!(out, "{t},{d},{f:.8e}");
    }
    match &a.out {
        Some(p) => {
            write_atomic(p, out.as_bytes())?;
            eprintln!("wrote {}", p.display());
        }
        None => print!("{out}"),
    }
    Ok(())
}

/// Reads `time_s,displacement_mm`; errors name the file and line.
fn read_depths(path: &Path) -> anyhow::Result<(Vec<f64>, Vec<f64>)> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("--csv {}", path.display()))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, header) = lines.next().ok_or_else(|| {
        anyhow!(
            "{}: empty; expected a header time_s,displacement_mm",
            path.display()
        )
    })?;
    let cols: Vec<&str> = header
        .trim_start_matches('\u{feff}')
        .split(',')
        .map(str::trim)
        .collect();
    let it = cols.iter().position(|c| *c == "time_s");
    let id = cols.iter().position(|c| *c == "displacement_mm");
    let (Some(it), Some(id)) = (it, id) else {
        bail!(
            "{}: the header must name time_s and displacement_mm (found {header})",
            path.display()
        );
    };
    let (mut time, mut depth) = (Vec::new(), Vec::new());
    for (i, l) in lines {
        let f: Vec<&str> = l.split(',').map(str::trim).collect();
        let num = |j: usize, name: &str| -> anyhow::Result<f64> {
            f.get(j)
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    anyhow!(
                        "{}: line {}: {name} is not a finite number",
                        path.display(),
                        i + 1
                    )
                })
        };
        let t = num(it, "time_s")?;
        if let Some(&p) = time.last() {
            if t < p {
                bail!(
                    "{}: line {}: time_s {t} goes back (previous {p})",
                    path.display(),
                    i + 1
                );
            }
        }
        time.push(t);
        depth.push(num(id, "displacement_mm")?);
    }
    if time.is_empty() {
        bail!("{}: no rows after the header", path.display());
    }
    Ok((time, depth))
}
