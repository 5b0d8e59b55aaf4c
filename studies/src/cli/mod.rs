//! The `palpate` command line: one module per subcommand, each with its own
//! clap `Args` and a `run` function.

use clap::{Parser, Subcommand};

pub mod anova;
pub mod calibrate;
pub mod diagnose;
pub mod doe;
pub mod experiment;
pub mod localize;
pub mod merge;
pub mod plan;
pub mod reading;
pub mod realtime;
pub mod run;
pub mod sample;
pub mod simulate;
pub mod simulate_r2;

/// palpate: calibrate soft-tissue material laws from force curves, quantify
/// their uncertainty and diagnose the gap between simulation and measurement.
///
/// Units throughout: mm, N, MPa, s. Data files are CSV with a header naming
/// each column with its unit (time_s, displacement_mm, force_N, stretch,
/// stress_MPa); lines starting with # are comments.
#[derive(Debug, Parser)]
#[command(name = "palpate", version, about, long_about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
///
/// Each subcommand's help is its `Args` doc comment: the first paragraph is
/// the line of `palpate --help`, the rest the long help of `palpate CMD
/// --help`. A `///` comment on a variant here would replace both (clap), so
/// the variants carry plain comments.
#[derive(Debug, Subcommand)]
pub enum Command {
    // Fit a law to homogeneous tests or a C1 record (calibrate::Args).
    Calibrate(calibrate::Args),
    // The FE forward models N1, N3, C1, Q1, R2 (simulate::Args).
    Simulate(simulate::Args),
    // MCMC posterior of a law's parameters (sample::Args).
    Sample(sample::Args),
    // ANOVA of a runs table (anova::Args).
    Anova(anova::Args),
    // Designed experiments from a manifest (doe::Args).
    Doe(doe::Args),
    // Sim-to-real gap diagnosis (diagnose::Args).
    Diagnose(diagnose::Args),
    // A whole study from one manifest (run::Args).
    Run(run::Args),
    // Assemble a study's results from its shards (merge::Args).
    Merge(merge::Args),
    // The real-time force model (realtime::Args); `surrogate` is its former
    // name, kept as a hidden alias.
    #[command(alias = "surrogate")]
    Realtime(realtime::Args),
    // Nodule localisation from an R2 record (localize::Args).
    Localize(localize::Args),
    // Experiment descriptions: presets, show, check (experiment::Args).
    Experiment(experiment::Args),
    // Experiment design from the Fisher information (plan::Args).
    Plan(plan::Args),
}

/// The command line with a negative number after an option joined to it
/// (`--depth -1e-3` -> `--depth=-1e-3`), so that clap reads it as the
/// option's value: clap's own test for a negative number takes `-1e-3`,
/// `-.5` and `-inf` for flags ("unexpected argument '-1'"), and the value's
/// check then names the option instead.
pub fn join_negative_values<I: IntoIterator<Item = std::ffi::OsString>>(
    args: I,
) -> Vec<std::ffi::OsString> {
    let mut out: Vec<std::ffi::OsString> = Vec::new();
    for a in args {
        let joined = match (out.last().and_then(|p| p.to_str()), a.to_str()) {
            (Some(opt), Some(value))
                if opt.starts_with("--")
                    && opt.len() > 2
                    && !opt.contains('=')
                    && value.starts_with('-')
                    && value.parse::<f64>().is_ok() =>
            {
                Some(format!("{opt}={value}"))
            }
            _ => None,
        };
        match joined {
            Some(j) => *out.last_mut().expect("an option before") = j.into(),
            None => out.push(a),
        }
    }
    out
}

/// The `--law` of `calibrate` and `sample`, parsed; missing or unknown is
/// an error naming the option.
fn parse_law(text: Option<&str>) -> anyhow::Result<palpate_material::Law> {
    let text = text
        .ok_or_else(|| anyhow::anyhow!("--law: give the material law (e.g. --law neo-hookean)"))?;
    text.parse()
        .map_err(|e| anyhow::anyhow!("--law {text}: {e}"))
}

/// Runs the parsed command line.
pub fn dispatch(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Calibrate(a) => calibrate::run(a),
        Command::Simulate(a) => simulate::run(a),
        Command::Sample(a) => sample::run(a),
        Command::Anova(a) => anova::run(a),
        Command::Doe(a) => doe::run(a),
        Command::Diagnose(a) => diagnose::run(a),
        Command::Run(a) => run::run(a),
        Command::Merge(a) => merge::run(a),
        Command::Realtime(a) => realtime::run(a),
        Command::Localize(a) => localize::run(a),
        Command::Experiment(a) => experiment::run(a),
        Command::Plan(a) => plan::run(a),
    }
}
