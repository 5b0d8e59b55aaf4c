//! `palpate experiment list|show|check`: the shipped presets, a preset as
//! TOML to copy and edit, and a description checked with its parameters
//! and the model it builds.

use std::path::PathBuf;

use crate::model::experiment::{preset, preset_names, ExperimentSpec};
use palpate_fe::experiment::Experiment;

/// Experiment descriptions: list the presets, print one to edit, check a file
///
/// An experiment description (TOML) names the specimen (an axisymmetric
/// cylinder, optionally layered; a block; a Gmsh mesh), its materials with
/// their parameters (fitted: `C10 = { start = 2e-3 }`, fixed: `C10 = 2e-3`),
/// the tool, the supports, the protocol and the mesh
/// (docs/guide/experiment.md). Every command takes one with --experiment
/// FILE (or a preset's name); a study manifest holds them as
/// [experiments.NAME] tables.
///
/// Examples:
///   palpate experiment list
///   palpate experiment show N1 > mine.toml
///   palpate experiment check mine.toml
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment)]
pub struct Args {
    #[command(subcommand)]
    pub command: Sub,
}

/// The subcommands of `palpate experiment`.
#[derive(Debug, clap::Subcommand)]
pub enum Sub {
    /// The presets: the reference problems of docs/benchmarks.md as descriptions.
    List,
    /// Print a preset as TOML, to copy and edit.
    Show {
        /// A preset's name (palpate experiment list).
        name: String,
    },
    /// Parse and check a description; print its parameters and the model it builds.
    Check {
        /// An experiment file (TOML) or a preset's name.
        file: PathBuf,
    },
}

/// Runs `palpate experiment`.
pub fn run(args: Args) -> anyhow::Result<()> {
    match args.command {
        Sub::List => {
            for name in preset_names() {
                let e = preset(&name);
                println!("{name:<10} {}", e.as_ref().map_or(String::new(), summary));
            }
            Ok(())
        }
        Sub::Show { name } => {
            print!("{}", show(&name)?);
            Ok(())
        }
        Sub::Check { file } => {
            print!("{}", check_text(&file.to_string_lossy())?);
            Ok(())
        }
    }
}

/// A preset as an experiment file: a header naming it, then its TOML.
pub fn show(name: &str) -> anyhow::Result<String> {
    let e = preset(name).ok_or_else(|| {
        anyhow::anyhow!(
            "`{name}`: not a preset; presets: {}",
            preset_names().join(", ")
        )
    })?;
    let name = e.name.clone().unwrap_or_else(|| name.to_string());
    Ok(format!(
        "# palpate experiment preset {name}: {}\n# The reference problem {name} of docs/benchmarks.md. Copy this file, edit it,\n# check it with `palpate experiment check FILE` and give it to any command\n# with --experiment FILE. Units mm, N, MPa, s.\n\n{}",
        summary(&e),
        e.to_toml()
    ))
}

/// The report of `palpate experiment check`: the parameters (name, start,
/// fitted or fixed, unit) and the model the description builds.
pub fn check_text(arg: &str) -> anyhow::Result<String> {
    let spec = ExperimentSpec::from_option(arg)
        .map_err(|e| anyhow::anyhow!("{}", e.to_string().trim_start_matches("--experiment ")))?;
    let e = &spec.experiment;
    let params = e
        .parameters()
        .map_err(|err| anyhow::anyhow!("{}: {err}", spec.source))?;
    let mut s = format!("{}: {}\n\nparameters\n", spec.source, summary(e));
    s.push_str(&format!(
        "  {:<16} {:>12}  {:<8} {:<6} bounds\n",
        "name", "start", "role", "unit"
    ));
    for p in &params {
        let role = match (p.fit, p.nuisance) {
            (false, _) => "fixed",
            (true, true) => "nuisance",
            (true, false) => "fitted",
        };
        s.push_str(&format!(
            "  {:<16} {:>12.6e}  {:<8} {:<6} [{}, {}]\n",
            p.spec.name, p.spec.initial, role, p.spec.unit, p.spec.lower, p.spec.upper
        ));
    }
    match e.model() {
        Ok(m) => s.push_str(&format!("\nmodel: {}\n", m.as_forward().name())),
        Err(err) => anyhow::bail!("{}: {err}", spec.source),
    }
    Ok(s)
}

/// One line: the specimen, the tool and the materials' laws.
pub fn summary(e: &Experiment) -> String {
    use palpate_fe::experiment::{Specimen, Tool};
    let specimen = match &e.specimen {
        Specimen::Cylinder(c) => {
            let h = c.height.or_else(|| {
                (!c.layers.is_empty()).then(|| c.layers.iter().map(|l| l.thickness).sum())
            });
            format!(
                "cylinder r {} x h {} mm{}",
                c.radius,
                h.map_or("?".into(), |h| h.to_string()),
                if c.layers.is_empty() {
                    String::new()
                } else {
                    format!(", {} layers", c.layers.len())
                }
            )
        }
        Specimen::Block(b) => match b.size {
            Some([x, y, z]) => format!("block {x} x {y} x {z} mm"),
            None => format!(
                "block {} x {} mm",
                b.length.unwrap_or(f64::NAN),
                b.height.unwrap_or(f64::NAN)
            ),
        },
        Specimen::Mesh(m) => format!("mesh {}", m.file),
    };
    let tool = match &e.tool {
        Tool::Sphere(t) => format!("sphere r {} mm", t.radius),
        Tool::Cone(_) => "cone".into(),
        Tool::Needle(_) => "needle".into(),
        Tool::FlatPunch(t) => format!("flat punch r {} mm", t.radius),
        Tool::Platens(_) => "platens".into(),
        Tool::Wheel(t) => format!("wheel r {} mm", t.radius),
    };
    let laws: Vec<String> = e
        .materials
        .iter()
        .map(|(n, m)| format!("{n}: {}", m.law))
        .collect();
    format!("{specimen}, {tool}; {}", laws.join(", "))
}
