//! `palpate diagnose`: the sim-to-real gap of a calibrated base model —
//! where the misfit lies, which unmodelled effect causes it, how far it
//! shrinks once that effect is added (GAP.md).

use crate::model::ExperimentSpec;
use crate::records::TestData;
use crate::report::{gap_summary, gap_svg};
use crate::run::output::{write_atomic, write_json};
use palpate_uq::gap::GapOptions;
use std::path::{Path, PathBuf};

/// Diagnose the sim-to-real gap of a record: where the misfit lies, which effect causes it, how far it shrinks
///
/// The base model is calibrated to the record; the misfit is located on the
/// experiment's axis (time, or the drive for untimed records) against the
/// noise estimated from the data; each candidate effect is scored, refitted
/// and cross-validated on held-out blocks; the verdict is the effect that
/// earns its parameters, `none` when none does (or when what it explains is
/// immaterial), and confounded effects are reported as such.
///
/// Homogeneous records (no --benchmark): `--data TEST=FILE` with the test
/// kinds and columns of `palpate calibrate` (uniaxial tension/compression,
/// biaxial, planar, general biaxial, simple_shear; a time_s column makes the
/// record timed; options in brackets: 'simple_shear[axial_stretch=0.9]=FILE').
/// The base is the elastic analytic test of that kind with --law; the
/// candidates offered by default:
///   uniaxial, biaxial, planar   material_form, zero_offset (stretch offset),
///                               viscoelasticity (timed records only),
///                               tension_compression_asymmetry (only when the
///                               stretches lie on both sides of 1)
///   simple_shear                material_form, viscoelasticity (timed only)
///   general_biaxial             material_form
/// (material_form needs a law with a richer form: neo-hookean,
/// reduced-polynomial:N<6, ogden:N.)
///
/// Benchmark force records (--benchmark C1 or N1, --data FILE with columns
/// displacement_mm, force_N[, time_s]): C1 offers material_form,
/// viscoelasticity, zero_offset, compressibility, tool_compliance; N1
/// friction, boundary_condition (material_form, zero_offset on request). A
/// bare `--data FILE` without --benchmark is read as a C1 record.
///
/// A lab's own experiment (--experiment FILE|PRESET, docs/guide/experiment.md;
/// --data FILE or force=FILE with displacement_mm, force_N[, time_s]): the
/// base is the description's FE model (its law replaced by --base when
/// given), meshed for the record's deepest displacement, and the candidates
/// are the effects that model offers: on an axisymmetric cylinder friction
/// (a finite tool friction), boundary_condition (the specimen's thickness
/// fitted on a bonded base, by finite differences of whole runs; a sliding
/// base otherwise), material_form, zero_offset; on other setups their own.
///
/// Examples:
///   palpate diagnose --data uniaxial=brain.csv --law neo-hookean --json gap.json
///   palpate diagnose --benchmark C1 --data record.csv --base neo-hookean
///   palpate diagnose --experiment gel-disc.toml --data force=indent.csv
#[derive(Debug, clap::Args)]
#[command(verbatim_doc_comment, allow_negative_numbers = true)]
pub struct Args {
    /// Benchmark a force record comes from: C1 (analytic compression,
    /// seconds) or N1 (FE needle indentation on the coarse mesh, frictionless
    /// needle, bonded base; some 100 FE runs, a few minutes on 2 cores for a
    /// 10 mm record). Leave out for homogeneous records (TEST=FILE).
    #[arg(long, conflicts_with = "experiment")]
    pub benchmark: Option<String>,
    /// A lab's own experiment: an experiment file (TOML), a preset's name
    /// (palpate experiment list) or the description as JSON text; its FE
    /// model is the base.
    #[arg(long, value_name = "FILE|PRESET")]
    pub experiment: Option<String>,
    /// The record: TEST=FILE or TEST[key=value,...]=FILE for a homogeneous
    /// test (as `palpate calibrate --data`), or FILE with --benchmark (CSV
    /// with displacement_mm, force_N and, for rate effects, time_s).
    #[arg(long, value_name = "TEST=FILE")]
    pub data: String,
    /// Base material law (neo-hookean, mooney-rivlin, reduced-polynomial:N,
    /// yeoh, arruda-boyce, ogden:N, gent, veronda-westmann, humphrey); default
    /// neo-hookean, or with --experiment the description's law. `--law` is
    /// the same option.
    #[arg(long, visible_alias = "law")]
    pub base: Option<String>,
    /// Candidate effects, comma separated. Default: those listed above for
    /// the record's kind (C1: every effect the model offers; N1: `friction`
    /// and `boundary_condition`; add `material_form` and `zero_offset` here:
    /// on a single force-depth curve friction and a stiffening law cannot be
    /// told apart, and the report then says so).
    #[arg(long, value_delimiter = ',')]
    pub effects: Vec<String>,
    /// Family-wise significance level of the tests.
    #[arg(long, default_value_t = GapOptions::default().alpha)]
    pub alpha: f64,
    /// Contiguous blocks for the blocked cross-validation.
    #[arg(long, default_value_t = GapOptions::default().folds, value_parser = crate::run::limits::parse_count::<usize>)]
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

pub use crate::api::diagnose::{
    diagnose_experiment, diagnose_record, explanation_summary, DEFAULT_BASE,
};

/// The force record of an experiment's diagnosis, `FILE` or `force=FILE`
/// ([`crate::api::diagnose::read_force_record`]).
pub fn read_force_record(data: &str) -> anyhow::Result<TestData> {
    crate::api::diagnose::read_force_record(data, &[])
}

/// Runs `palpate diagnose` ([`crate::api::diagnose`]).
pub fn run(args: Args) -> anyhow::Result<()> {
    use crate::api::diagnose::{diagnose, gap_options, read_record};
    // The options are checked before the record is read, by their names.
    let options = gap_options(Some(args.alpha), Some(args.folds), &args.effects)?;
    let experiment = args
        .experiment
        .as_deref()
        .map(ExperimentSpec::from_option)
        .transpose()?;
    let record = match &experiment {
        Some(_) => read_force_record(&args.data)?,
        None => read_record(args.benchmark.as_deref(), &args.data, &[])?,
    };
    crate::run::output::check_outputs(
        &[Path::new(&record.file)],
        &crate::run::output::given(&[
            ("--json", &args.json),
            ("--report", &args.report),
            ("--plot", &args.plot),
        ]),
    )?;
    let report = diagnose(&record, experiment, args.base.as_deref(), &options)?;
    println!("{}", gap_summary(&report));
    println!("{}", explanation_summary(&report));
    if let Some(p) = &args.json {
        write_json(p, &report)?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = &args.report {
        write_atomic(p, report.to_markdown().as_bytes())?;
        eprintln!("wrote {}", p.display());
    }
    if let Some(p) = &args.plot {
        write_atomic(p, gap_svg(&report, &record.file).as_bytes())?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}
