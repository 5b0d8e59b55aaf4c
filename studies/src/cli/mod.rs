//! The `palpate` command line: one module per subcommand, each with its own
//! clap `Args` and a `run` function.

use clap::{Parser, Subcommand};

pub mod anova;
pub mod calibrate;
pub mod diagnose;
pub mod doe;
pub mod localize;
pub mod merge;
pub mod run;
pub mod sample;
pub mod sample_fe;
pub mod simulate;
pub mod simulate_r2;
pub mod surrogate;

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
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Fit a hyperelastic law to homogeneous-test data or to a C1 force record.
    Calibrate(calibrate::Args),
    /// Run a finite-element forward model (N1 needle, C1 compression) and write its force curve.
    Simulate(simulate::Args),
    /// Sample the Bayesian posterior of a model's parameters by MCMC, with diagnostics.
    Sample(sample::Args),
    /// ANOVA of a table with one row per run (factor columns hold level names).
    Anova(anova::Args),
    /// Generate and run a designed experiment (factorial design) from a manifest.
    Doe(doe::Args),
    // The help of `diagnose` is its Args' doc comment (the candidates per test kind).
    Diagnose(diagnose::Args),
    /// Run a whole study described by one TOML manifest into a run folder.
    Run(run::Args),
    /// Assemble a study's results from its shards (palpate run --shard I/N).
    Merge(merge::Args),
    /// Build (from FE runs) or query the real-time force surrogate of Q1 or N1.
    Surrogate(surrogate::Args),
    /// Locate nodules (x, depth, 94 % intervals) from an R2 rolled force record.
    Localize(localize::Args),
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
        Command::Surrogate(a) => surrogate::run(a),
        Command::Localize(a) => localize::run(a),
    }
}
