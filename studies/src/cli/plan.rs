//! `palpate plan --experiment FILE|PRESET --vary FIELD=VALUES --noise SD`:
//! which candidate experiment would best determine the parameters, from
//! the Fisher information at a prior guess (`crate::steps::plan`).

use std::path::PathBuf;

use anyhow::anyhow;
use clap::Parser;

use crate::model::ExperimentSpec;
use crate::run::output::{check_outputs, given, write_json};
use crate::steps::plan::{noise_from_record, parse_noise, plan, table, PlanOptions, Vary};
use palpate_inverse::design::{Criterion, Noise};

/// Plan an experiment: expected standard errors of the parameters for candidate tools, depths, protocols
///
/// Before an experiment is run: for each candidate (the description with
/// some of its fields varied), the Fisher information J^T J / sigma^2 of the
/// free parameters at a prior guess, from one FE run with the model's exact
/// sensitivities (central finite differences for a model without them).
/// It gives the standard errors a fit to such a record would have, their
/// correlations and which parameters the record could not determine (a
/// parameter no output depends on, or two the force cannot tell apart, are
/// reported as not identifiable). Candidates are ranked, best first.
///
/// The free parameters are the description's fitted ones
/// (`C10 = { start = 1e-3 }`); fixed ones (`C10 = 1e-3`) are held. The
/// guess is the description's starts, or --guess NAME=VALUE.
///
/// --vary FIELD=V1,V2,.. or FIELD=START:STOP:COUNT (repeatable; every
/// combination is a candidate). FIELD is a path into the description as
/// `palpate experiment show NAME` prints it: tool.tip_radius, tool.radius,
/// tool.half_angle, protocol.segments[0].ramp_to (the depth of the first
/// ramp), protocol.segments[1].hold, protocol.samples, specimen.height,
/// mesh.level... A candidate the description's checks refuse (a tool as
/// large as the specimen) stops the plan with the field named.
///
/// --noise SD (N per sample), or a percentage of each candidate's peak
/// force (1%), or --noise-from RECORD.csv (estimated from the record's
/// second differences).
///
/// --criterion: worst-relative (default: the largest SE/|guess| among the
/// free parameters), d-optimal (-ln det of the information: the smallest
/// joint confidence region), or a parameter's name (its SE).
///
/// Examples:
///   palpate experiment show N1 > n1.toml     # edit: law = "reduced-polynomial:2"
///   palpate plan --experiment n1.toml --vary protocol.segments[0].ramp_to=2,5,10 \
///       --vary tool.tip_radius=1,2.5 --noise 0.002 --json plan.json
///   palpate plan --experiment N1 --vary tool.tip_radius=0.5:5:4 --noise 1%
#[derive(Debug, Parser)]
#[command(verbatim_doc_comment)]
pub struct Args {
    /// The experiment description: a file (TOML) or a preset's name (palpate experiment list).
    #[arg(long, value_name = "FILE|PRESET")]
    pub experiment: String,
    /// A field and its candidate values: FIELD=V1,V2,.. or FIELD=START:STOP:COUNT (repeatable).
    #[arg(long, value_name = "FIELD=VALUES")]
    pub vary: Vec<String>,
    /// Noise SD per sample in N (0.002), or a percentage of each candidate's peak force (1%).
    #[arg(long, value_name = "SD|P%")]
    pub noise: Option<String>,
    /// Estimate the noise SD from a record (CSV with displacement_mm,force_N).
    #[arg(long, value_name = "RECORD.csv", conflicts_with = "noise")]
    pub noise_from: Option<PathBuf>,
    /// How candidates are ranked: worst-relative, d-optimal or a parameter's name.
    #[arg(long, default_value = "worst-relative")]
    pub criterion: String,
    /// A prior guess replacing the description's start (repeatable).
    #[arg(long, value_name = "NAME=VALUE")]
    pub guess: Vec<String>,
    /// Write the plan as JSON (every candidate: standard errors, correlations, Fisher information).
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<PathBuf>,
}

/// Runs `palpate plan`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let spec = ExperimentSpec::from_option(&args.experiment)?;
    check_outputs(&[], &given(&[("--json", &args.json)]))?;
    let vary = args
        .vary
        .iter()
        .map(|v| v.parse::<Vary>().map_err(|e| anyhow!("--vary {e}")))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let noise: Noise = match (&args.noise, &args.noise_from) {
        (Some(n), _) => parse_noise(n).map_err(|e| anyhow!("--noise {e}"))?,
        (None, Some(f)) => {
            let sd = noise_from_record(f).map_err(|e| anyhow!("--noise-from {e}"))?;
            eprintln!("noise SD from {}: {sd:.4e} N", f.display());
            Noise::Sd(sd)
        }
        (None, None) => anyhow::bail!(
            "--noise: missing; give the noise SD per sample (--noise 0.002 in N, or --noise 1% of the peak force) or --noise-from RECORD.csv"
        ),
    };
    let criterion: Criterion = args
        .criterion
        .parse()
        .map_err(|e| anyhow!("--criterion {e}"))?;
    let guess = args
        .guess
        .iter()
        .map(|g| {
            let (n, v) = super::calibrate::split_pair(g, "NAME=VALUE, e.g. C10=0.002")
                .map_err(|e| anyhow!("--guess {e}"))?;
            let v: f64 = v
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| anyhow!("--guess {g}: `{v}` is not a finite number"))?;
            Ok((n.to_string(), v))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let options = PlanOptions {
        vary,
        noise,
        criterion,
        guess,
    };
    let p = plan(&spec, &options)?;
    print!("{}", table(&p));
    if let Some(path) = &args.json {
        write_json(path, &p)?;
    }
    Ok(())
}
