//! `palpate simulate`: run a finite-element forward model (N1 needle
//! indentation or C1 compression, BENCHMARKS.md) and write its force curve.

use std::path::PathBuf;

use anyhow::{anyhow, bail, Context};
use indicatif::{ProgressBar, ProgressStyle};
use palpate_core::{Drive, Loading};
use palpate_fe::{
    Base, Bulk, C1Fe, MeshDensity, N1Needle, Platens, Progress, Simulation, ToolShape,
};
use palpate_material::Law;

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
    /// N1: Coulomb friction coefficient between needle and material (default 0.8).
    #[arg(long, default_value_t = 0.8)]
    pub friction: f64,
    /// C1: bonded (no-slip) platens instead of frictionless ones.
    #[arg(long)]
    pub bonded: bool,
    /// N1: bottom face free to slide radially instead of fixed.
    #[arg(long)]
    pub sliding_base: bool,
    /// N1 tool: needle (BENCHMARKS.md), sphere:RADIUS, punch:RADIUS (flat, edge rounded 0.1 mm) or platen.
    #[arg(long, default_value = "needle")]
    pub tool: String,
    /// Final tool displacement in mm (default: 10 for N1, 2 for C1).
    #[arg(long)]
    pub depth: Option<f64>,
    /// Spacing of the output samples in mm (default: 0.25 for N1, 0.1 for C1).
    #[arg(long)]
    pub step: Option<f64>,
    /// Mesh density: coarse, medium, fine or a refinement level N (N1: elements of 0.4/N mm under the tool; C1: 19N x 9N elements).
    #[arg(long, default_value = "medium")]
    pub mesh: String,
    /// Incompressibility: exact (Lagrange multiplier per element) or a bulk-to-shear modulus ratio K/mu such as 1000.
    #[arg(long, default_value = "exact")]
    pub bulk: String,
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

fn parse_mesh(s: &str) -> anyhow::Result<usize> {
    match s {
        "coarse" => Ok(1),
        "medium" => Ok(2),
        "fine" => Ok(3),
        n => match n.parse::<usize>() {
            Ok(k) if (1..=12).contains(&k) => Ok(k),
            _ => bail!("--mesh `{s}`: expected coarse, medium, fine or a level 1..12"),
        },
    }
}

fn parse_bulk(s: &str) -> anyhow::Result<Bulk> {
    if s == "exact" {
        return Ok(Bulk::Exact);
    }
    match s.parse::<f64>() {
        Ok(r) if r > 0.0 && r.is_finite() => Ok(Bulk::Ratio(r)),
        _ => bail!("--bulk `{s}`: expected `exact` or a positive ratio K/mu such as 1000"),
    }
}

fn parse_tool(s: &str) -> anyhow::Result<ToolShape> {
    let num = |v: &str| -> anyhow::Result<f64> {
        v.parse::<f64>()
            .ok()
            .filter(|r| *r > 0.0 && r.is_finite())
            .ok_or_else(|| anyhow!("--tool `{s}`: `{v}` is not a positive radius in mm"))
    };
    match s.split_once(':') {
        None if s == "needle" => Ok(ToolShape::n1_needle()),
        None if s == "platen" => Ok(ToolShape::Platen),
        Some(("sphere", r)) => Ok(ToolShape::Sphere { radius: num(r)? }),
        Some(("punch", r)) => {
            let radius = num(r)?;
            Ok(ToolShape::FlatPunch {
                radius,
                edge_radius: (0.1f64).min(0.5 * radius),
            })
        }
        _ => bail!("--tool `{s}`: expected needle, sphere:RADIUS, punch:RADIUS or platen"),
    }
}

/// Runs `palpate simulate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let law: Law = args
        .law
        .parse()
        .map_err(|e| anyhow!("--law `{}`: {e}", args.law))?;
    let theta = parse_params(&law, &args.params)?;
    let level = parse_mesh(&args.mesh)?;
    let bulk = parse_bulk(&args.bulk)?;
    let n1 = args.benchmark.eq_ignore_ascii_case("n1");
    let depth = args.depth.unwrap_or(if n1 { 10.0 } else { 2.0 });
    let step = args.step.unwrap_or(if n1 { 0.25 } else { 0.1 });
    if !(depth > 0.0 && depth.is_finite() && step > 0.0 && step.is_finite()) {
        bail!("--depth and --step must be positive (got {depth} and {step})");
    }
    if !(args.friction >= 0.0 && args.friction.is_finite()) {
        bail!("--friction must be >= 0 (got {})", args.friction);
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
    let (title, result) = if n1 {
        let mut m = N1Needle::new(law);
        m.friction = args.friction;
        m.bulk = bulk;
        m.mesh = MeshDensity { level };
        m.tool = parse_tool(&args.tool)?;
        if args.sliding_base {
            m.base = Base::Sliding;
        }
        (
            palpate_core::ForwardModel::name(&m),
            m.simulate(&theta, &loading, Some(&mut cb)),
        )
    } else {
        let mut m = C1Fe::new(
            law,
            if args.bonded {
                Platens::Bonded
            } else {
                Platens::Frictionless
            },
        );
        m.bulk = bulk;
        m.elements = (19 * level, 9 * level);
        (
            palpate_core::ForwardModel::name(&m),
            m.simulate(&theta, &loading, Some(&mut cb)),
        )
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
