//! Runs a study manifest into a run folder:
//!
//! * `results.json` — every number, byte-identical on a rerun (no times, no
//!   paths outside the manifest's own names);
//! * `report.md` — a readable report with comparison tables;
//! * `plots/*.svg`;
//! * `provenance.json` — hashes, git commit, crate versions, seed, threads, timings.
//!
//! The folder is staged, locked, marked while incomplete and resumable
//! ([`crate::run_folder`]): each fit and each diagnosed record is a unit
//! cached under the hash of its inputs, so a rerun (after a kill, or after
//! an edit of another step) computes only the units whose inputs changed.

use crate::calibration::{Calibration, TestData, TestKind};
use crate::manifest::{CalibrateStep, DiagnoseStep, Manifest, Step};
use crate::output::{write_atomic, write_json};
use crate::provenance::{crate_versions, git_state, hash_file, Provenance};
use crate::run_folder::RunFolder;
use crate::shard::{Shard, ShardRecord};
use anyhow::Context;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The results of a whole study (`results.json`).
#[derive(Debug, Clone, Serialize)]
pub struct StudyResults {
    pub study: String,
    pub description: String,
    pub seed: u64,
    pub steps: Vec<StepResult>,
}

/// The results of one step. Each fit is a [`FitEntry`] and each case a
/// [`DiagnoseEntry`], held as JSON so that a unit read from the cache and
/// one computed now give the same bytes.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StepResult {
    Calibrate {
        name: String,
        fits: Vec<serde_json::Value>,
    },
    Diagnose {
        name: String,
        cases: Vec<serde_json::Value>,
    },
    /// [`crate::predict_step`]: each model's run and each (model, record) comparison.
    Predict {
        name: String,
        runs: Vec<serde_json::Value>,
        comparisons: Vec<serde_json::Value>,
    },
    /// [`crate::two_stage`]: the staged inverse FE identification of a Q1 record.
    TwoStage {
        name: String,
        result: serde_json::Value,
    },
    /// [`crate::anova_step`]: the runs, our analysis and the published one.
    Anova {
        name: String,
        runs: serde_json::Value,
        analysis: serde_json::Value,
        published: Option<serde_json::Value>,
    },
    /// [`crate::localize_step`]: per RD, the localisation and the peak-force table.
    Localize {
        name: String,
        results: Vec<serde_json::Value>,
    },
    /// [`crate::sample_step`]: the posterior summary.
    Sample {
        name: String,
        result: serde_json::Value,
    },
}

/// How to run a study.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Run folder (default `runs/<study name>`).
    pub out: Option<PathBuf>,
    /// Compute every unit again (the cache of finished units is emptied).
    pub fresh: bool,
    /// Compute only this shard's units into the cache ([`crate::shard`]):
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

/// One fit of a calibrate step.
#[derive(Debug, Clone, Serialize)]
pub struct FitEntry {
    pub model: String,
    pub group: String,
    pub residual: String,
    pub calibration: Calibration,
}

/// One diagnosed data set.
#[derive(Debug, Clone, Serialize)]
pub struct DiagnoseEntry {
    pub data: String,
    pub report: serde_json::Value,
}

/// Progress messages of a run (the CLI shows them; tests ignore them).
pub trait RunObserver {
    fn message(&self, text: &str);
    /// `done` of `total` load steps of the FE runs of a step (`label`);
    /// called on the runner's thread.
    fn progress(&self, _label: &str, _done: u64, _total: u64) {}
}

