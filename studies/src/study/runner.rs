//! Runs a study manifest into a run folder:
//!
//! * `results.json` — every number, byte-identical on a rerun (no times, no
//!   paths outside the manifest's own names);
//! * `report.md` — a readable report with comparison tables;
//! * `plots/*.svg`;
//! * `provenance.json` — hashes, git commit, crate versions, seed, threads, timings.
//!
//! The folder is staged, locked, marked while incomplete and resumable
//! ([`crate::run::run_folder`]): each fit and each diagnosed record is a unit
//! cached under the hash of its inputs, so a rerun (after a kill, or after
//! an edit of another step) computes only the units whose inputs changed.

use crate::records::{TestData, TestKind};
use crate::run::output::{write_atomic, write_json};
use crate::run::provenance::{crate_versions, git_state, hash_file, Provenance};
use crate::run::run_folder::RunFolder;
use crate::run::shard::{Shard, ShardRecord};
use crate::run::step::{Run, Sharding};
use crate::study::manifest::Manifest;
use anyhow::Context;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

pub use crate::run::step::{RunObserver, StepResult};

/// The results of a whole study (`results.json`).
#[derive(Debug, Clone, Serialize)]
pub struct StudyResults {
    pub study: String,
    pub description: String,
    pub seed: u64,
    pub steps: Vec<StepResult>,
}

/// How to run a study.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Run folder (default `runs/<study name>`).
    pub out: Option<PathBuf>,
    /// Compute every unit again (the cache of finished units is emptied).
    pub fresh: bool,
    /// Compute only this shard's units into the cache ([`crate::run::shard`]):
    /// no results are written, other shards may run at the same time.
    pub shard: Option<Shard>,
}

/// How many units a run computed, found in the cache, or left to other
/// shards (these counts are not part of the results).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct UnitCounts {
    pub computed: usize,
    pub cached: usize,
    /// Units of other shards not in the cache yet (shard runs only).
    pub others: usize,
}

/// What [`run_study_counted`] did.
#[derive(Debug, Clone)]
pub struct RunSummary {
    /// The run folder.
    pub folder: PathBuf,
    pub units: UnitCounts,
    /// Steps a shard run deferred (they need the results of steps whose
    /// units other shards compute).
    pub deferred_steps: Vec<String>,
}

/// Runs the manifest at `path` into `out_dir` (default `runs/<study name>`),
/// reusing the finished units of an earlier run into the same folder.
pub fn run_study(
    path: &Path,
    out_dir: Option<&Path>,
    observer: &dyn RunObserver,
) -> anyhow::Result<PathBuf> {
    let options = RunOptions {
        out: out_dir.map(Path::to_path_buf),
        fresh: false,
        shard: None,
    };
    run_study_with(path, &options, observer)
}

/// Runs the manifest at `path` as `options` say (see [`run_study`]).
pub fn run_study_with(
    path: &Path,
    options: &RunOptions,
    observer: &dyn RunObserver,
) -> anyhow::Result<PathBuf> {
    run_study_counted(path, options, observer).map(|s| s.folder)
}

