//! What a study step is, to the runner: the [`Step`] trait every step kind
//! implements (its own file under `crate::steps`, one line in that module's
//! registry), the [`Study`] a step is checked against, the [`Run`] it runs
//! in (the cache of units, shards, the observer) and the [`StepResult`] it
//! leaves in `results.json`.

use crate::model::{ModelEntry, ModelSpec};
use crate::records::{DataSpec, TestData, TestKind};
use crate::run::run_folder::RunFolder;
use crate::run::shard::Shard;
use serde::{Deserialize, Serialize};
use std::any::Any;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// One kind of study step (`[[steps]] [steps.KIND]` in a manifest).
pub trait Step: std::fmt::Debug + Send + Sync + Any {
    /// The step's name (a file-name prefix in the run folder).
    fn name(&self) -> &str;

    /// Checks the step against the rest of the study (models, data sets,
    /// earlier steps, files); errors name `at` and the offending field.
    fn validate(&self, study: &Study, at: &At) -> anyhow::Result<()>;

    /// Input files beside the data sets, relative to the manifest's folder
    /// (hashed into the provenance, kept out of the run folder).
    fn inputs(&self) -> Vec<PathBuf> {
        Vec::new()
    }

    /// When a shard run may run the step ([`Sharding`]).
    fn sharding(&self) -> Sharding {
        Sharding::Units
    }

    /// Runs the step: writes its files into `run.out`, appends its section
    /// to `report` and returns its entry of `results.json` (a JSON object
    /// whose first field is `name`). `done` holds the results of the steps
    /// before it.
    fn run(
        &self,
        run: &Run,
        done: &[StepResult],
        report: &mut String,
    ) -> anyhow::Result<serde_json::Value>;
}

/// When a shard run ([`crate::run::shard`]) may run a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sharding {
    /// Its units are spread over the shards.
    Units,
    /// It needs the results of earlier steps: it runs in a shard only when
    /// no earlier step was deferred.
    AfterEarlierSteps,
    /// It has no units of its own: the merge runs it.
    AtMerge,
}

/// Where a step sits in its manifest, for messages.
#[derive(Debug, Clone)]
pub struct At<'a> {
    /// The manifest file as shown.
    pub file: String,
    /// The step's place in `steps`.
    pub index: usize,
    /// The step's kind as spelled in manifests.
    pub kind: &'static str,
    /// The manifest's folder (relative paths start there).
    pub dir: &'a Path,
}

impl At<'_> {
    /// `steps[I].KIND ("NAME")`.
    pub fn step(&self, name: &str) -> String {
        format!("steps[{}].{} (\"{name}\")", self.index, self.kind)
    }
}

/// Name, description and seed of a study.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudyMeta {
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// Seed for everything random in the study (noise, MCMC, run order).
    #[serde(default)]
    pub seed: u64,
}

/// A study as its steps see it: the manifest's tables, and the steps as
/// [`Step`] objects.
pub struct Study<'a> {
    pub study: &'a StudyMeta,
    pub data: &'a BTreeMap<String, DataSpec>,
    pub models: &'a BTreeMap<String, ModelEntry>,
    pub steps: Vec<StepRef<'a>>,
}

/// A step of a study with its kind.
#[derive(Clone, Copy)]
pub struct StepRef<'a> {
    /// The kind as spelled in manifests.
    pub kind: &'static str,
    pub step: &'a dyn Step,
}

impl<'a> StepRef<'a> {
    /// The step's name.
    pub fn name(&self) -> &'a str {
        self.step.name()
    }

    /// The step's settings when it is a `T`.
    pub fn get<T: Step>(&self) -> Option<&'a T> {
        let any: &'a dyn Any = self.step;
        any.downcast_ref::<T>()
    }
}

impl Study<'_> {
    /// Checks that a model spec predicts the records of data set `data`.
    pub(crate) fn check_predicts(
        &self,
        where_: String,
        at: &str,
        model: &str,
        spec: &ModelSpec,
        data: &str,
    ) -> anyhow::Result<()> {
        let Some(d) = self.data.get(data) else {
            return Ok(());
        };
        let test = TestKind::parse(&d.test)?;
        if spec.test().ok() != Some(test) {
            anyhow::bail!(
                "{where_}: {at}: model \"{model}\" ({}) does not predict data set \"{data}\" (a {} test)",
                spec.kind(),
                d.test
            );
        }
        Ok(())
    }
}

/// The first entry of a list that appears twice.
pub(crate) fn duplicate(list: &[String]) -> Option<&String> {
    list.iter()
        .enumerate()
        .find(|(i, x)| list[..*i].contains(x))
        .map(|(_, x)| x)
}

/// The names of a table's entries, for messages (`none` when empty).
pub(crate) fn keys<V>(m: &BTreeMap<String, V>) -> String {
    if m.is_empty() {
        "none".into()
    } else {
        m.keys().cloned().collect::<Vec<_>>().join(", ")
    }
}

/// The results of one step in `results.json`: `{"KIND": {"name": ..., ...}}`.
/// Each fit, case or run is held as JSON so that a unit read from the
/// cache and one computed now give the same bytes.
#[derive(Debug, Clone)]
pub struct StepResult {
    /// The step's kind, as spelled in manifests.
    pub kind: &'static str,
    /// What [`Step::run`] returned.
    pub body: serde_json::Value,
}

impl StepResult {
    /// The step's name.
    pub fn name(&self) -> &str {
        self.body.get("name").and_then(|n| n.as_str()).unwrap_or("")
    }

    /// A field of the step's result (`fits` of a calibrate step, ...).
    pub fn get(&self, field: &str) -> Option<&serde_json::Value> {
        self.body.get(field)
    }
}

/// The list `field` of the results of the step of kind `kind` named `name`
/// in `done` (a predict step reads its calibrate step's `fits`).
pub fn find_list<'r>(
    done: &'r [StepResult],
    kind: &str,
    name: &str,
    field: &str,
) -> Option<&'r Vec<serde_json::Value>> {
    done.iter()
        .find(|r| r.kind == kind && r.name() == name)?
        .get(field)?
        .as_array()
}

impl Serialize for StepResult {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(1))?;
        m.serialize_entry(self.kind, &self.body)?;
        m.end()
    }
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

/// One study run: what every step needs (the fields are the crate's).
pub struct Run<'a> {
    pub(crate) manifest: &'a Study<'a>,
    /// The manifest's folder (its relative paths start there).
    pub(crate) manifest_dir: &'a Path,
    pub(crate) data: &'a BTreeMap<String, TestData>,
    /// The staging folder the files are written into.
    pub(crate) out: &'a Path,
    pub(crate) folder: &'a RunFolder,
    pub(crate) observer: &'a dyn RunObserver,
    /// A shard run computes only its own units ([`crate::run::shard`]).
    pub(crate) shard: Option<Shard>,
    /// The step being run and the number of its units met so far (the
    /// unit's place, which says which shard computes it).
    pub(crate) step_index: AtomicUsize,
    pub(crate) unit_index: AtomicUsize,
    pub(crate) computed: AtomicUsize,
    pub(crate) cached: AtomicUsize,
    pub(crate) others: AtomicUsize,
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
}
