//! `palpate diagnose`: the sim-to-real gap of a calibrated base model —
//! where the misfit lies, which unmodelled effect causes it, how far it
//! shrinks once that effect is added (GAP.md).

use crate::calibration::{TestData, TestKind};
use crate::models::{build, default_effects, gap_base, parse_effects};
use crate::output::{write_atomic, write_json};
use crate::report::{gap_summary, gap_svg};
use anyhow::Context;
use palpate_material::Law;
use palpate_uq::gap::{diagnose, GapOptions, GapReport};
use std::path::{Path, PathBuf};

/// Diagnose the gap between a base model and a measured force record.
///
/// The base model (e.g. incompressible neo-Hookean C1 compression) is
/// calibrated to the record; the misfit is located on the experiment's axis
/// (time, or displacement for untimed records) against the noise estimated
/// from the data; each candidate effect the model offers (material_form,
/// viscoelasticity, zero_offset, compressibility, tool_compliance for C1;
/// friction, boundary_condition, material_form, zero_offset for N1) is
/// scored, refitted and cross-validated on held-out blocks; the verdict is
/// the effect that earns its parameters, `none` when none does, and
/// confounded effects are reported as such.
///
/// Example: palpate diagnose --benchmark C1 --data record.csv --base neo-hookean --json gap.json
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment, allow_negative_numbers = true)]
pub struct Args {
    /// Benchmark the record comes from: C1 (analytic compression, seconds) or
    /// N1 (FE needle indentation on the coarse mesh, frictionless needle,
    /// bonded base; candidates friction, boundary_condition, material_form,
    /// zero_offset; some 100 FE runs, a few minutes on 2 cores for a 10 mm record).
    #[arg(long, default_value = "C1")]
    pub benchmark: String,
    /// The record: CSV with displacement_mm, force_N and (for rate effects) time_s.
    #[arg(long)]
    pub data: PathBuf,
    /// Base material law (neo-hookean, mooney-rivlin, reduced-polynomial:N, ...).
    #[arg(long, default_value = "neo-hookean")]
    pub base: String,
    /// Candidate effects, comma separated. Default: for C1 every effect the
    /// model offers; for N1 the GAP.md N1 effects `friction` and
    /// `boundary_condition` (add `material_form` and `zero_offset` here: on a
    /// single force-depth curve friction and a stiffening law cannot be told
    /// apart, and the report then says so).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Family-wise significance level of the tests.
    #[arg(long, default_value_t = GapOptions::default().alpha)]
    pub alpha: f64,
    /// Contiguous blocks for the blocked cross-validation.
    #[arg(long, default_value_t = GapOptions::default().folds, value_parser = crate::limits::parse_count::<usize>)]
    pub folds: usize,
    /// Write the diagnosis as JSON (GAP.md contract).
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<PathBuf>,
    /// Write a readable markdown report.
    #[arg(long, value_name = "OUT.md")]
    pub report: Option<PathBuf>,
    /// Draw data, base fit, enriched fit and residuals with the flagged windows (SVG).
    #[arg(long, value_name = "OUT.svg")]
    pub plot: Option<PathBuf>,
}

/// Diagnoses one record (shared with the manifest step).
pub fn diagnose_file(
    benchmark: &str,
    base: &str,
    data: &Path,
    options: &GapOptions,
) -> anyhow::Result<GapReport> {
    let law: Law = base
        .parse()
        .map_err(|e| anyhow::anyhow!("--base {base}: {e}"))?;
    let test = match TestKind::parse(benchmark) {
        Ok(t @ (TestKind::C1 | TestKind::N1)) => t,
        _ => anyhow::bail!(
            "--benchmark {benchmark}: the gap diagnosis takes a C1 or N1 record; expected C1 or N1"
        ),
    };
    let spec = gap_base(test, law).with_context(|| format!("--benchmark {benchmark}"))?;
    let model = build(&spec).map_err(|e| anyhow::anyhow!("{e}"))?;
    // C1 and N1 records share the columns displacement_mm, force_N[, time_s].
    let record = TestData::read("record", TestKind::C1, data)?;
    let mut options = options.clone();
    if options.effects.is_none() {
        options.effects = default_effects(&spec);
    }
    if let Some(effects) = &options.effects {
        crate::models::check_effects(model.as_ref(), effects)
            .map_err(|e| anyhow::anyhow!("--effects {e} (--benchmark {benchmark})"))?;
    }
    diagnose(model.as_ref(), &record.loading, &record.observed, &options)
        .with_context(|| format!("diagnosing {}", data.display()))
}

/// Runs `palpate diagnose`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mut options = GapOptions {
        alpha: args.alpha,
        folds: args.folds,
        ..GapOptions::default()
    };
    if !args.effects.is_empty() {
        options.effects = Some(parse_effects(&args.effects).context("--effects")?);
    }
    // The options are checked before the record is read, by their names.
    options.validate().map_err(|e| match e {
        palpate_uq::gap::GapError::InvalidOption { option, reason } => {
            anyhow::anyhow!("--{option} {reason}")
        }
        e => anyhow::anyhow!("{e}"),
    })?;
    crate::output::check_outputs(
        &[&args.data],
        &crate::output::given(&[
            ("--json", &args.json),
            ("--report", &args.report),
            ("--plot", &args.plot),
        ]),
    )?;
    let report = diagnose_file(&args.benchmark, &args.base, &args.data, &options)?;
    println!("{}", gap_summary(&report));
    if let Some(p) = &args.json {
        write_json(p, &report)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = &args.report {
        write_atomic(p, report.to_markdown().as_bytes())?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = &args.plot {
        write_atomic(
            p,
            gap_svg(&report, &args.data.display().to_string()).as_bytes(),
        )?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}
