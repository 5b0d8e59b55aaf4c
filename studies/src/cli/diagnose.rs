//! `palpate diagnose`: the sim-to-real gap of a calibrated base model —
//! where the misfit lies, which unmodelled effect causes it, how far it
//! shrinks once that effect is added (GAP.md).

use crate::cli::calibrate::read_data;
use crate::model::{build, default_effects, gap_base_for, parse_effects, ExperimentSpec};
use crate::records::{TestData, TestKind};
use crate::report::{gap_summary, gap_svg};
use crate::run::output::{write_atomic, write_json};
use crate::steps::diagnose::{experiment_base, experiment_effects};
use anyhow::Context;
use palpate_material::Law;
use palpate_uq::gap::{diagnose, GapOptions, GapReport};
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

/// Reads the record of `--data`: a C1 or N1 force record with
/// `--benchmark` (or a bare FILE, read as C1), else a homogeneous record
/// through [`read_data`], the reader of `palpate calibrate`.
pub fn read_record(benchmark: Option<&str>, data: &str) -> anyhow::Result<TestData> {
    let force_record = |test: TestKind, path: &str| TestData::read("record", test, Path::new(path));
    match benchmark {
        Some(b) => match TestKind::parse(b) {
            Ok(t @ (TestKind::C1 | TestKind::N1)) => {
                let path = data.split_once('=').filter(|(k, _)| k.eq_ignore_ascii_case(b));
                force_record(t, path.map(|(_, p)| p).unwrap_or(data))
            }
            _ => anyhow::bail!(
                "--benchmark {b}: the gap diagnosis takes a C1 or N1 force record; expected C1 or N1 (or leave --benchmark out and give --data TEST=FILE for a homogeneous record)"
            ),
        },
        None if Path::new(data).is_file() => force_record(TestKind::C1, data),
        None => {
            let mut records = read_data(&[data.to_string()], None)?;
            Ok(records.remove(0))
        }
    }
}

/// The base law without --base (and without --experiment).
pub const DEFAULT_BASE: &str = "neo-hookean";

/// The force record of an experiment's diagnosis: `FILE` or `force=FILE`
/// (columns displacement_mm, force_N, optionally time_s).
pub fn read_force_record(data: &str) -> anyhow::Result<TestData> {
    let path = match data.split_once('=') {
        Some((k, p)) if !Path::new(data).is_file() => {
            anyhow::ensure!(
                k.eq_ignore_ascii_case("force") || k.eq_ignore_ascii_case("n1"),
                "--data {data}: an experiment is diagnosed on a force record: FILE or force=FILE (columns displacement_mm, force_N), not {k}=FILE"
            );
            p
        }
        _ => data,
    };
    TestData::read("record", TestKind::N1, Path::new(path))
        .with_context(|| format!("--data {path}"))
}

/// Diagnoses a force record of an experiment (`--experiment`): the base is
/// its FE model ([`experiment_base`]), the candidates unless given are the
/// effects it offers that the record can show ([`experiment_effects`]).
pub fn diagnose_experiment(
    record: &TestData,
    spec: ExperimentSpec,
    base: Option<&str>,
    options: &GapOptions,
) -> anyhow::Result<GapReport> {
    let spec = experiment_base(spec, base, record)?;
    let model = build(&spec).map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut options = options.clone();
    if options.effects.is_none() {
        options.effects = Some(experiment_effects(model.as_ref(), &record.loading));
    }
    if let Some(effects) = &options.effects {
        crate::model::check_effects(model.as_ref(), effects)
            .map_err(|e| anyhow::anyhow!("--effects {e}"))?;
        anyhow::ensure!(
            !effects.is_empty(),
            "{}: {} offers no candidate effect this record can show; give --effects",
            record.file,
            model.name()
        );
    }
    diagnose(model.as_ref(), &record.loading, &record.observed, &options)
        .with_context(|| format!("diagnosing {}", record.file))
}

/// Diagnoses one record (shared with the manifest step).
pub fn diagnose_record(
    record: &TestData,
    base: &str,
    options: &GapOptions,
) -> anyhow::Result<GapReport> {
    let law: Law = base
        .parse()
        .map_err(|e| anyhow::anyhow!("--base {base}: {e}"))?;
    let spec = gap_base_for(record, law).with_context(|| format!("--data {}", record.file))?;
    let model = build(&spec).map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut options = options.clone();
    if options.effects.is_none() {
        options.effects = default_effects(&spec, model.as_ref(), &record.loading);
    }
    if options.paths.is_none() {
        options.paths = crate::steps::diagnose::noise_paths(record);
    }
    if let Some(effects) = &options.effects {
        crate::model::check_effects(model.as_ref(), effects)
            .map_err(|e| anyhow::anyhow!("--effects {e} ({} record)", record.name))?;
        if effects.is_empty() {
            anyhow::bail!(
                "{}: {} offers no candidate effect this record can show; give --effects or a law with a richer form (neo-hookean, reduced-polynomial:N, ogden:N)",
                record.file,
                model.name()
            );
        }
    }
    diagnose(model.as_ref(), &record.loading, &record.observed, &options)
        .with_context(|| format!("diagnosing {}", record.file))
}

/// The explanation set and its remainder, for stdout: one line per member
/// (parameters with standard errors, shares of the excess misfit), then the
/// remainder's note.
pub fn explanation_summary(r: &GapReport) -> String {
    use std::fmt::Write;
    let unit = r.plot.data_unit();
    let mut s = String::new();
    if r.explanation_set.is_empty() {
        let _ = writeln!(s, "explanation: none");
    } else {
        let names: Vec<&str> = r.explanation_set.iter().map(|m| m.effect.name()).collect();
        let _ = writeln!(s, "explanation: {{{}}}", names.join(", "));
    }
    let pct = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{:.0} %", 100.0 * v));
    for (k, m) in r.explanation_set.iter().enumerate() {
        let _ = writeln!(
            s,
            "  {}. {}: {}; share of the excess misfit {} (in order), {} (dropped one out); misfit after {:.4e} {unit}, held-out {:.4e} {unit}{}",
            k + 1,
            m.effect,
            m.params_text(),
            pct(m.share_marginal),
            pct(m.share_dropped),
            m.misfit_after,
            m.heldout_after,
            if m.confounded_with.is_empty() {
                String::new()
            } else {
                let c: Vec<&str> = m.confounded_with.iter().map(|e| e.name()).collect();
                format!("; cannot be told apart from {}", c.join(", "))
            }
        );
    }
    if !r.dropped.is_empty() {
        let d: Vec<&str> = r.dropped.iter().map(|e| e.name()).collect();
        let _ = writeln!(s, "  dropped by the backward check: {}", d.join(", "));
    }
    let _ = write!(s, "remainder: {}", r.remainder.note);
    s
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
    let experiment = args
        .experiment
        .as_deref()
        .map(ExperimentSpec::from_option)
        .transpose()?;
    let record = match &experiment {
        Some(_) => read_force_record(&args.data)?,
        None => read_record(args.benchmark.as_deref(), &args.data)?,
    };
    crate::run::output::check_outputs(
        &[Path::new(&record.file)],
        &crate::run::output::given(&[
            ("--json", &args.json),
            ("--report", &args.report),
            ("--plot", &args.plot),
        ]),
    )?;
    let report = match experiment {
        Some(spec) => diagnose_experiment(&record, spec, args.base.as_deref(), &options)?,
        None => diagnose_record(
            &record,
            args.base.as_deref().unwrap_or(DEFAULT_BASE),
            &options,
        )?,
    };
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
