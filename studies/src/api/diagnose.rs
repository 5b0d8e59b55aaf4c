//! The sim-to-real gap of a record (GAP.md): the base model calibrated to
//! it, where the misfit lies, which unmodelled effect causes it and how far
//! it shrinks once that effect is added. `palpate diagnose` and the Python
//! package's `diagnose` call [`gap_options`], [`read_record`] (or
//! [`read_force_record`] for an experiment) and [`diagnose`].

use crate::model::{build, default_effects, gap_base_for, parse_effects, ExperimentSpec};
use crate::records::arrays::{placeholder, record_for, ArrayRecord};
use crate::records::data_option::read_data_with;
use crate::records::{ReadOptions, TestData, TestKind};
use crate::steps::diagnose::{experiment_base, experiment_effects};
use anyhow::Context;
use palpate_material::Law;
use palpate_uq::gap::{GapOptions, GapReport};
use std::path::Path;

/// The options of a diagnosis from the command line's (`--alpha`,
/// `--folds`, `--effects`), checked before any record is read; the errors
/// name the option.
pub fn gap_options(
    alpha: Option<f64>,
    folds: Option<usize>,
    effects: &[String],
) -> anyhow::Result<GapOptions> {
    let mut options = GapOptions::default();
    if let Some(a) = alpha {
        options.alpha = a;
    }
    if let Some(k) = folds {
        options.folds = k;
    }
    if !effects.is_empty() {
        options.effects = Some(parse_effects(effects).context("--effects")?);
    }
    options.validate().map_err(|e| match e {
        palpate_uq::gap::GapError::InvalidOption { option, reason } => {
            anyhow::anyhow!("--{option} {reason}")
        }
        e => anyhow::anyhow!("{e}"),
    })?;
    Ok(options)
}

/// Diagnoses `record`: against the FE model of `experiment` (its base law
/// replaced by `base` when given) or against the model of the record's test
/// with the law `base` ([`DEFAULT_BASE`] when `None`).
pub fn diagnose(
    record: &TestData,
    experiment: Option<ExperimentSpec>,
    base: Option<&str>,
    options: &GapOptions,
) -> anyhow::Result<GapReport> {
    match experiment {
        Some(spec) => diagnose_experiment(record, spec, base, options),
        None => diagnose_record(record, base.unwrap_or(DEFAULT_BASE), options),
    }
}

/// Reads the record of `--data`: a C1 or N1 force record with
/// `--benchmark` (or a bare FILE, read as C1), else a homogeneous record
/// through [`read_data_with`], the reader of `palpate calibrate`; a file
/// part `<array:K>` takes the columns of `arrays[K]`.
pub fn read_record(
    benchmark: Option<&str>,
    data: &str,
    arrays: &[ArrayRecord],
) -> anyhow::Result<TestData> {
    let force_record = |test: TestKind, path: &str| match record_for(path, arrays)? {
        Some(r) => TestData::from_table(
            "record",
            test,
            r.table("record arrays")?,
            ReadOptions::default(),
        ),
        None => TestData::read("record", test, Path::new(path)),
    };
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
        None if Path::new(data).is_file() || placeholder(data).is_some() => {
            force_record(TestKind::C1, data)
        }
        None => {
            let mut records = read_data_with(&[data.to_string()], None, arrays)?;
            Ok(records.remove(0))
        }
    }
}

/// The base law without --base (and without --experiment).
pub const DEFAULT_BASE: &str = "neo-hookean";

/// The force record of an experiment's diagnosis: `FILE` or `force=FILE`
/// (columns displacement_mm, force_N, optionally time_s), or `<array:K>`.
pub fn read_force_record(data: &str, arrays: &[ArrayRecord]) -> anyhow::Result<TestData> {
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
    match record_for(path, arrays).with_context(|| format!("--data {path}"))? {
        Some(r) => TestData::from_table(
            "record",
            TestKind::N1,
            r.table("record arrays")?,
            ReadOptions::default(),
        ),
        None => TestData::read("record", TestKind::N1, Path::new(path))
            .with_context(|| format!("--data {path}")),
    }
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
    palpate_uq::gap::diagnose(model.as_ref(), &record.loading, &record.observed, &options)
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
    palpate_uq::gap::diagnose(model.as_ref(), &record.loading, &record.observed, &options)
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