/// Runs the manifest at `path` as `options` say and counts the units.
///
/// With `options.shard`, only that shard's units not yet cached are
/// computed; steps that need the results of a step with units of other
/// shards still missing are deferred; nothing but the cache and the
/// shard's record (`.palpate/shards/I-of-N.json`) is written.
pub fn run_study_counted(
    path: &Path,
    options: &RunOptions,
    observer: &dyn RunObserver,
) -> anyhow::Result<RunSummary> {
    if let (Some(shard), true) = (options.shard, options.fresh) {
        anyhow::bail!(
            "--fresh with --shard {shard}: a shard would empty the cache the other shards fill; \
             empty it once before the shards (palpate run --fresh without --shard, or remove RUN_DIR/{}/cache)",
            crate::run::run_folder::STATE
        );
    }
    let started = std::time::Instant::now();
    let started_unix_s = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    let manifest = Manifest::read(path)?.validate(path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let out = options
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(&manifest.study.name));

    let mut data = BTreeMap::new();
    for (name, spec) in &manifest.data {
        let kind = TestKind::parse(&spec.test)
            .map_err(|e| anyhow::anyhow!("{}: data.{name}.test: {e}", path.display()))?;
        let options = spec
            .read_options()
            .map_err(|e| anyhow::anyhow!("{}: data.{name}: {e:#}", path.display()))?;
        let d = TestData::read_with(name, kind, &dir.join(&spec.file), options)
            .map_err(|e| anyhow::anyhow!("{}: data.{name}: {e:#}", path.display()))?;
        data.insert(name.clone(), d);
    }
    // Data files, then the steps' own inputs (published tables, replicate
    // files), a pattern as the files it matches now.
    let mut data_files: Vec<PathBuf> = manifest.data.values().map(|d| dir.join(&d.file)).collect();
    for p in manifest.steps.iter().flat_map(|s| s.step().inputs()) {
        let p = dir.join(p);
        if crate::records::replicates::is_pattern(&p.to_string_lossy()) {
            data_files.extend(
                crate::records::replicates::expand(&p.to_string_lossy())
                    .with_context(|| format!("{}: a step's input", path.display()))?,
            );
        } else {
            data_files.push(p);
        }
    }
    let inputs: Vec<PathBuf> = std::iter::once(path.to_path_buf())
        .chain(data_files.iter().cloned())
        .collect();
    check_not_inside(&out, &inputs)?;
    let folder = match options.shard {
        None => RunFolder::open(&out, options.fresh)?,
        Some(shard) => RunFolder::open_shared(&out, shard)?,
    };
    // A shard's files (plots, report) are thrown away: only its units count.
    let scratch = match options.shard {
        Some(_) => Some(
            tempfile::Builder::new()
                .prefix(crate::run::run_folder::SHARD_SCRATCH)
                .tempdir_in(out.join(crate::run::run_folder::STATE))
                .with_context(|| format!("cannot create a scratch folder in {}", out.display()))?,
        ),
        None => None,
    };
    let stage = match &scratch {
        Some(s) => s.path().to_path_buf(),
        None => folder.staging().to_path_buf(),
    };
    let mut results = StudyResults {
        study: manifest.study.name.clone(),
        description: manifest.study.description.clone(),
        seed: manifest.study.seed,
        steps: Vec::new(),
    };
    let mut report = String::new();
    let _ = writeln!(report, "# Study `{}`\n", manifest.study.name);
    if !manifest.study.description.is_empty() {
        let _ = writeln!(report, "{}\n", manifest.study.description.trim());
    }
    let study = manifest.study_view();
    let run = Run {
        manifest: &study,
        manifest_dir: dir,
        data: &data,
        out: &stage,
        folder: &folder,
        observer,
        shard: options.shard,
        step_index: AtomicUsize::new(0),
        unit_index: AtomicUsize::new(0),
        computed: AtomicUsize::new(0),
        cached: AtomicUsize::new(0),
        others: AtomicUsize::new(0),
    };
    // Shard runs: the steps left for a later pass or the merge.
    let mut deferred: Vec<String> = Vec::new();
    for (i, step) in study.steps.iter().enumerate() {
        run.step_index.store(i, Ordering::Relaxed);
        run.unit_index.store(0, Ordering::Relaxed);
        if let Some(shard) = options.shard {
            // Steps on the results of other steps wait until those are whole;
            // steps without units of their own are left to the merge.
            let at_merge = step.step.sharding() == Sharding::AtMerge;
            let waits = step.step.sharding() != Sharding::Units && !deferred.is_empty();
            if waits || at_merge {
                observer.message(&format!(
                    "{}: left to {} (shard {shard})",
                    step.name(),
                    if waits {
                        "a later pass of the shards or the merge"
                    } else {
                        "the merge"
                    }
                ));
                deferred.push(step.name().to_string());
                continue;
            }
        }
        let others_before = run.others.load(Ordering::Relaxed);
        let body = step.step.run(&run, &results.steps, &mut report)?;
        if run.others.load(Ordering::Relaxed) > others_before {
            deferred.push(step.name().to_string());
        } else {
            results.steps.push(StepResult {
                kind: manifest.steps[i].kind(),
                body,
            });
        }
    }
    let units = UnitCounts {
        computed: run.computed.load(Ordering::Relaxed),
        cached: run.cached.load(Ordering::Relaxed),
        others: run.others.load(Ordering::Relaxed),
    };
    if let Some(shard) = options.shard {
        let record = ShardRecord {
            shard: shard.to_string(),
            manifest: path.to_path_buf(),
            cwd: std::env::current_dir().context("cannot read the working directory")?,
            manifest_sha256: hash_file(path)?.sha256,
            computed: units.computed,
            cached: units.cached,
            others: units.others,
            deferred_steps: deferred.clone(),
        };
        record.write(&out, shard)?;
        std::fs::remove_file(
            crate::run::shard::records_dir(&out).join(format!("{}.running", shard.stem())),
        )
        .ok();
        drop(scratch);
        return Ok(RunSummary {
            folder: out,
            units,
            deferred_steps: deferred,
        });
    }
    write_json(&stage.join("results.json"), &results)?;
    write_atomic(&stage.join("report.md"), report.as_bytes())?;
    let (git_commit, git_dirty) = git_state();
    let provenance = Provenance {
        palpate_version: env!("CARGO_PKG_VERSION").to_string(),
        manifest: hash_file(path)?,
        data: data_files
            .iter()
            .map(|f| hash_file(f))
            .collect::<anyhow::Result<_>>()?,
        git_commit,
        git_dirty,
        crate_versions: crate_versions(),
        seed: manifest.study.seed,
        threads: rayon::current_num_threads(),
        started_unix_s,
        wall_time_s: started.elapsed().as_secs_f64(),
        command_line: std::env::args().collect(),
    };
    write_json(&stage.join("provenance.json"), &provenance)?;
    Ok(RunSummary {
        folder: folder.commit()?,
        units,
        deferred_steps: deferred,
    })
}

/// Refuses a run folder that is an input file or holds one (the swap of a
/// rerun would remove it): the manifest and its data stay outside.
fn check_not_inside(out: &Path, inputs: &[PathBuf]) -> anyhow::Result<()> {
    let Ok(out_c) = out.canonicalize() else {
        return Ok(()); // a new folder holds nothing yet
    };
    for i in inputs {
        if let Ok(c) = i.canonicalize() {
            if c.starts_with(&out_c) {
                anyhow::bail!(
                    "run folder {}: holds the input {}; keep the manifest and its data outside the run folder (give another --out)",
                    out.display(),
                    i.display()
                );
            }
        }
    }
    Ok(())
}