impl<F: Fn(&str)> RunObserver for F {
    fn message(&self, text: &str) {
        self(text)
    }
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
            crate::run_folder::STATE
        );
    }
    let started = std::time::Instant::now();
    let started_unix_s = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    let manifest = Manifest::read(path)?;
    manifest.validate(path)?;
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
    // Data files, then the published tables of anova steps.
    let data_files: Vec<PathBuf> = manifest
        .data
        .values()
        .map(|d| dir.join(&d.file))
        .chain(manifest.steps.iter().filter_map(|s| match s {
            Step::Anova(a) => a.published.as_ref().map(|p| dir.join(p)),
            Step::TwoStage(t) => Some(dir.join(&t.record)),
            _ => None,
        }))
        .collect();
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
                .prefix(crate::run_folder::SHARD_SCRATCH)
                .tempdir_in(out.join(crate::run_folder::STATE))
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
    let run = Run {
        manifest: &manifest,
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
    for (i, step) in manifest.steps.iter().enumerate() {
        run.step_index.store(i, Ordering::Relaxed);
        run.unit_index.store(0, Ordering::Relaxed);
        if let Some(shard) = options.shard {
            // Steps on the results of other steps wait until those are whole;
            // steps without units of their own are left to the merge.
            let waits = matches!(step, Step::Predict(_) | Step::Anova(_)) && !deferred.is_empty();
            if waits || matches!(step, Step::Anova(_)) {
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
        let r = match step {
            Step::Calibrate(c) => run.calibrate(c, &mut report)?,
            Step::Diagnose(d) => run.diagnose(d, &mut report)?,
            Step::Predict(p) => {
                crate::predict_step::run_predict(&run, p, &results.steps, &mut report)?
            }
            Step::Anova(a) => crate::anova_step::run_anova(&run, a, &results.steps, &mut report)?,
            Step::TwoStage(t) => crate::two_stage_step::run_two_stage(&run, t, &mut report)?,
            Step::Localize(l) => crate::localize_step::run_localize(&run, l, &mut report)?,
            Step::Sample(p) => crate::sample_step::run_sample(&run, p, &mut report)?,
        };
        if run.others.load(Ordering::Relaxed) > others_before {
            deferred.push(step.name().to_string());
        } else {
            results.steps.push(r);
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
            crate::shard::records_dir(&out).join(format!("{}.running", shard.stem())),
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

/// One study run: what every step needs.
pub(crate) struct Run<'a> {
    pub(crate) manifest: &'a Manifest,
    /// The manifest's folder (its relative paths start there).
    pub(crate) manifest_dir: &'a Path,
    pub(crate) data: &'a BTreeMap<String, TestData>,
    /// The staging folder the files are written into.
    pub(crate) out: &'a Path,
    pub(crate) folder: &'a RunFolder,
    pub(crate) observer: &'a dyn RunObserver,
    /// A shard run computes only its own units ([`crate::shard`]).
    pub(crate) shard: Option<Shard>,
    /// The step being run and the number of its units met so far (the
    /// unit's place, which says which shard computes it).
    step_index: AtomicUsize,
    unit_index: AtomicUsize,
    computed: AtomicUsize,
    cached: AtomicUsize,
    others: AtomicUsize,
}

impl Run<'_> {
    /// A unit's record: from the cache when its inputs are unchanged, else
    /// computed and cached at once (so a kill after it keeps it). `None`:
    /// a unit of another shard, not cached yet (shard runs only).
    pub(crate) fn unit<T, K>(
        &self,
        label: &str,
        inputs: &K,
        compute: impl FnOnce() -> anyhow::Result<T>,
    ) -> anyhow::Result<Option<T>>
    where
        T: Serialize + serde::de::DeserializeOwned,
        K: std::fmt::Debug,
    {
        let key = RunFolder::key(inputs);
        let claim = self.claim(&key);
        if claim.is_none() {
            if let Some(record) = self.folder.cached(&key) {
                self.observer.message(&format!("{label} (cached)"));
                return Ok(Some(record));
            }
            // Unreadable: computed again (by its owner).
        }
        if claim == Some(false) {
            return Ok(None);
        }
        self.observer.message(label);
        let record = compute()?;
        self.folder.store(&key, &record)?;
        Ok(Some(record))
    }

    /// Takes the next unit of the step (key `key`): `None` when it is
    /// cached, else whether this process computes it (every unit without
    /// shards; the shard's own ones with). Counts the unit. Call it once
    /// per unit, in the manifest's order, cached or not.
    pub(crate) fn claim(&self, key: &str) -> Option<bool> {
        let k = self.unit_index.fetch_add(1, Ordering::Relaxed);
        if self.folder.has(key) {
            self.cached.fetch_add(1, Ordering::Relaxed);
            return None;
        }
        let mine = self
            .shard
            .is_none_or(|s| s.owns(self.step_index.load(Ordering::Relaxed), k));
        let counter = if mine { &self.computed } else { &self.others };
        counter.fetch_add(1, Ordering::Relaxed);
        Some(mine)
    }

    /// Counts the next unit of the step (key `key`) as one that cannot be
    /// computed yet (it needs units of other shards): cached, or left to a
    /// later pass or the merge whichever shard owns it. Call it where
    /// [`Run::claim`] would be called.
    pub(crate) fn wait(&self, key: &str) {
        self.unit_index.fetch_add(1, Ordering::Relaxed);
        let counter = if self.folder.has(key) {
            &self.cached
        } else {
            &self.others
        };
        counter.fetch_add(1, Ordering::Relaxed);
    }

    /// The units of `keys` (in order, each claimed once): cached ones read,
    /// this process's computed in parallel (`compute(k)`), each cached as
    /// soon as it is done, others' `None`.
    pub(crate) fn units<T>(
        &self,
        keys: &[String],
        label: &str,
        compute: impl Fn(usize) -> anyhow::Result<T> + Sync,
    ) -> anyhow::Result<Vec<Option<T>>>
    where
        T: Serialize + serde::de::DeserializeOwned + Send,
    {
        self.units_when(keys, &vec![true; keys.len()], label, compute)
    }

    /// [`Run::units`] for units of a second level: unit k can be computed
    /// only when `ready[k]` (the units it needs are all there); one not
    /// ready is counted with [`Run::wait`] at its place and is `None`. Every
    /// process meets the units in the same order, ready or not, so they
    /// agree on each unit's owner.
    pub(crate) fn units_when<T>(
        &self,
        keys: &[String],
        ready: &[bool],
        label: &str,
        compute: impl Fn(usize) -> anyhow::Result<T> + Sync,
    ) -> anyhow::Result<Vec<Option<T>>>
    where
        T: Serialize + serde::de::DeserializeOwned + Send,
    {
        use rayon::prelude::*;
        let claims: Vec<Option<Option<bool>>> = keys
            .iter()
            .zip(ready)
            .map(|(k, &r)| {
                if r {
                    Some(self.claim(k))
                } else {
                    self.wait(k);
                    None
                }
            })
            .collect();
        let mut out: Vec<Option<T>> = keys
            .iter()
            .zip(&claims)
            .map(|(k, c)| c.and_then(|_| self.folder.cached(k)))
            .collect();
        let cached = out.iter().filter(|u| u.is_some()).count();
        if cached > 0 {
            self.observer
                .message(&format!("{label}: {cached} of {} cached", keys.len()));
        }
        let todo: Vec<usize> = (0..keys.len())
            .filter(|&k| out[k].is_none() && matches!(claims[k], Some(c) if c != Some(false)))
            .collect();
        if !todo.is_empty() {
            self.observer.message(&format!(
                "{label}: computing {} of {}",
                todo.len(),
                keys.len()
            ));
            // Each unit is cached as soon as it is computed: a kill (or a
            // failed unit) keeps the others (FE runs of minutes each).
            let folder = self.folder;
            let done: Vec<anyhow::Result<T>> = todo
                .par_iter()
                .map(|&k| {
                    let unit = compute(k)?;
                    folder.store(&keys[k], &unit)?;
                    Ok(unit)
                })
                .collect();
            for (&k, r) in todo.iter().zip(done) {
                out[k] = Some(r?);
            }
        }
        Ok(out)
    }

    fn calibrate(&self, step: &CalibrateStep, report: &mut String) -> anyhow::Result<StepResult> {
        crate::calibrate_step::run_calibrate(self, step, report)
    }

    fn diagnose(&self, step: &DiagnoseStep, report: &mut String) -> anyhow::Result<StepResult> {
        crate::diagnose_step::run_diagnose(self, step, report)
    }
}
