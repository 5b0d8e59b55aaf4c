//! `palpate simulate`: run a finite-element forward model (N1 needle
//! indentation or C1 compression, BENCHMARKS.md) and write its force curve.

use std::path::PathBuf;

use anyhow::{anyhow, bail, Context};
use indicatif::{ProgressBar, ProgressStyle};
use palpate_core::ForwardModel;
use palpate_core::{Drive, Loading};
use palpate_fe::{Progress, Simulation};
use palpate_material::Law;

use crate::models::{C1FeSpec, Model, ModelSpec, N1NeedleSpec};
use crate::output::write_atomic;
use crate::plot::{Plot, Series};

/// Options of `palpate simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Benchmark: N1 (needle indentation of a 70 x 80 mm cylinder) or C1 (compression of a 38 x 9 mm cylinder).
    #[arg(long, value_parser = ["N1", "C1", "n1", "c1"])]
    pub benchmark: String,
    /// Material law: neo-hookean, mooney-rivlin, reduced-polynomial:N, yeoh, arruda-boyce, ogden:N.
    #[arg(long)]
    pub law: String,
    /// A law parameter in MPa (or 1), e.g. --param C10=0.001101295; repeat for each parameter of the law.
    #[arg(long = "param", value_name = "NAME=VALUE")]
    pub params: Vec<String>,
    /// N1: Coulomb friction coefficient between needle and material [default: 0.8].
    #[arg(long)]
    pub friction: Option<f64>,
    /// C1: bonded (no-slip) platens instead of frictionless ones.
    #[arg(long)]
    pub bonded: bool,
    /// N1: bottom face free to slide radially instead of fixed.
    #[arg(long)]
    pub sliding_base: bool,
    /// N1 tool: needle (BENCHMARKS.md), sphere:RADIUS, punch:RADIUS (flat, edge rounded 0.1 mm) or platen [default: needle].
    #[arg(long)]
    pub tool: Option<String>,
    /// Final tool displacement in mm (default: 10 for N1, 2 for C1).
    #[arg(long)]
    pub depth: Option<f64>,
    /// Spacing of the output samples in mm (default: 0.25 for N1, 0.1 for C1).
    #[arg(long)]
    pub step: Option<f64>,
    /// Mesh density: coarse, medium, fine or a refinement level N = 1..12 (N1: elements of 0.4/N mm under the tool; C1: 19N x 9N elements) [default: medium].
    #[arg(long)]
    pub mesh: Option<String>,
    /// Incompressibility: exact (Lagrange multiplier per element) or a bulk-to-shear modulus ratio K/mu such as 1000 [default: exact].
    #[arg(long)]
    pub bulk: Option<String>,
    /// Write the force curve as CSV (columns displacement_mm,force_N).
    #[arg(long, value_name = "OUT.csv")]
    pub csv: Option<PathBuf>,
    /// Write the final deformed state as a VTK .vtu file for ParaView.
    #[arg(long, value_name = "OUT.vtu")]
    pub vtu: Option<PathBuf>,
    /// Write an SVG plot of force against displacement.
    #[arg(long, value_name = "OUT.svg")]
    pub plot: Option<PathBuf>,
}

fn parse_params(law: &Law, given: &[String]) -> anyhow::Result<Vec<f64>> {
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
    law.check(&p)
        .map_err(|e| anyhow!("parameters of {law}: {e}"))?;
    Ok(p)
}

/// The model the options describe: N1 -> `n1_needle`, C1 -> `c1_fe`
/// (the settings a benchmark does not have are ignored).
pub fn model_spec(args: &Args) -> ModelSpec {
    if args.benchmark.eq_ignore_ascii_case("n1") {
        ModelSpec::N1Needle(N1NeedleSpec {
            law: args.law.clone(),
            friction: args.friction,
            mesh: args.mesh.clone(),
            bulk: args.bulk.clone(),
            base: args.sliding_base.then(|| "sliding".into()),
            tool: args.tool.clone(),
        })
    } else {
        ModelSpec::C1Fe(C1FeSpec {
            law: args.law.clone(),
            platens: args.bonded.then(|| "bonded".into()),
            mesh: args.mesh.clone(),
            bulk: args.bulk.clone(),
        })
    }
}

/// Runs `palpate simulate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let model = model_spec(&args)
        .validate()
        .map_err(|e| anyhow!("{}", e.as_option()))?;
    let law: Law = args
        .law
        .parse()
        .map_err(|e| anyhow!("--law `{}`: {e}", args.law))?;
    let theta = parse_params(&law, &args.params)?;
    let n1 = args.benchmark.eq_ignore_ascii_case("n1");
    let depth = args.depth.unwrap_or(if n1 { 10.0 } else { 2.0 });
    let step = args.step.unwrap_or(if n1 { 0.25 } else { 0.1 });
    if !(depth > 0.0 && depth.is_finite() && step > 0.0 && step.is_finite()) {
        bail!("--depth and --step must be positive (got {depth} and {step})");
    }
    let n = (depth / step).ceil() as usize;
    let drive: Vec<f64> = (0..=n).map(|k| (k as f64 * step).min(depth)).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive.clone());

    let bar = ProgressBar::new(drive.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} samples  {msg}  [{elapsed_precise}]")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut cb = |p: &Progress| {
        bar.set_position(p.sample as u64 + 1);
        bar.set_message(format!(
            "d = {:.3} mm  F = {:.5} N  ({} increments, {} iterations)",
            p.drive,
            p.outputs.first().copied().unwrap_or(0.0),
            p.increments,
            p.iterations
        ));
    };
    let (title, result) = match &model {
        Model::N1Needle(m) => (m.name(), m.simulate(&theta, &loading, Some(&mut cb))),
        Model::C1Fe(m) => (m.name(), m.simulate(&theta, &loading, Some(&mut cb))),
        _ => bail!("--benchmark {}: expected N1 or C1", args.benchmark),
    };
    bar.finish_and_clear();
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
                write_curve(path, &drive[..completed.len()], &completed)?;
                eprintln!(
                    "wrote the {} converged samples to {}",
                    completed.len(),
                    path.display()
                );
            }
            bail!("{title}: did not converge at sample {sample} (drive {d} mm) after {cuts} step cuts: {reason}");
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
    if let Some(path) = &args.csv {
        write_curve(path, &drive, &sim.forces)?;
    }
    if let Some(path) = &args.vtu {
        let vtu = palpate_fe::vtu::to_vtu(&solver).map_err(|e| anyhow!("{e}"))?;
        write_atomic(path, vtu.as_bytes())?;
    }
    if let Some(path) = &args.plot {
        let plot = Plot::new(&title, "displacement (mm)", "force (N)").with(Series::line(
            "FE",
            &drive,
            &sim.forces,
        ));
        write_atomic(path, plot.to_svg().as_bytes())
            .with_context(|| format!("plot {}", path.display()))?;
    }
    if args.csv.is_none() {
        println!("displacement_mm,force_N");
        for (d, f) in drive.iter().zip(&sim.forces) {
            println!("{d:.6},{f:.9e}");
        }
    }
    Ok(())
}

fn write_curve(path: &std::path::Path, d: &[f64], f: &[f64]) -> anyhow::Result<()> {
    let mut s = String::from("displacement_mm,force_N\n");
    for (d, f) in d.iter().zip(f) {
        s.push_str(&format!("{d:.6},{f:.9e}\n"));
    }
    write_atomic(path, s.as_bytes())
}
